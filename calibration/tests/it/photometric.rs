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
use fabkit_calibration::photometric::{
    capture_fault, pin_primitives, rms_over_skin, shadow_map, Capture, ContactRegion, ImageFault,
    ImprintMap, LeaveOneOut, PhotometricModel, ShadowMap, ShadowRings, CONTACT_REACH_PX,
};
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::CameraModel;
use fabkit_designs::optics::{ring_of_lights, Light, Reflectance, ResolvedOptics};
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

/// The scene and the captures: rays, reference surface, reference image and per capture its
/// pins, surface and image.
/// Lights the fit does not know: R-Tac0's ring of eight LEDs under its diffuser, warm white.
fn warm_ring() -> Vec<Light> {
    ring_of_lights(8, 9.5, -21.0, 0.0, Some([0.0, 0.0, 1.0]), |_| {
        [1.0, 0.9, 0.75]
    })
}

struct Captures {
    rays: PixelRays,
    reference: SurfaceHits,
    reference_image: Vec<[f64; 3]>,
    scenes: Vec<PressedCapture>,
}

/// One capture: where its imprints are, its surface, its image (counts) and its shadows.
type PressedCapture = (Vec<Pin>, SurfaceHits, Vec<[f64; 3]>, ShadowMap);

/// The balls of [`ring_pins`] turned by `turn_deg`, pressed 1 mm: where each imprint is and
/// its solids.
fn balls(turn_deg: f64) -> (Vec<Pin>, Vec<Primitive>) {
    let pins = ring_pins(turn_deg, 1.0);
    let solids = pins
        .iter()
        .map(|p| Primitive::Sphere {
            centre_mm: p.centre_mm,
            radius_mm: p.radius_mm,
        })
        .collect();
    (pins, solids)
}

/// R-Tac0's own pins at the places of [`ring_pins`]: a 0.8 mm hemispherical tip on a 1.6 mm
/// shaft 5.6 mm long, pressed 1.54 mm along the skin's normal (the point table of `fabkit
/// fixtures rtac0 --pins-preset rtac0`): deeper than the tip's radius, so the shaft enters
/// the skin and its wall shadows the skin beside the imprint from the LED ring.
fn rtac0_pins(turn_deg: f64) -> (Vec<Pin>, Vec<Primitive>) {
    let (mut pins, mut solids) = (Vec::new(), Vec::new());
    for p in ring_pins(turn_deg, 1.0) {
        let l = p.centre_mm.iter().map(|x| x * x).sum::<f64>().sqrt();
        let axis = p.centre_mm.map(|x| x / l);
        let tip = axis.map(|x| x * (15.0 - 1.54));
        solids.extend(pin_primitives(tip, axis, 0.8, 0.8, 5.6));
        pins.push(Pin {
            centre_mm: axis.map(|x| x * (15.0 - 1.54 + 0.8)),
            radius_mm: 0.8,
        });
    }
    (pins, solids)
}

fn captures(lights: Vec<Light>, pressed: fn(f64) -> (Vec<Pin>, Vec<Primitive>)) -> Captures {
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let rays = PixelRays::new(&cam, &benchmark_pose());
    let surface = ReferenceSurface::of(&rtac0_body()).unwrap();
    let reference = reference_hits(&rays, &surface);
    // a matte grey skin with the default glossy lobe and camera
    let optics = ResolvedOptics {
        surface: Reflectance {
            albedo_rgb: [0.6, 0.6, 0.6],
            specular: 0.04,
            roughness: 0.5,
            darkness_per_mm: None,
        },
        ..crate::shading::optics_with(lights)
    };
    let imaging = Imaging::new(optics, [319.5, 239.5], &rays, &reference);
    let reference_image = counts(imaging.image(
        &rays,
        &reference,
        &reference,
        None,
        1000 * crate::common::seed_set(),
    ));
    let turns = [0.0, 40.0, 80.0, 120.0, 160.0];
    let rings = ShadowRings::of(&rays, &reference);
    let scenes = turns
        .iter()
        .enumerate()
        .map(|(k, &turn)| {
            let (pins, solids) = pressed(turn);
            let prims = ExactPrimitives::new(&solids).unwrap();
            let hits = indented_hits(&rays, &reference, &prims, surface.base_z_mm());
            let seed = 1000 * crate::common::seed_set() + k as u64 + 1;
            let image = counts(imaging.image(&rays, &reference, &hits, Some(&prims), seed));
            let shadows = shadow_map(&rays, &hits, &prims, &rings);
            (pins, hits, image, shadows)
        })
        .collect();
    Captures {
        rays,
        reference,
        reference_image,
        scenes,
    }
}

/// Each capture re-rendered from the model fitted on the others, at its own gain: the RMS
/// over the skin pixels `counted` keeps, and the largest distance between a pin's imprint
/// centroid in the capture and in its re-rendering, px.
fn leave_one_out(c: &Captures, counted: impl Fn(usize) -> bool) -> (f64, f64) {
    let (rays, reference) = (&c.rays, &c.reference);
    let (mut worst_rms, mut worst_centroid) = (0.0f64, 0.0f64);
    for k in 0..c.scenes.len() {
        let others: Vec<Capture> = (0..c.scenes.len())
            .filter(|&j| j != k)
            .map(|j| Capture {
                image: &c.scenes[j].2,
                hits: &c.scenes[j].1,
                shadows: &c.scenes[j].3,
            })
            .collect();
        let model =
            PhotometricModel::fit(rays, reference, &c.reference_image, &others, 255.0).unwrap();
        let (pins, hits, image, shadows) = &c.scenes[k];
        let gain = model.gain_of(
            &Capture {
                image,
                hits,
                shadows,
            },
            reference,
        );
        let again = model.render(rays, reference, hits, shadows, gain);
        let keep = |p: &[[f64; 3]]| -> Vec<[f64; 3]> {
            p.iter()
                .enumerate()
                .map(|(i, x)| if counted(i) { *x } else { [f64::NAN; 3] })
                .collect()
        };
        let rms = rms_over_skin(&keep(&again), &keep(image));
        eprintln!(
            "capture {k}: gain {gain:.4}, re-rendered within {rms:.2} grey levels RMS; fit residuals {:?}",
            model.residual_rms
        );
        worst_rms = worst_rms.max(rms);
        for j in 0..pins.len() {
            let base = |i: usize| gain * model.reference[i][1];
            // the imprint's contrast above the camera's noise (sigma about 1.8 counts at half
            // scale), the same threshold for both
            let contrast = |x: f64| (x.abs() - NOISE_FLOOR).max(0.0);
            let a = centroid(rays, hits, pins, j, |i| contrast(image[i][1] - base(i)));
            let b = centroid(rays, hits, pins, j, |i| contrast(again[i][1] - base(i)));
            let (Some(a), Some(b)) = (a, b) else { continue };
            worst_centroid = worst_centroid.max((a[0] - b[0]).hypot(a[1] - b[1]));
        }
    }
    (worst_rms, worst_centroid)
}

#[test]
fn leave_one_out_re_renders_each_capture_within_3_grey_levels() {
    let c = captures(warm_ring(), balls);
    let (rms, centroid) = leave_one_out(&c, |_| true);
    // measured 2.196 to 2.199 grey levels and 0.067 to 0.074 px on seed sets 0 to 2
    assert!(rms < 3.0, "{rms} grey levels RMS");
    assert!(centroid < 0.2, "imprint centroids {centroid} px apart");
}

/// The leave-one-out without refitting ([`LeaveOneOut::model`]: the appearance's medians
/// sorted once and read without the left-out capture's value, the normal equations summed
/// over the others' rows) is the fit on the other captures to the bit, each capture left out
/// in turn, and [`LeaveOneOut::all`] is the fit on all of them: images of integer counts (ties in the medians) at five gains, so that the values
/// divided by their gains differ in their last digits too.
#[test]
fn the_leave_one_out_is_the_fit_on_the_others_to_the_bit() {
    let mut c = captures(warm_ring(), balls);
    for (scene, g) in c.scenes.iter_mut().zip([0.96, 1.04, 0.98, 1.05, 0.97]) {
        for p in scene.2.iter_mut() {
            *p = p.map(|x| (x * g).clamp(0.0, 255.0).round());
        }
    }
    let all = all_captures(&c);
    let (rays, reference, image) = (&c.rays, &c.reference, &c.reference_image);
    let gains = PhotometricModel::reference_gains(rays, reference, image, &all, 255.0);
    let fits = LeaveOneOut::new(rays, reference, image, &all, 255.0).unwrap();
    let whole = PhotometricModel::fit(rays, reference, image, &all, 255.0).unwrap();
    let bits = |v: &[[f64; 3]]| -> Vec<u64> { v.iter().flatten().map(|x| x.to_bits()).collect() };
    let b = |x: &[f64]| -> Vec<u64> { x.iter().map(|v| v.to_bits()).collect() };
    // the fit on every capture from the same state: the fit's model to the bit
    let same = fits.all().unwrap();
    assert!(bits(&same.reference) == bits(&whole.reference));
    for ch in 0..3 {
        assert_eq!(b(&same.coefficients[ch]), b(&whole.coefficients[ch]));
        assert_eq!(
            b(&same.shadow_coefficients[ch]),
            b(&whole.shadow_coefficients[ch])
        );
    }
    assert_eq!(b(&same.gains), b(&whole.gains));
    assert_eq!(b(&same.residual_rms), b(&whole.residual_rms));
    assert_eq!(b(&gains), b(&whole.gains));
    // without rendering the captures: the same model, no residuals
    let bare = [
        PhotometricModel::fit_unrendered(rays, reference, image, &all, 255.0).unwrap(),
        fits.all_unrendered().unwrap(),
    ];
    for m in &bare {
        assert!(bits(&m.reference) == bits(&whole.reference));
        for ch in 0..3 {
            assert_eq!(b(&m.coefficients[ch]), b(&whole.coefficients[ch]));
            assert_eq!(
                b(&m.shadow_coefficients[ch]),
                b(&whole.shadow_coefficients[ch])
            );
        }
        assert_eq!(b(&m.gains), b(&whole.gains));
        assert!(m.residual_rms.is_empty());
    }
    let mut moved = 0;
    for k in 0..all.len() {
        let keep = |&j: &usize| j != k;
        let others: Vec<Capture> = (0..all.len()).filter(keep).map(|j| all[j]).collect();
        let their: Vec<f64> = (0..all.len()).filter(keep).map(|j| gains[j]).collect();
        let refit =
            PhotometricModel::fit_with_gains(rays, reference, image, &others, &their, 255.0)
                .unwrap();
        let m = fits.model(k).unwrap();
        let (x, y) = (bits(&m.reference), bits(&refit.reference));
        let differ = x.iter().zip(&y).filter(|(p, q)| p != q).count();
        assert!(
            x.len() == y.len() && differ == 0,
            "capture {k}: {differ} values differ"
        );
        for ch in 0..3 {
            assert_eq!(
                b(&m.coefficients[ch]),
                b(&refit.coefficients[ch]),
                "capture {k}"
            );
            let (s, r) = (&m.shadow_coefficients[ch], &refit.shadow_coefficients[ch]);
            assert_eq!(b(s), b(r), "capture {k}");
        }
        assert_eq!(m.gains, refit.gains);
        assert_eq!(m.axis, refit.axis);
        assert!(m.residual_rms.is_empty());
        // the left-out capture's values do move the medians: the test is not of one model
        moved += m
            .reference
            .iter()
            .zip(&whole.reference)
            .filter(|(a, b)| {
                a.iter()
                    .zip(b.iter())
                    .any(|(x, y)| x.to_bits() != y.to_bits())
            })
            .count();
    }
    assert!(moved > 1000, "{moved} pixels moved");
    assert!(fits.model(all.len()).is_err());
}

/// R-Tac0's own pins press their shafts into the skin; the shadows the shafts' walls cast
/// beside the imprints from the LED ring (lights the fit does not know) are held by the
/// shadow term: without it these captures re-render about 4 grey levels RMS off.
#[test]
fn leave_one_out_holds_the_shadows_beside_deep_pin_imprints() {
    let c = captures(warm_ring(), rtac0_pins);
    let shadowed: usize = c.scenes.iter().map(|s| s.3.pixels.len()).sum();
    // measured 12,797
    assert!(shadowed > 1000, "{shadowed} shadowed pixels");
    let (rms, centroid) = leave_one_out(&c, |_| true);
    // measured 2.309 to 2.311 grey levels and 0.083 to 0.097 px on seed sets 0 to 2
    assert!(rms < 3.0, "{rms} grey levels RMS");
    assert!(centroid < 0.2, "imprint centroids {centroid} px apart");
}

/// What a real capture adds (the artifacts of `imprints::synthetic::Shading::real_rim` and
/// `real_capture`, put on the physically rendered images): a global gain that drifts by up to
/// 5 % (0.96 to 1.05), 12 LED highlights on the skin's rim (peak 300 counts, sigma 8 px,
/// clipped at 255, each image's a little brighter or dimmer) that each move by 1.5 px between
/// images, and three dark specks per capture off the pins. The fit measures each capture's
/// gain and takes the median of the images for the appearance; re-rendered, every capture is
/// still within 3 grey levels RMS over the skin away from the highlights (24 px, 3 sigma; no
/// model can say where a highlight moves) and its imprints within 0.2 px.
#[test]
fn leave_one_out_holds_with_gain_drift_moving_led_highlights_and_specks() {
    let mut c = captures(warm_ring(), balls);
    let (w, h) = (c.rays.width, c.rays.height);
    let (cx, cy) = (0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
    let skin_r = (0..w * h)
        .filter(|&i| c.reference.t_mm[i].is_finite())
        .map(|i| ((i % w) as f64 - cx).hypot((i / w) as f64 - cy))
        .fold(0.0f64, f64::max);
    let ring: Vec<[f64; 2]> = (0..12)
        .map(|k| {
            let a = std::f64::consts::TAU * (k as f64 + 0.5) / 12.0;
            let r = 0.9 * skin_r.min(cy);
            [cx + r * a.cos(), cy + r * a.sin()]
        })
        .collect();
    // each image's highlights: the ring moved 1.5 px per highlight, a flicker of +-10 %
    let lit = |img: &mut Vec<[f64; 3]>, k: usize, gain: f64| {
        for p in img.iter_mut() {
            *p = p.map(|x| x * gain);
        }
        for (j, q) in ring.iter().enumerate() {
            let a = 2.399963 * (7 * k + j) as f64;
            let (u0, v0) = (q[0] + 1.5 * a.cos(), q[1] + 1.5 * a.sin());
            let peak = 300.0 * (1.0 + 0.1 * (1.7 * (k + 3 * j) as f64).sin());
            for (i, p) in img.iter_mut().enumerate().take(w * h) {
                let d2 = ((i % w) as f64 - u0).powi(2) + ((i / w) as f64 - v0).powi(2);
                if d2 < 1600.0 {
                    let add = peak * (-d2 / 128.0).exp();
                    *p = p.map(|x| x + add);
                }
            }
        }
        for p in img.iter_mut() {
            *p = p.map(|x| x.clamp(0.0, 255.0).round());
        }
    };
    lit(&mut c.reference_image, 0, 1.0);
    let gains = [0.96, 1.04, 0.98, 1.05, 0.97];
    for (k, scene) in c.scenes.iter_mut().enumerate() {
        lit(&mut scene.2, k + 1, gains[k]);
        // three specks, 1.5 px, 60 counts dark, 30 px or more from any pressed pixel
        let pressed: Vec<usize> = (0..w * h).filter(|&i| scene.1.contact[i]).collect();
        let mut placed = 0;
        for t in 0..200 {
            if placed == 3 {
                break;
            }
            let a = 2.399963 * (t + 11 * k) as f64;
            let r = 0.6 * skin_r.min(cy) * ((t as f64 * 0.37).fract());
            let (u, v) = (cx + r * a.cos(), cy + r * a.sin());
            let far = pressed
                .iter()
                .all(|&i| ((i % w) as f64 - u).hypot((i / w) as f64 - v) >= 30.0);
            if !far {
                continue;
            }
            for i in 0..w * h {
                if ((i % w) as f64 - u).hypot((i / w) as f64 - v) <= 1.5 {
                    scene.2[i] = scene.2[i].map(|x| (x - 60.0).max(0.0));
                }
            }
            placed += 1;
        }
        assert_eq!(placed, 3);
    }
    let away = |i: usize| {
        let (u, v) = ((i % w) as f64, (i / w) as f64);
        ring.iter().all(|q| (q[0] - u).hypot(q[1] - v) > 24.0 + 1.5)
    };
    let (rms, centroid) = leave_one_out(&c, away);
    // measured 2.416 to 2.417 grey levels and 0.071 to 0.076 px on seed sets 0 to 2
    assert!(rms < 3.0, "{rms} grey levels RMS away from the highlights");
    assert!(centroid < 0.2, "imprint centroids {centroid} px apart");
    // the gains the test chose, recovered by the fit on all five (issue 96): a median ratio of
    // counts rounded to integers near 100 to 200 is quantised by up to 0.5 / 100; measured
    // within 0.0007 on seed sets 0 to 2
    let all = all_captures(&c);
    let model =
        PhotometricModel::fit(&c.rays, &c.reference, &c.reference_image, &all, 255.0).unwrap();
    for (k, g) in gains.iter().enumerate() {
        let off = model.gains[k] / g - 1.0;
        assert!(
            off.abs() < 0.005,
            "capture {k}: gain {} chosen {g}",
            model.gains[k]
        );
    }
}

/// The pin's solids have the fixtures' pin profile: rays parallel to the axis from below meet
/// it at the hemisphere's height `rt - sqrt(rt^2 - rho^2)` for `rho < rt`, on the 45 deg cone
/// at `rho` for `rt <= rho < rs`, and miss it beyond the shaft.
#[test]
fn pin_solids_have_the_pin_profile() {
    use fabkit_calibration::photometric::pin_primitives;
    let a = {
        let v = [0.3f64, -0.2, 0.93];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / n)
    };
    let tip = [1.0, 2.0, 12.0];
    let (rt, rs) = (0.5, 0.8);
    let prims = ExactPrimitives::new(&pin_primitives(tip, a, rt, rs, 10.0)).unwrap();
    // a unit vector perpendicular to the axis
    let e = {
        let c = [a[1], -a[0], 0.0];
        let n = (c[0] * c[0] + c[1] * c[1]).sqrt();
        c.map(|x| x / n)
    };
    for k in 0..=40 {
        let rho = 0.9 * f64::from(k) / 40.0;
        let start: [f64; 3] = std::array::from_fn(|i| tip[i] + rho * e[i] - 5.0 * a[i]);
        let hit = prims.first_crossing(start, a, 20.0);
        let want = if rho < rt {
            Some(rt - (rt * rt - rho * rho).sqrt())
        } else if rho < rs {
            Some(rho)
        } else {
            None
        };
        match (hit, want) {
            (Some(c), Some(h)) => assert!(
                (c.t_mm - 5.0 - h).abs() < 1e-9,
                "rho {rho}: {} vs {h}",
                c.t_mm - 5.0
            ),
            (None, None) => {}
            (c, h) => panic!("rho {rho}: {:?} vs {h:?}", c.map(|c| c.t_mm - 5.0)),
        }
    }
}

/// The captures are read at their own depth: an 8-bit RGB PNG gives its counts and full scale
/// 255, a 16-bit one its counts and 65535, a grey one three equal channels; an image of
/// another size than the camera's is refused naming the option and both sizes.
#[test]
fn captures_are_read_as_rgb_counts_at_their_depth() {
    use fabkit_calibration::capture_images::read_rgb;
    let d = tempfile::tempdir().unwrap();
    let (w, h) = (5u32, 3u32);
    let rgb8 = image::RgbImage::from_fn(w, h, |x, y| image::Rgb([x as u8 * 40, y as u8 * 90, 7]));
    rgb8.save(d.path().join("a.png")).unwrap();
    let rgb16: image::ImageBuffer<image::Rgb<u16>, Vec<u16>> =
        image::ImageBuffer::from_fn(w, h, |x, y| {
            image::Rgb([x as u16 * 9000, y as u16 * 20000, 65535])
        });
    rgb16.save(d.path().join("b.png")).unwrap();
    let grey = image::GrayImage::from_fn(w, h, |x, _| image::Luma([x as u8 * 50]));
    grey.save(d.path().join("c.png")).unwrap();
    let (a, fa) = read_rgb(&d.path().join("a.png"), "--images", (w, h), "cam.yaml").unwrap();
    assert_eq!(fa, 255.0);
    assert_eq!(a[(2 * w + 4) as usize], [160.0, 180.0, 7.0]);
    let (b, fb) = read_rgb(&d.path().join("b.png"), "--images", (w, h), "cam.yaml").unwrap();
    assert_eq!(fb, 65535.0);
    assert_eq!(b[(w + 3) as usize], [27000.0, 20000.0, 65535.0]);
    let (c, _) = read_rgb(&d.path().join("c.png"), "--reference", (w, h), "cam.yaml").unwrap();
    assert_eq!(c[3], [150.0; 3]);
    let e = read_rgb(&d.path().join("a.png"), "--images", (6, 3), "cam.yaml")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("--images = ") && e.contains("5 x 3 px") && e.contains("6 x 3 px"),
        "{e}"
    );
}

/// A fixtures folder's pins: the point table's tips and axes and the pin's shape from the
/// manifest; a bad axis, a missing column and a manifest without a pin are refused naming the
/// file and the field.
#[test]
fn pins_are_read_from_a_fixtures_folder() {
    use fabkit_calibration::photometric::read_pins;
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir(d.path().join("points")).unwrap();
    let header = "id,ring,tip_x_mm,tip_y_mm,tip_z_mm,contact_x_mm,contact_y_mm,contact_z_mm,axis_x,axis_y,axis_z,indentation_depth_mm";
    let table = |rows: &str| {
        std::fs::write(
            d.path().join("points/point_table.csv"),
            format!("{header}\n{rows}"),
        )
        .unwrap()
    };
    table("1,0,0,0,13.459,0,0,15,0,0,1,1.541\n2,1,4.13,0,12.81,4.6,0,14.28,0.306858322,0,0.951755205,1.541\n");
    let manifest = |pin: &str| {
        std::fs::write(
            d.path().join("manifest.json"),
            format!(r#"{{"parts": [{{"name": "pin_dome", "params": {{}}}}, {pin}]}}"#),
        )
        .unwrap()
    };
    manifest(
        r#"{"name": "pin", "params": {"length_mm": 5.6, "pin": {"shaft_diameter_mm": 1.6, "tip_radius_mm": 0.8}}}"#,
    );
    let pins = read_pins(d.path()).unwrap();
    assert_eq!(pins.rows.len(), 2);
    assert_eq!(pins.rows[1].0, "2");
    assert_eq!(pins.rows[0].1, [0.0, 0.0, 13.459]);
    assert_eq!(
        (pins.tip_radius_mm, pins.shaft_radius_mm, pins.length_mm),
        (0.8, 0.8, 5.6)
    );
    assert_eq!(pins.primitives(&["2".into()]).unwrap().len(), 2);
    assert_eq!(pins.primitives(&["7".into()]).unwrap_err(), "7");

    table("1,0,0,0,13.459,0,0,15,0,0,2,1.541\n");
    let e = read_pins(d.path()).unwrap_err().to_string();
    assert!(
        e.contains("point_table.csv: line 2 axis") && e.contains("unit vector"),
        "{e}"
    );
    std::fs::write(
        d.path().join("points/point_table.csv"),
        "id,tip_x_mm\n1,0\n",
    )
    .unwrap();
    let e = read_pins(d.path()).unwrap_err().to_string();
    assert!(e.contains("has no column tip_y_mm"), "{e}");
    table("1,0,0,0,13.459,0,0,15,0,0,1,1.541\n");
    manifest(r#"{"name": "semidome_p001", "params": {}}"#);
    let e = read_pins(d.path()).unwrap_err().to_string();
    assert!(
        e.contains("manifest.json: parts") && e.contains("pin"),
        "{e}"
    );
}

/// ShadowTac-like lights: one LED per channel (red, green, blue) at three azimuths 120 deg
/// apart on the chamber wall, facing the axis. The spatial term and the shadow rings are round
/// the optical axis; the candidate point lights follow such lights only in part: each capture
/// re-renders from the others within about 4.7 grey levels with the balls (9.2 without the
/// point lights) and 6.4 with R-Tac0's pins, whose hard single-LED shadows the candidates
/// place only roughly. Bounds with a little room, so that a change that loses this ground
/// shows: measured 4.665 to 4.669 and 6.419 to 6.424 on seed sets 0, 1 and 2 (the camera noise
/// moves them by 0.1 %: what remains is the model's error, not noise), so 5 and 7 (7 % and 9 %
/// above) are a regression guard, not a statistical bound.
#[test]
fn side_leds_at_three_azimuths_re_render_within_5_and_7_grey_levels() {
    let lights = ring_of_lights(3, 12.0, 2.0, 90.0, None, |k| {
        [[1.0, 0.1, 0.1], [0.1, 1.0, 0.1], [0.1, 0.1, 1.0]][k as usize]
    });
    let (rms, _) = leave_one_out(&captures(lights.clone(), balls), |_| true);
    assert!(rms < 5.0, "balls: {rms} grey levels RMS");
    let (rms, _) = leave_one_out(&captures(lights, rtac0_pins), |_| true);
    assert!(rms < 7.0, "R-Tac0's pins: {rms} grey levels RMS");
}

/// Every capture of `c`, to fit.
fn all_captures(c: &Captures) -> Vec<Capture<'_>> {
    c.scenes
        .iter()
        .map(|s| Capture {
            image: &s.2,
            hits: &s.1,
            shadows: &s.3,
        })
        .collect()
}

/// R-Tac0's captures under a warm LED ring and the model fitted to them.
fn warm_ring_model() -> (Captures, PhotometricModel) {
    let c = captures(warm_ring(), rtac0_pins);
    let all = all_captures(&c);
    let m = PhotometricModel::fit(&c.rays, &c.reference, &c.reference_image, &all, 255.0).unwrap();
    (c, m)
}

/// photometric.json's model section round-trips: read back with the fitted appearance, the
/// model renders every capture to the same values; a file of another basis or a short
/// coefficient list is refused naming its key.
#[test]
fn the_model_json_reads_back_to_the_same_images() {
    let (c, m) = warm_ring_model();
    // through text, as the file is written and read
    let text = serde_json::to_string(&m.model_json()).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let back = PhotometricModel::from_json(&json, m.reference.clone(), m.width, m.height).unwrap();
    for s in &c.scenes {
        let a = m.render(&c.rays, &c.reference, &s.1, &s.3, 1.0);
        let b = back.render(&c.rays, &c.reference, &s.1, &s.3, 1.0);
        for (x, y) in a.iter().zip(&b) {
            for ch in 0..3 {
                assert!(x[ch] == y[ch] || (x[ch].is_nan() && y[ch].is_nan()));
            }
        }
    }
    let mut other = json.clone();
    other["light_terms"] = serde_json::json!(12);
    let e =
        PhotometricModel::from_json(&other, m.reference.clone(), m.width, m.height).unwrap_err();
    assert!(
        e.contains("model.light_terms = 12") && e.contains("fit it again"),
        "{e}"
    );
    let mut short = json.clone();
    short["coefficients_rgb"][1] = serde_json::json!([1.0, 2.0]);
    let e =
        PhotometricModel::from_json(&short, m.reference.clone(), m.width, m.height).unwrap_err();
    assert!(
        e.contains("model.coefficients_rgb must be 3 lists of"),
        "{e}"
    );
    let e = PhotometricModel::from_json(&json, vec![[0.0; 3]; 4], m.width, m.height).unwrap_err();
    assert!(e.contains("the appearance has 4 pixels"), "{e}");
}

/// Issue 95: a model's values were not checked when read (an axis of [0, 0, 0] panicked in the
/// render, coefficients of 1e308 or a scale of 1e-300 gave saturated images). Every numeric
/// field set to 0, -1, 1e-300, 1e300 and null (JSON's NaN), one at a time, and the appearance
/// to inf, -1e30 and NaN: each is refused naming the file's field, or the model renders a
/// finite image wherever the skin is.
#[test]
fn every_model_value_is_checked_when_read() {
    let (c, m) = warm_ring_model();
    let json: serde_json::Value =
        serde_json::from_str(&serde_json::to_string(&m.model_json()).unwrap()).unwrap();
    let mut fields: Vec<(Vec<String>, String)> = Vec::new();
    let key = |path: &[&str]| path.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    for ch in 0..3 {
        for k in [0, 5, fabkit_calibration::photometric::COEFFICIENTS - 1] {
            fields.push((
                key(&["coefficients_rgb", &ch.to_string(), &k.to_string()]),
                "coefficients_rgb".into(),
            ));
        }
        fields.push((
            key(&["shadow", "coefficients_rgb", &ch.to_string(), "0"]),
            "shadow.coefficients_rgb".into(),
        ));
    }
    for q in 0..3 {
        fields.push((
            key(&["optical_axis", &q.to_string()]),
            "optical_axis".into(),
        ));
        fields.push((
            key(&["shadow", "rings", "axis", &q.to_string()]),
            "shadow.rings".into(),
        ));
        fields.push((
            key(&["shadow", "rings", "centre_mm", &q.to_string()]),
            "shadow.rings".into(),
        ));
    }
    fields.push((key(&["shadow", "rings", "scale_mm"]), "shadow.rings".into()));
    fields.push((key(&["full_scale_counts"]), "full_scale_counts".into()));
    let values = [
        serde_json::json!(0.0),
        serde_json::json!(-1.0),
        serde_json::json!(1e-300),
        serde_json::json!(1e300),
        serde_json::Value::Null,
    ];
    let s = &c.scenes[0];
    for (path, name) in &fields {
        for v in &values {
            let mut bad = json.clone();
            let mut at = &mut bad;
            for p in path {
                at = match p.parse::<usize>() {
                    Ok(i) => &mut at[i],
                    Err(_) => &mut at[p.as_str()],
                };
            }
            *at = v.clone();
            match PhotometricModel::from_json(&bad, m.reference.clone(), m.width, m.height) {
                Err(e) => assert!(e.contains(&format!("model.{name}")), "{path:?} = {v}: {e}"),
                Ok(back) => {
                    let img = back.render(&c.rays, &c.reference, &s.1, &s.3, 1.0);
                    for (p, r) in img.iter().zip(&m.reference) {
                        for ch in 0..3 {
                            assert!(
                                r[ch].is_nan() || p[ch].is_finite(),
                                "{path:?} = {v}: accepted, and renders {}",
                                p[ch]
                            );
                        }
                    }
                }
            }
        }
    }
    for x in [f64::INFINITY, -1e30, f64::NEG_INFINITY] {
        let mut appearance = m.reference.clone();
        let k = appearance.iter().position(|p| p[0].is_finite()).unwrap();
        appearance[k][1] = x;
        let e = PhotometricModel::from_json(&json, appearance, m.width, m.height).unwrap_err();
        assert!(
            e.contains("appearance.npy: pixel") && e.contains("channel 1"),
            "{e}"
        );
    }
}

/// Issue 95: a capture the camera saw no imprint in fitted "within 0.00 counts" to an
/// all-zero model. The rendered captures show theirs far above the noise; the reference's
/// copy, the reference with the camera's noise, a dark and a white frame at the same pins do
/// not, and the fit refuses them naming the capture.
#[test]
fn captures_show_their_imprints_and_frames_without_them_are_refused() {
    let c = captures(warm_ring(), balls);
    let fault = |image: &[[f64; 3]], k: usize| {
        let (_, hits, _, shadows) = &c.scenes[k];
        let capture = Capture {
            image,
            hits,
            shadows,
        };
        capture_fault(&c.reference, &c.reference_image, &capture, 255.0)
    };
    for (k, s) in c.scenes.iter().enumerate() {
        assert_eq!(fault(&s.2, k), None, "capture {k}");
    }
    // the margin: the same imprint at a tenth of its contrast still shows
    let faint: Vec<[f64; 3]> = c.scenes[0]
        .2
        .iter()
        .zip(&c.reference_image)
        .map(|(y, r)| std::array::from_fn(|ch| r[ch] + 0.1 * (y[ch] - r[ch])))
        .collect();
    assert_eq!(fault(&faint, 0), None);
    let noisy: Vec<[f64; 3]> = c
        .reference_image
        .iter()
        .enumerate()
        .map(|(i, r)| r.map(|x| x + [-1.5, 0.5, 1.0, -0.5][(i * 7) % 4]))
        .collect();
    for (image, what) in [(c.reference_image.clone(), "copy"), (noisy, "noisy copy")] {
        assert!(
            matches!(fault(&image, 1), Some(ImageFault::NoImprint { .. })),
            "{what}: {:?}",
            fault(&image, 1)
        );
    }
    let flat = |v: f64| vec![[v; 3]; c.reference_image.len()];
    assert!(matches!(
        fault(&flat(0.0), 1),
        Some(ImageFault::Dark { .. })
    ));
    assert!(matches!(
        fault(&flat(255.0), 1),
        Some(ImageFault::Saturated { .. })
    ));
    // the fit names the capture
    let captures: Vec<Capture> = c
        .scenes
        .iter()
        .enumerate()
        .map(|(k, s)| Capture {
            image: if k == 2 { &c.reference_image } else { &s.2 },
            hits: &s.1,
            shadows: &s.3,
        })
        .collect();
    let e = PhotometricModel::fit(&c.rays, &c.reference, &c.reference_image, &captures, 255.0)
        .unwrap_err();
    assert!(e.starts_with("capture 2: no imprint at its pins"), "{e}");
}

/// Issue 95: a 16384 x 16384 16-bit RGB capture (a camera of that size passes the camera
/// rule) was refused as "not a readable PNG or JPEG image: Memory limit exceeded". The PNG's
/// header alone (its pixels are never decoded) now gives the size, the memory it would take
/// and the limit, in words.
#[test]
fn a_capture_past_the_decoders_memory_limit_is_refused_in_words() {
    use fabkit_calibration::capture_images::read_rgb;
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 == 1 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let chunk = |kind: &[u8], data: &[u8]| -> Vec<u8> {
        let mut v = (data.len() as u32).to_be_bytes().to_vec();
        let body = [kind, data].concat();
        v.extend(&body);
        v.extend(crc32(&body).to_be_bytes());
        v
    };
    let side = 16384u32;
    let mut ihdr = side.to_be_bytes().to_vec();
    ihdr.extend(side.to_be_bytes());
    ihdr.extend([16, 2, 0, 0, 0]); // 16-bit, RGB, deflate, adaptive filter, no interlace
    let png = [
        b"\x89PNG\r\n\x1a\n".to_vec(),
        chunk(b"IHDR", &ihdr),
        chunk(b"IDAT", &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01]),
        chunk(b"IEND", &[]),
    ]
    .concat();
    let d = tempfile::tempdir().unwrap();
    let file = d.path().join("big.png");
    std::fs::write(&file, png).unwrap();
    let e = read_rgb(&file, "--images", (side, side), "cam.yaml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--images = ")
            && e.contains(
                "16384 x 16384 pixels (1536 MiB decoded) decode to more than the 512 MiB"
            )
            && !e.contains("Memory limit exceeded"),
        "{e}"
    );
}

/// The numbers JSON cannot hold, as Python's json writes them, are quoted so that the model's
/// reader names their field; text inside strings and finite numbers are left as they are.
#[test]
fn non_finite_numbers_are_quoted_outside_strings_only() {
    use fabkit_calibration::photometric::quote_non_finite;
    let text = r#"{"a": NaN, "b": [-Infinity, 1e999, -2.5e-3, Infinity], "NaN \"Infinity\"": "1e999", "é": 1}"#;
    let v: serde_json::Value = serde_json::from_str(&quote_non_finite(text)).unwrap();
    assert_eq!(v["a"], "NaN");
    assert_eq!(
        v["b"],
        serde_json::json!(["-Infinity", "1e999", -2.5e-3, "Infinity"])
    );
    assert_eq!(v["NaN \"Infinity\""], "1e999");
    assert_eq!(v["é"], 1);
    let plain = r#"{"x": [1, 2.5, -3e5]}"#;
    assert_eq!(quote_non_finite(plain), plain);
}

/// The lights the test chose, recovered by the fit (issue 96). A ring of 24 white LEDs is put
/// on one of the nine candidate rings of the shadow term ([`ShadowRings::lights`]; each LED
/// aimed along the optical axis, so its light also falls as the cosine off its beam, which the
/// candidates' shares leave out) and R-Tac0's pins shadow the skin beside their imprints.
/// In every channel the fit gives that ring the largest shadow weight, ahead of the next by
/// at least 0.3, and the nine weights add up to the share of the skin's light the rings stand
/// for, 1 here (no other light), within 0.2. Measured on seed sets 0 to 2: leads of 0.49 to
/// 1.01 and sums off 1 by 0.001 to 0.147 (the rest of the weights, a pattern of +-0.3 the same
/// for every ring, is the emitters' cosine and the candidates' overlap, not noise: the three
/// channels, each with its own noise, agree within 0.02).
#[test]
fn the_shadow_weights_find_the_ring_of_lights_the_test_chose() {
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let rays = PixelRays::new(&cam, &benchmark_pose());
    let reference = reference_hits(&rays, &ReferenceSurface::of(&rtac0_body()).unwrap());
    let rings = ShadowRings::of(&rays, &reference);
    for m in [1usize, 4, 5, 8] {
        let lights: Vec<Light> = rings
            .lights(m)
            .iter()
            .map(|p| Light {
                position_mm: *p,
                direction: rings.axis,
                cone_half_angle_deg: 90.0,
                colour_rgb: [1.0; 3],
                intensity: 100.0,
            })
            .collect();
        let c = captures(lights, rtac0_pins);
        let model = PhotometricModel::fit(
            &c.rays,
            &c.reference,
            &c.reference_image,
            &all_captures(&c),
            255.0,
        )
        .unwrap();
        for (ch, w) in model.shadow_coefficients.iter().enumerate() {
            let next = (0..w.len())
                .filter(|&j| j != m)
                .map(|j| w[j])
                .fold(f64::MIN, f64::max);
            let sum: f64 = w.iter().sum();
            eprintln!(
                "ring {m}, channel {ch}: lead {:.3}, sum {sum:.3}",
                w[m] - next
            );
            assert!(
                w[m] - next > 0.3,
                "ring {m}, channel {ch}: its weight {} leads the next by {}: {w:?}",
                w[m],
                w[m] - next
            );
            assert!(
                (sum - 1.0).abs() < 0.2,
                "ring {m}, channel {ch}: the weights add up to {sum}, not 1: {w:?}"
            );
        }
    }
}

/// The colour the test chose, recovered (issue 96): under the warm LED ring (RGB 1, 0.9,
/// 0.75) on a grey skin the model's appearance holds the light's colour times the albedo, so
/// its red and blue over its green are 1 / 0.9 and 0.75 / 0.9 at the median pixel. The camera
/// adds no white balance; the noise (about 1.8 counts at 150) and the rounding move a median
/// ratio over about 220,000 pixels by less than 0.1 %: within 0.5 % (measured within
/// 0.001 % on seed sets 0 to 2).
#[test]
fn the_appearance_holds_the_colour_of_the_lights_the_test_chose() {
    let (_, model) = warm_ring_model();
    for (ch, want) in [(0usize, 1.0 / 0.9), (2, 0.75 / 0.9)] {
        let mut r: Vec<f64> = model
            .reference
            .iter()
            .filter(|p| p[1] >= 20.0)
            .map(|p| p[ch] / p[1])
            .collect();
        r.sort_unstable_by(f64::total_cmp);
        let median = r[r.len() / 2];
        eprintln!(
            "channel {ch}: {median:.5} over {} pixels, chosen {want:.5}",
            r.len()
        );
        assert!(
            (median / want - 1.0).abs() < 0.005,
            "channel {ch} over green: {median}, chosen {want}"
        );
    }
}

/// Capture `k` of `c` re-rendered from the model fitted on the others, at its gain against
/// that model's appearance: the gain and the fit within `reach_px` of its imprints.
fn contact_leave_one_out(
    c: &Captures,
    k: usize,
    image: &[[f64; 3]],
    reach_px: f64,
) -> (f64, ContactRegion) {
    let others: Vec<Capture> = all_captures(c)
        .into_iter()
        .enumerate()
        .filter(|&(j, _)| j != k)
        .map(|(_, x)| x)
        .collect();
    let model =
        PhotometricModel::fit(&c.rays, &c.reference, &c.reference_image, &others, 255.0).unwrap();
    let (_, hits, _, shadows) = &c.scenes[k];
    let capture = Capture {
        image,
        hits,
        shadows,
    };
    let gain = model.gain_of(&capture, &c.reference);
    let again = model.render(&c.rays, &c.reference, hits, shadows, gain);
    let region = model.contact_region(&capture, &c.reference, &again, gain, reach_px);
    (gain, region)
}

/// Issue 101: real captures are 0 to 4 % brighter or darker than the reference, and the skin's
/// residual followed that. On R-Tac0's pin captures (physical image model, warm LED ring, the
/// pins' shaft shadows), the third capture's exposure raised by 3 % (counts scaled and
/// rounded, clipped at 255): its gain, least squares over the skin 30 px or more from every
/// imprint, is 1.03 within 0.5 % in the fit on all five and against the appearance fitted on
/// the other four, and the others' 1 (measured within 0.03 % on seed sets 0 to 2: 1.02990 to
/// 1.02995, the others 0.99979 to 0.99989). Re-rendered from the others at that gain, every
/// capture fits within 15 px of its five imprints (about 8,100 pixels: the pressed pixels,
/// their rims and the shafts' shadows) within 5.5 counts RMS (measured 4.44 to 4.65, against
/// 2.3 over the whole skin, `leave_one_out_holds_the_shadows_beside_deep_pin_imprints`: the
/// model's error sits where the pins press; the camera's noise, about 1.8 counts, is part of
/// it), and the centroid of each imprint's rendered darkening lies within 0.3 px of the
/// capture's (measured at most 0.17 px, medians per capture 0.06 to 0.13). 0.3 px: the
/// whole-skin test holds the contrast centroid of the pressed pixels alone within 0.2 px; the
/// darkening here also takes the shafts' shadows, which the candidate rings place only
/// roughly, and 0.3 is a tenth of the shift the next test reads.
#[test]
fn a_capture_at_a_known_gain_is_recovered_and_fits_where_the_pins_press() {
    let mut c = captures(warm_ring(), rtac0_pins);
    let chosen = 1.03;
    let k_bright = 2;
    for p in c.scenes[k_bright].2.iter_mut() {
        *p = p.map(|x| (x * chosen).round().clamp(0.0, 255.0));
    }
    let all = all_captures(&c);
    let model =
        PhotometricModel::fit(&c.rays, &c.reference, &c.reference_image, &all, 255.0).unwrap();
    eprintln!("fit gains {:?}", model.gains);
    let off = model.gains[k_bright] / chosen - 1.0;
    assert!(
        off.abs() < 0.005,
        "fit: gain {} chosen {chosen}",
        model.gains[k_bright]
    );
    for (k, g) in model
        .gains
        .iter()
        .enumerate()
        .filter(|&(k, _)| k != k_bright)
    {
        assert!((g - 1.0).abs() < 0.005, "capture {k}: gain {g}, chosen 1");
    }
    let (mut worst_rms, mut worst_offset) = (0.0f64, 0.0f64);
    for k in 0..c.scenes.len() {
        let image = c.scenes[k].2.clone();
        let (gain, region) = contact_leave_one_out(&c, k, &image, CONTACT_REACH_PX);
        let offsets: Vec<f64> = region.imprints.iter().filter_map(|f| f.offset_px).collect();
        eprintln!(
            "capture {k}: gain {gain:.5}, within {} px of {} imprints ({} pixels) {:.3} counts RMS, floor {:.2}, offsets {offsets:.3?} px, median {:?}",
            region.reach_px,
            region.imprints.len(),
            region.pixels,
            region.rms_counts,
            region.darkening_floor_counts,
            region.median_offset_px
        );
        let want = if k == k_bright { chosen } else { 1.0 };
        assert!(
            (gain / want - 1.0).abs() < 0.005,
            "capture {k}: leave-one-out gain {gain}, chosen {want}"
        );
        assert_eq!(region.reach_px, CONTACT_REACH_PX);
        assert_eq!(region.imprints.len(), 5, "capture {k}");
        assert_eq!(
            offsets.len(),
            5,
            "capture {k}: an imprint without darkening"
        );
        assert!(
            region.pixels > 1000,
            "capture {k}: {} pixels",
            region.pixels
        );
        worst_rms = worst_rms.max(region.rms_counts);
        worst_offset = offsets.iter().copied().fold(worst_offset, f64::max);
        assert!(region.median_offset_px.is_some_and(|m| m <= worst_offset));
    }
    assert!(worst_rms < 5.5, "{worst_rms} counts RMS within 15 px");
    assert!(
        worst_offset < 0.5,
        "imprint centroids {worst_offset} px apart"
    );
}

/// The centroid report shows a shift of the imprints the ground truth does not know: the
/// second capture's change from the reference moved by (3, -2) px (the reference plus the
/// capture's difference from it at the pixel 3 px left and 2 px below), re-rendered from the
/// others at its own pins. Every imprint's real darkening centroid lies (3, -2) px from the
/// rendered one within 0.5 px per axis (measured within 0.2 px on seed sets 0 to 2, mostly
/// short of the shift: the 15 px neighbourhood cuts the shifted darkening's far edge), and
/// the median offset is the shift's 3.61 px within 0.5.
#[test]
fn imprints_shifted_by_a_known_offset_show_it_in_the_centroid_report() {
    let c = captures(warm_ring(), rtac0_pins);
    let (w, h) = (c.rays.width as i64, c.rays.height as i64);
    let (du, dv) = (3i64, -2i64);
    let k = 1;
    let image = &c.scenes[k].2;
    let shifted: Vec<[f64; 3]> = (0..w * h)
        .map(|i| {
            let (u, v) = (i % w - du, i / w - dv);
            let i = i as usize;
            if u < 0 || v < 0 || u >= w || v >= h {
                return image[i];
            }
            let j = (v * w + u) as usize;
            std::array::from_fn(|ch| {
                let d = image[j][ch] - c.reference_image[j][ch];
                (c.reference_image[i][ch] + d).round().clamp(0.0, 255.0)
            })
        })
        .collect();
    let (_, region) = contact_leave_one_out(&c, k, &shifted, CONTACT_REACH_PX);
    let want = (du as f64).hypot(dv as f64);
    for (j, f) in region.imprints.iter().enumerate() {
        let (Some(a), Some(b)) = (f.real_centroid_px, f.rendered_centroid_px) else {
            panic!("imprint {j}: no darkening centroid: {f:?}");
        };
        let d = [a[0] - b[0], a[1] - b[1]];
        eprintln!(
            "imprint {j} at {:.1?}: real - rendered {d:.3?} px",
            f.centre_px
        );
        assert!(
            (d[0] - du as f64).abs() < 0.5 && (d[1] - dv as f64).abs() < 0.5,
            "imprint {j}: centroids {d:?} px apart, shifted ({du}, {dv})"
        );
    }
    let m = region.median_offset_px.unwrap();
    assert!(
        (m - want).abs() < 0.5,
        "median offset {m} px, shifted {want}"
    );
}

/// The imprint map: two pressed blobs give two imprints numbered in raster order, each
/// pixel's distance to its nearest pressed pixel (Euclidean, px) and which imprint that is, up
/// to the reach; beyond it none.
#[test]
fn the_imprint_map_measures_distances_to_the_nearest_imprint() {
    let (w, h) = (40usize, 20usize);
    let mut contact = vec![false; w * h];
    for (u, v) in [(5, 5), (6, 5), (5, 6), (30, 12)] {
        contact[v * w + u] = true;
    }
    let map = ImprintMap::of(&contact, w, h, 10.0);
    assert_eq!(map.centres_px.len(), 2);
    assert_eq!(map.pressed, vec![3, 1]);
    assert_eq!(map.centres_px[0], [16.0 / 3.0, 16.0 / 3.0]);
    assert_eq!(map.centres_px[1], [30.0, 12.0]);
    let at = |u: usize, v: usize| v * w + u;
    // 3 px right and 4 below (6, 5): 5 px
    assert_eq!(map.imprint_near(at(9, 9), 5.0), Some(0));
    assert_eq!(map.imprint_near(at(9, 9), 4.99), None);
    assert_eq!(map.imprint_near(at(25, 12), 5.0), Some(1));
    assert!(!map.beyond_reach(at(15, 5)));
    assert!(map.beyond_reach(at(17, 5)));
    assert_eq!(map.imprint_near(at(5, 5), 0.0), Some(0));
}
