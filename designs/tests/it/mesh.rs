use fabkit_designs::geometry::*;

fn tetra() -> Mesh {
    Mesh {
        vertices: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
        triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    }
}

#[test]
fn tetrahedron_volume_area_genus() {
    let m = tetra();
    assert!((m.signed_volume() - 1.0 / 6.0).abs() < 1e-15);
    assert_eq!(m.genus(), 0);
    assert!(m.check_closed_manifold().is_ok());
    let a = 1.5 + 3f64.sqrt() / 2.0;
    assert!((m.surface_area() - a).abs() < 1e-12);
}

#[test]
fn flipped_triangle_is_caught() {
    let mut m = tetra();
    m.triangles[0] = [0, 1, 2];
    assert!(matches!(
        m.check_closed_manifold(),
        Err(TopologyError::InconsistentWinding(_))
    ));
}

#[test]
fn missing_triangle_is_open() {
    let mut m = tetra();
    m.triangles.pop();
    assert!(matches!(
        m.check_closed_manifold(),
        Err(TopologyError::OpenOrNonManifoldEdges(_))
    ));
}

/// A part resting on z = 0 whose height is a whole number of 0.05 mm layers keeps every layer
/// once stored as f32: its top, truncated to whole nanometres as PrusaSlicer's SLA slicer does,
/// is at least k layers up, for every height from 0.05 mm to 200 mm; x and y still round to the
/// nearest f32, and z moves by at most one unit in the last place.
#[test]
fn f32_rounding_keeps_every_whole_layer() {
    for k in 1..=4000u32 {
        let h = f64::from(k) * 0.05;
        let m = Mesh {
            vertices: vec![[0.1, 0.2, 0.0], [h, 0.0, 0.0], [0.0, h, 0.0], [0.3, 0.7, h]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        }
        .rounded_to_f32();
        let top = m.vertices[3][2];
        let top_nm = (top / 1e-6) as i64;
        let first_nm = 50_000i64;
        let layers = 1 + (top_nm - first_nm).div_euclid(50_000);
        assert_eq!(layers, i64::from(k), "height {h} mm stored as {top}");
        assert!(top >= h && top - h <= f64::from(h as f32).abs() * f64::from(f32::EPSILON));
        assert_eq!(m.vertices[0][0], 0.1f32 as f64);
        assert_eq!(m.vertices[0][1], 0.2f32 as f64);
        assert_eq!(m.vertices[1][0], h as f32 as f64);
        assert_eq!(m.vertices[0][2], 0.0);
    }
}
