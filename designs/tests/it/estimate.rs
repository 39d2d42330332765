//! The work estimate ([`fabkit_designs::estimate`]) against the kits it estimates.

use fabkit_designs::estimate::{check_work, estimate, MAX_TRIANGLES_LIMIT};
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::{build_kit, library, stack, ChordTolerance, DesignError};

/// Every library design and preset, at two tolerances: the estimate, made from the parameters
/// before anything is built, is within 0.75 to 2.6 times the triangles of the built kit, and its
/// marker count is the kit's.
///
/// Measured 0.87 (uvdtact_no_markers at 0.05 mm) to 2.28 (digit_pinki at 0.05 mm); the bounds
/// are 14 % beyond them (0.8 and 2.5 were 8 % and 10 %). An estimate that left out the markers
/// (36 to 91 % of it where there are any) would fall to 0.6 or less.
#[test]
fn estimate_is_within_a_small_factor_of_every_library_kit() {
    let materials = MaterialsTable::embedded().unwrap();
    let mut checked = 0;
    for d in crate::common::library_designs_and_presets() {
        for mm in [0.01, 0.05] {
            let tol = ChordTolerance::new(mm).unwrap();
            let kit = build_kit(&d, tol).unwrap();
            let actual: usize = kit.parts.iter().map(|p| p.solid.triangle_count()).sum();
            if d.body.flat_outline().is_some() {
                // a flat skin's trays and layers: their own estimate (prisms, ribs, markers
                // and their holes), and its part families'
                let layers = fabkit_designs::stack::flat::validate(&d, &materials).unwrap();
                let e = fabkit_designs::flat::estimated_triangles(
                    &layers,
                    d.mold.laser_cut.is_some(),
                    tol,
                ) + fabkit_designs::parts::flat_family::estimated_triangles(&d, tol);
                let actual = actual
                    + kit
                        .assembly
                        .iter()
                        .map(|m| m.solid.triangle_count())
                        .sum::<usize>();
                let ratio = e / actual as f64;
                assert!(
                    (0.75..=2.6).contains(&ratio),
                    "{} at {mm} mm: estimate {e} vs {actual} triangles ({ratio:.2})",
                    d.name
                );
                checked += 1;
                continue;
            }
            let st = stack::validate(&d, &materials, tol).unwrap();
            let e = estimate(&d, &st, tol);
            let ratio = e.triangles as f64 / actual as f64;
            assert!(
                (0.75..=2.6).contains(&ratio),
                "{} at {mm} mm: estimate {} vs {actual} triangles ({ratio:.2})",
                d.name,
                e.triangles
            );
            let placed: u64 = kit.summary["markers"]
                .as_array()
                .map_or(0, |a| a.iter().map(|m| m["count"].as_u64().unwrap()).sum());
            assert_eq!(e.markers, placed, "{}", d.name);
            checked += 1;
        }
    }
    assert!(checked >= 20, "{checked} kits");
}

/// Past the limit the estimate is refused with the estimate, the limit and how to raise it;
/// the estimate grows about as 1 / tolerance (a little slower: small circles keep their
/// minimum of 8 segments).
#[test]
fn check_work_refuses_past_the_limit_and_names_the_remedy() {
    let materials = MaterialsTable::embedded().unwrap();
    let d = library::load("shadowtac").unwrap();
    let coarse = ChordTolerance::new(0.01).unwrap();
    let fine = ChordTolerance::new(0.001).unwrap();
    let st = stack::validate(&d, &materials, coarse).unwrap();
    let e_coarse = estimate(&d, &st, coarse).triangles as f64;
    let e_fine = estimate(&d, &st, fine).triangles as f64;
    // measured 7.29: a revolved surface's facets go as 1 / tolerance (segments along and around
    // as 1 / sqrt(tolerance)); counts rounded up to multiples of 4 (at least 8) and flat faces
    // keep the coarse count relatively larger
    assert!(
        (6.0..11.0).contains(&(e_fine / e_coarse)),
        "{e_fine} / {e_coarse}"
    );
    let ok = check_work(&d, &st, coarse, MAX_TRIANGLES_LIMIT).unwrap();
    match check_work(&d, &st, coarse, ok.triangles - 1) {
        Err(DesignError::WorkLimit(m)) => {
            assert!(
                m.contains(&format!("about {} triangles", ok.triangles))
                    && m.contains(&format!("more than the limit of {}", ok.triangles - 1))
                    && m.contains("469 marker features")
                    && m.contains("--max-triangles"),
                "{m}"
            );
        }
        other => panic!("{other:?}"),
    }
}
