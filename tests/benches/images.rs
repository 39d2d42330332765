//! Criterion benchmark of image formation (`fabkit_calibration::groundtruth::shading`): one
//! 640 x 480 frame of the R-Tac0-like fisheye camera (the benchmark pose) on the R-Tac0 skin
//! with a 4 mm sphere tip pressed 2 mm into it, lit by two lights, on one thread (a one-thread
//! rayon pool; wall time, so run it on a quiet machine).
//!
//! - `radiance_two_lights_shadows`: every pixel's radiance, with a shadow ray per light
//!   against the tip;
//! - `expose_8bit`: the camera's response (gain, vignetting, seeded noise, 8 bit);
//! - `frame_image_two_lights_shadows_8bit`: both, the whole image of a frame as `fabkit
//!   groundtruth --images` makes it (the 20 ms target);
//! - `indented_hits`: the surface along every ray (closed-form skin, exact tip), for scale.
//!
//! Not timed: the camera's rays (once per camera).

use criterion::{criterion_group, criterion_main, Criterion};
use fabkit_calibration::groundtruth::exact::ExactPrimitives;
use fabkit_calibration::groundtruth::rays::PixelRays;
use fabkit_calibration::groundtruth::shading::{expose, frame_radiance, Exposure, Imaging};
use fabkit_calibration::groundtruth::surface::ReferenceSurface;
use fabkit_calibration::groundtruth::synthetic::{benchmark_pose, rtac0_body};
use fabkit_calibration::groundtruth::{indented_hits, reference_hits};
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::CameraModel;
use fabkit_designs::optics::{CameraResponse, Light, Reflectance, ResolvedOptics};
use fabkit_designs::primitives::Primitive;

fn bench(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let rays = PixelRays::new(&cam, &benchmark_pose());
    let prims = ExactPrimitives::new(&[Primitive::Sphere {
        centre_mm: [2.0, -1.0, 15.0],
        radius_mm: 4.0,
    }])
    .unwrap();
    let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
    let reference = reference_hits(&rays, &surface);
    let hits = indented_hits(&rays, &reference, &prims, surface.base_z_mm());
    let light = |x: f64| Light {
        position_mm: [x, 0.0, -2.0],
        direction: [0.0, 0.0, 1.0],
        cone_half_angle_deg: 90.0,
        colour_rgb: [1.0, 1.0, 1.0],
        intensity: 100.0,
    };
    let optics = ResolvedOptics {
        lights: vec![light(9.5), light(-9.5)],
        light_sources: vec!["bench".into(); 2],
        surface: Reflectance::default(),
        marker_albedo_rgb: [0.9; 3],
        camera: CameraResponse {
            vignetting: 0.2,
            ..CameraResponse::default()
        },
        markers: Vec::new(),
        marker_sources: Vec::new(),
        dimples: Vec::new(),
        dimple_sources: Vec::new(),
    };
    let rad = pool.install(|| frame_radiance(&rays, None, &hits, &optics, Some(&prims)));
    let mut g = c.benchmark_group("images_640x480_one_thread");
    g.sample_size(20);
    g.bench_function("radiance_two_lights_shadows", |b| {
        b.iter(|| pool.install(|| frame_radiance(&rays, None, &hits, &optics, Some(&prims))))
    });
    g.bench_function("expose_8bit", |b| {
        b.iter(|| {
            pool.install(|| {
                expose(
                    &rad,
                    640,
                    480,
                    [320.0, 240.0],
                    &optics.camera,
                    Exposure {
                        gain: 1.0,
                        frame: 0,
                    },
                )
            })
        })
    });
    let imaging = Imaging::new(optics.clone(), [320.0, 240.0], &rays, &reference);
    g.bench_function("frame_image_two_lights_shadows_8bit", |b| {
        b.iter(|| pool.install(|| imaging.image(&rays, &reference, &hits, Some(&prims), 1)))
    });
    g.bench_function("indented_hits", |b| {
        b.iter(|| indented_hits(&rays, &reference, &prims, surface.base_z_mm()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
