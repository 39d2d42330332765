//! UVDtact's acrylic shell, made to order by a machine shop (Sec. III: "CNC machining,
//! followed by vapor polishing", 2 mm wall): its solid against the analytic volume, its
//! drawing's dimensions against the solid, its least wall against a brute-force distance
//! between the exact curves, the assembly's core as the same hollow shell, and bad values
//! refused by path.

use crate::common::{assert_each_rule_names_its_path, RuleCase};
use fabkit_designs::assembly::ExactShape;
use fabkit_designs::parts::core_shell::{DimensionAxis, MachinedPart};
use fabkit_designs::{build_kit, library, ChordTolerance, Design, Kit};
use std::f64::consts::PI;
use std::sync::OnceLock;

fn uvdtact() -> Design {
    library::load("uvdtact").unwrap()
}

fn kit() -> &'static Kit {
    static KIT: OnceLock<Kit> = OnceLock::new();
    KIT.get_or_init(|| build_kit(&uvdtact(), ChordTolerance::new(0.01).unwrap()).unwrap())
}

fn shell() -> &'static MachinedPart {
    let k = kit();
    assert_eq!(k.machined_parts.len(), 1);
    &k.machined_parts[0]
}

/// The skin is the 9 x 24 mm half ellipsoid, its layers 1.5 + 0.5 + 0.4 mm: the shell's outer
/// surface is the body's offset 2.4 mm inward (rim 6.6 mm, pole 21.6 mm), its inner surface
/// the half ellipsoid 4.6 x 19.6 mm, both continued 5 mm under the base plane (26.6 mm from
/// the pole). Volume: the outer solid (exact curve) less pi 4.6^2 (2/3 19.6 + 5), within the
/// chords (area x tolerance).
#[test]
fn acrylic_shell_has_its_analytic_size_and_volume() {
    let s = shell();
    assert_eq!(s.name, "acrylic_shell");
    assert_eq!(s.material, "pmma");
    let b = s.solid.bounding_box().unwrap();
    for (got, want) in [
        (b.max[0] - b.min[0], 13.2),
        (b.max[1] - b.min[1], 13.2),
        (b.min[2], -5.0),
        (b.max[2], 21.6),
    ] {
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
    }
    let d = uvdtact();
    let outer = d.body.analytic_solid_volume_mm3(-2.4, 5.0);
    let inner = PI * 4.6 * 4.6 * (2.0 / 3.0 * 19.6 + 5.0);
    let want = outer - inner;
    let bound = s.solid.mesh().surface_area() * 0.01;
    let v = s.solid.volume();
    assert!((v - want).abs() <= bound, "{v} vs {want} (bound {bound})");
    assert!(
        v < want + 1e-9,
        "an inscribed polyline cannot hold more: {v} > {want}"
    );
    assert!(matches!(s.exact, ExactShape::CoreShell { .. }));
}

/// Every dimension of the drawing is what the solid measures: the overall length and the
/// outer diameter from its bounding box, the bore, its depth, the pole wall and the foot from
/// the profile's own points.
#[test]
fn drawing_dimensions_are_the_solids() {
    let s = shell();
    let b = s.solid.bounding_box().unwrap();
    let label = |l: &str| {
        s.drawing
            .dimensions
            .iter()
            .find(|d| d.label == l)
            .unwrap_or_else(|| panic!("no dimension {l}: {:?}", s.drawing.dimensions))
    };
    let overall = label("26.60");
    assert_eq!(overall.axis, DimensionAxis::Vertical);
    assert!((overall.value_mm - (b.max[2] - b.min[2])).abs() < 1e-6);
    assert!((label("Ø13.20").value_mm - (b.max[0] - b.min[0])).abs() < 1e-6);
    // the bore: the profile's innermost point on the open end, and its deepest on the axis
    let pts = &s.drawing.section_rz_mm;
    let bore_r = pts
        .iter()
        .filter(|p| (p[1] + 5.0).abs() < 1e-9)
        .map(|p| p[0])
        .fold(f64::INFINITY, f64::min);
    let axis_z: Vec<f64> = pts.iter().filter(|p| p[0] == 0.0).map(|p| p[1]).collect();
    assert_eq!(axis_z.len(), 2, "{axis_z:?}");
    let (inner_pole, outer_pole) = (axis_z[1].min(axis_z[0]), axis_z[1].max(axis_z[0]));
    assert!((label("Ø9.20").value_mm - 2.0 * bore_r).abs() < 1e-6);
    assert!((label("24.60").value_mm - (inner_pole + 5.0)).abs() < 1e-6);
    assert!((label("2.00").value_mm - (outer_pole - inner_pole)).abs() < 1e-6);
    assert!((label("5.00").value_mm - 5.0).abs() < 1e-6);
    assert_eq!(s.drawing.dimensions.len(), 6);
    assert!(s
        .drawing
        .notes
        .iter()
        .any(|n| n.contains("general tolerance +/-0.05 mm")));
}

/// The wall is 2 mm at the pole and the rim and thinner between (the inner half ellipsoid is
/// not the outer surface's normal offset, which folds): the least wall the part reports is the
/// smallest distance from 4001 points of the exact inner ellipse to 40001 points of the exact
/// outer offset curve, within 2 µm, and the drawing's notes give it.
#[test]
fn least_wall_is_the_distance_between_the_exact_curves() {
    let s = shell();
    let (a, c, d) = (9.0f64, 24.0f64, -2.4f64);
    let outer: Vec<[f64; 2]> = (0..=40000)
        .map(|i| {
            let th = std::f64::consts::FRAC_PI_2 * i as f64 / 40000.0;
            let n = [c * th.cos(), a * th.sin()];
            let l = n[0].hypot(n[1]);
            [a * th.cos() + d * n[0] / l, c * th.sin() + d * n[1] / l]
        })
        .collect();
    let mut least = f64::INFINITY;
    for i in 0..=4000 {
        let th = std::f64::consts::FRAC_PI_2 * i as f64 / 4000.0;
        let p = [4.6 * th.cos(), 19.6 * th.sin()];
        for q in &outer {
            least = least.min((p[0] - q[0]).hypot(p[1] - q[1]));
        }
    }
    let got = s.params["least_wall_mm"].as_f64().unwrap();
    // measured -1.8e-4 mm: fabkit reads the outer curve from a polyline within 1 µm inside it
    // (`least_wall_mm`), so it may come out up to 1e-3 mm short; the samples (2001 and 4001 of
    // the inner curve, 40001 of the outer) add under 1e-5 mm
    assert!((got - least).abs() < 2e-3, "{got} vs {least}");
    // measured 1.329 mm
    assert!(got < 2.0 && got > 1.0, "{got}");
    let note = format!("{got:.2} mm at its thinnest");
    assert!(
        s.drawing.notes.iter().any(|n| n.contains(&note)),
        "{:?}",
        s.drawing.notes
    );
}

/// The assembly's core is the same hollow shell (so that the camera's side sees a bore), not
/// the solid under its outer surface; its STEP solid is the same profile revolved.
#[test]
fn assembly_core_is_the_machined_shell() {
    let m = kit()
        .assembly
        .iter()
        .find(|m| m.name == "core_envelope")
        .unwrap();
    let (a, b) = (m.solid.volume(), shell().solid.volume());
    assert!((a - b).abs() < 1e-6 * b, "{a} vs {b}");
    match &m.exact {
        Some(ExactShape::Revolved { profile_rz_mm }) => {
            assert_eq!(profile_rz_mm, &shell().drawing.section_rz_mm)
        }
        other => panic!("{other:?}"),
    }
}

/// Designs without `core.machining` have no machined part (R-Tac0's bought test tube).
#[test]
fn bought_cores_are_not_machined() {
    let d = library::load("rtac0").unwrap();
    let k = build_kit(&d, ChordTolerance::new(0.05).unwrap()).unwrap();
    assert!(k.machined_parts.is_empty());
}

#[test]
fn bad_machining_values_are_refused_by_path() {
    fn m(d: &mut Design) -> &mut fabkit_designs::schema::CoreMachining {
        d.core.as_mut().unwrap().machining.as_mut().unwrap()
    }
    let cases: &[RuleCase] = &[
        ("core.machining.part_name", |d| {
            m(d).part_name = "Acrylic shell".into()
        }),
        ("core.machining.finish", |d| m(d).finish = " ".into()),
        ("core.machining.general_tolerance_mm", |d| {
            m(d).general_tolerance_mm = 0.0
        }),
        ("core.machining.general_tolerance_mm", |d| {
            m(d).general_tolerance_mm = f64::NAN
        }),
        // the 6.6 mm rim radius leaves no bore under a 7 mm wall
        ("core.wall_thickness_mm", |d| {
            d.core.as_mut().unwrap().wall_thickness_mm = 7.0
        }),
    ];
    assert_each_rule_names_its_path(uvdtact, cases);
}

/// The drawing and the STEP file are named after the part: a name another part of the kit
/// has is refused by path.
#[test]
fn machined_part_name_must_be_its_own() {
    let mut d = uvdtact();
    d.core
        .as_mut()
        .unwrap()
        .machining
        .as_mut()
        .unwrap()
        .part_name = "shell_holder".into();
    match build_kit(&d, ChordTolerance::new(0.05).unwrap()) {
        Err(fabkit_designs::DesignError::Params(e)) => assert!(
            e.0.len() == 1
                && e.0[0].path == "core.machining.part_name"
                && e.0[0].value == "shell_holder",
            "{e}"
        ),
        other => panic!("{:?}", other.map(|k| k.design)),
    }
}
