//! Seeded synthetic truth -> noise -> solve -> the pose is recovered within the issue's bounds
//! (300 trials of the benchmark scene, `fabkit_calibration::synthetic`); RANSAC rejects
//! mislabelled pins; bad input is a named error, never a panic.

use fabkit_calibration::synthetic::{
    benchmark_camera, benchmark_trial, pin_layout, rotation_error_deg, translation_error_mm, Trial,
};
use fabkit_calibration::{solve_pnp, PnpError, PnpOptions};
use nalgebra::{Isometry3, Point3, Vector2, Vector3};

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

fn errors(trials: &[Trial], opts: &PnpOptions) -> (f64, f64, Vec<fabkit_calibration::PnpSolution>) {
    let cam = benchmark_camera();
    let (mut er, mut et, mut sols) = (Vec::new(), Vec::new(), Vec::new());
    for t in trials {
        let s = solve_pnp(&cam, &t.points(), &t.pixels(), opts).unwrap();
        er.push(rotation_error_deg(&s.t_cam_sensor, &t.t_cam_sensor()));
        et.push(translation_error_mm(&s.t_cam_sensor, &t.t_cam_sensor()));
        sols.push(s);
    }
    (rms(&er), rms(&et), sols)
}

#[test]
fn noise_free_observations_give_the_true_pose() {
    let cam = benchmark_camera();
    for seed in 0..20 {
        let t = benchmark_trial(seed, 0.0, 0);
        let s = solve_pnp(&cam, &t.points(), &t.pixels(), &PnpOptions::default()).unwrap();
        assert!(rotation_error_deg(&s.t_cam_sensor, &t.t_cam_sensor()) < 1e-7);
        assert!(translation_error_mm(&s.t_cam_sensor, &t.t_cam_sensor()) < 1e-8);
        assert!(s.rms_reprojection_error_px < 1e-7);
    }
}

/// The three seed sets the statistical tests run on (issue 96: a bound that holds on one set
/// only is tuned to it): trials `300 k .. 300 (k + 1)`.
const SEED_SETS: [std::ops::Range<u64>; 3] = [0..300, 300..600, 600..900];

/// The bound on the RMS of an error over `trials` that a correct, efficient solver exceeds
/// with a probability under about 1e-9: from the Cramer-Rao bound at each trial's true pose
/// (pnp::pose_uncertainty: Sigma = sigma^2 (J^T J)^-1, Hartley & Zisserman Ch. 5), the
/// squared error of a trial is to first order a quadratic form in Gaussian noise, of mean
/// tr(S) and variance 2 tr(S^2) for its block S (rotation in deg^2 or translation in mm^2);
/// the mean over the trials is bounded at its mean plus 6 standard deviations. Returns (the
/// Cramer-Rao RMS, the bound), for rotation (`block` 0, deg) or translation (3, mm).
fn crb_bound(trials: &[Trial], sigma_px: f64, block: usize) -> (f64, f64) {
    let cam = benchmark_camera();
    let scale = if block == 0 {
        180.0 / std::f64::consts::PI
    } else {
        1.0
    };
    let (mut mean, mut var) = (0.0, 0.0);
    for t in trials {
        // the pins a correct RANSAC keeps: all but the swapped ones
        let inliers: Vec<bool> = (0..t.points().len())
            .map(|i| !t.swapped.contains(&i))
            .collect();
        let u = fabkit_calibration::pnp::pose_uncertainty(
            &cam,
            &t.points(),
            &t.pixels(),
            &inliers,
            &t.t_cam_sensor(),
        )
        .unwrap();
        let c = nalgebra::Matrix3::from_fn(|i, j| {
            u.covariance_per_px2[block + i][block + j] * sigma_px * sigma_px * scale * scale
        });
        mean += c.trace();
        var += 2.0 * (c * c).trace();
    }
    let n = trials.len() as f64;
    let (mean, sd) = (mean / n, var.sqrt() / n);
    (mean.sqrt(), (mean + 6.0 * sd).sqrt())
}

#[test]
fn rotation_and_translation_rms_over_300_seeded_trials_meet_the_cramer_rao_bound() {
    let plain = PnpOptions {
        ransac: None,
        ..Default::default()
    };
    for seeds in SEED_SETS {
        let trials: Vec<Trial> = seeds.clone().map(|s| benchmark_trial(s, 0.5, 0)).collect();
        let (r, t, _) = errors(&trials, &plain);
        let (crb_r, bound_r) = crb_bound(&trials, 0.5, 0);
        let (crb_t, bound_t) = crb_bound(&trials, 0.5, 3);
        eprintln!(
            "seeds {seeds:?}: rotation {r:.4} deg (Cramer-Rao {crb_r:.4}, bound {bound_r:.4}), translation {t:.4} mm (Cramer-Rao {crb_t:.4}, bound {bound_t:.4})"
        );
        assert!(
            r <= bound_r,
            "{seeds:?}: rotation RMS {r} deg over {bound_r}"
        );
        assert!(
            t <= bound_t,
            "{seeds:?}: translation RMS {t} mm over {bound_t}"
        );
        // The issue's targets (0.191 deg, 0.045 mm) are of the scene's geometry: its
        // Cramer-Rao RMS, a property of the pins and poses, not of the noise drawn (0.1827 to
        // 0.1834 deg and 0.0432 to 0.0434 mm on the three sets), lies within them; the solver
        // reaches it (measured 0.98 to 1.02 of it). The 4 % to the targets is ten times the
        // 0.4 % the seed sets move the bound by: not a margin on noise but the scene's figure.
        assert!(crb_r <= 0.191 && crb_t <= 0.045, "{crb_r} deg, {crb_t} mm");
    }
    let trials: Vec<Trial> = (0..300).map(|s| benchmark_trial(s, 0.5, 0)).collect();
    let (r, t, _) = errors(&trials, &plain);
    // RANSAC on clean data keeps every point and the same accuracy.
    let (r2, t2, sols) = errors(&trials, &PnpOptions::default());
    assert!(sols.iter().all(|s| s.inliers.iter().all(|&b| b)));
    assert!(
        (r2 - r).abs() < 1e-6 && (t2 - t).abs() < 1e-6,
        "{r2} vs {r}, {t2} vs {t}"
    );
}

#[test]
fn ransac_rejects_swapped_pins_and_keeps_the_cramer_rao_bound_of_the_rest() {
    for seeds in SEED_SETS {
        // three pins of each trial swapped: the pose is as good as the Cramer-Rao bound of the
        // 27 others allows (the swapped ones rejected)
        let swapped: Vec<Trial> = seeds.clone().map(|s| benchmark_trial(s, 0.5, 3)).collect();
        let (r1, t1, _) = errors(&swapped, &PnpOptions::default());
        let (crb_r, bound_r) = crb_bound(&swapped, 0.5, 0);
        let (crb_t, bound_t) = crb_bound(&swapped, 0.5, 3);
        eprintln!(
            "seeds {seeds:?}, 3 swapped: rotation {r1:.4} deg (Cramer-Rao {crb_r:.4}, bound {bound_r:.4}), translation {t1:.4} mm (Cramer-Rao {crb_t:.4}, bound {bound_t:.4})"
        );
        assert!(
            r1 <= bound_r,
            "{seeds:?}: rotation RMS {r1} deg over {bound_r}"
        );
        assert!(
            t1 <= bound_t,
            "{seeds:?}: translation RMS {t1} mm over {bound_t}"
        );
    }
    let clean: Vec<Trial> = (0..300).map(|s| benchmark_trial(s, 0.5, 0)).collect();
    let swapped: Vec<Trial> = (0..300).map(|s| benchmark_trial(s, 0.5, 3)).collect();
    let (r0, _, _) = errors(&clean, &PnpOptions::default());
    let (_, _, sols) = errors(&swapped, &PnpOptions::default());
    // Every swapped pin is rejected (they land tens of px from their true position).
    for (t, s) in swapped.iter().zip(&sols) {
        for &i in &t.swapped {
            assert!(!s.inliers[i], "seed {}: swapped pin {i} kept", t.seed);
        }
    }
    // Without RANSAC the swapped pins ruin the pose: the test would catch a no-op RANSAC.
    let (rn, _, _) = errors(
        &swapped,
        &PnpOptions {
            ransac: None,
            ..Default::default()
        },
    );
    // measured 81 x: one swapped pair moves the least-squares pose by degrees
    assert!(rn > 3.0 * r0, "no-RANSAC rotation RMS {rn}");
}

/// The same pairs in any order give the same pose, bit for bit, and the same inliers (each
/// flag following its pair): with three swapped pins that RANSAC must reject and the
/// threshold from the data (issue 97: on real captures the pose moved 0.83 deg with the order
/// of the captures and 1.96 deg with the sampler's seed, which is gone).
#[test]
fn the_pose_does_not_depend_on_the_order_of_the_pairs() {
    let cam = benchmark_camera();
    for seed in 0..5 {
        let seed = 1000 * crate::common::seed_set() + seed;
        let t = benchmark_trial(seed, 0.5, 3);
        let (pts, px) = (t.points(), t.pixels());
        let a = solve_pnp(&cam, &pts, &px, &PnpOptions::default()).unwrap();
        assert_eq!(
            a.inliers.iter().filter(|&&b| !b).count(),
            3,
            "seed {seed}: {:?}",
            a.inliers
        );
        let n = pts.len();
        let orders: Vec<Vec<usize>> = [1usize, 7, 13, 29]
            .iter()
            .map(|&step| (0..n).map(|i| (i * step + 5) % n).collect())
            .chain(std::iter::once((0..n).rev().collect()))
            .collect();
        for order in orders {
            let p: Vec<_> = order.iter().map(|&i| pts[i]).collect();
            let q: Vec<_> = order.iter().map(|&i| px[i]).collect();
            let b = solve_pnp(&cam, &p, &q, &PnpOptions::default()).unwrap();
            assert_eq!(
                b.t_cam_sensor, a.t_cam_sensor,
                "seed {seed}, order {order:?}"
            );
            for (k, &i) in order.iter().enumerate() {
                assert_eq!(b.inliers[k], a.inliers[i]);
                assert_eq!(b.residuals_px[k], a.residuals_px[i]);
            }
            assert_eq!(b.ransac_threshold_px, a.ransac_threshold_px);
        }
    }
}

/// RANSAC's samples: a fixed schedule of triples of distinct indices that reaches every
/// triple of a few points soon (each of the C(n, 3) within 40 x C(n, 3) draws for n up to 12).
#[test]
fn the_sample_schedule_reaches_every_triple() {
    use fabkit_calibration::pnp::Triples;
    for n in 3..=12usize {
        let all = n * (n - 1) * (n - 2) / 6;
        let mut seen = std::collections::BTreeSet::new();
        let mut t = Triples::new(n);
        for _ in 0..40 * all {
            let mut s = t.next_triple();
            assert!(s.iter().all(|&i| i < n) && s[0] != s[1] && s[1] != s[2] && s[0] != s[2]);
            s.sort_unstable();
            seen.insert(s);
        }
        assert_eq!(seen.len(), all, "n = {n}");
        // the same n, the same schedule
        let (mut a, mut b) = (Triples::new(n), Triples::new(n));
        assert!((0..100).all(|_| a.next_triple() == b.next_triple()));
    }
}

fn project_all(pose: &Isometry3<f64>, pts: &[Vector3<f64>]) -> Vec<Vector2<f64>> {
    let cam = benchmark_camera();
    pts.iter()
        .map(|p| cam.project(&(pose * Point3::from(*p)).coords).unwrap())
        .collect()
}

#[test]
fn bad_input_is_a_named_error() {
    let cam = benchmark_camera();
    let t = benchmark_trial(1, 0.5, 0);
    let (p, uv) = (t.points(), t.pixels());
    let o = PnpOptions::default();
    assert_eq!(
        solve_pnp(&cam, &p[..3], &uv[..3], &o).unwrap_err(),
        PnpError::TooFewPoints {
            given: 3,
            needed: 4
        }
    );
    assert!(matches!(
        solve_pnp(&cam, &p, &uv[..10], &o),
        Err(PnpError::LengthMismatch { .. })
    ));
    let mut bad = uv.clone();
    bad[5].x = f64::NAN;
    assert_eq!(
        solve_pnp(&cam, &p, &bad, &o).unwrap_err(),
        PnpError::NonFinite {
            index: 5,
            what: "pixel"
        }
    );
    let mut badp = p.clone();
    badp[2].z = f64::INFINITY;
    assert_eq!(
        solve_pnp(&cam, &badp, &uv, &o).unwrap_err(),
        PnpError::NonFinite {
            index: 2,
            what: "point"
        }
    );
    // Collinear points: the rotation about their line is free.
    let line: Vec<Vector3<f64>> = (0..6)
        .map(|i| Vector3::new(i as f64, 0.5 * i as f64, 5.0))
        .collect();
    let pose = t.t_cam_sensor();
    let e = solve_pnp(&cam, &line, &project_all(&pose, &line), &o).unwrap_err();
    assert!(matches!(e, PnpError::Degenerate { .. }), "{e}");
    assert_eq!(e.to_string(), "degenerate layout: the points are collinear");
    // A pixel far outside the lens's image circle.
    let mut far = uv.clone();
    far[4] = Vector2::new(1e6, 1e6);
    assert!(matches!(
        solve_pnp(&cam, &p, &far, &o),
        Err(PnpError::Unprojectable { index: 4, .. })
    ));
    // Garbage labels everywhere: RANSAC finds no consensus rather than a wrong pose.
    let mut shuffled = uv.clone();
    shuffled.reverse();
    let e = solve_pnp(&cam, &p, &shuffled, &o);
    assert!(
        matches!(
            e,
            Err(PnpError::TooFewInliers { .. }) | Err(PnpError::NoSolution)
        ),
        "{e:?}"
    );
}

#[test]
fn layout_of_the_benchmark_matches_the_issue() {
    let pts = pin_layout(30, 15.0, 75.0);
    assert_eq!(pts.len(), 30);
    let polar: Vec<f64> = pts
        .iter()
        .map(|p| (p.z / p.norm()).acos().to_degrees())
        .collect();
    assert!(polar[0].abs() < 1e-9 && (polar[29] - 75.0).abs() < 1e-9);
    assert!(pts.iter().all(|p| (p.norm() - 15.0).abs() < 1e-12));
}

/// A scene of `n` pins within `max_polar_deg` of the pole, seen with noise `sigma_px`.
fn scene(seed: u64, n: usize, max_polar_deg: f64, sigma_px: f64) -> Trial {
    let mut t = benchmark_trial(seed, 0.0, 0);
    let cam = benchmark_camera();
    let iso = t.t_cam_sensor();
    let pts = pin_layout(n, 15.0, max_polar_deg);
    // seeded noise, the same generator for every scene
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut normal = || {
        let mut u = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (u1, u2) = (1.0 - u(), u());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    };
    t.points_mm = pts.iter().map(|p| [p.x, p.y, p.z]).collect();
    t.pixels_px = pts
        .iter()
        .map(|p| {
            let uv = cam.project(&(iso * Point3::from(*p)).coords).unwrap();
            [uv.x + sigma_px * normal(), uv.y + sigma_px * normal()]
        })
        .collect();
    t
}

/// The reported pose covariance predicts the pose error: over 300 seeded trials of the
/// benchmark scene at 0.5 px noise, the RMS rotation and translation errors are within 20 % of
/// what the covariance gives for that noise (0.18 deg and 0.04 mm both), and the geometry is
/// not weak.
#[test]
fn pose_covariance_predicts_the_pose_error() {
    use fabkit_calibration::pnp::{WEAK_POSE_DEG_PER_PX, WEAK_POSE_MM_PER_PX};
    let cam = benchmark_camera();
    let sigma = 0.5;
    let (mut er, mut et, mut pr, mut pt) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for seed in 0..300 {
        let t = benchmark_trial(seed, sigma, 0);
        let opts = PnpOptions {
            ransac: None,
            ..Default::default()
        };
        let s = solve_pnp(&cam, &t.points(), &t.pixels(), &opts).unwrap();
        let u = fabkit_calibration::pose_uncertainty(
            &cam,
            &t.points(),
            &t.pixels(),
            &s.inliers,
            &s.t_cam_sensor,
        )
        .unwrap();
        er.push(rotation_error_deg(&s.t_cam_sensor, &t.t_cam_sensor()));
        et.push(translation_error_mm(&s.t_cam_sensor, &t.t_cam_sensor()));
        let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        pr.push(sigma * norm(u.rotation_std_deg_per_px));
        pt.push(sigma * norm(u.translation_std_mm_per_px));
        assert!(u
            .rotation_std_deg_per_px
            .iter()
            .all(|&x| x < WEAK_POSE_DEG_PER_PX));
        assert!(u
            .translation_std_mm_per_px
            .iter()
            .all(|&x| x < WEAK_POSE_MM_PER_PX));
    }
    let (r, t, p_r, p_t) = (rms(&er), rms(&et), rms(&pr), rms(&pt));
    eprintln!("observed {r:.4} deg, {t:.4} mm; predicted {p_r:.4} deg, {p_t:.4} mm at {sigma} px");
    // measured 1.000 (rotation) and 1.019 (translation); the RMS of 300 trials' 3-D errors
    // varies by about 1 / sqrt(2 x 3 x 300) = 2.4 % (one sd), so 20 % is about 8 sd beyond it
    assert!(
        (r / p_r - 1.0).abs() < 0.2,
        "rotation: observed {r} deg, predicted {p_r} deg"
    );
    assert!(
        (t / p_t - 1.0).abs() < 0.2,
        "translation: observed {t} mm, predicted {p_t} mm"
    );
}

/// Four pins within 18 deg of the pole fit with a low RMS and a pose degrees off (it exited 0
/// without a word): the report gives the large covariance and warns of the weak geometry; the
/// benchmark's 30 pins over 75 deg do not warn.
#[test]
fn four_pins_near_the_pole_report_their_covariance_and_warn() {
    use fabkit_calibration::report::{ExtrinsicsReport, Provenance};
    use fabkit_calibration::tables::Pairs;
    let cam = benchmark_camera();
    let report = |t: &Trial| {
        let s = solve_pnp(&cam, &t.points(), &t.pixels(), &PnpOptions::default()).unwrap();
        let pairs = Pairs {
            ids: (0..t.points_mm.len()).map(|i| i.to_string()).collect(),
            points_mm: t.points(),
            pixels_px: t.pixels(),
        };
        let prov = Provenance {
            fabkit_version: String::new(),
            command_line: String::new(),
            camera_file: String::new(),
            points_file: String::new(),
            points_from: "xyz".into(),
            observation_files: Vec::new(),
            capture_plan: None,
            unobserved_ids: Vec::new(),
            reference_image: None,
        };
        (
            s.clone(),
            ExtrinsicsReport::new(
                &fabkit_calibration::refraction::Imaging::straight(&cam),
                &pairs,
                &s,
                prov,
            ),
        )
    };
    let weak = scene(3, 4, 18.0, 0.15);
    let (s, r) = report(&weak);
    let off = rotation_error_deg(&s.t_cam_sensor, &weak.t_cam_sensor());
    let u = r.pose_uncertainty.as_ref().expect("a covariance");
    let worst = u
        .rotation_std_deg_per_px
        .iter()
        .copied()
        .fold(0.0, f64::max);
    // measured 16.0 deg/px: eight times the bound
    assert!(worst > 2.0, "{u:?}");
    assert!(
        r.warnings.len() == 1
            && r.warnings[0].starts_with("weak geometry: the pose is uncertain by up to")
            && r.warnings[0].contains("4 pins, the farthest 18.0 deg from the sensor axis"),
        "{:?}",
        r.warnings
    );
    assert!(r.to_json().contains("\"rotation_std_deg_per_px\""));
    eprintln!(
        "4 pins within 18 deg: RMS {:.3} px, pose {off:.2} deg off, std up to {worst:.2} deg/px",
        s.rms_reprojection_error_px
    );
    let (_, r) = report(&benchmark_trial(3, 0.5, 0));
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

/// The benchmark lens as a camera file that follows it only roughly: the fisheye's k1 0.08 off,
/// errors of several px that grow towards the edge of the field, as a real file of a
/// wide-angle lens has.
fn rough_benchmark_camera() -> fabkit_calibration::CameraModel {
    use fabkit_calibration::{CameraModel, Distortion};
    let truth = fabkit_calibration::synthetic::benchmark_intrinsics();
    let Distortion::Fisheye(k) = truth.distortion else {
        panic!("the benchmark lens is a fisheye")
    };
    CameraModel::new(fabkit_calibration::Intrinsics {
        distortion: Distortion::Fisheye([k[0] + 0.08, k[1], k[2], k[3]]),
        ..truth
    })
    .unwrap()
}

/// Through [`rough_benchmark_camera`] with 3 pins swapped, 20 seeds: a fixed 3 px threshold
/// drops good pins in about half of them (11 of 20), the threshold from the data (the default;
/// 4.4 to 7.6 px here) keeps every pin that is not swapped and rejects the swapped ones in all.
#[test]
fn the_threshold_from_the_data_follows_a_rough_camera_file() {
    use fabkit_calibration::RansacOptions;
    let rough = rough_benchmark_camera();
    let fixed = PnpOptions {
        ransac: Some(RansacOptions {
            threshold_px: Some(3.0),
            ..RansacOptions::default()
        }),
        ..Default::default()
    };
    let (mut fixed_failed, mut thresholds) = (0, Vec::new());
    for seed in 0..20 {
        let t = benchmark_trial(seed, 0.5, 3);
        let (pts, px) = (t.points(), t.pixels());
        if !matches!(
            solve_pnp(&rough, &pts, &px, &fixed),
            Ok(s) if s.inliers.iter().filter(|&&b| b).count() >= 27
        ) {
            fixed_failed += 1;
        }
        let s = solve_pnp(&rough, &pts, &px, &PnpOptions::default()).unwrap();
        for i in 0..pts.len() {
            assert_eq!(
                s.inliers[i],
                !t.swapped.contains(&i),
                "seed {seed}: pin {i} (swapped: {:?})",
                t.swapped
            );
        }
        thresholds.push(s.ransac_threshold_px.unwrap());
        // measured 0.04 to 0.52 deg over the 20 seeds: a quarter of the bound
        assert!(rotation_error_deg(&s.t_cam_sensor, &t.t_cam_sensor()) < 2.0);
    }
    eprintln!("fixed 3 px failed {fixed_failed} of 20; thresholds {thresholds:?}");
    // measured 11 of 20: a fixed 3 px drops good pins of a rough file's edge in about half
    assert!(
        fixed_failed >= 8,
        "fixed 3 px failed only {fixed_failed} of 20"
    );
    assert!(thresholds.iter().all(|&t| t > 3.0));
}

/// The final refinement reaches the optimum of the pins it keeps (issue 97: on real captures
/// it stopped 1.96 deg short with one seed): through [`rough_benchmark_camera`] (the camera's
/// distance trades against the lens along a flat valley of the reprojection error)
/// with three pins swapped, the returned pose is a stationary point of the reprojection error
/// over its inliers (the Gauss-Newton step from it would gain at most 1e-6 of the cost: the
/// refinement stops at a relative change of 1e-8), and a second solve on those inliers alone
/// (SQPnP and Levenberg-Marquardt, no RANSAC) finds no lower cost. Measured on seed sets 0 to
/// 2: gains of at most 5e-11 of the cost; second solves equal to 1e-12.
#[test]
fn the_final_pose_is_the_optimum_of_its_inliers() {
    use fabkit_calibration::pnp::reprojection_normal_equations;
    let rough = rough_benchmark_camera();
    let (mut worst_gain, mut worst_second) = (0.0f64, f64::INFINITY);
    for seed in 0..20 {
        let seed = 1000 * crate::common::seed_set() + seed;
        let t = benchmark_trial(seed, 0.5, 3);
        let (pts, px) = (t.points(), t.pixels());
        let s = solve_pnp(&rough, &pts, &px, &PnpOptions::default()).unwrap();
        let keep: Vec<usize> = (0..pts.len()).filter(|&i| s.inliers[i]).collect();
        let (p, q): (Vec<_>, Vec<_>) = keep.iter().map(|&i| (pts[i], px[i])).unzip();
        let (jtj, jte, cost) =
            reprojection_normal_equations(&rough, &p, &q, &s.t_cam_sensor).unwrap();
        let d = jtj.cholesky().unwrap().solve(&(-jte));
        let gain = -(d.dot(&jte)) - 0.5 * (d.transpose() * jtj * d)[0];
        worst_gain = worst_gain.max(gain / cost);
        assert!(
            gain <= 1e-6 * cost,
            "seed {seed}: a step would gain {gain} of {cost} px^2"
        );
        let plain = PnpOptions {
            ransac: None,
            ..Default::default()
        };
        let second = solve_pnp(&rough, &p, &q, &plain).unwrap();
        let c2 = reprojection_normal_equations(&rough, &p, &q, &second.t_cam_sensor)
            .unwrap()
            .2;
        worst_second = worst_second.min(c2 / cost - 1.0);
        assert!(
            c2 >= cost * (1.0 - 1e-9),
            "seed {seed}: a second solve reaches {c2} < {cost}"
        );
    }
    eprintln!("worst predicted gain {worst_gain:.2e} of the cost; second solves at least {worst_second:.2e} above");
}
