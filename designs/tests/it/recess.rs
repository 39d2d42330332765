//! The recess under a solid skin (`layers[i].recess`, a layer feature): its outline against
//! the published DIGIT Pinki gel, its volume and area against its mesh, and its rules.

use fabkit_designs::geometry::ChordTolerance;
use fabkit_designs::parts::recess::{check_recess, Recess};

/// The published DIGIT Pinki recess (`Pinki Gel.step`, mm, base plane z = -8.5).
fn pinki() -> Recess {
    Recess {
        base_diameter_mm: 9.853289,
        depth_mm: 3.298931,
        cap_radius_mm: 7.438943,
        draft_angle_deg: 2.0,
        fillet_radius_mm: 0.25,
    }
}

#[test]
fn the_outline_meets_the_published_torus_and_circles() {
    let o = pinki().outline().unwrap();
    // torus: major radius 4.628990 about the axis, centre plane z = -7.139707
    assert!((o.fillet_centre[0] - 4.628990).abs() < 2e-5, "{o:?}");
    assert!(
        (o.fillet_centre[1] - (8.5 - 7.139707)).abs() < 2e-5,
        "{o:?}"
    );
    // the cone's top circle R4.878837 at z = -7.130982; the roof's edge R4.789966 at z = -6.948430
    assert!(
        (o.wall_top[0] - 4.878837).abs() < 2e-5 && (o.wall_top[1] - (8.5 - 7.130982)).abs() < 2e-5
    );
    assert!(
        (o.roof_edge[0] - 4.789966).abs() < 2e-5
            && (o.roof_edge[1] - (8.5 - 6.948430)).abs() < 2e-5
    );
    assert!((o.cap_centre_h_mm - (8.5 - 12.640012)).abs() < 2e-5);
}

#[test]
fn the_volume_is_the_revolved_outline_and_the_mesh_holds_it() {
    let r = pinki();
    let o = r.outline().unwrap();
    // the published gel: 2132.3 mm^3 = the R7.5 hemisphere on 8.1 mm of cylinder less the recess
    let outer =
        2.0 / 3.0 * std::f64::consts::PI * 7.5f64.powi(3) + std::f64::consts::PI * 56.25 * 8.1;
    assert!(
        ((outer - o.volume_mm3()) - 2132.3).abs() < 0.05,
        "{}",
        outer - o.volume_mm3()
    );
    let tol = ChordTolerance::new(0.002).unwrap();
    let s = o.solid(-8.5, 0.0, tol).unwrap();
    assert!(
        (s.volume() - o.volume_mm3()).abs() / o.volume_mm3() < 2e-3,
        "{} {}",
        s.volume(),
        o.volume_mm3()
    );
    for v in s.mesh().vertices.iter().filter(|v| v[2] > -8.5 + 1e-9) {
        let p = [v[0].hypot(v[1]), v[2] + 8.5];
        assert!(o.distance_mm(p) < 1e-9, "{p:?}: {}", o.distance_mm(p));
    }
}

#[test]
fn the_surface_area_is_the_meshs() {
    let o = pinki().outline().unwrap();
    let tol = ChordTolerance::new(0.001).unwrap();
    let mesh = o.solid(-8.5, 0.0, tol).unwrap().mesh().clone();
    // the mesh's area less its flat base (the mouth's disc)
    let mut area = 0.0;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        if [a, b, c].iter().all(|v| v[2] == -8.5) {
            continue;
        }
        let (u, v) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        area += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    }
    let exact = o.surface_area_mm2();
    assert!((area - exact).abs() / exact < 1e-3, "{area} {exact}");
}

#[test]
fn a_sharp_edge_is_where_the_cone_leaves_the_sphere() {
    let mut r = pinki();
    r.fillet_radius_mm = 0.0;
    let o = r.outline().unwrap();
    assert_eq!(o.wall_top, o.roof_edge);
    let [rr, h] = o.wall_top;
    assert!((rr.hypot(h - o.cap_centre_h_mm) - r.cap_radius_mm).abs() < 1e-12);
    assert!((rr - (4.926644 - h * 2f64.to_radians().tan())).abs() < 1e-6);
}

#[test]
fn broken_rules_name_their_field() {
    let mut errs = Vec::new();
    let mut r = pinki();
    r.cap_radius_mm = 3.0; // the sphere through the apex misses the mouth's edge
    check_recess("layers[0].recess", &r, 7.5, 15.6, &mut errs);
    assert_eq!(errs.len(), 1, "{errs:?}");
    assert_eq!(errs[0].path, "layers[0].recess.cap_radius_mm");
    let mut r = pinki();
    r.fillet_radius_mm = 3.0;
    errs.clear();
    check_recess("layers[0].recess", &r, 7.5, 15.6, &mut errs);
    assert_eq!(
        errs[0].path, "layers[0].recess.fillet_radius_mm",
        "{errs:?}"
    );
    let mut r = pinki();
    r.base_diameter_mm = 15.0;
    r.depth_mm = 20.0;
    r.draft_angle_deg = 45.0;
    errs.clear();
    check_recess("layers[0].recess", &r, 7.5, 15.6, &mut errs);
    assert_eq!(errs.len(), 1, "{errs:?}");
    r.draft_angle_deg = 2.0;
    errs.clear();
    check_recess("layers[0].recess", &r, 7.5, 15.6, &mut errs);
    let paths: Vec<_> = errs.iter().map(|e| e.path.as_str()).collect();
    assert!(
        paths.contains(&"layers[0].recess.base_diameter_mm")
            && paths.contains(&"layers[0].recess.depth_mm"),
        "{paths:?}"
    );
}
