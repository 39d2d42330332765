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
    for (young, poisson, thickness, name) in [
        (0.0, 0.5, 2.0, "young_mpa"),
        (0.1, 0.6, 2.0, "poisson"),
        (0.1, -0.1, 2.0, "poisson"),
        (0.1, 0.5, 0.4, "thickness_mm"),
        (0.1, 0.5, f64::INFINITY, "thickness_mm"),
    ] {
        let skin = fabkit_calibration::elastic::Skin::BondedLayer {
            young_mpa: young,
            poisson,
            thickness_mm: thickness,
        };
        let err = fabkit_calibration::elastic::solve_skin_contact(grid, &h, 0.3, skin)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with(name), "{err}");
    }
    assert!(solve_contact(ContactGrid { n: 1, cell_mm: 0.1 }, &[0.0], 0.1, 0.1).is_err());
    assert!(solve_contact(grid, &h[1..], 0.3, 0.1).is_err());
}

/// The bonded layer's compliance factor `K(t)` has the limits its physics gives (module docs
/// of elastic.rs): 1 for a thick layer, the constrained modulus's `t (1 - 2 nu) / (2 (1 -
/// nu)^2)` for a thin compressible one, lubrication's `2 t^3 / 3` for a thin incompressible
/// one; it rises with the thickness and stays finite for huge `t`.
#[test]
fn the_layer_factor_has_its_limits() {
    use fabkit_calibration::elastic::layer_factor;
    for nu in [0.0, 0.3, 0.45, 0.5] {
        assert!((layer_factor(50.0, nu) - 1.0).abs() < 1e-12);
        assert_eq!(layer_factor(1e6, nu), 1.0);
        let mut last = 0.0;
        for i in 1..200 {
            let k = layer_factor(i as f64 * 0.05, nu);
            assert!(k > last && k <= 1.0, "nu {nu}, t {}: {k}", i as f64 * 0.05);
            last = k;
        }
    }
    for nu in [0.0, 0.3, 0.45] {
        let t = 1e-4;
        let want = t * (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu) * (1.0 - nu));
        assert!((layer_factor(t, nu) / want - 1.0).abs() < 1e-3, "nu {nu}");
    }
    let t = 1e-2;
    assert!((layer_factor(t, 0.5) / (2.0 * t * t * t / 3.0) - 1.0).abs() < 1e-3);
}

/// A paraboloid (R 4 mm) on an incompressible layer bonded to a rigid base (9DTact's 2.8 mm gel
/// on its window) at contact radii from a quarter to two thirds of the thickness: the grid's
/// load within 0.3 % of the axisymmetric solution ([`axisymmetric_layer_contact`], a
/// different reduction of the same problem; measured 0.03 %) and its contact radius within a
/// cell; that solution within 1.5 % of Garcia and Garcia's published bottom-effect series for a
/// bonded sample (Biophys. J. 114, 2018, 2923-2932: `1 + 1.133 c + 1.497 c^2 + 1.469 c^3 +
/// 0.755 c^4`, `c = sqrt(R d) / h`; measured 0.1 % to 1.3 %), which is up to 2.4 times
/// Hertz's here, so a half-space's answer fails by far. A layer a thousand times thicker than
/// the contact gives the half-space's load within 0.3 %.
#[test]
fn a_paraboloid_on_a_bonded_layer_is_the_axisymmetric_solution() {
    use fabkit_calibration::elastic::{solve_skin_contact, Skin};
    let (r, h, young, nu): (f64, f64, f64, f64) = (4.0, 2.8, 0.075, 0.5);
    let layer = Skin::BondedLayer {
        young_mpa: young,
        poisson: nu,
        thickness_mm: h,
    };
    let e_star = layer.e_star_mpa();
    for a in [0.7, 1.2, 1.8] {
        let (d, load) = axisymmetric_layer_contact(r, a, h, nu, e_star);
        let c = (r * d).sqrt() / h;
        let hertz = 4.0 / 3.0 * e_star * r.sqrt() * d.powf(1.5);
        let garcia = 1.0 + 1.133 * c + 1.497 * c * c + 1.469 * c.powi(3) + 0.755 * c.powi(4);
        assert!(
            (load / hertz / garcia - 1.0).abs() < 0.015,
            "c {c}: {} against {garcia}",
            load / hertz
        );
        let n = 40;
        let grid = ContactGrid {
            n,
            cell_mm: 3.0 * a / n as f64,
        };
        let heights: Vec<f64> = (0..n * n)
            .map(|k| {
                let (x, y) = grid.centre_mm(k % n, k / n);
                (x * x + y * y) / (2.0 * r)
            })
            .collect();
        let on_layer = solve_skin_contact(grid, &heights, d, layer).unwrap();
        assert!(
            (on_layer.load_n / load - 1.0).abs() < 0.003,
            "a {a}: {} N against {load}",
            on_layer.load_n
        );
        let cells = on_layer.in_contact.iter().filter(|&&b| b).count() as f64;
        let a_grid = (cells * grid.cell_mm * grid.cell_mm / std::f64::consts::PI).sqrt();
        assert!((a_grid - a).abs() < grid.cell_mm, "{a_grid} against {a}");
        // in contact the surface is the indenter's, and nowhere does it overlap it
        for ((h, u), touching) in heights
            .iter()
            .zip(&on_layer.displacement_mm)
            .zip(&on_layer.in_contact)
        {
            let gap = h + u - d;
            assert!(gap > -1e-6 && (!touching || gap.abs() < 1e-6));
        }
    }
    let d = 0.1;
    let grid = ContactGrid {
        n: 24,
        cell_mm: 0.1,
    };
    let heights = sphere_heights(grid, r, 0.0, 0.0);
    let thick = Skin::BondedLayer {
        young_mpa: young,
        poisson: nu,
        thickness_mm: 1000.0 * (r * d).sqrt(),
    };
    let half = solve_contact(grid, &heights, d, thick.e_star_mpa()).unwrap();
    let on_thick = solve_skin_contact(grid, &heights, d, thick).unwrap();
    assert!((on_thick.load_n / half.load_n - 1.0).abs() < 0.003);
}

/// A flat punch as wide as the grid (12 mm) pressed into a thin compressible layer (0.5 mm,
/// nu 0.3) compresses each column on its own away from the punch's edge: the pressure at the
/// centre is the constrained modulus's `M d / h`, `M = E (1 - nu) / ((1 + nu)(1 - 2 nu))`,
/// within 1 %; on a half-space it would be several times less (the punch's pressure there
/// scales with its width, not the layer's thickness).
#[test]
fn a_thin_compressible_layer_is_a_winkler_bed() {
    use fabkit_calibration::elastic::{solve_skin_contact, Skin};
    let (young, nu, h, d) = (0.1, 0.3, 0.5, 0.05);
    let n = 48;
    let grid = ContactGrid { n, cell_mm: 0.25 };
    let skin = Skin::BondedLayer {
        young_mpa: young,
        poisson: nu,
        thickness_mm: h,
    };
    let flat = vec![0.0; n * n];
    let c = solve_skin_contact(grid, &flat, d, skin).unwrap();
    let m = young * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let centre = c.pressure_mpa[(n / 2) * n + n / 2];
    assert!(
        (centre / (m * d / h) - 1.0).abs() < 0.01,
        "{centre} against {}",
        m * d / h
    );
    let half = solve_contact(grid, &flat, d, skin.e_star_mpa()).unwrap();
    assert!(half.pressure_mpa[(n / 2) * n + n / 2] < 0.3 * centre);
}

/// The frictionless contact of a paraboloid `z = r^2 / 2R` with a layer bonded to a rigid base,
/// solved axisymmetrically for a given contact radius `a`: the approach and the load `(d, F)`.
/// An oracle independent of the grid: the pressure written as
/// `p(r) = int_r^a phi(t) / sqrt(t^2 - r^2) dt`, whose Hankel transform is
/// `int_0^a phi(t) sin(kt) / k dt`, turns the surface's displacement `(2 / E*) int_0^inf
/// K(kh) p(k) J0(kr) dk` inside the contact, after Abel's operator and a derivative, into
/// the Fredholm equation `phi(t) + 2/pi int_0^a phi(s) M(s, t) ds = 2 E* t / (pi R)`,
/// `M(s, t) = int_0^inf (K - 1) sin(ks) sin(kt) dk` (Hertz's `phi` when `K = 1`), solved by
/// Nystrom's method on 48 Gauss-Legendre nodes; then `F = 2 pi int_0^a phi(t) t dt` and
/// `d = a^2 / R + (2 / E*) int_0^a phi(s) int_0^inf (K - 1) sin(ks) cos(ka) / k dk ds`.
fn axisymmetric_layer_contact(r_sphere: f64, a: f64, h: f64, nu: f64, e_star: f64) -> (f64, f64) {
    use fabkit_calibration::elastic::layer_factor;
    let kmax = 40.0 / h;
    let steps = 8000usize;
    let dk = kmax / steps as f64;
    let simpson = |f: &dyn Fn(f64) -> f64| -> f64 {
        let mut s = 0.0;
        for i in 0..=steps {
            let k = i as f64 * dk;
            let w = if i == 0 || i == steps {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            s += w * f(k);
        }
        s * dk / 3.0
    };
    let km1 = |k: f64| layer_factor(k * h, nu) - 1.0;
    let m = |u: f64| simpson(&|k| km1(k) * (k * u).cos());
    // Gauss-Legendre nodes on [0, a]
    let nq = 48;
    let (xs, ws) = gauss_legendre(nq);
    let t: Vec<f64> = xs.iter().map(|x| 0.5 * a * (x + 1.0)).collect();
    let w: Vec<f64> = ws.iter().map(|x| 0.5 * a * x).collect();
    let mut mat = nalgebra::DMatrix::<f64>::zeros(nq, nq);
    let mut rhs = nalgebra::DVector::<f64>::zeros(nq);
    for i in 0..nq {
        for j in 0..nq {
            let mm = 0.5 * (m(t[j] - t[i]) - m(t[j] + t[i]));
            mat[(i, j)] = (if i == j { 1.0 } else { 0.0 }) + 2.0 / std::f64::consts::PI * w[j] * mm;
        }
        rhs[i] = 2.0 * e_star * t[i] / (std::f64::consts::PI * r_sphere);
    }
    let phi = mat.lu().solve(&rhs).unwrap();
    let load = 2.0 * std::f64::consts::PI * (0..nq).map(|j| w[j] * phi[j] * t[j]).sum::<f64>();
    let l = |s: f64| {
        simpson(&|k| {
            if k == 0.0 {
                -s
            } else {
                km1(k) * (k * s).sin() * (k * a).cos() / k
            }
        })
    };
    let delta =
        a * a / r_sphere + 2.0 / e_star * (0..nq).map(|j| w[j] * phi[j] * l(t[j])).sum::<f64>();
    (delta, load)
}

fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut xs = vec![0.0; n];
    let mut ws = vec![0.0; n];
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
            p0 = p1;
            p1 = p2;
        }
        let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
        xs[i] = x;
        ws[i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
    (xs, ws)
}

/// The displacement at a depth under the surface ([`depth_factor`]): the surface's at depth 0,
/// none at a bonded layer's base, Boussinesq's under a point load in a half-space
/// (`P / (4 pi G) (z^2 / rho^3 + 2 (1 - nu) / rho)`, Johnson Eq. 3.21c; a cell's pressure
/// seen from 1 mm deep matches it within 0.5 % at every offset); in a bonded layer a cell
/// deep, the surface's influence (computed by another route) away from the loaded cell, and
/// nearly none by the base; under a sphere's contact on
/// 9DTact's 2.8 mm layer the face 0.3 mm deep sinks less than the surface in the contact and
/// follows it within 0.02 mm away from it, and bad depths are refused by name.
#[test]
fn the_displacement_at_a_depth_is_boussinesqs() {
    use fabkit_calibration::elastic::{
        depth_factor, displacement_at_depth, influence_at_depth, layer_factor, solve_skin_contact,
        Skin,
    };
    for nu in [0.3, 0.45, 0.5] {
        for t in [0.2, 1.0, 3.0] {
            assert!((depth_factor(0.0, t, nu) - layer_factor(t, nu)).abs() < 1e-12);
            assert!(depth_factor(t, t, nu).abs() < 1e-12, "nu {nu} t {t}");
        }
        assert!(
            (depth_factor(0.7, 400.0, nu) - depth_factor(0.7, f64::INFINITY, nu)).abs() < 1e-12
        );
    }
    // Boussinesq, half-space of nu 0.5 (G = E / 3, E* = 4 E / 3)
    let e_star = 0.1;
    let g = e_star * 0.75 / 3.0;
    let grid = ContactGrid {
        n: 32,
        cell_mm: 0.05,
    };
    let z = 1.0;
    let k = influence_at_depth(grid, Skin::HalfSpace { e_star_mpa: e_star }, z);
    let m = 2 * grid.n - 1;
    let load = grid.cell_mm * grid.cell_mm;
    for di in (grid.n - 1)..m {
        let r = (di - (grid.n - 1)) as f64 * grid.cell_mm;
        let rho = r.hypot(z);
        let want = load / (4.0 * std::f64::consts::PI * g) * (z * z / rho.powi(3) + 1.0 / rho);
        let got = k[(grid.n - 1) * m + di];
        assert!(
            (got / want - 1.0).abs() < 0.005,
            "r {r}: {got} against {want}"
        );
    }
    // a layer's interior by two routes: a cell deep its influence is the surface's (Love's
    // rectangles plus the layer's correction to K) away from the loaded cell, within 1 % of the
    // largest; near the base it vanishes (the base holds)
    use fabkit_calibration::elastic::influence;
    let layer = Skin::BondedLayer {
        young_mpa: 0.1,
        poisson: 0.5,
        thickness_mm: 2.8,
    };
    let grid = ContactGrid {
        n: 48,
        cell_mm: 0.1,
    };
    let m = 2 * grid.n - 1;
    let surface = influence(grid, layer);
    let shallow = influence_at_depth(grid, layer, 0.1);
    let deep = influence_at_depth(grid, layer, 2.7);
    let peak = surface.iter().cloned().fold(0.0, f64::max);
    for dj in 0..m {
        for di in 0..m {
            let (x, y) = (di as f64 - 47.0, dj as f64 - 47.0);
            let k = dj * m + di;
            if x.hypot(y) >= 5.0 {
                assert!(
                    (shallow[k] - surface[k]).abs() < 0.01 * peak,
                    "({x}, {y}) cells: {} against {}",
                    shallow[k],
                    surface[k]
                );
            }
            assert!(deep[k].abs() < 0.05 * peak, "{}", deep[k]);
        }
    }
    // a sphere on the layer: the face 0.3 mm deep
    let skin = Skin::BondedLayer {
        young_mpa: 0.1,
        poisson: 0.5,
        thickness_mm: 2.8,
    };
    let n = 64;
    let grid = ContactGrid { n, cell_mm: 0.2 };
    let heights = sphere_heights(grid, 4.0, 0.0, 0.0);
    let c = solve_skin_contact(grid, &heights, 1.0, skin).unwrap();
    let deep = displacement_at_depth(&c, skin, 0.3).unwrap();
    let centre = (n / 2) * n + n / 2;
    assert!(deep[centre] < c.displacement_mm[centre] && deep[centre] > 0.8);
    for (k, (d, u)) in deep.iter().zip(&c.displacement_mm).enumerate() {
        let (x, y) = grid.centre_mm(k % n, k / n);
        if x.hypot(y) > 5.0 {
            assert!((d - u).abs() < 0.02, "({x}, {y})");
        }
    }
    assert_eq!(
        displacement_at_depth(&c, skin, 0.0).unwrap(),
        c.displacement_mm
    );
    for bad in [-0.1, 0.1, 2.8, f64::NAN] {
        let err = displacement_at_depth(&c, skin, bad)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("depth_mm"), "{err}");
    }
}

/// The solver works on a window round the cells the indenters overlap; where the skin's bulge
/// meets an indenter outside it, the window grows. A pin (a 0.5 mm sphere 0.3 mm into 1 mm of
/// incompressible gel) under a plate hanging 3 um above the undeformed skin from 1 mm out: the
/// pin's bulge lifts the skin into the plate, which the first window does not hold. The
/// answer holds the contact conditions on the whole grid (no overlap anywhere, no gap where
/// the skin touches, no tension), so it is the whole grid's (the problem has one solution),
/// and the plate carries load.
#[test]
fn the_window_grows_where_the_bulge_meets_an_indenter() {
    use fabkit_calibration::elastic::{solve_skin_contact, Skin};
    let n = 64;
    let grid = ContactGrid { n, cell_mm: 0.1 };
    let skin = Skin::BondedLayer {
        young_mpa: 0.1,
        poisson: 0.5,
        thickness_mm: 1.0,
    };
    let d = 0.3;
    let pin = sphere_heights(grid, 0.5, 0.0, 0.0);
    let heights: Vec<f64> = (0..n * n)
        .map(|k| {
            let (x, y) = grid.centre_mm(k % n, k / n);
            if x.hypot(y) > 1.0 {
                pin[k].min(d + 0.003)
            } else {
                pin[k]
            }
        })
        .collect();
    let c = solve_skin_contact(grid, &heights, d, skin).unwrap();
    let mut plate_load = 0.0;
    for k in 0..n * n {
        let gap = heights[k] + c.displacement_mm[k] - d;
        assert!(gap > -1e-6, "overlap {gap} at cell {k}");
        assert!(c.pressure_mpa[k] >= 0.0);
        if c.in_contact[k] {
            assert!(gap.abs() < 1e-6, "gap {gap} in contact at cell {k}");
        }
        if heights[k] > d {
            plate_load += c.pressure_mpa[k] * grid.cell_mm * grid.cell_mm;
        }
    }
    assert!(
        plate_load > 0.01 * c.load_n,
        "the plate carries {plate_load} N of {} N",
        c.load_n
    );
}
