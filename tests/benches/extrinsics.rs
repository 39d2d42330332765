//! Criterion benchmark of the extrinsics solve on the issue-5 synthetic scene
//! (`fabkit_calibration::synthetic`: 30 pins, Kannala-Brandt f = 215 px, sigma 0.5 px):
//! one solve without RANSAC, with RANSAC on clean data, and with RANSAC and 3 swapped pins.
//! Figures and the OpenCV comparison: docs/src/benchmarks.md, "Extrinsics: accuracy and speed".

use criterion::{criterion_group, criterion_main, Criterion};
use fabkit_calibration::synthetic::{benchmark_camera, benchmark_trial};
use fabkit_calibration::{solve_pnp, PnpOptions};

fn bench(c: &mut Criterion) {
    let cam = benchmark_camera();
    let sets = |swapped| -> Vec<_> {
        (0..300)
            .map(|s| {
                let t = benchmark_trial(s, 0.5, swapped);
                (t.points(), t.pixels())
            })
            .collect()
    };
    let clean = sets(0);
    let swapped = sets(3);
    let plain = PnpOptions {
        ransac: None,
        ..Default::default()
    };
    let ransac = PnpOptions::default();
    let mut g = c.benchmark_group("extrinsics_300_trials");
    g.sample_size(20);
    g.bench_function("no_ransac", |b| {
        b.iter(|| {
            clean
                .iter()
                .map(|(p, uv)| solve_pnp(&cam, p, uv, &plain).is_ok() as usize)
                .sum::<usize>()
        })
    });
    g.bench_function("ransac_clean", |b| {
        b.iter(|| {
            clean
                .iter()
                .map(|(p, uv)| solve_pnp(&cam, p, uv, &ransac).is_ok() as usize)
                .sum::<usize>()
        })
    });
    g.bench_function("ransac_3_swapped", |b| {
        b.iter(|| {
            swapped
                .iter()
                .map(|(p, uv)| solve_pnp(&cam, p, uv, &ransac).is_ok() as usize)
                .sum::<usize>()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
