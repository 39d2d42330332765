//! The photometric model (calibration/src/photometric.rs) fitted from synthetic pin captures
//! rendered by the physical image model (groundtruth::shading) under lights the fit does not
//! know: R-Tac0's skin through the benchmark fisheye, five captures of five pins (1.5 mm
//! balls pressed 1 mm in) turned 40 deg apart, each with its own camera noise. Each capture
//! re-rendered from the model fitted on the other four matches it within 3 grey levels RMS
//! over the skin, and the centroid of each imprint within 0.2 px.

use fabkit_calibration::groundtruth::exact::ExactPrimitives;
use fabkit_calibration::groundtruth::rays::PixelRays;
use fabkit_calibration::groundtruth::shading::Imaging;
use fabkit_calibration::groundtruth::surface::ReferenceSurface;
use fabkit_calibration::groundtruth::synthetic::{benchmark_pose, rtac0_body};
use fabkit_calibration::groundtruth::{indented_hits, reference_hits, SurfaceHits};
use fabkit_calibration::imprints::synthetic::{ring_pins, Pin};
use fabkit_calibration::photometric::{rms_over_skin, Capture, PhotometricModel};
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::CameraModel;
use fabkit_designs::optics::{ring_of_lights, CameraResponse, Reflectance, ResolvedOptics};
use fabkit_designs::primitives::Primitive;

/// Contrast below this many counts is the camera's noise, not the imprint.
const NOISE_FLOOR: f64 = 4.0;

fn counts(img: Vec<[u16; 3]>) -> Vec<[f64; 3]> {
    img.into_iter().map(|p| p.map(f64::from)).collect()
}

/// The weighted centroid, px, of `weight` over the pressed pixels nearest pin `j`.
fn centroid(
    rays: &PixelRays,
    hits: &SurfaceHits,
    pins: &[Pin],
    j: usize,
    weight: impl Fn(usize) -> f64,
) -> Option<[f64; 2]> {
    let o = rays.origin_mm;
    let (mut su, mut sv, mut sw) = (0.0, 0.0, 0.0);
    for i in 0..rays.dirs.len() {
        if !hits.contact[i] {
            continue;
        }
        let p: [f64; 3] = std::array::from_fn(|k| o[k] + hits.t_mm[i] * rays.dirs[i][k]);
        let d = |q: &Pin| (0..3).map(|k| (p[k] - q.centre_mm[k]).powi(2)).sum::<f64>();
        let nearest = (0..pins.len())
            .min_by(|&a, &b| d(&pins[a]).total_cmp(&d(&pins[b])))
            .unwrap();
        if nearest != j {
            continue;
        }
        let wgt = weight(i);
        su += wgt * (i % rays.width) as f64;
        sv += wgt * (i / rays.width) as f64;
        sw += wgt;
    }
    (sw > 0.0).then(|| [su / sw, sv / sw])
}

#[test]
fn leave_one_out_re_renders_each_capture_within_3_grey_levels() {
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let rays = PixelRays::new(&cam, &benchmark_pose());
    let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
    let reference = reference_hits(&rays, &surface);
    // lights the fit does not know: R-Tac0's ring of eight LEDs under its diffuser, warm white,
    // and a glossy lobe
    let optics = ResolvedOptics {
        lights: ring_of_lights(8, 9.5, -21.0, 0.0, Some([0.0, 0.0, 1.0]), |_| {
            [1.0, 0.9, 0.75]
        }),
        light_sources: vec!["test".into(); 8],
        surface: Reflectance {
            albedo_rgb: [0.6, 0.6, 0.6],
            specular: 0.04,
            roughness: 0.5,
        },
        marker_albedo_rgb: [0.9; 3],
        camera: CameraResponse::default(),
        markers: Vec::new(),
        marker_sources: Vec::new(),
        dimples: Vec::new(),
        dimple_sources: Vec::new(),
    };
    let imaging = Imaging::new(optics, [319.5, 239.5], &rays, &reference);
    let reference_image = counts(imaging.image(&rays, &reference, None, 0));
    let turns = [0.0, 40.0, 80.0, 120.0, 160.0];
    let scenes: Vec<(Vec<Pin>, SurfaceHits, Vec<[f64; 3]>)> = turns
        .iter()
        .enumerate()
        .map(|(k, &turn)| {
            let pins = ring_pins(turn, 1.0);
            let prims = ExactPrimitives::new(
                &pins
                    .iter()
                    .map(|p| Primitive::Sphere {
                        centre_mm: p.centre_mm,
                        radius_mm: p.radius_mm,
                    })
                    .collect::<Vec<_>>(),
            )
            .unwrap();
            let hits = indented_hits(&rays, &reference, &prims, surface.base_z_mm());
            let image = counts(imaging.image(&rays, &hits, Some(&prims), k as u64 + 1));
            (pins, hits, image)
        })
        .collect();
    for k in 0..scenes.len() {
        let others: Vec<Capture> = (0..scenes.len())
            .filter(|&j| j != k)
            .map(|j| Capture {
                image: &scenes[j].2,
                hits: &scenes[j].1,
            })
            .collect();
        let model = PhotometricModel::fit(&rays, &reference, &reference_image, &others).unwrap();
        let (pins, hits, image) = &scenes[k];
        let again: Vec<[f64; 3]> = model
            .render(&reference, hits, 1.0)
            .into_iter()
            .map(|p| p.map(|x| x.clamp(0.0, 255.0)))
            .collect();
        let rms = rms_over_skin(&again, image);
        eprintln!(
            "capture {k}: re-rendered within {rms:.2} grey levels RMS; fit residuals {:?}",
            model.residual_rms
        );
        assert!(rms < 3.0, "capture {k}: {rms} grey levels RMS");
        for j in 0..pins.len() {
            let base = |i: usize| model.reference[i][1];
            // the imprint's contrast above the camera's noise (sigma about 1.8 counts at half
            // scale), the same threshold for both
            let contrast = |x: f64| (x.abs() - NOISE_FLOOR).max(0.0);
            let a = centroid(&rays, hits, pins, j, |i| contrast(image[i][1] - base(i)));
            let b = centroid(&rays, hits, pins, j, |i| contrast(again[i][1] - base(i)));
            let (Some(a), Some(b)) = (a, b) else { continue };
            let d = (a[0] - b[0]).hypot(a[1] - b[1]);
            eprintln!("  pin {j}: centroid {a:?} vs {b:?}: {d:.3} px");
            assert!(d < 0.2, "capture {k} pin {j}: centroids {d} px apart");
        }
    }
}
