//! The sensor's mass properties combined from its members' (export/src/mass.rs): two halves of
//! a box combine into the whole box, in closed form.

use fabkit_designs::geometry::{cuboid, Mesh};
use fabkit_export::mass::{member_mass, sensor_mass};

fn box_mesh(min: [f64; 3], max: [f64; 3]) -> Mesh {
    cuboid(min, max).unwrap().mesh()
}

/// A 20 x 10 x 6 mm box of density 1.2 g/cm^3, cut at x = 5 into two members (and a third
/// member without a material): combined, they are the whole box, mass 1.44 g, centre (0, 0, 3)
/// and inertia m (b^2 + c^2) / 12 etc. on the diagonal, within 1e-12 relative; the member
/// without a material is named as not counted.
#[test]
fn two_halves_of_a_box_combine_into_the_box() {
    let (a, b, c, rho) = (20.0, 10.0, 6.0, 1.2);
    let left = member_mass(&box_mesh([-10.0, -5.0, 0.0], [5.0, 5.0, 6.0]), rho);
    let right = member_mass(&box_mesh([5.0, -5.0, 0.0], [10.0, 5.0, 6.0]), rho);
    let s = sensor_mass([
        ("left", Some(&left)),
        ("board", None),
        ("right", Some(&right)),
    ]);
    let m = rho * 1e-3 * a * b * c;
    assert!((s.mass_g - m).abs() < 1e-12 * m, "{s:?}");
    for (k, want) in [0.0, 0.0, 3.0].into_iter().enumerate() {
        assert!((s.centre_of_mass_mm[k] - want).abs() < 1e-12 * a, "{s:?}");
    }
    let want = [
        m * (b * b + c * c) / 12.0,
        m * (a * a + c * c) / 12.0,
        m * (a * a + b * b) / 12.0,
    ];
    for i in 0..3 {
        for j in 0..3 {
            let w = if i == j { want[i] } else { 0.0 };
            assert!(
                (s.inertia_g_mm2[i][j] - w).abs() < 1e-12 * want[2],
                "{i}{j}: {s:?}"
            );
        }
    }
    assert_eq!(s.counted, ["left", "right"]);
    assert_eq!(s.not_counted, ["board"]);
}
