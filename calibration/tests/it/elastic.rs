//! The elastic contact of a half-space (calibration/src/elastic.rs) against Hertz's sphere
//! (Johnson, Contact Mechanics, 1985, Sec. 4.2): contact radius sqrt(R d), load
//! 4/3 E* sqrt(R) d^1.5, the surface's profile inside and round the contact
//! ([`hertz_depth_mm`]).

use fabkit_calibration::elastic::{solve_contact, sphere_heights, ContactGrid};
use fabkit_calibration::press::hertz_depth_mm;

/// A 4 mm sphere pressed 0.5 mm into a half-space (E* = 0.1 MPa, a soft silicone's), on 32 x 32
/// cells over six contact radii: the load within 2 % of Hertz's (measured 1.0 % low: the
/// pressure is constant over each cell), the contact's area-equivalent radius within a cell of
/// sqrt(R d) (measured 0.011 mm off, cells 0.27 mm), the surface's displacement within 2 % of
/// the approach of Hertz's profile everywhere (measured 0.0072 mm of 0.5), and exactly the
/// sphere inside the contact (the displacement there is the approach less the sphere's height,
/// to 1e-6 mm); no pressure is negative and the sphere overlaps the surface nowhere.
#[test]
fn a_sphere_on_a_half_space_is_hertzs() {
    let (r, d, e): (f64, f64, f64) = (4.0, 0.5, 0.1);
    let a = (r * d).sqrt();
    let n = 32;
    let grid = ContactGrid {
        n,
        cell_mm: 6.0 * a / n as f64,
    };
    let h = sphere_heights(grid, r, 0.0, 0.0);
    let c = solve_contact(grid, &h, d, e).unwrap();
    let load = 4.0 / 3.0 * e * r.sqrt() * d.powf(1.5);
    assert!(
        (c.load_n / load - 1.0).abs() < 0.02,
        "{} N against {load}",
        c.load_n
    );
    let cells = c.in_contact.iter().filter(|&&b| b).count() as f64;
    let a_num = (cells * grid.cell_mm * grid.cell_mm / std::f64::consts::PI).sqrt();
    assert!((a_num - a).abs() < grid.cell_mm, "{a_num} against {a}");
    for j in 0..n {
        for i in 0..n {
            let k = j * n + i;
            let (x, y) = grid.centre_mm(i, j);
            let u = c.displacement_mm[k];
            let want = hertz_depth_mm(r, d, x.hypot(y));
            assert!(
                (u - want).abs() < 0.02 * d,
                "({x}, {y}): {u} against {want}"
            );
            assert!(c.pressure_mpa[k] >= 0.0);
            let gap = h[k] + u - d;
            if c.in_contact[k] {
                assert!(gap.abs() < 1e-6, "({x}, {y}) in contact, gap {gap}");
            } else {
                assert!(gap > -1e-6, "({x}, {y}) overlapped by {gap}");
            }
        }
    }
}

/// An off-centre sphere gives the same contact moved by whole cells (the grid is a
/// convolution), the same input the same bits, and bad values are refused by name.
#[test]
fn the_contact_moves_with_the_sphere_and_bad_values_are_refused() {
    let grid = ContactGrid {
        n: 24,
        cell_mm: 0.25,
    };
    let centred = solve_contact(grid, &sphere_heights(grid, 4.0, 0.0, 0.0), 0.3, 0.1).unwrap();
    let moved = solve_contact(grid, &sphere_heights(grid, 4.0, 0.5, -0.25), 0.3, 0.1).unwrap();
    assert!((centred.load_n / moved.load_n - 1.0).abs() < 1e-6);
    for j in 4..20 {
        for i in 4..20 {
            let (a, b) = (
                centred.pressure_mpa[j * 24 + i],
                moved.pressure_mpa[(j - 1) * 24 + i + 2],
            );
            assert!(
                (a - b).abs()
                    < 1e-6 * centred.pressure_mpa.iter().cloned().fold(0.0, f64::max) + 1e-12
            );
        }
    }
    let again = solve_contact(grid, &sphere_heights(grid, 4.0, 0.0, 0.0), 0.3, 0.1).unwrap();
    assert_eq!(again, centred);
    let h = sphere_heights(grid, 4.0, 0.0, 0.0);
    for (e, approach, name) in [
        (0.0, 0.3, "e_star_mpa"),
        (0.1, -1.0, "approach_mm"),
        (f64::NAN, 0.3, "e_star_mpa"),
    ] {
        let err = solve_contact(grid, &h, approach, e)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with(name), "{err}");
    }
    assert!(solve_contact(ContactGrid { n: 1, cell_mm: 0.1 }, &[0.0], 0.1, 0.1).is_err());
    assert!(solve_contact(grid, &h[1..], 0.3, 0.1).is_err());
}
