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

/// The unit right tetrahedron's mass properties in closed form: volume 1/6, centroid
/// (1/4, 1/4, 1/4); about the origin the integral of x^2 is 1/60 and of xy 1/120, so about the
/// centroid Ixx = 2/60 - (1/6)(2/16) = 1/80 and Ixy = -(1/120 - (1/6)(1/16)) = 1/480.
#[test]
fn a_tetrahedrons_mass_properties_are_its_closed_form() {
    let p = tetra().mass_properties();
    assert!((p.volume_mm3 - 1.0 / 6.0).abs() < 1e-15);
    for k in 0..3 {
        assert!((p.centroid_mm[k] - 0.25).abs() < 1e-15, "{p:?}");
        assert!((p.inertia_mm5[k][k] - 1.0 / 80.0).abs() < 1e-15, "{p:?}");
        for j in 0..3 {
            if j != k {
                assert!((p.inertia_mm5[k][j] - 1.0 / 480.0).abs() < 1e-15, "{p:?}");
            }
        }
    }
}

/// A 10 x 20 x 30 mm box far from the origin (centre (100, -50, 300)), turned about all three
/// axes: its centroid is the turned centre and its inertia R diag(V (b^2 + c^2) / 12, ...) R^T,
/// within 1e-9 relative.
#[test]
fn a_turned_boxs_inertia_is_the_turned_diagonal() {
    let (a, b, c) = (10.0, 20.0, 30.0);
    let centre = [100.0, -50.0, 300.0];
    let half = [a / 2.0, b / 2.0, c / 2.0];
    let solid = cuboid(
        std::array::from_fn(|k| centre[k] - half[k]),
        std::array::from_fn(|k| centre[k] + half[k]),
    )
    .unwrap();
    let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1);
    let turned_centre = r * nalgebra::Vector3::from(centre);
    let affine = nalgebra::Affine3::from_matrix_unchecked(r.to_homogeneous());
    let p = solid.transform(&affine).mesh().mass_properties();
    let v = a * b * c;
    assert!((p.volume_mm3 - v).abs() < 1e-9 * v, "{p:?}");
    for k in 0..3 {
        assert!(
            (p.centroid_mm[k] - turned_centre[k]).abs() < 1e-9 * 300.0,
            "{p:?}"
        );
    }
    let diag = nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(
        v * (b * b + c * c) / 12.0,
        v * (a * a + c * c) / 12.0,
        v * (a * a + b * b) / 12.0,
    ));
    let want = r.matrix() * diag * r.matrix().transpose();
    let scale = want.abs().max();
    for i in 0..3 {
        for j in 0..3 {
            assert!(
                (p.inertia_mm5[i][j] - want[(i, j)]).abs() < 1e-9 * scale,
                "{i}{j}: {} vs {}",
                p.inertia_mm5[i][j],
                want[(i, j)]
            );
        }
    }
}

/// A tessellated sphere (R10, chord tolerance 0.01 mm) has the sphere's inertia per volume,
/// 2 R^2 / 5 on each axis and no product, within the tessellation's 0.3 %.
#[test]
fn a_spheres_inertia_per_volume_is_two_fifths_r_squared() {
    let s = sphere(10.0, ChordTolerance::new(0.01).unwrap()).unwrap();
    let p = s.mesh().mass_properties();
    for k in 0..3 {
        let per = p.inertia_mm5[k][k] / p.volume_mm3;
        assert!((per / 40.0 - 1.0).abs() < 3e-3, "{k}: {per}");
        assert!(p.centroid_mm[k].abs() < 1e-9, "{p:?}");
        for j in 0..3 {
            if j != k {
                assert!(
                    p.inertia_mm5[k][j].abs() < 1e-3 * p.inertia_mm5[k][k],
                    "{p:?}"
                );
            }
        }
    }
}
