//! Criterion benchmark of the ground-truth casts on the issue-6 scene
//! (`fabkit_calibration::groundtruth::synthetic`): a 640 x 480 frame of the R-Tac0-like fisheye
//! camera against the R-Tac0 skin with six protrusions, about 200k triangles at 0.00085 mm chord
//! tolerance. Measured in CPU time of the benchmark thread (the machine is shared), one thread.
//!
//! - `full_cast`: every ray against every triangle (skin and protrusions; `cast_into`, which
//!   visits the triangles in leaf order for a whole frame);
//! - `full_cast_tile_order`: the same cast walking the hierarchy by 8 x 8 pixel tiles;
//! - `analytic_reference_plus_protrusion_triangles`: the skin in closed form for every ray, then
//!   the protrusion triangles (the cast skips the tiles that miss the protrusions' box);
//! - `reachable_rays_only`: only the rays that can reach a protrusion's bounds (tiles meeting a
//!   box of the protrusions' hierarchy) get the closed-form skin and the triangle cast; the
//!   other pixels keep the reference depth, rendered once per camera
//!   (`BenchScene::protrusion_frame`).
//!
//! Not timed: the hierarchy build and the rays, tiles and cube-face cells of the camera (once
//! per camera).
//! Figures and the Open3D comparison: docs/src/benchmarks.md, "Ground truth".

use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use fabkit_calibration::groundtruth::mesh::{CastOrder, FrameHits, Hit};
use fabkit_calibration::groundtruth::synthetic::{thread_cpu_time_s, BenchScene, FrameScratch};

/// CPU time of the benchmark thread, ns.
struct ThreadCpu;

struct NsFormatter;

impl ValueFormatter for NsFormatter {
    fn scale_values(&self, ns: f64, values: &mut [f64]) -> &'static str {
        let (f, u) = if ns < 1e3 {
            (1.0, "ns")
        } else if ns < 1e6 {
            (1e-3, "us")
        } else {
            (1e-6, "ms")
        };
        values.iter_mut().for_each(|v| *v *= f);
        u
    }
    fn scale_throughputs(&self, _typical: f64, t: &Throughput, values: &mut [f64]) -> &'static str {
        let n = match *t {
            Throughput::Elements(n) | Throughput::Bytes(n) | Throughput::BytesDecimal(n) => {
                n as f64
            }
            _ => 1.0,
        };
        values.iter_mut().for_each(|v| *v = n * 1e9 / *v / 1e6);
        "M rays/CPU-s"
    }
    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

impl Measurement for ThreadCpu {
    type Intermediate = f64;
    type Value = f64;
    fn start(&self) -> f64 {
        thread_cpu_time_s()
    }
    fn end(&self, i: f64) -> f64 {
        (thread_cpu_time_s() - i) * 1e9
    }
    fn add(&self, a: &f64, b: &f64) -> f64 {
        a + b
    }
    fn zero(&self) -> f64 {
        0.0
    }
    fn to_f64(&self, v: &f64) -> f64 {
        *v
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &NsFormatter
    }
}

fn bench(c: &mut Criterion<ThreadCpu>) {
    let scene = BenchScene::new(0.00085);
    let (all, prot) = scene.casters();
    let rays = &scene.rays;
    rays.tiles();
    rays.raster();
    let n = rays.len();
    eprintln!(
        "scene: {} triangles (skin {}, protrusions {}), {n} rays",
        all.triangle_count(),
        scene.body_mesh.triangles.len(),
        scene.protrusion_mesh.triangles.len()
    );
    let inf = vec![f64::INFINITY; n];
    let mut out = FrameHits {
        t_mm: Vec::new(),
        triangle: Vec::new(),
        normal: Vec::new(),
    };
    let mut g = c.benchmark_group("groundtruth_640x480_200k_triangles");
    g.sample_size(20);
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("full_cast", |b| {
        b.iter(|| all.cast_into(rays, &inf, &mut out))
    });
    g.bench_function("full_cast_tile_order", |b| {
        b.iter(|| all.cast_each_in(CastOrder::Tiles, rays, &inf, &mut |_| {}))
    });
    let mut scratch = FrameScratch::default();
    let mut hits: Vec<Hit> = Vec::new();
    g.bench_function("analytic_reference_plus_protrusion_triangles", |b| {
        b.iter(|| scene.protrusion_frame_all_rays(&prot, &mut scratch, &mut hits))
    });
    g.bench_function("reachable_rays_only", |b| {
        b.iter(|| scene.protrusion_frame(&prot, &mut scratch, &mut hits))
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpu);
    targets = bench
}
criterion_main!(benches);
