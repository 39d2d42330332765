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
