//! The housing of a flat sensor (`flat_housing`; parts/flat_housing.rs) on 9DTact's published
//! numbers (the library design `ninedtact`): its parts are closed solids of the published volumes,
//! they fit together and round the skin in the sensor frame as the published sensor's do, and
//! every rule is refused by its path.

use crate::common::refused_paths;
use fabkit_designs::schema::value_at;
use fabkit_designs::{library, ChordTolerance, Design};
use serde_json::{json, Value};
use std::f64::consts::PI;

fn tol() -> ChordTolerance {
    ChordTolerance::new(0.01).unwrap()
}

fn ninedtact() -> Design {
    library::load("ninedtact").unwrap()
}

/// `d` with the value at each `(path, value)` replaced.
fn with(d: &Design, changes: &[(&str, Value)]) -> Design {
    let mut v = serde_json::to_value(d).unwrap();
    for (path, value) in changes {
        *value_at(&mut v, path).unwrap_or_else(|| panic!("no {path}")) = value.clone();
    }
    serde_json::from_value(v).unwrap()
}

/// The three printed parts are closed solids of the published parts' volumes (the STEP files'
/// by OCCT: shell 5224.227, base 2419.591, ring 158.562 mm3) within the tessellation's share;
/// the ring's is also the analytic one (the square less the bore and the 45-degree
/// countersink's frustum). The window fills the chamber less its clearance from the collar's
/// top up to the skin's base plane, the ring the aperture up to the collar's top, and the
/// members fit (the build's fit check passed, and the skin lies on the shell's top face).
#[test]
fn ninedtact_housing_has_the_published_volumes_and_fits() {
    let k = fabkit_designs::build_kit(&ninedtact(), tol()).unwrap();
    let ring_analytic = 11.9 * 11.9 * 2.8
        - PI * 5.05 * 5.05 * 1.9
        - PI * 0.9 / 3.0 * (5.05 * 5.05 + 5.05 * 5.95 + 5.95 * 5.95);
    assert!((ring_analytic - 158.562).abs() < 1e-3, "{ring_analytic}");
    for (name, published) in [
        ("flat_shell", 5224.227),
        ("flat_base", 2419.591),
        ("isolation_ring", ring_analytic),
    ] {
        let p = k.parts.iter().find(|p| p.name == name).unwrap();
        let mesh = p.written_mesh();
        mesh.check_closed_manifold().unwrap();
        let v = mesh.signed_volume();
        // an inscribed tessellation misses at most its area times the chord tolerance
        let bound = mesh.surface_area() * tol().mm();
        assert!(
            (v - published).abs() < bound,
            "{name}: {v} mm3 against {published} (bound {bound})"
        );
    }
    let member = |name: &str| k.assembly.iter().find(|m| m.name == name).unwrap();
    let bb = |name: &str| member(name).solid.bounding_box().unwrap();
    let window = bb("window");
    assert!((window.min[2] + 10.4).abs() < 1e-9 && window.max[2].abs() < 1e-9);
    assert!((window.max[0] - (28.5 / 2.0 - 0.1)).abs() < 1e-9);
    let ring = bb("isolation_ring");
    assert!((ring.min[2] + 13.2).abs() < 1e-9 && (ring.max[2] + 10.4).abs() < 1e-9);
    let shell = bb("flat_shell");
    assert!(shell.max[2].abs() < 1e-9 && (shell.min[2] + 19.5).abs() < 1e-9);
    let base = bb("flat_base");
    assert!((base.min[2] + 22.5).abs() < 1e-9 && (base.max[2] + 14.0).abs() < 1e-9);
    let black = bb("black_gel");
    assert!(black.min[2].abs() < 1e-9 && black.max[0] <= 16.25);
    // the housing's parts, its window's drawing, its bought items and its assembly steps
    assert!(k.cut_parts.iter().any(|c| c.name == "window"));
    assert!(k
        .bought_items
        .iter()
        .any(|b| b.contains("heat-set inserts")));
    assert!(k
        .procedure
        .iter()
        .any(|s| s.text.contains("screw the base to the shell")));
}

/// A camera boss moved onto the shell's screw boss is an interference the fit check names.
#[test]
fn a_base_that_does_not_fit_the_shell_is_refused() {
    let d = with(
        &ninedtact(),
        &[(
            "flat_housing.base.camera_bosses.xy_mm",
            json!([[12.0, 8.5], [-8.5, 7.75], [-8.5, -7.75], [8.5, -7.75]]),
        )],
    );
    let paths = refused_paths(&d, "a boss into the shell's");
    assert!(
        paths
            .iter()
            .any(|p| p == "flat_housing.base" || p == "flat_housing.shell"),
        "{paths:?}"
    );
}

/// One mutation per rule, each refused at its path.
#[test]
fn flat_housing_rules_are_refused_by_path() {
    let base = ninedtact();
    let cases: &[(&str, Value, &str)] = &[
        (
            "flat_housing.shell.height_mm",
            json!(0.0),
            "flat_housing.shell.height_mm",
        ),
        (
            "flat_housing.shell.wall_mm",
            json!(13.0),
            "flat_housing.shell.wall_mm",
        ),
        (
            "flat_housing.shell.chamber_corner_radius_mm",
            json!(11.0),
            "flat_housing.shell.chamber_corner_radius_mm",
        ),
        (
            "flat_housing.shell.chamber_depth_mm",
            json!(18.0),
            "flat_housing.shell.chamber_depth_mm",
        ),
        (
            "flat_housing.shell.collar.inner_mm",
            json!(12.0),
            "flat_housing.shell.collar.inner_mm",
        ),
        (
            "flat_housing.shell.collar.width_mm",
            json!(4.0),
            "flat_housing.shell.collar.width_mm",
        ),
        (
            "flat_housing.shell.collar.height_mm",
            json!(11.2),
            "flat_housing.shell.collar.height_mm",
        ),
        (
            "flat_housing.shell.ceiling_fillet_mm",
            json!(1.2),
            "flat_housing.shell.ceiling_fillet_mm",
        ),
        (
            "flat_housing.shell.outline.corner_radius_mm",
            json!(13.0),
            "flat_housing.shell.outline.corner_radius_mm",
        ),
        (
            "flat_housing.screws.insert_depth_mm",
            json!(7.0),
            "flat_housing.screws.insert_depth_mm",
        ),
        (
            "flat_housing.screws.insert_diameter_mm",
            json!(5.4),
            "flat_housing.screws.insert_diameter_mm",
        ),
        (
            "flat_housing.screws.counterbore_diameter_mm",
            json!(2.0),
            "flat_housing.screws.counterbore_diameter_mm",
        ),
        (
            "flat_housing.screws.counterbore_depth_mm",
            json!(3.0),
            "flat_housing.screws.counterbore_depth_mm",
        ),
        (
            "flat_housing.screws.xy_mm",
            json!([[14.0, 10.0]]),
            "flat_housing.screws.xy_mm[0]",
        ),
        (
            "flat_housing.screws.xy_mm",
            json!([]),
            "flat_housing.screws.xy_mm",
        ),
        (
            "flat_housing.shell.cable_slot.width_mm",
            json!(27.0),
            "flat_housing.shell.cable_slot.width_mm",
        ),
        (
            "flat_housing.shell.cable_slot.above_bottom_mm",
            json!(4.0),
            "flat_housing.shell.cable_slot.above_bottom_mm",
        ),
        (
            "flat_housing.shell.cable_slot.chamfer_mm",
            json!(3.0),
            "flat_housing.shell.cable_slot.chamfer_mm",
        ),
        (
            "flat_housing.shell.cable_slot.corner_radius_mm",
            json!(0.8),
            "flat_housing.shell.cable_slot.corner_radius_mm",
        ),
        (
            "flat_housing.base.camera_bosses.hole_diameter_mm",
            json!(5.3),
            "flat_housing.base.camera_bosses.hole_diameter_mm",
        ),
        (
            "flat_housing.base.camera_bosses.hole_floor_mm",
            json!(3.0),
            "flat_housing.base.camera_bosses.hole_floor_mm",
        ),
        (
            "flat_housing.base.camera_bosses.through_diameter_mm",
            json!(3.0),
            "flat_housing.base.camera_bosses.through_diameter_mm",
        ),
        (
            "flat_housing.base.posts.pin_diameter_mm",
            json!(2.8),
            "flat_housing.base.posts.pin_diameter_mm",
        ),
        (
            "flat_housing.base.posts.pin_fillet_mm",
            json!(0.8),
            "flat_housing.base.posts.pin_fillet_mm",
        ),
        (
            "flat_housing.base.camera_pocket.depth_mm",
            json!(3.0),
            "flat_housing.base.camera_pocket.depth_mm",
        ),
        (
            "flat_housing.base.camera_pocket.width_mm",
            json!(29.0),
            "flat_housing.base.camera_pocket.width_mm",
        ),
        (
            "flat_housing.base.camera_pocket.y_mm",
            json!([7.55, -4.35]),
            "flat_housing.base.camera_pocket.y_mm[1]",
        ),
        (
            "flat_housing.base.camera_pocket.channel.width_mm",
            json!(9.0),
            "flat_housing.base.camera_pocket.channel.width_mm",
        ),
        (
            "flat_housing.base.camera_pocket.channel.corner_radius_mm",
            json!(2.0),
            "flat_housing.base.camera_pocket.channel.corner_radius_mm",
        ),
        (
            "flat_housing.base.camera_pocket.channel.exit_depth_mm",
            json!(2.0),
            "flat_housing.base.camera_pocket.channel.exit_depth_mm",
        ),
        (
            "flat_housing.base.camera_pocket.channel.ramp_y_mm",
            json!([7.6, 12.543]),
            "flat_housing.base.camera_pocket.channel.ramp_y_mm[0]",
        ),
        (
            "flat_housing.base.camera_pocket.channel.ramp_radii_mm",
            json!([2.0, 0.0]),
            "flat_housing.base.camera_pocket.channel.ramp_radii_mm[1]",
        ),
        (
            "flat_housing.base.camera_pocket.channel.ramp_radii_mm",
            json!([4.0, 3.0]),
            "flat_housing.base.camera_pocket.channel.ramp_radii_mm[0]",
        ),
        (
            "flat_housing.isolation_ring.outer_mm",
            json!(12.5),
            "flat_housing.isolation_ring.outer_mm",
        ),
        (
            "flat_housing.isolation_ring.bore_diameter_mm",
            json!(11.9),
            "flat_housing.isolation_ring.bore_diameter_mm",
        ),
        (
            "flat_housing.isolation_ring.countersink_mm",
            json!(1.0),
            "flat_housing.isolation_ring.countersink_mm",
        ),
        (
            "flat_housing.window.clearance_mm",
            json!(-0.1),
            "flat_housing.window.clearance_mm",
        ),
        (
            "flat_housing.window.material",
            json!("pla"),
            "flat_housing.window.material",
        ),
        (
            "flat_housing.shell.material",
            json!("no_such_resin"),
            "flat_housing.shell.material",
        ),
        // the skin: wider than the shell's top face; its inner layer narrower than the chamber
        ("body.width_mm", json!(31.0), "flat_housing.shell.outline"),
        (
            "flat_housing.shell.wall_mm",
            json!(1.0),
            "flat_housing.shell.wall_mm",
        ),
    ];
    for (path, value, want) in cases {
        let d = with(&base, &[(path, value.clone())]);
        let paths = refused_paths(&d, &format!("{path} = {value}"));
        assert!(
            paths.iter().any(|p| p == want),
            "{path} = {value}: refused at {paths:?}, not {want}"
        );
    }
    // a curved skin refuses the flat housing
    let mut d = library::load("rtac0").unwrap();
    d.flat_housing = base.flat_housing.clone();
    assert!(refused_paths(&d, "a curved skin's flat housing").contains(&"flat_housing".into()));
}
