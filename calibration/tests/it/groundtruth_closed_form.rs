//! Ground truth against closed forms: a sphere (the R-Tac0 skin) and a plane seen through the
//! Kannala-Brandt fisheye and the OpenCV pinhole (plumb_bob) models. Per pixel, the rendered
//! range equals the closed-form ray-sphere or ray-plane distance along the pixel's bearing to
//! 1 nm (closed-form surfaces: the same closed form, measured 0) or 1 um plus the chord
//! tolerance (triangle meshes, measured 2.7 um at 4 um; camera at the
//! sphere centre so that the rays meet the facets head on), the hit point reprojects onto its
//! pixel centre (forward model, checked against OpenCV in tests/calibrate_opencv.rs), and
//! z-depth is the hit's camera-frame z.

use fabkit_calibration::groundtruth::exact::ExactPrimitives;
use fabkit_calibration::groundtruth::mesh::{MeshCaster, NO_HIT};
use fabkit_calibration::groundtruth::rays::PixelRays;
use fabkit_calibration::groundtruth::surface::ReferenceSurface;
use fabkit_calibration::groundtruth::synthetic::{rtac0_body, skin_mesh, RTAC0_RADIUS_MM};
use fabkit_calibration::groundtruth::{indented_hits, reference_hits, DepthFrame};
use fabkit_calibration::nalgebra::{
    Isometry3, Point3, Translation3, UnitQuaternion, Vector2, Vector3,
};
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::{CameraModel, Distortion, Intrinsics};
use fabkit_designs::geometry::{ChordTolerance, Mesh};
use fabkit_designs::primitives::Primitive;

fn cameras() -> Vec<(&'static str, CameraModel)> {
    vec![
        (
            "fisheye (R-Tac0-like, 160 deg)",
            CameraModel::new(benchmark_intrinsics()).unwrap(),
        ),
        (
            "plumb_bob (k1 = -0.26)",
            CameraModel::new(Intrinsics {
                image_width_px: 640,
                image_height_px: 480,
                fx_px: 300.5,
                fy_px: 299.25,
                cx_px: 318.75,
                cy_px: 241.5,
                distortion: Distortion::PlumbBob([-0.26, 0.07, 0.001, -0.0005, -0.008]),
            })
            .unwrap(),
        ),
    ]
}

/// A pose slightly off the axis and tilted (the camera 10 mm below the sphere centre).
fn pose() -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(0.4, -0.3, 10.2),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.03, -0.02, 0.5)),
    )
}

/// Closed-form far intersection of the ray o + t d with the sphere |p| = r (o inside).
fn sphere_t(o: Vector3<f64>, d: Vector3<f64>, r: f64) -> f64 {
    let b = o.dot(&d);
    -b + (b * b - (o.norm_squared() - r * r)).sqrt()
}

/// Checks every pixel of `frame` against `closed` (sensor-frame ray -> expected range) within
/// `tol_mm`; returns (pixels checked, worst error mm).
fn check(
    cam: &CameraModel,
    rays: &PixelRays,
    frame: &DepthFrame,
    closed: impl Fn(Vector3<f64>, Vector3<f64>) -> Option<f64>,
    tol_mm: impl Fn(usize) -> f64,
    what: &str,
) -> (usize, f64) {
    let o = Vector3::from(rays.origin_mm);
    let (mut n, mut worst) = (0, 0.0f64);
    for p in 0..rays.len() {
        let (u, v) = ((p % rays.width) as f64, (p / rays.width) as f64);
        let Ok(b) = cam.unproject(&Vector2::new(u, v)) else {
            assert!(
                frame.range_mm[p].is_nan(),
                "{what}: pixel ({u}, {v}) does not unproject but has a depth"
            );
            continue;
        };
        let d = rays.t_cam_sensor.rotation.inverse() * b;
        let expect = closed(o, d);
        let got = frame.range_mm[p];
        match expect {
            None => assert!(
                got.is_nan(),
                "{what}: pixel ({u}, {v}) should miss, got {got}"
            ),
            Some(t) => {
                assert!(
                    got.is_finite(),
                    "{what}: pixel ({u}, {v}) should hit at {t}"
                );
                let e = (got - t).abs();
                assert!(
                    e <= tol_mm(p),
                    "{what}: pixel ({u}, {v}): range {got} vs closed form {t} ({e} mm)"
                );
                worst = worst.max(e);
                // z-depth and reprojection of the camera-frame hit point.
                let q = Point3::from(frame.point_cam_mm[p]);
                assert!((frame.zdepth_mm[p] - q.z).abs() < 1e-9);
                let uv = cam.project(&q.coords).unwrap();
                assert!(
                    (uv.x - u).abs() < 1e-6 && (uv.y - v).abs() < 1e-6,
                    "{what}: ({u}, {v}) reprojects to {uv:?}"
                );
                n += 1;
            }
        }
    }
    (n, worst)
}

#[test]
fn sphere_through_both_camera_models_matches_the_closed_form_to_1_nm() {
    let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
    let r = RTAC0_RADIUS_MM;
    for (name, cam) in cameras() {
        let rays = PixelRays::new(&cam, &pose());
        let frame = DepthFrame::new(&rays, &reference_hits(&rays, &surface));
        let closed = |o: Vector3<f64>, d: Vector3<f64>| {
            let t = sphere_t(o, d, r);
            ((o + t * d).z >= 0.0).then_some(t)
        };
        // Only the spherical part (z >= 0) is compared; the cylinder below is checked by the
        // surface unit tests.
        let mut f2 = frame.clone();
        let o = Vector3::from(rays.origin_mm);
        for p in 0..rays.len() {
            let d = Vector3::from(rays.dirs[p]);
            if d.iter().all(|c| c.is_finite()) && closed(o, d).is_none() {
                f2.range_mm[p] = f64::NAN;
            }
        }
        let (n, worst) = check(&cam, &rays, &f2, closed, |_| 1e-6, name);
        eprintln!(
            "sphere, {name}: {n} pixels, worst |range - closed form| = {:.2e} um",
            worst * 1e3
        );
        // measured 133,108 (fisheye) and 255,344 (plumb_bob)
        assert!(n > 50_000, "{name}: {n} pixels on the sphere");
    }
}

#[test]
fn tessellated_sphere_is_within_1_um_plus_the_chord_tolerance() {
    let tol = ChordTolerance::new(0.004).unwrap();
    let caster = MeshCaster::new(&skin_mesh(&rtac0_body(), tol));
    // Camera at the sphere centre: every ray meets the facets head on.
    let at_centre = Isometry3::from_parts(
        Translation3::new(0.0, 0.0, 0.0),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.02, 0.01, 0.3)),
    );
    for (name, cam) in cameras() {
        let rays = PixelRays::new(&cam, &at_centre);
        let hits = caster.cast(&rays, &vec![f64::INFINITY; rays.len()]);
        let mut frame = DepthFrame::new(
            &rays,
            &reference_hits(&rays, &ReferenceSurface::of(&rtac0_body()).unwrap()),
        );
        for p in 0..rays.len() {
            frame.range_mm[p] = if hits.triangle[p] == NO_HIT {
                f64::NAN
            } else {
                hits.t_mm[p]
            };
            let b = rays.bearings[p];
            let t = frame.range_mm[p];
            frame.zdepth_mm[p] = t * b[2];
            frame.point_cam_mm[p] = [t * b[0], t * b[1], t * b[2]];
        }
        // The hemisphere, and the cylinder r = 15.0 from z = 0 down to the base plane z = -6
        // (where the skin mesh is open). Rays that meet the cylinder within `edge` of the base
        // plane may hit or pass the facets' lower edge: they are left out of the comparison.
        let edge = 1e-3 + tol.mm();
        let cylinder_z = |o: Vector3<f64>, d: Vector3<f64>| -> Option<(f64, f64)> {
            let t = sphere_t(o, d, RTAC0_RADIUS_MM);
            if (o + t * d).z >= 0.0 {
                return None;
            }
            let (a, b) = (d.x * d.x + d.y * d.y, o.x * d.x + o.y * d.y);
            let c = o.x * o.x + o.y * o.y - RTAC0_RADIUS_MM * RTAC0_RADIUS_MM;
            let t = (-b + (b * b - a * c).sqrt()) / a;
            Some((t, (o + t * d).z))
        };
        let o = Vector3::from(rays.origin_mm);
        for p in 0..rays.len() {
            let d = rays.t_cam_sensor.rotation.inverse() * Vector3::from(rays.bearings[p]);
            if let Some((_, z)) = cylinder_z(o, d) {
                if (z + 6.0).abs() < edge {
                    frame.range_mm[p] = f64::NAN;
                }
            }
        }
        let closed = |o: Vector3<f64>, d: Vector3<f64>| match cylinder_z(o, d) {
            None => Some(sphere_t(o, d, RTAC0_RADIUS_MM)),
            Some((t, z)) => (z >= -6.0 + edge).then_some(t),
        };
        let (n, worst) = check(&cam, &rays, &frame, closed, |_| 1e-3 + tol.mm(), name);
        eprintln!(
            "tessellated sphere ({} mm), {name}: {n} pixels, worst {:.3} um",
            tol.mm(),
            worst * 1e3
        );
        // measured 307,053 and 291,467
        assert!(n > 50_000);
        assert!(worst > 0.0, "the facets are not the sphere");
    }
}

#[test]
fn plane_through_both_camera_models_matches_the_closed_form_exact_and_meshed() {
    // The plane z = 8 mm (sensor frame) as the bottom face of a large box protrusion, and as
    // two triangles.
    let z0 = 8.0;
    let plane = vec![Primitive::Box {
        centre_mm: [0.0, 0.0, z0 + 1.0],
        axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        half_extents_mm: [40.0, 40.0, 1.0],
    }];
    let exact = ExactPrimitives::new(&plane).unwrap();
    let quad = Mesh {
        vertices: vec![
            [-40.0, -40.0, z0],
            [40.0, -40.0, z0],
            [40.0, 40.0, z0],
            [-40.0, 40.0, z0],
        ],
        triangles: vec![[0, 2, 1], [0, 3, 2]],
    };
    let caster = MeshCaster::new(&quad);
    let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
    for (name, cam) in cameras() {
        let rays = PixelRays::new(&cam, &pose());
        let reference = reference_hits(&rays, &surface);
        let closed = |o: Vector3<f64>, d: Vector3<f64>| {
            let t = (z0 - o.z) / d.z;
            let p = o + t * d;
            (t > 0.0 && p.x.abs() <= 40.0 && p.y.abs() <= 40.0).then_some(t)
        };
        // Exact: the plane is where the protrusion pushes in (everywhere it is nearer than the
        // skin); compare those pixels.
        let ind = indented_hits(&rays, &reference, &exact, surface.base_z_mm());
        let mut frame = DepthFrame::new(&rays, &ind);
        for p in 0..rays.len() {
            if !ind.contact[p] {
                frame.range_mm[p] = f64::NAN;
            }
        }
        let o = Vector3::from(rays.origin_mm);
        let closed_contact = |oo: Vector3<f64>, d: Vector3<f64>| {
            let t = closed(oo, d)?;
            (t < sphere_t(oo, d, RTAC0_RADIUS_MM) && (oo + t * d).z >= surface.base_z_mm())
                .then_some(t)
        };
        let (n, worst) = check(&cam, &rays, &frame, closed_contact, |_| 1e-6, name);
        eprintln!(
            "plane (exact), {name}: {n} pixels, worst {:.2e} um",
            worst * 1e3
        );
        // measured 53,053 (fisheye) and 108,494 (plumb_bob)
        assert!(n > 10_000);
        // Meshed: two triangles, every ray.
        let hits = caster.cast(&rays, &vec![f64::INFINITY; rays.len()]);
        for p in 0..rays.len() {
            let t = if hits.triangle[p] == NO_HIT {
                f64::NAN
            } else {
                hits.t_mm[p]
            };
            let b = rays.bearings[p];
            frame.range_mm[p] = t;
            frame.zdepth_mm[p] = t * b[2];
            frame.point_cam_mm[p] = [t * b[0], t * b[1], t * b[2]];
        }
        let (n, worst) = check(&cam, &rays, &frame, closed, |_| 1e-6, name);
        eprintln!(
            "plane (2 triangles), {name}: {n} pixels, worst {:.2e} um",
            worst * 1e3
        );
        // measured 190,865 and 291,467
        assert!(n > 10_000);
        let _ = o;
    }
}

/// A flat skin's ground truth ranges to its outermost layer's face: 9DTact's black gel wraps
/// the translucent gel's sides by 0.8 mm (ninedtact.yaml, mold_2's pocket 31.1 x 24.1 R1.8 over
/// mold_1's 29.5 x 22.5 R1.0), so a ray 15.2 mm out along x (past the body's 14.75 mm, inside
/// the wrap's 15.55 mm) meets the contact face at z = 2.8 mm, not a side wall; Soter's layers
/// do not wrap, and its surface is its body's.
#[test]
fn a_wrapped_flat_skins_surface_is_its_outer_layers_face() {
    let nine = fabkit_designs::library::load("ninedtact").unwrap();
    let s = ReferenceSurface::of_design(&nine).unwrap();
    let ReferenceSurface::Flat {
        half_width_mm,
        half_length_mm,
        corner_radius_mm,
        top_z_mm,
    } = s
    else {
        panic!("{s:?}")
    };
    for (got, want) in [
        (half_width_mm, 15.55),
        (half_length_mm, 12.05),
        (corner_radius_mm, 1.8),
        (top_z_mm, 2.8),
    ] {
        assert!((got - want).abs() < 1e-12, "{s:?}");
    }
    assert_ne!(Some(s), ReferenceSurface::of(&nine.body));
    // from under the middle, straight up at x = 15.2 mm: the contact face
    let o = [0.0, 0.0, -10.0];
    let d = Vector3::new(15.2, 0.0, 12.8).normalize();
    let e = s.exit(o, [d.x, d.y, d.z]).unwrap();
    assert!(e.on_skin && (e.normal[2] - 1.0).abs() < 1e-12, "{e:?}");
    let soter = fabkit_designs::library::load("soter_channels").unwrap();
    assert_eq!(
        ReferenceSurface::of_design(&soter),
        ReferenceSurface::of(&soter.body)
    );
}
