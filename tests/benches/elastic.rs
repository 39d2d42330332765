//! Criterion benchmark of the elastic skin (`fabkit_calibration::elastic`,
//! `groundtruth::press_skin`) on the 9DTact ball press: a 4 mm sphere 1.715 mm into 2.8 mm of
//! incompressible gel bonded to its window, on the grid `groundtruth --press-image` uses (194 x
//! 194 cells of 0.15 mm, 29 mm a side). Timed: the kernels, once per sensor and grid (the
//! surface's influence transformed, and the seen face's 0.3 mm deep), and one frame: the
//! contact solved (Polonsky and Keer's conjugate gradient by FFT convolutions), the seen face
//! convolved, and the seen face sampled at 640 x 480 points of the contact face (one per pixel
//! of a camera that sees 32 x 24 mm). One thread (the kernels' Hankel tables use rayon
//! otherwise). Figures: docs/src/benchmarks.md, "Elastic skin".

use criterion::{criterion_group, criterion_main, Criterion};
use fabkit_calibration::elastic::{
    influence_at_depth, sphere_heights, ContactSolver, Convolver, Skin,
};
use fabkit_calibration::groundtruth::press_skin::{Face, PressedSkin, SkinModel};

fn bench(c: &mut Criterion) {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .ok();
    let model = SkinModel {
        thickness_mm: 2.8,
        poisson: 0.5,
        seen_depth_mm: 0.3,
        seen: "the black gel's inner face".into(),
    };
    let (radius, depth): (f64, f64) = (4.0, 1.715);
    let a = (2.0 * radius * depth - depth * depth).sqrt();
    let grid = PressedSkin::grid_for(&model, a + 4.0 * model.thickness_mm);
    assert_eq!(grid.n, 194);
    let skin: Skin = model.skin();
    let heights = sphere_heights(grid, radius, 0.0, 0.0);
    let mut g = c.benchmark_group("elastic_9dtact_ball");
    g.sample_size(10);
    g.bench_function("kernels", |b| {
        b.iter(|| {
            let s = ContactSolver::new(grid, skin).unwrap();
            let d = Convolver::new(grid.n, &influence_at_depth(grid, skin, 0.3));
            (s, d)
        })
    });
    let solver = ContactSolver::new(grid, skin).unwrap();
    let seen = Convolver::new(grid.n, &influence_at_depth(grid, skin, 0.3));
    let pressed = PressedSkin::solve(&model, radius, [0.0, 0.0], depth).unwrap();
    g.bench_function("frame_640x480", |b| {
        b.iter(|| {
            let contact = solver.solve(&heights, depth).unwrap();
            let face = seen.apply(&contact.pressure_mpa);
            let mut sum = face[0];
            for v in 0..480 {
                for u in 0..640 {
                    let (x, y) = (u as f64 * 0.05 - 16.0, v as f64 * 0.05 - 12.0);
                    sum += pressed.sample(Face::Seen, x, y).0;
                }
            }
            sum
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
