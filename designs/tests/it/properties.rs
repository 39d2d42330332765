//! Property tests of the geometry core (STYLE.md, "Tests"): random valid parameters -> build
//! -> closed, consistently oriented 2-manifold, expected genus and shell count, and a volume
//! within the bound that the chord tolerance implies.
//!
//! The bound: every facet of a tessellation lies within the chord tolerance `tol` of the true
//! surface, so the region between the mesh and the true surface is a layer at most `tol` thick
//! over the surface, and |V_mesh - V_exact| <= A_mesh * tol. For a convex body whose mesh
//! vertices lie on its surface, every facet lies inside the body, so V_mesh <= V_exact too.
//!
//! The exact values here (volumes, surfaces, distances) are computed in this file from the
//! definitions, not from the code under test, except `BodyProfile::analytic_solid_volume_mm3`,
//! which the brief names as the reference and which is itself cross-checked against a closed
//! form where one exists (`analytic_volume_matches_closed_forms`).

use fabkit_designs::geometry::{self, ChordTolerance, Mesh, Solid};
use fabkit_designs::profile::BodyProfile;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI};

/// Floating-point noise allowed on top of the chord-tolerance bound, relative to the volume.
const VOLUME_NOISE_REL: f64 = 1e-9;
/// How far a mesh vertex may lie from the true surface, mm.
const VERTEX_ON_SURFACE_MM: f64 = 1e-9;

/// How close to the fold limit of a profile (`offset_is_valid`) the inner offset may go.
const DEPTH_FRACTION: f64 = 0.995;

/// A deterministic runner: fixed seed, a modest number of cases, no persistence files.
fn runner(cases: u32) -> TestRunner {
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    let seed = [7 + crate::common::seed_set() as u8; 32];
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed))
}

fn tol_mm() -> impl Strategy<Value = f64> {
    0.002..=0.05f64
}

/// The three body profiles with sizes in realistic ranges.
fn body() -> impl Strategy<Value = BodyProfile> {
    prop_oneof![
        (3.0..=40.0f64, prop_oneof![Just(0.0), 0.0..=20.0f64]).prop_map(|(r, l)| {
            BodyProfile::HemisphereOnCylinder {
                radius_mm: r,
                cylinder_length_mm: l,
            }
        }),
        // height up to half the base diameter (half is a hemisphere)
        (5.0..=60.0f64, prop_oneof![Just(0.5), 0.1..=0.5f64]).prop_map(|(b, f)| {
            BodyProfile::SphericalCap {
                base_diameter_mm: b,
                height_mm: f * b,
            }
        }),
        (5.0..=40.0f64, 3.0..=40.0f64).prop_map(|(d, h)| BodyProfile::HalfEllipsoid {
            diameter_mm: d,
            height_mm: h,
        }),
    ]
}

/// The largest inward offset depth s for which `offset_is_valid(-s')` holds for all s' < s.
fn valid_depth_limit(p: &BodyProfile) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 1000.0f64);
    assert!(p.offset_is_valid(-lo) && !p.offset_is_valid(-hi));
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if p.offset_is_valid(-mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// A random profile case: body, tolerance, shell offsets d_in < d_out <= 0 (both valid, the
/// shell at least `tol` thick, as `stack::validate` demands of a layer) and a below-base
/// extension.
#[derive(Debug, Clone)]
struct ProfileCase {
    body: BodyProfile,
    tol: f64,
    d_in: f64,
    d_out: f64,
    below_mm: f64,
}

fn profile_case() -> impl Strategy<Value = ProfileCase> {
    (
        body(),
        tol_mm(),
        prop_oneof![Just(0.0), 0.0..=1.0f64],
        0.0..=1.0f64,
        prop_oneof![Just(0.0), 0.0..=5.0f64],
    )
        .prop_filter_map(
            "no room for a shell",
            |(body, tol, f_out, f_th, below_mm)| {
                // up to 0.995 of the fold limit, where the offset of a flat ellipse has a radius
                // of curvature of a few hundredths of a millimetre at its rim
                let avail = DEPTH_FRACTION * valid_depth_limit(&body) - tol;
                if avail <= 0.0 {
                    return None;
                }
                let d_out = -f_out * 0.8 * avail;
                let d_in = d_out - tol - f_th * (avail + d_out);
                Some(ProfileCase {
                    body,
                    tol,
                    d_in,
                    d_out,
                    below_mm,
                })
            },
        )
}

// ---------------------------------------------------------------------------------------------
// The true surface, from the definitions.

/// A piece of the boundary of a profile region in the (r, z) half-plane.
#[derive(Debug, Clone, Copy)]
enum Piece {
    /// Arc about the origin of radius `rho`, angles from the +r axis in [a_end, pi/2].
    Arc {
        rho: f64,
        a_end: f64,
    },
    /// The offset at signed normal distance `d` (negative inward) of the quarter ellipse
    /// (r/a)^2 + (z/c)^2 = 1, z >= 0.
    EllipseOffset {
        a: f64,
        c: f64,
        d: f64,
    },
    Segment([f64; 2], [f64; 2]),
}

use fabkit_designs::geometry::profile2d::point_segment_distance as seg_dist;

/// Distance from `q` to the ellipse (r/a)^2 + (z/c)^2 = 1, by a scan for the nearest parameter
/// and bisection of the foot-point condition (q - E(th)) . E'(th) = 0 to machine precision.
fn ellipse_distance(q: [f64; 2], a: f64, c: f64) -> f64 {
    let e = |th: f64| [a * th.cos(), c * th.sin()];
    let f = |th: f64| {
        let p = e(th);
        (q[0] - p[0]).hypot(q[1] - p[1])
    };
    // (q - E) . E', positive left of a minimum of |q - E|, negative right of it
    let g = |th: f64| {
        let p = e(th);
        (q[0] - p[0]) * (-a * th.sin()) + (q[1] - p[1]) * (c * th.cos())
    };
    let (t0, t1, n) = (-0.3, FRAC_PI_2 + 0.3, 1024);
    let th_k = |k: usize| t0 + (t1 - t0) * k as f64 / n as f64;
    let k = (1..n)
        .min_by(|&i, &j| f(th_k(i)).total_cmp(&f(th_k(j))))
        .unwrap();
    let (mut lo, mut hi) = (th_k(k - 1), th_k(k + 1));
    let mut best = f(th_k(k));
    if g(lo) >= 0.0 && g(hi) <= 0.0 {
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if g(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        best = best.min(f(lo)).min(f(hi));
    }
    best
}

fn piece_distance(q: [f64; 2], piece: &Piece) -> f64 {
    match *piece {
        Piece::Arc { rho, a_end } => {
            let ang = q[1].atan2(q[0]);
            if ang >= a_end - 1e-12 && ang <= FRAC_PI_2 + 1e-12 {
                (q[0].hypot(q[1]) - rho).abs()
            } else {
                let e0 = [rho * a_end.cos(), rho * a_end.sin()];
                let e1 = [0.0, rho];
                (q[0] - e0[0])
                    .hypot(q[1] - e0[1])
                    .min((q[0] - e1[0]).hypot(q[1] - e1[1]))
            }
        }
        Piece::EllipseOffset { a, c, d } => {
            if q[1] < -1e-12 || q[0] < 0.0 {
                return f64::INFINITY;
            }
            let inside = (q[0] / a).powi(2) + (q[1] / c).powi(2) <= 1.0;
            let dist = ellipse_distance(q, a, c);
            let signed = if inside { -dist } else { dist };
            (signed - d).abs()
        }
        Piece::Segment(a, b) => seg_dist(q, a, b),
    }
}

/// Independent description of a body (from its parameters): (base z, pieces of the offset
/// surface at `d` continued `below` under the base plane, rim radius, pole z).
fn offset_surface(body: &BodyProfile, d: f64, below: f64) -> (f64, Vec<Piece>, f64, f64) {
    match *body {
        BodyProfile::Flat { .. } => panic!("curved bodies only"),
        BodyProfile::HemisphereOnCylinder {
            radius_mm,
            cylinder_length_mm,
        } => {
            let rho = radius_mm + d;
            let zb = -cylinder_length_mm;
            (
                zb,
                vec![
                    Piece::Arc { rho, a_end: 0.0 },
                    Piece::Segment([rho, 0.0], [rho, zb - below]),
                ],
                rho,
                rho,
            )
        }
        BodyProfile::SphericalCap {
            base_diameter_mm,
            height_mm,
        } => {
            let b = base_diameter_mm / 2.0;
            let rs = (b * b + height_mm * height_mm) / (2.0 * height_mm);
            let zb = rs - height_mm;
            let rho = rs + d;
            let rim = (rho * rho - zb * zb).sqrt();
            (
                zb,
                vec![
                    Piece::Arc {
                        rho,
                        a_end: (zb / rho).asin(),
                    },
                    Piece::Segment([rim, zb], [rim, zb - below]),
                ],
                rim,
                rho,
            )
        }
        BodyProfile::HalfEllipsoid {
            diameter_mm,
            height_mm,
        } => {
            let (a, c) = (diameter_mm / 2.0, height_mm);
            (
                0.0,
                vec![
                    Piece::EllipseOffset { a, c, d },
                    Piece::Segment([a + d, 0.0], [a + d, -below]),
                ],
                a + d,
                c + d,
            )
        }
    }
}

/// The boundary of the solid at offset `d`, or of the shell between `d_in` and `d_out`.
fn region_boundary(body: &BodyProfile, d_in: Option<f64>, d_out: f64, below: f64) -> Vec<Piece> {
    let (zb, mut pieces, rim_out, pole_out) = offset_surface(body, d_out, below);
    let zbot = zb - below;
    match d_in {
        None => pieces.push(Piece::Segment([0.0, zbot], [rim_out, zbot])),
        Some(d_in) => {
            let (_, inner, rim_in, pole_in) = offset_surface(body, d_in, below);
            pieces.extend(inner);
            pieces.push(Piece::Segment([rim_in, zbot], [rim_out, zbot]));
            pieces.push(Piece::Segment([0.0, pole_in], [0.0, pole_out]));
        }
    }
    pieces
}

/// Largest distance from a mesh vertex to the region boundary, mm. The distance is evaluated
/// once per ring of vertices (same z, same radius to 1e-7 mm) at a representative point q0 and
/// bounded for the others by the triangle inequality: dist(q) <= dist(q0) + |q - q0|.
fn max_vertex_distance(mesh: &Mesh, pieces: &[Piece]) -> (f64, [f64; 3]) {
    let mut cache: HashMap<(u64, i64), ([f64; 2], f64)> = HashMap::new();
    let mut worst = (0.0f64, [0.0; 3]);
    for v in &mesh.vertices {
        let q = [v[0].hypot(v[1]), v[2]];
        let key = (q[1].to_bits(), (q[0] * 1e7).round() as i64);
        let (q0, d0) = *cache.entry(key).or_insert_with(|| {
            let d = pieces
                .iter()
                .map(|p| piece_distance(q, p))
                .fold(f64::INFINITY, f64::min);
            (q, d)
        });
        let d = d0 + (q[0] - q0[0]).abs();
        if d > worst.0 {
            worst = (d, *v);
        }
    }
    worst
}

/// The surface oracle itself: points of the true ellipse offset (foot + d * unit normal, from
/// the definition) are on it, a point moved 1e-7 mm along the normal is 1e-7 mm off, and the
/// scaled ellipse with semi-axes (a + d, c + d), which is not an offset, is far off.
#[test]
fn the_surface_oracle_is_sharp() {
    let (a, c, d) = (9.0, 24.0, -3.0); // smallest radius of curvature 81/24 = 3.375
    let piece = Piece::EllipseOffset { a, c, d };
    let mut scaled_off: f64 = 0.0;
    for k in 0..=200 {
        let th = FRAC_PI_2 * k as f64 / 200.0;
        let n = [c * th.cos(), a * th.sin()];
        let nl = n[0].hypot(n[1]);
        let n = [n[0] / nl, n[1] / nl];
        let p = [a * th.cos() + d * n[0], c * th.sin() + d * n[1]];
        let on = piece_distance(p, &piece);
        assert!(on <= 1e-12, "theta {th}: {on}");
        let moved = piece_distance([p[0] + 1e-7 * n[0], p[1] + 1e-7 * n[1]], &piece);
        assert!((moved - 1e-7).abs() <= 1e-12, "theta {th}: {moved}");
        let s = [(a + d) * th.cos(), (c + d) * th.sin()];
        scaled_off = scaled_off.max(piece_distance(s, &piece));
    }
    // measured 0.406 mm (an offset ellipse is no ellipse); a blunt oracle would give about 0
    assert!(scaled_off > 0.1, "{scaled_off}");
    // and the arc: a cap's offset arc ends on the base plane
    let arc = Piece::Arc {
        rho: 5.0,
        a_end: 0.3,
    };
    assert!(piece_distance([5.0 * 0.3f64.cos(), 5.0 * 0.3f64.sin()], &arc) < 1e-15);
    assert!((piece_distance([5.0, 0.0], &arc) - 2.0 * 5.0 * (0.15f64).sin()).abs() < 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Checks shared by the properties.

/// A mesh and its solid are each a closed, consistently oriented 2-manifold of one shell and
/// the given genus, and agree on their volume.
fn check_topology(what: &str, mesh: &Mesh, solid: &Solid, genus: i64) -> Result<(), TestCaseError> {
    mesh.check_closed_manifold()
        .map_err(|e| TestCaseError::fail(format!("{what}: {e}")))?;
    prop_assert_eq!(mesh.genus(), genus, "{}: mesh genus", what);
    prop_assert_eq!(mesh.shell_count(), 1, "{}: mesh shells", what);
    prop_assert_eq!(solid.genus() as i64, genus, "{}: solid genus", what);
    prop_assert_eq!(solid.shell_count(), 1, "{}: solid shells", what);
    // Both volumes sum signed terms of the size of area x extent (a thin shell's volume is a
    // small difference of two large ones), so the noise scales with that.
    let v = mesh.signed_volume();
    let bb = mesh.bounding_box().unwrap().size();
    let scale = mesh.surface_area() * bb[0].hypot(bb[1]).hypot(bb[2]);
    prop_assert!(
        (solid.volume() - v).abs() <= 1e-12 * scale,
        "{}: kernel volume {} vs mesh volume {}",
        what,
        solid.volume(),
        v
    );
    Ok(())
}

/// |V_mesh - V_exact| <= A_mesh * tol (+ noise), and with `inscribed`, V_mesh <= V_exact.
/// `noise_scale` is the size of the terms `exact` was computed from (for a shell, the sum of
/// the two solids' volumes it is the difference of).
fn check_volume(
    what: &str,
    mesh: &Mesh,
    exact: f64,
    noise_scale: f64,
    tol: f64,
    inscribed: bool,
) -> Result<(), TestCaseError> {
    let v = mesh.signed_volume();
    let noise = VOLUME_NOISE_REL * noise_scale;
    let bound = mesh.surface_area() * tol + noise;
    prop_assert!(
        (v - exact).abs() <= bound,
        "{}: |V_mesh {} - V_exact {}| = {} exceeds A*tol = {}",
        what,
        v,
        exact,
        (v - exact).abs(),
        bound
    );
    if inscribed {
        prop_assert!(
            v <= exact + noise,
            "{}: V_mesh {} above V_exact {} by {} (facets should be inscribed)",
            what,
            v,
            exact,
            v - exact
        );
    }
    Ok(())
}

fn revolve_solid(
    pl: &geometry::Polyline2,
    tol: ChordTolerance,
) -> Result<(Mesh, Solid), TestCaseError> {
    let mesh = geometry::revolve(pl, tol).map_err(|e| TestCaseError::fail(e.to_string()))?;
    let solid = Solid::from_mesh(&mesh).map_err(|e| TestCaseError::fail(e.to_string()))?;
    Ok((mesh, solid))
}

// ---------------------------------------------------------------------------------------------
// Profiles.

fn check_profile_case(c: &ProfileCase) -> Result<(), TestCaseError> {
    let tol = ChordTolerance::new(c.tol).unwrap();
    let b = &c.body;
    prop_assert!(
        b.violations().is_empty(),
        "generated an invalid body {:?}",
        b
    );
    prop_assert!(b.offset_is_valid(c.d_in) && b.offset_is_valid(c.d_out));
    prop_assert!(c.d_in < c.d_out && c.d_out <= 0.0);

    // The shell between the two offsets.
    let pl = b.shell_profile(c.d_in, c.d_out, c.below_mm, tol.half());
    let (mesh, solid) = revolve_solid(&pl, tol)?;
    check_topology("shell", &mesh, &solid, 0)?;
    let (v_out, v_in) = (
        b.analytic_solid_volume_mm3(c.d_out, c.below_mm),
        b.analytic_solid_volume_mm3(c.d_in, c.below_mm),
    );
    check_volume("shell", &mesh, v_out - v_in, v_out + v_in, c.tol, false)?;
    let (worst, at) = max_vertex_distance(
        &mesh,
        &region_boundary(b, Some(c.d_in), c.d_out, c.below_mm),
    );
    prop_assert!(
        worst <= VERTEX_ON_SURFACE_MM,
        "shell vertex {:?} lies {} mm off the true surface",
        at,
        worst
    );

    // The same shell with each surface on its own segment count (what a featureless cast
    // layer is built from): the same solid as the outer enclosed solid less the inner one
    // continued under the base, and the same vertices, without the boolean.
    let (outer, inner) = (
        b.offset_polyline(c.d_out, c.below_mm, tol.half()),
        b.offset_polyline(c.d_in, c.below_mm, tol.half()),
    );
    let mesh = geometry::revolve_shell(&outer, &inner, tol)
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    let solid = Solid::from_mesh(&mesh).map_err(|e| TestCaseError::fail(e.to_string()))?;
    check_topology("shell on two counts", &mesh, &solid, 0)?;
    check_volume(
        "shell on two counts",
        &mesh,
        v_out - v_in,
        v_out + v_in,
        c.tol,
        false,
    )?;
    let (_, enclosed_out) = revolve_solid(&b.solid_profile(c.d_out, c.below_mm, tol.half()), tol)?;
    let (_, enclosed_in) =
        revolve_solid(&b.solid_profile(c.d_in, c.below_mm + 1.0, tol.half()), tol)?;
    let difference = enclosed_out
        .difference(&enclosed_in)
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert!(
        (difference.volume() - solid.volume()).abs() <= 1e-12 * (v_out + v_in),
        "shell on two counts: volume {} against the boolean's {}",
        solid.volume(),
        difference.volume()
    );
    prop_assert_eq!(
        solid.mesh().vertices.len(),
        difference.mesh().vertices.len()
    );

    // The full solids at both offsets: convex, so the inscribed mesh is not larger.
    for d in [c.d_out, c.d_in] {
        let pl = b.solid_profile(d, c.below_mm, tol.half());
        let (mesh, solid) = revolve_solid(&pl, tol)?;
        check_topology("solid", &mesh, &solid, 0)?;
        let exact = b.analytic_solid_volume_mm3(d, c.below_mm);
        check_volume("solid", &mesh, exact, exact, c.tol, true)?;
        let (worst, at) = max_vertex_distance(&mesh, &region_boundary(b, None, d, c.below_mm));
        prop_assert!(
            worst <= VERTEX_ON_SURFACE_MM,
            "solid vertex {:?} at d = {} lies {} mm off the true surface",
            at,
            d,
            worst
        );
    }
    Ok(())
}

#[test]
fn revolved_profiles_are_closed_genus0_and_within_the_chord_bound() {
    runner(64)
        .run(&profile_case(), |c| check_profile_case(&c))
        .unwrap();
}

/// One case of each profile at the smallest tolerance, largest sizes and the deepest offsets
/// the generator allows: the corners a random sample may miss.
#[test]
fn revolved_profiles_at_the_corners_of_the_ranges() {
    let bodies = [
        BodyProfile::HemisphereOnCylinder {
            radius_mm: 40.0,
            cylinder_length_mm: 20.0,
        },
        BodyProfile::HemisphereOnCylinder {
            radius_mm: 3.0,
            cylinder_length_mm: 0.0,
        },
        BodyProfile::SphericalCap {
            base_diameter_mm: 60.0,
            height_mm: 30.0,
        },
        BodyProfile::SphericalCap {
            base_diameter_mm: 5.0,
            height_mm: 0.5,
        },
        BodyProfile::HalfEllipsoid {
            diameter_mm: 40.0,
            height_mm: 3.0,
        },
        BodyProfile::HalfEllipsoid {
            diameter_mm: 5.0,
            height_mm: 40.0,
        },
    ];
    for body in bodies {
        for tol in [0.002, 0.05] {
            let avail = DEPTH_FRACTION * valid_depth_limit(&body) - tol;
            let d_out = -0.8 * avail;
            let c = ProfileCase {
                body: body.clone(),
                tol,
                d_in: -avail - tol,
                d_out,
                below_mm: 5.0,
            };
            check_profile_case(&c).unwrap_or_else(|e| panic!("{c:?}: {e}"));
            let c = ProfileCase {
                d_in: -tol,
                d_out: 0.0,
                below_mm: 0.0,
                ..c
            };
            check_profile_case(&c).unwrap_or_else(|e| panic!("{c:?}: {e}"));
        }
    }
}

/// The reference volumes used above agree with closed forms: the half ellipsoid's quadrature
/// at d = 0 (2/3 pi a^2 c) and the sphere formulas against a cap computed from first principles.
#[test]
fn analytic_volume_matches_closed_forms() {
    runner(64)
        .run(
            &(5.0..=40.0f64, 3.0..=40.0f64, 0.0..=5.0f64),
            |(dia, h, below)| {
                let b = BodyProfile::HalfEllipsoid {
                    diameter_mm: dia,
                    height_mm: h,
                };
                let a = dia / 2.0;
                let exact = 2.0 / 3.0 * PI * a * a * h + PI * a * a * below;
                let v = b.analytic_solid_volume_mm3(0.0, below);
                prop_assert!((v - exact).abs() <= 1e-9 * exact, "{} vs {}", v, exact);
                Ok(())
            },
        )
        .unwrap();
    runner(64)
        .run(
            &(5.0..=60.0f64, 0.1..=0.5f64, 0.0..=0.9f64),
            |(base, f, g)| {
                let h = f * base;
                let b = BodyProfile::SphericalCap {
                    base_diameter_mm: base,
                    height_mm: h,
                };
                // inward offset by g * h: a cap of the concentric sphere, height h - g h
                let d = -g * h;
                let bb = base / 2.0;
                let rs = (bb * bb + h * h) / (2.0 * h);
                let (rho, hh) = (rs + d, h + d);
                let exact = PI * hh * hh * (3.0 * rho - hh) / 3.0;
                let v = b.analytic_solid_volume_mm3(d, 0.0);
                prop_assert!((v - exact).abs() <= 1e-9 * exact, "{} vs {}", v, exact);
                Ok(())
            },
        )
        .unwrap();
}

// ---------------------------------------------------------------------------------------------
// Primitives.

#[derive(Debug, Clone)]
enum Primitive {
    Sphere { r: f64 },
    Cylinder { h: f64, r: f64 },
    Cone { h: f64, r_low: f64, r_high: f64 },
    Cuboid { min: [f64; 3], size: [f64; 3] },
}

fn primitive() -> impl Strategy<Value = Primitive> {
    let pos = || -20.0..=20.0f64;
    prop_oneof![
        (0.5..=40.0f64).prop_map(|r| Primitive::Sphere { r }),
        (0.2..=50.0f64, 0.5..=40.0f64).prop_map(|(h, r)| Primitive::Cylinder { h, r }),
        (
            0.2..=50.0f64,
            0.5..=40.0f64,
            prop_oneof![Just(0.0), 0.0..=1.0f64],
            any::<bool>()
        )
            .prop_map(|(h, r, f, flip)| {
                let (r_low, r_high) = if flip { (f * r, r) } else { (r, f * r) };
                Primitive::Cone { h, r_low, r_high }
            }),
        (
            [pos(), pos(), pos()],
            [0.1..=40.0f64, 0.1..=40.0f64, 0.1..=40.0f64]
        )
            .prop_map(|(min, size)| Primitive::Cuboid { min, size }),
    ]
}

#[test]
fn primitives_are_closed_and_within_the_chord_bound() {
    runner(128)
        .run(&(primitive(), tol_mm()), |(p, tol_mm)| {
            let tol = ChordTolerance::new(tol_mm).unwrap();
            let (solid, exact) = match p {
                Primitive::Sphere { r } => (geometry::sphere(r, tol), 4.0 / 3.0 * PI * r.powi(3)),
                Primitive::Cylinder { h, r } => (geometry::cylinder(h, r, tol), PI * r * r * h),
                Primitive::Cone { h, r_low, r_high } => (
                    geometry::cone(h, r_low, r_high, tol),
                    PI * h * (r_low * r_low + r_low * r_high + r_high * r_high) / 3.0,
                ),
                Primitive::Cuboid { min, size } => (
                    geometry::cuboid(min, [min[0] + size[0], min[1] + size[1], min[2] + size[2]]),
                    size[0] * size[1] * size[2],
                ),
            };
            let solid = solid.map_err(|e| TestCaseError::fail(format!("{p:?}: {e}")))?;
            let mesh = solid.mesh();
            check_topology(&format!("{p:?}"), &mesh, &solid, 0)?;
            // convex with vertices on the surface: inscribed
            check_volume(&format!("{p:?}"), &mesh, exact, exact, tol_mm, true)?;
            if let Primitive::Sphere { r } = p {
                for v in &mesh.vertices {
                    let off = (v[0].hypot(v[1]).hypot(v[2]) - r).abs();
                    prop_assert!(
                        off <= VERTEX_ON_SURFACE_MM,
                        "sphere vertex {:?} off by {}",
                        v,
                        off
                    );
                }
            }
            Ok(())
        })
        .unwrap();
}

// ---------------------------------------------------------------------------------------------
// Booleans.

#[derive(Debug, Clone)]
struct BoxMinusCylinder {
    min: [f64; 3],
    size: [f64; 3],
    r: f64,
    centre: [f64; 2],
    /// None: through hole; Some(depth): blind hole from the top face.
    depth: Option<f64>,
}

fn box_minus_cylinder() -> impl Strategy<Value = BoxMinusCylinder> {
    (
        [-20.0..=20.0f64, -20.0..=20.0f64, -20.0..=20.0f64],
        [4.0..=40.0f64, 4.0..=40.0f64, 2.0..=30.0f64],
        0.0..=1.0f64,
        [0.0..=1.0f64, 0.0..=1.0f64],
        prop_oneof![Just(None), (0.2..=0.8f64).prop_map(Some)],
    )
        .prop_map(|(min, size, fr, fc, depth)| {
            // a wall of at least 0.5 mm all round the hole
            let r_max = 0.5 * size[0].min(size[1]) - 0.5;
            let r = 0.5 + fr * (r_max - 0.5);
            let centre = [
                min[0] + r + 0.5 + fc[0] * (size[0] - 2.0 * r - 1.0),
                min[1] + r + 0.5 + fc[1] * (size[1] - 2.0 * r - 1.0),
            ];
            BoxMinusCylinder {
                min,
                size,
                r,
                centre,
                depth: depth.map(|f| f * size[2]),
            }
        })
}

#[test]
fn box_minus_cylinder_has_the_expected_genus_and_volume() {
    runner(64)
        .run(&(box_minus_cylinder(), tol_mm()), |(c, tol_mm)| {
            let tol = ChordTolerance::new(tol_mm).unwrap();
            let max = [
                c.min[0] + c.size[0],
                c.min[1] + c.size[1],
                c.min[2] + c.size[2],
            ];
            let block = geometry::cuboid(c.min, max).unwrap();
            // the tool pokes 1 mm out of each face it passes through
            let (z0, len) = match c.depth {
                None => (c.min[2] - 1.0, c.size[2]),
                Some(depth) => (max[2] - depth, depth),
            };
            let tool = geometry::cylinder(max[2] + 1.0 - z0, c.r, tol)
                .unwrap()
                .translate([c.centre[0], c.centre[1], z0]);
            let part = block
                .difference(&tool)
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
            let genus = if c.depth.is_none() { 1 } else { 0 };
            let mesh = part.mesh();
            check_topology(&format!("{c:?}"), &mesh, &part, genus)?;
            // The removed prism is inscribed in the cylinder: its cross-section is smaller by
            // at most perimeter x tol.
            let exact = c.size[0] * c.size[1] * c.size[2] - PI * c.r * c.r * len;
            let v = part.volume();
            let noise = VOLUME_NOISE_REL * exact;
            let bound = 2.0 * PI * c.r * tol_mm * len;
            prop_assert!(
                v >= exact - noise && v - exact <= bound + noise,
                "{:?}: volume {} vs exact {} (bound {})",
                c,
                v,
                exact,
                bound
            );
            Ok(())
        })
        .unwrap();
}
