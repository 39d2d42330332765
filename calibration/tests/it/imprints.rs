//! Pin-imprint detection (R-Tac0 Sec. IV-A) on synthetic captures rendered with the
//! ground-truth caster: the R-Tac0 skin (a 15 mm hemisphere) seen by the benchmark fisheye
//! from 10 mm below its centre, one pin per ring pressed 1 mm in (a 1.5 mm ball tip), blurred,
//! vignetted, with flickering LED reflections at the rim and noise of 2 grey levels: every pin
//! found, nothing else (the reflections are not pins), centres within 0.1 px RMS of the true
//! centroids of the imprints.

use fabkit_calibration::groundtruth::surface::ReferenceSurface;
use fabkit_calibration::imprints::synthetic::{render, Pin, Shading};
use fabkit_calibration::imprints::{detect, reference_mask, DetectParams};
use fabkit_calibration::nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use fabkit_calibration::synthetic::benchmark_camera;

fn pose() -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(0.3, -0.2, 10.4),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.02, -0.015, 0.4)),
    )
}

/// One pin per ring (polar 0, 18, 34, 50 and 64 deg), turned by `turn_deg` between captures,
/// pressed `depth_mm` into the R = 15 mm skin along its normal by a ball of 1.5 mm radius.
fn capture_pins(turn_deg: f64, depth_mm: f64) -> Vec<Pin> {
    [
        (0.0, 0.0),
        (18.0, 30.0),
        (34.0, 150.0),
        (50.0, 250.0),
        (64.0, 330.0),
    ]
    .iter()
    .map(|&(polar, az)| {
        let (p, a) = (f64::to_radians(polar), f64::to_radians(az + turn_deg));
        let n = [p.sin() * a.cos(), p.sin() * a.sin(), p.cos()];
        let c = 15.0 + 1.5 - depth_mm;
        Pin {
            centre_mm: n.map(|x| c * x),
            radius_mm: 1.5,
        }
    })
    .collect()
}

#[test]
fn imprints_are_found_alone_and_centred_within_a_tenth_of_a_pixel() {
    let design = fabkit_designs::library::load("rtac0").unwrap();
    let surface = ReferenceSurface::of(&design.body).unwrap();
    let cam = benchmark_camera();
    let (mut sq, mut n, mut extra) = (0.0, 0, 0);
    for (k, turn) in [0.0, 45.0, 90.0, 135.0, 200.0, 290.0]
        .into_iter()
        .enumerate()
    {
        let pins = capture_pins(turn, 1.0);
        let r = render(
            &cam,
            &pose(),
            &surface,
            &pins,
            &Shading::default(),
            k as u64,
        );
        let mask = reference_mask(&r.reference, 255.0, 4);
        let spots = detect(
            &r.reference,
            &r.capture,
            Some(&mask),
            &DetectParams::default(),
        )
        .unwrap();
        let truth: Vec<[f64; 2]> = r.centres_px.iter().map(|c| c.unwrap()).collect();
        assert_eq!(
            spots.len(),
            truth.len(),
            "capture {k}: {spots:?} vs {truth:?}"
        );
        // without the reference's mask the flickering reflections show as spots too
        let all = detect(&r.reference, &r.capture, None, &DetectParams::default()).unwrap();
        extra += all.len() - spots.len();
        for t in &truth {
            let e = spots
                .iter()
                .map(|s| (s.u_px - t[0]).hypot(s.v_px - t[1]))
                .fold(f64::INFINITY, f64::min);
            sq += e * e;
            n += 1;
        }
    }
    assert!(
        extra > 0,
        "the LED reflections should differ between the images"
    );
    let rms = (sq / n as f64).sqrt();
    assert!(rms < 0.1, "centroid error {rms:.4} px RMS over {n} pins");
}
