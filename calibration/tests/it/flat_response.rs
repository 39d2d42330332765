//! The response of a flat sensor's image to its elastic skin (calibration/src/flat_response.rs)
//! on the real 9DTact captures: fitted on the board press, checked on the ball press.

use fabkit_calibration::board::*;
use fabkit_calibration::elastic::bump_heights;
use fabkit_calibration::flat_response::*;
use fabkit_calibration::groundtruth::press_skin::{Face, PressedSkin, SkinModel};
use fabkit_calibration::imprints::GrayImage;
use fabkit_calibration::press::{fit_sphere_press, PressOptions};

fn load(dir: &str, name: &str) -> GrayImage {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/9dtact_sensor1")
        .join(dir)
        .join(name);
    let i = image::open(p).unwrap().into_luma8();
    GrayImage {
        width: i.width() as usize,
        height: i.height() as usize,
        data: i.into_raw().into_iter().map(f32::from).collect(),
    }
}

fn model() -> SkinModel {
    SkinModel {
        thickness_mm: 2.8,
        poisson: 0.5,
        seen_depth_mm: 0.3,
        seen: "the black gel's inner face".into(),
    }
}

/// The real ball press (a 4 mm ball 1.715 mm deep) through the camera the real board press
/// calibrates: its skin solved elastically, and the pixels within 3 mm of the contact's edge
/// on the contact face (the disc and its halo).
struct BallPress {
    reference: GrayImage,
    capture: GrayImage,
    skin: PressedSkin,
    /// The seen face's sink per pixel (the black gel's inner face), the outer surface's, and
    /// the rigid skin's (the sphere's intersection: flat outside it).
    seen: Vec<f64>,
    surface: Vec<f64>,
    rigid: Vec<f64>,
    region: Vec<bool>,
    lit: Vec<bool>,
}

fn ball_press() -> BallPress {
    let table = crate::common::grid_table("board_table.csv", 7, 9, 2.5, 2.8);
    let grid = board_grid(&table).unwrap();
    let (bref, bcap) = (
        load("camera_calibration", "ref.png"),
        load("camera_calibration", "sample.png"),
    );
    let (_, find) = find_bumps(&bref, &bcap, &grid, "sample.png").unwrap();
    let bc = solve_board_camera(&grid, &find, (640, 480), 11.548).unwrap();
    let (reference, capture) = (
        load("depth_calibration", "ref.png"),
        load("depth_calibration", "sample.png"),
    );
    let fit = fit_sphere_press(
        &reference,
        &capture,
        &bc.camera,
        &bc.t_cam_sensor,
        2.8,
        &PressOptions::sphere(4.0),
    )
    .unwrap();
    let skin = PressedSkin::solve(&model(), 4.0, fit.centre_mm, fit.depth_mm).unwrap();
    let seen = sink_per_pixel(&skin, Face::Seen, &bc.camera, &bc.t_cam_sensor, 2.8);
    let surface = sink_per_pixel(&skin, Face::Surface, &bc.camera, &bc.t_cam_sensor, 2.8);
    let inv = bc.t_cam_sensor.inverse();
    let on_plane: Vec<nalgebra::Vector2<f64>> = (0..640 * 480)
        .map(|p| {
            let px = nalgebra::Vector2::new((p % 640) as f64, (p / 640) as f64);
            pixel_on_plane(&bc.camera, &inv, 2.8, px).unwrap()
        })
        .collect();
    let rho = |q: &nalgebra::Vector2<f64>| (q.x - fit.centre_mm[0]).hypot(q.y - fit.centre_mm[1]);
    let rigid = on_plane
        .iter()
        .map(|q| {
            let r = rho(q);
            (fit.depth_mm - (4.0 - (16.0 - r * r).max(0.0).sqrt())).max(0.0)
        })
        .collect();
    let region = on_plane
        .iter()
        .map(|q| rho(q) < skin.contact_radius_mm + 3.0)
        .collect();
    let lit = reference.data.iter().map(|&r| r > 40.0).collect();
    BallPress {
        reference,
        capture,
        skin,
        seen,
        surface,
        rigid,
        region,
        lit,
    }
}

const KNOTS_MM: [f64; 13] = [
    -0.3, -0.2, -0.1, -0.05, 0.0, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0, 1.5, 2.0,
];
const BLURS_PX: [f64; 6] = [1.0, 2.0, 3.0, 4.0, 5.0, 8.0];

/// The best response of each skin model to the real ball press, over the disc and its halo:
/// the elastic skin's seen face (the black gel's inner face, 0.3 mm deep) leaves 1.7 grey
/// levels RMS (asserted under 2.5), its outer surface 2.3, the rigid skin (the sphere's
/// intersection, flat outside it: what the ground truth drew before the elastic model) 11.9
/// (asserted over 8): the dent's shape and the bulge round it are what the capture shows. The
/// fitted response darkens with the sink and brightens with the rise, more steeply for the
/// rise; the capture is darker than its reference by 2.1 % (its gain, measured 0.979: an
/// exposure change the response must not take up).
#[test]
fn the_elastic_skin_explains_the_real_ball_press() {
    let b = ball_press();
    let best = |sink: &[f64]| {
        let f = fit_response(
            &[FitCapture {
                reference: &b.reference,
                capture: &b.capture,
                sink_mm: sink,
                mask: &b.lit,
            }],
            &KNOTS_MM,
            &BLURS_PX,
        );
        let pred = render(&f.response, f.gains[0], &b.reference, sink);
        (rms_over(&pred, &b.capture, &b.region), f)
    };
    let (seen, f) = best(&b.seen);
    let (surface, _) = best(&b.surface);
    let (rigid, _) = best(&b.rigid);
    assert!(seen < 2.5, "{seen}");
    assert!(seen < surface && rigid > 8.0, "{seen} {surface} {rigid}");
    let r = &f.response;
    assert!(r.at(-0.2) > 10.0 && r.at(1.0) < -20.0 && r.at(1.5) < r.at(1.0));
    assert!(r.at(-0.2) / 0.2 > -r.at(1.0) / 1.0, "{r:?}");
    assert!(f.gains[0] > 0.96 && f.gains[0] < 0.995, "{}", f.gains[0]);
    assert!(b.skin.contact_radius_mm > 3.0 && b.skin.contact_radius_mm < 3.3);
}

/// A capture rendered from the ball press's elastic skin with a known response (9DTact-like:
/// steep for the rise, about 35 grey levels per mm of sink), gain 0.98 and blur 1.5 px, plus
/// Gaussian noise of 1 grey level (a fixed seed): the response's knots are recovered within 5
/// % of the largest (or 0.5 grey levels), the gain within 0.5 %, the blur exactly (it is one of
/// those tried), and the re-render within 2 grey levels RMS over the disc and halo.
#[test]
fn a_known_response_is_recovered_from_a_synthetic_capture() {
    use rand_distr::{Distribution, Normal};
    let b = ball_press();
    let truth = FlatResponse {
        knots_mm: KNOTS_MM.to_vec(),
        grey: KNOTS_MM
            .iter()
            .map(|&u| if u < 0.0 { -120.0 * u } else { -35.0 * u })
            .collect(),
        blur_px: 2.0,
    };
    let clean = render(&truth, 0.98, &b.reference, &b.seen);
    use rand_chacha::rand_core::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let noise = Normal::new(0.0, 1.0).unwrap();
    let capture = GrayImage {
        width: 640,
        height: 480,
        data: clean
            .data
            .iter()
            .map(|&x| x + noise.sample(&mut rng) as f32)
            .collect(),
    };
    let f = fit_response(
        &[FitCapture {
            reference: &b.reference,
            capture: &capture,
            sink_mm: &b.seen,
            mask: &b.lit,
        }],
        &KNOTS_MM,
        &BLURS_PX,
    );
    assert_eq!(f.response.blur_px, 2.0);
    assert!((f.gains[0] / 0.98 - 1.0).abs() < 0.005, "{}", f.gains[0]);
    let largest = truth.grey.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for (k, (got, want)) in f.response.grey.iter().zip(&truth.grey).enumerate() {
        let reached = b.seen.iter().any(|&u| (u - KNOTS_MM[k]).abs() < 0.05);
        if reached {
            assert!(
                (got - want).abs() < (0.05 * largest).max(0.5),
                "knot {} mm: {got} against {want}",
                KNOTS_MM[k]
            );
        }
    }
    let pred = render(&f.response, f.gains[0], &b.reference, &b.seen);
    assert!(rms_over(&pred, &clean, &b.region) < 2.0);
}

/// A board's bump heights: 0 at a bump's axis, the hemisphere's `R - sqrt(R^2 - r^2)` off
/// it, the floor's height between bumps.
#[test]
fn bump_heights_are_capped_cylinders_on_a_floor() {
    use fabkit_calibration::elastic::ContactGrid;
    let grid = ContactGrid {
        n: 41,
        cell_mm: 0.1,
    };
    let h = bump_heights(grid, [0.0, 0.0], &[[0.0, 0.0], [2.5, 0.0]], 0.6, 1.5);
    let at = |i: usize, j: usize| h[j * 41 + i];
    assert_eq!(at(20, 20), 0.0);
    let r: f64 = 0.3;
    assert!((at(23, 20) - (0.6 - (0.36 - r * r).sqrt())).abs() < 1e-12);
    assert_eq!(at(32, 20), 1.5);
    assert_eq!(at(20, 30), 1.5);
}
