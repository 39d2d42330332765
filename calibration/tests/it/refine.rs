//! Intrinsics refinement (`fabkit_calibration::refine`, R-Tac0 Sec. IV-A) on synthetic pin
//! observations: the benchmark scene (30 pins to 75 deg, the 160 deg Kannala-Brandt lens, a
//! camera tilted up to 3 deg; noise 0.2 px) with a camera file whose principal point and first
//! distortion terms are off; and pins seen from near the sphere's axis, where the focal length
//! trades against the camera's distance.

use fabkit_calibration::nalgebra::{
    Isometry3, Point3, Translation3, UnitQuaternion, Vector2, Vector3,
};
use fabkit_calibration::refine::{refine_intrinsics, RefineError, RefineParameters};
use fabkit_calibration::synthetic::{benchmark_intrinsics, benchmark_trial, pin_layout};
use fabkit_calibration::{solve_pnp, CameraModel, Distortion, Intrinsics, PnpOptions};

/// The camera file: the true lens with the principal point 3 and 2 px off and k1, k2 wrong.
fn camera_file() -> CameraModel {
    let mut file = benchmark_intrinsics();
    file.cx_px += 3.0;
    file.cy_px -= 2.0;
    file.distortion = Distortion::Fisheye([-0.01, 0.0, -0.0015, 0.0002]);
    CameraModel::new(file).unwrap()
}

fn truth_vector(i: &Intrinsics) -> Vec<f64> {
    let mut v = vec![i.fx_px, i.fy_px, i.cx_px, i.cy_px];
    v.extend_from_slice(i.distortion.coefficients());
    v
}

/// Largest |error / standard deviation| of a refined parameter or the pose's translation:
/// about 215 are checked (30 seeds, 4 to 8 refined intrinsics and 3 translations each); for
/// all of them to lie within it but with a probability of 1e-6 (Bonferroni over 330), each
/// must with 1 - 3e-9: 2 (1 - Phi(6.0)) = 2.0e-9. A bound of 3 was exceeded somewhere about
/// one run in five with ten seeds.
const Z_MAX: f64 = 6.0;

#[test]
fn refined_intrinsics_recover_the_truth_within_their_standard_deviations() {
    let truth = truth_vector(&benchmark_intrinsics());
    let cam = camera_file();
    let (mut z2, mut nz) = (0.0, 0);
    let mut by_criterion = 0;
    // three seed sets of ten (issue 96: a bound that holds on one set only is tuned to it)
    for seed in 1..=30 {
        let t = benchmark_trial(seed, 0.2, 0);
        let sol = solve_pnp(&cam, &t.points(), &t.pixels(), &PnpOptions::default()).unwrap();
        let r = refine_intrinsics(
            &cam,
            &t.points(),
            &t.pixels(),
            &sol.t_cam_sensor,
            &RefineParameters::Constrained,
        )
        .unwrap();
        // the residual RMS is the noise's: 30 x RMS^2 / sigma^2 is chi-square with 60 - p
        // degrees of freedom (p = 6 pose + 4 to 8 intrinsics), below 125 (Wilson-Hilferty, 50
        // dof) but with a probability of 3e-8 per seed, 1e-6 over the 30: RMS under
        // sqrt(125 x 0.2^2 / 30) = 0.41 px. Measured 0.20 to 0.30 px.
        assert!(
            r.rms_after_px < r.rms_before_px && r.rms_after_px < 0.41,
            "seed {seed}: rms {} -> {} px",
            r.rms_before_px,
            r.rms_after_px
        );
        let refined: Vec<&str> = r
            .parameters
            .iter()
            .filter(|p| p.held.is_none())
            .map(|p| p.name.as_str())
            .collect();
        for n in ["cx", "cy", "k1", "k2"] {
            assert!(refined.contains(&n), "seed {seed}: {n} not refined");
        }
        // k3 and k4 are the camera file's (the truth's): a fit that frees them gains too
        // little to pay for them (the Bayesian information criterion), or they trade
        // against the others beyond the condition number
        for p in &r.parameters[6..] {
            if let Some(why) = &p.held {
                by_criterion += usize::from(why.contains("the Bayesian information criterion"));
            }
        }
        for (p, tv) in r.parameters.iter().zip(&truth) {
            match (&p.held, p.std) {
                (Some(_), None) => assert_eq!(p.value, p.initial, "seed {seed}: {}", p.name),
                (None, Some(sd)) => {
                    let z = (p.value - tv) / sd;
                    assert!(
                        z.abs() < Z_MAX,
                        "seed {seed}: {} = {} +- {sd}, true {tv} ({z:.2} sigma)",
                        p.name,
                        p.value
                    );
                    z2 += z * z;
                    nz += 1;
                }
                other => panic!("seed {seed}: {}: {other:?}", p.name),
            }
        }
        // the pose follows the intrinsics to the truth, within its own standard deviations
        // (the covariance with the intrinsics': the focal length trades against the distance)
        let (_, t_std) = r.pose_std.expect("a covariance");
        let off = r.t_cam_sensor.translation.vector - t.t_cam_sensor().translation.vector;
        eprintln!(
            "seed {seed}: translation off by {:?} mm, std {t_std:?} mm",
            off.as_slice()
        );
        for (k, sd) in t_std.iter().enumerate() {
            let z = off[k] / sd;
            assert!(
                z.abs() < Z_MAX,
                "seed {seed}: t[{k}] off by {} mm +- {sd} ({z:.2} sigma)",
                off[k]
            );
            z2 += z * z;
            nz += 1;
        }
    }
    // k3 held by the information criterion where the condition number did not hold it:
    // measured in 26 of the 30 seeds
    eprintln!("k3 or k4 held by the information criterion in {by_criterion} of 30 seeds");
    assert!(by_criterion >= 15, "{by_criterion}");
    // the standard deviations are the spread of the errors (not 10 x too small or too large)
    let z_rms = (z2 / nz as f64).sqrt();
    // measured 1.024 over 214; an RMS of n unit normals varies by 1 / sqrt(2n) = 5 %
    assert!(
        (0.4..1.7).contains(&z_rms),
        "errors over standard deviations: RMS {z_rms:.2} over {nz}"
    );
}

/// 29 pins on a 13.46 mm sphere up to 72 deg, the camera 10.4 mm below its centre on the axis
/// (tilted 1.4 deg), noise 0.2 px (seeded).
fn near_axis() -> (Vec<Vector3<f64>>, Vec<Vector2<f64>>) {
    let pose = Isometry3::from_parts(
        Translation3::new(0.3, -0.2, 10.4),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.02, -0.015, 0.4)),
    );
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let pts = pin_layout(29, 13.46, 72.0);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut unit = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let px = pts
        .iter()
        .map(|p| {
            let (a, b) = (unit().max(1e-300), unit());
            let g = (-2.0 * a.ln()).sqrt();
            let tau = std::f64::consts::TAU * b;
            cam.project(&(pose * Point3::from(*p)).coords).unwrap()
                + 0.2 * Vector2::new(g * tau.cos(), g * tau.sin())
        })
        .collect();
    (pts, px)
}

#[test]
fn near_the_axis_the_focal_length_is_held_and_the_report_says_why() {
    let (pts, px) = near_axis();
    let cam = camera_file();
    let sol = solve_pnp(&cam, &pts, &px, &PnpOptions::default()).unwrap();
    let r = refine_intrinsics(
        &cam,
        &pts,
        &px,
        &sol.t_cam_sensor,
        &RefineParameters::Constrained,
    )
    .unwrap();
    for p in &r.parameters[..2] {
        let why = p
            .held
            .as_deref()
            .unwrap_or_else(|| panic!("{} refined", p.name));
        assert!(
            why.contains("the focal length (fx and fy together)")
                && why.contains("the camera's distance along its axis (tz)")
                && why.contains("condition number"),
            "{}: {why}",
            p.name
        );
        assert_eq!((p.value, p.std), (p.initial, None));
    }
    assert!(r.condition_number <= fabkit_calibration::refine::MAX_CONDITION);
    assert!(r.parameters[2..4].iter().all(|p| p.held.is_none()));

    // naming the focal length is refused, naming what trades against it
    let only = |s: &str| RefineParameters::Only(s.split(',').map(String::from).collect());
    let e =
        refine_intrinsics(&cam, &pts, &px, &sol.t_cam_sensor, &only("fx,fy,cx,cy,k1")).unwrap_err();
    match &e {
        RefineError::Unconstrained { name, with, .. } => {
            assert!(name == "fx" || name == "fy", "{e}");
            assert!(with.contains("(tz)"), "{e}");
        }
        other => panic!("{other}"),
    }
    assert!(e
        .to_string()
        .starts_with("--refine-intrinsics fx,fy,cx,cy,k1: the captures do not constrain f"));
    // cx, cy, k1, k2 alone are well conditioned
    let r = refine_intrinsics(&cam, &pts, &px, &sol.t_cam_sensor, &only("cx,cy,k1,k2")).unwrap();
    let held: Vec<&str> = r
        .parameters
        .iter()
        .filter(|p| p.held.is_some())
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(held, ["fx", "fy", "k3", "k4"]);

    // names the model does not have, and a name twice
    let e = refine_intrinsics(&cam, &pts, &px, &sol.t_cam_sensor, &only("cx,p1")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "--refine-intrinsics cx,p1: 'p1' is not a parameter of the fisheye model (its parameters: fx, fy, cx, cy, k1, k2, k3, k4)"
    );
    let e = refine_intrinsics(&cam, &pts, &px, &sol.t_cam_sensor, &only("cx,cx")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "--refine-intrinsics cx,cx: 'cx' is named twice"
    );
    // fewer observations than the fit needs
    let e = refine_intrinsics(&cam, &pts[..4], &px[..4], &sol.t_cam_sensor, &only("cx,cy"))
        .unwrap_err();
    assert!(matches!(e, RefineError::TooFewObservations { .. }), "{e}");
}

/// A pin at the edge of the camera model's field (issue 97: `--no-ransac --refine-intrinsics`
/// failed with "a point does not project at the camera file's intrinsics" where k1 and k2
/// alone worked): the camera file's plumb_bob k1 = -0.05 folds the image back beyond a radius
/// of 1 / sqrt(0.15), and the outermost of 25 pins lies 1e-7 inside it, so that the Jacobian's
/// step of k1 one way (6e-8) puts it outside. The refinement takes the other side's difference
/// there and recovers the camera the pixels were made with (k1 = -0.048, cx 2 px away).
#[test]
fn a_pin_at_the_edge_of_the_files_field_is_refined_one_sided() {
    let lens = |cx_px: f64, k1: f64| Intrinsics {
        image_width_px: 640,
        image_height_px: 480,
        fx_px: 300.0,
        fy_px: 300.0,
        cx_px,
        cy_px: 240.0,
        distortion: Distortion::PlumbBob([k1, 0.0, 0.0, 0.0, 0.0]),
    };
    let truth = CameraModel::new(lens(320.0, -0.048)).unwrap();
    let file = CameraModel::new(lens(322.0, -0.05)).unwrap();
    let r_edge = 1.0 / (0.15f64).sqrt() * (1.0 - 1e-7);
    // pins on a 10 mm sphere about the camera, out to the edge, five per ring
    let mut pts = Vec::new();
    for (ring, frac) in [0.0, 0.3, 0.55, 0.8, 1.0].iter().enumerate() {
        let theta = (r_edge * frac).atan();
        for k in 0..5 {
            let a = 2.0 * std::f64::consts::PI * (k as f64 + 0.37 * ring as f64) / 5.0;
            pts.push(
                10.0 * Vector3::new(theta.sin() * a.cos(), theta.sin() * a.sin(), theta.cos()),
            );
        }
    }
    let pose = Isometry3::identity();
    let px: Vec<Vector2<f64>> = pts.iter().map(|p| truth.project(p).unwrap()).collect();
    // the precondition: at the file's values a little more distortion puts the outermost
    // pins outside the field
    assert!(file.project(&pts[24]).is_some());
    let folded = CameraModel::new(lens(322.0, -0.05 - 6e-8)).unwrap();
    assert!(folded.project(&pts[24]).is_none());
    let only = RefineParameters::Only(vec!["cx".into(), "k1".into()]);
    let r = refine_intrinsics(&file, &pts, &px, &pose, &only).unwrap();
    let got = r.camera.intrinsics();
    let Distortion::PlumbBob(k) = got.distortion else {
        unreachable!()
    };
    // noise-free pixels: the truth to the refinement's convergence (measured 1e-13 px and
    // 7e-18)
    assert!(
        (got.cx_px - 320.0).abs() < 1e-6 && (k[0] + 0.048).abs() < 1e-9,
        "cx {} k1 {}",
        got.cx_px,
        k[0]
    );
}

/// Refined over the inner pins only (RANSAC kept them: the camera file's pinhole model put the
/// outer ones out), a plumb_bob model of a 160 deg equidistant lens folds its image back before
/// the outer pins (issue 97: the outer ring then no longer projected at all, its residuals
/// empty); `refine_intrinsics_keeping` refuses every step that would leave one of them
/// unprojected, and the refined model still fits the inner pins.
#[test]
fn the_refined_model_keeps_every_pin_projecting() {
    use fabkit_calibration::refine::{refine_intrinsics_keeping, refine_intrinsics_through};
    let lens = Intrinsics {
        image_width_px: 640,
        image_height_px: 480,
        fx_px: 172.0,
        fy_px: 172.0,
        cx_px: 320.0,
        cy_px: 240.0,
        distortion: Distortion::Fisheye([0.0; 4]),
    };
    let file = CameraModel::new(Intrinsics {
        distortion: Distortion::PlumbBob([0.0; 5]),
        ..lens
    })
    .unwrap();
    let truth = CameraModel::new(lens).unwrap();
    let pose = Isometry3::from_parts(
        Translation3::new(0.2, -0.1, 2.0),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.015, -0.01, 0.3)),
    );
    let pts = pin_layout(29, 16.65, 72.0);
    let px: Vec<Vector2<f64>> = pts
        .iter()
        .map(|p| truth.project(&(pose * Point3::from(*p)).coords).unwrap())
        .collect();
    // the inner 19 pins (to about 55 deg off the dome's axis)
    let (inner_p, inner_x) = (&pts[..19], &px[..19]);
    let which = RefineParameters::Only(["k1", "k2", "k3"].map(String::from).to_vec());
    let projects = |cam: &CameraModel, t: &Isometry3<f64>| {
        pts.iter()
            .filter(|p| cam.project(&(t * Point3::from(**p)).coords).is_some())
            .count()
    };
    assert_eq!(
        projects(&file, &pose),
        29,
        "the file's pinhole sees every pin"
    );
    let free = refine_intrinsics_through(&file, None, inner_p, inner_x, &pose, &which).unwrap();
    let kept =
        refine_intrinsics_keeping(&file, None, inner_p, inner_x, &pose, &which, &pts).unwrap();
    let (n_free, n_kept) = (
        projects(&free.camera, &free.t_cam_sensor),
        projects(&kept.camera, &kept.t_cam_sensor),
    );
    eprintln!(
        "free: {n_free} of 29 project, RMS {:.3} px; kept: {n_kept}, RMS {:.3} px",
        free.rms_after_px, kept.rms_after_px
    );
    // measured: unconstrained 22 of 29 project (inner RMS 0.036 px); kept, all 29 (inner RMS
    // 0.147 px)
    assert!(
        n_free < 29,
        "the unconstrained fit folds before an outer pin"
    );
    assert_eq!(n_kept, 29);
    assert!(kept.rms_after_px < free.rms_before_px, "{kept:?}");
}
