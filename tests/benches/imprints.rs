//! Criterion benchmark of the pin-imprint detector (`fabkit_calibration::imprints`) on one
//! synthetic 640 x 480 capture and its reference (the R-Tac0 skin seen by the benchmark
//! fisheye, 5 pins pressed 1 mm, blur, vignetting, LED reflections, noise of 2 grey levels;
//! rendered once, outside the timing): `detect` with the mask given, and `reference_mask`
//! plus `detect` (what a capture costs when its reference is new). One thread: the detector
//! does not use rayon. Figures: README, "Calibration: extrinsics accuracy and speed".

use criterion::{criterion_group, criterion_main, Criterion};
use fabkit_calibration::groundtruth::surface::ReferenceSurface;
use fabkit_calibration::imprints::synthetic::{render, ring_pins, Shading};
use fabkit_calibration::imprints::{detect, reference_mask, DetectParams};
use fabkit_calibration::nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use fabkit_calibration::synthetic::benchmark_camera;

fn bench(c: &mut Criterion) {
    let design = fabkit::designs::library::load("rtac0").unwrap();
    let surface = ReferenceSurface::of(&design.body).unwrap();
    let pose = Isometry3::from_parts(
        Translation3::new(0.3, -0.2, 10.4),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.02, -0.015, 0.4)),
    );
    let pins = ring_pins(0.0, 1.0);
    let r = render(
        &benchmark_camera(),
        &pose,
        &surface,
        &pins,
        &Shading::default(),
        1,
    );
    let mask = reference_mask(&r.reference, 255.0, 4);
    let p = DetectParams::default();
    assert_eq!(
        detect(&r.reference, &r.capture, Some(&mask), &p)
            .unwrap()
            .len(),
        5
    );
    let mut g = c.benchmark_group("imprints_640x480");
    g.sample_size(50);
    g.bench_function("detect", |b| {
        b.iter(|| detect(&r.reference, &r.capture, Some(&mask), &p).unwrap())
    });
    g.bench_function("mask_and_detect", |b| {
        b.iter(|| {
            let m = reference_mask(&r.reference, 255.0, 4);
            detect(&r.reference, &r.capture, Some(&m), &p).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
