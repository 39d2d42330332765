use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::variant::*;
use fabkit_designs::ChordTolerance;

#[test]
fn shadowtac_metrics_match_the_design() {
    let tol = ChordTolerance::new(0.05).unwrap();
    let materials = MaterialsTable::embedded().unwrap();
    // the paper's text: dimples concentric at 1.4 mm, one open mold
    let d = fabkit_designs::library::load("shadowtac")
        .unwrap()
        .with_preset("paper_text")
        .unwrap();
    let Outcome::Ok { metrics: m, kit } = evaluate(&d, &materials, tol) else {
        panic!("shadowtac builds");
    };
    assert_eq!(m.parts.len(), kit.parts.len());
    assert_eq!(
        m.triangles,
        kit.parts
            .iter()
            .map(|p| p.solid.triangle_count())
            .sum::<usize>()
    );
    assert_eq!(m.markers.len(), 1);
    let mk = &m.markers[0];
    // concentric at 1.4 mm: every ring's neighbours are about 1.4 mm apart. Measured 543
    // markers (the patterned cap's 1070 mm^2 / 1.4^2 = 547) and a median of 1.395 mm: rings
    // 1.4 mm of arc apart (none nearer across rings), round(2 pi r / 1.4) markers on each, so
    // neighbours along a ring 1.4 (1 +- 1 / 2n) apart, +-0.9 % round the median marker (r 12.5,
    // n 56), +-8 % only on ring 1
    assert!(mk.count > 400, "{mk:?}");
    assert!(mk.median_spacing_mm > 1.3 && mk.median_spacing_mm < 1.45);
    // the thinnest wall is at the dimples: between the outer ring's recesses and the base
    // plane, below the wall between neighbouring dimples' bases (spacing minus the 0.45 mm
    // diameter), and above the SLA profile's 0.4 mm minimum wall
    let w = m.min_wall_mm.unwrap();
    assert!(w < mk.min_spacing_mm - 0.45 && w > 0.4, "{w} {mk:?}");
    let at = m.min_wall_at.unwrap();
    assert_eq!(
        at, "layers[0].markers[0]: between recesses and the base plane",
        "{w}"
    );
    // one pour: the skin, its mass is the volume times the density plus the waste allowance
    assert_eq!(m.casts.len(), 1);
    let c = &m.casts[0];
    let rho = materials.get(&c.material).unwrap().density_g_per_cm3;
    assert!((c.total_mass_g - c.cavity_volume_ml * rho * 1.2).abs() < 1e-6 * c.total_mass_g);
    // 0.45 mm dimples: SLA (0.4 mm holes) and PolyJet (0.5 mm features) differ, FDM cannot
    let v = printability(&d, &materials, tol);
    let by = |p: &str| v.iter().find(|x| x.profile == p).unwrap();
    assert!(by("sla").printable);
    assert!(!by("fdm").printable);
    assert!(by("fdm").violations[0].contains("printer profile 'fdm'"));
    assert!(!by("polyjet").printable);
}
