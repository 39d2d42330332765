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

#[test]
fn rotation_and_translation_rms_over_300_seeded_trials_meet_the_issue_bounds() {
    let trials: Vec<Trial> = (0..300).map(|s| benchmark_trial(s, 0.5, 0)).collect();
    let plain = PnpOptions {
        ransac: None,
        ..Default::default()
    };
    let (r, t, _) = errors(&trials, &plain);
    assert!(r <= 0.191, "rotation RMS {r} deg");
    assert!(t <= 0.045, "translation RMS {t} mm");
    // RANSAC on clean data keeps every point and the same accuracy.
    let (r2, t2, sols) = errors(&trials, &PnpOptions::default());
    assert!(sols.iter().all(|s| s.inliers.iter().all(|&b| b)));
    assert!(
        (r2 - r).abs() < 1e-6 && (t2 - t).abs() < 1e-6,
        "{r2} vs {r}, {t2} vs {t}"
    );
}

#[test]
fn ransac_rejects_swapped_pins_and_keeps_rotation_rms_within_10_percent() {
    let clean: Vec<Trial> = (0..300).map(|s| benchmark_trial(s, 0.5, 0)).collect();
    let swapped: Vec<Trial> = (0..300).map(|s| benchmark_trial(s, 0.5, 3)).collect();
    let (r0, _, _) = errors(&clean, &PnpOptions::default());
    let (r1, t1, sols) = errors(&swapped, &PnpOptions::default());
    assert!(r1 <= 1.1 * r0, "swapped {r1} deg vs clean {r0} deg");
    assert!(t1 <= 0.05, "translation RMS {t1} mm");
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
    assert!(rn > 3.0 * r0, "no-RANSAC rotation RMS {rn}");
}

#[test]
fn same_input_same_pose() {
    let cam = benchmark_camera();
    let t = benchmark_trial(3, 0.5, 3);
    let a = solve_pnp(&cam, &t.points(), &t.pixels(), &PnpOptions::default()).unwrap();
    let b = solve_pnp(&cam, &t.points(), &t.pixels(), &PnpOptions::default()).unwrap();
    assert_eq!(a, b);
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
