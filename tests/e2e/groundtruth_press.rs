//! `fabkit groundtruth --press-image` on the real 9DTact ball press
//! (tests/data/9dtact_sensor1/depth_calibration, a 4.0 mm ball) through the camera its board
//! press calibrates (`fabkit calibrate board`): the press is fitted, one frame is rendered with
//! the sphere placed where the fit puts it, beside copies of the captures; bad input is refused
//! by option with nothing written.

use crate::common::*;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn data(dir: &str, name: &str) -> PathBuf {
    repo_root()
        .join("tests/data/9dtact_sensor1")
        .join(dir)
        .join(name)
}

/// The ball press's capture and reference.
fn ball(name: &str) -> String {
    data("depth_calibration", name).display().to_string()
}

/// `fabkit fixtures ninedtact` and `fabkit calibrate board` on the real board press in `dir`:
/// board/camera.yaml and board/extrinsics.json.
fn setup(dir: &Path) {
    let o = run(dir, &["fixtures", "ninedtact", "--out", "fx"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (r, s) = (
        data("camera_calibration", "ref.png"),
        data("camera_calibration", "sample.png"),
    );
    let o = run(
        dir,
        &[
            "calibrate",
            "board",
            "--points",
            "fx/points/board_table.csv",
            "--reference",
            r.to_str().unwrap(),
            "--image",
            s.to_str().unwrap(),
            "--out",
            "board",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// The command on `image` against `reference` with `radius` into `gt`.
fn press_args<'a>(image: &'a str, reference: &'a str, radius: &'a str) -> Vec<&'a str> {
    vec![
        "groundtruth",
        "ninedtact",
        "--camera",
        "board/camera.yaml",
        "--extrinsics",
        "board/extrinsics.json",
        "--press-image",
        image,
        "--press-reference",
        reference,
        "--sphere-radius-mm",
        radius,
        "--out",
        "gt",
    ]
}

/// The real press: press.json's depth between 1.5 and 1.8 mm (measured 1.715 mm, standard
/// deviation 0.0016 mm, spread 0.076 mm over the core's choice) and its centre within 0.05 mm
/// of (0.79, 0.79) mm (measured (0.778, 0.784)); the rendered z-depth difference is deepest at
/// the pixel the sphere's lowest point projects to, by the fitted depth within 0.01 mm
/// (measured 0.0003 mm: the camera's 0.01 rad tilt and float32), and as deep there as at the
/// fit's apex pixel within 0.01 mm; the contact mask is a disc about that pixel (the radius of
/// the nearest pixel outside it over the farthest inside, measured 63.6 / 67.2 px: the lens's
/// distortion) of the sphere's intersection with the face (sqrt(2 R d - d^2) = 3.28 mm; the
/// capture's darkening ends at its edge). The deformed skin (press/skin/) is as deep, touches
/// the sphere over less than its intersection, and bulges round it (an incompressible layer
/// bonded to its window) where the real capture shows its bright halo. The captures are copied byte for byte, and a second run writes the
/// same bytes.
#[test]
fn the_real_ball_press_is_fitted_and_rendered_beside_its_capture() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    setup(d);
    let (image, reference) = (ball("sample.png"), ball("ref.png"));
    let args = press_args(&image, &reference, "4");
    let o = run(d, &args, &[]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert!(out.contains("press: a 4 mm sphere at ("), "{out}");
    assert!(
        out.contains("reference + the press of a 4 mm sphere"),
        "{out}"
    );
    let gt = d.join("gt");
    let p: Value = serde_json::from_slice(&std::fs::read(gt.join("press.json")).unwrap()).unwrap();
    let f = |k: &str| p[k].as_f64().unwrap();
    let depth = f("depth_mm");
    assert!(depth > 1.5 && depth < 1.8, "{p}");
    let c = [
        p["centre_mm"][0].as_f64().unwrap(),
        p["centre_mm"][1].as_f64().unwrap(),
    ];
    assert!(
        (c[0] - 0.79).abs() < 0.05 && (c[1] - 0.79).abs() < 0.05,
        "{p}"
    );
    for k in ["depth_std_mm", "depth_spread_mm"] {
        assert!(f(k) > 0.0 && f(k) < 0.1, "{k}: {p}");
    }
    for s in p["centre_std_mm"].as_array().unwrap() {
        assert!(
            s.as_f64().unwrap() > 0.0 && s.as_f64().unwrap() < 0.01,
            "{p}"
        );
    }
    assert!(
        f("gain_grey_per_mm") > 30.0 && f("gain_grey_per_mm") < 40.0,
        "{p}"
    );
    assert_eq!(p["indenter"]["radius_mm"], 4.0);
    let sc = &p["sphere"]["centre_mm"];
    assert_eq!(sc[0].as_f64().unwrap(), c[0]);
    assert!(
        (sc[2].as_f64().unwrap() - (2.8 - depth + 4.0)).abs() < 1e-12,
        "{p}"
    );
    // the captures, copied byte for byte beside their frames
    assert_eq!(
        std::fs::read(gt.join("press/capture.png")).unwrap(),
        std::fs::read(&image).unwrap()
    );
    assert_eq!(
        std::fs::read(gt.join("reference/capture.png")).unwrap(),
        std::fs::read(&reference).unwrap()
    );

    let (w, h) = (640usize, 480usize);
    let dz = read_npy_f32(&gt.join("press/delta_zdepth_mm.npy"));
    assert_eq!(dz.len(), w * h);
    let px = &p["sphere"]["lowest_point_px"];
    let (u, v) = (px[0].as_f64().unwrap(), px[1].as_f64().unwrap());
    let at = |u: f64, v: f64| -(dz[v.round() as usize * w + u.round() as usize] as f64);
    let deepest = dz
        .iter()
        .filter(|x| x.is_finite())
        .fold(0.0f64, |m, x| m.max(-(*x as f64)));
    assert!(
        (deepest - depth).abs() < 0.01,
        "deepest {deepest} mm, fitted {depth} mm"
    );
    assert!(
        (at(u, v) - depth).abs() < 0.01,
        "{} mm at ({u}, {v}) px",
        at(u, v)
    );
    let apex = &p["centre_px"];
    let (au, av) = (apex[0].as_f64().unwrap(), apex[1].as_f64().unwrap());
    assert!(
        (at(au, av) - depth).abs() < 0.01,
        "{} mm at the apex",
        at(au, av)
    );

    let mask = image::open(gt.join("press/contact_mask.png"))
        .unwrap()
        .into_luma8();
    assert_eq!((mask.width(), mask.height()), (w as u32, h as u32));
    let (mut inside, mut r_in_max, mut r_out_min) = (0usize, 0.0f64, f64::INFINITY);
    for (x, y, m) in mask.enumerate_pixels() {
        let r = (x as f64 - u).hypot(y as f64 - v);
        if m.0[0] == 255 {
            inside += 1;
            r_in_max = r_in_max.max(r);
        } else {
            assert_eq!(m.0[0], 0);
            r_out_min = r_out_min.min(r);
        }
    }
    // measured: 13,388 pixels, from 63.6 to 67.2 px
    assert!(r_out_min / r_in_max > 0.9, "{r_out_min} / {r_in_max} px");
    assert!(r_in_max > 50.0 && r_in_max < 75.0, "{r_in_max} px");
    let disc = std::f64::consts::PI * r_out_min * r_out_min;
    assert!(inside as f64 >= 0.95 * disc, "{inside} pixels, disc {disc}");
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(gt.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(
        manifest["configurations"][0]["contact_pixels"].as_u64(),
        Some(inside as u64)
    );
    assert_eq!(manifest["press"]["depth_mm"].as_f64(), Some(depth));

    // the skin as the sphere deforms it: as deep, its contact inside the sphere's intersection
    // (measured 12,755 of 13,388 pixels; 3.16 mm of 3.28), bulging round it (measured 0.19 mm
    // at about 1.5 mm past the contact) and settled far from it
    let skin = read_npy_f32(&gt.join("press/skin/delta_zdepth_mm.npy"));
    let deepest_skin = skin
        .iter()
        .filter(|x| x.is_finite())
        .fold(0.0f64, |m, x| m.max(-(*x as f64)));
    assert!((deepest_skin - depth).abs() < 0.01, "{deepest_skin}");
    let skin_mask = image::open(gt.join("press/skin/contact_mask.png"))
        .unwrap()
        .into_luma8();
    let touching = skin_mask.pixels().filter(|m| m.0[0] == 255).count();
    assert!(
        touching < inside && touching as f64 > 0.8 * inside as f64,
        "{touching} of {inside}"
    );
    let (mut bulge, mut far) = (0.0f64, 0.0f64);
    for (k, x) in skin.iter().enumerate() {
        let r = ((k % w) as f64 - u).hypot((k / w) as f64 - v);
        if r > r_out_min && r < r_out_min + 60.0 {
            bulge = bulge.max(*x as f64);
        } else if r > 220.0 && x.is_finite() {
            far = far.max(x.abs() as f64);
        }
    }
    assert!(bulge > 0.05 && bulge < 0.4, "bulge {bulge} mm");
    assert!(far < 0.05, "{far} mm far from the press");
    // the real capture's bright halo is the bulge: ring means (2 px rings, 72 to 200 px from
    // the lowest point's pixel) of the capture's brightening and of the skin's rise correlate
    // (measured 0.98) and peak at the same radius (measured 90 and 92 px)
    let grey = |f: &str| image::open(f).unwrap().into_luma8();
    let (cap, refc) = (grey(&image), grey(&reference));
    let rings: Vec<f64> = (36..=100).map(|k| 2.0 * k as f64).collect();
    let (mut bright, mut rise) = (
        vec![(0.0, 0usize); rings.len()],
        vec![(0.0, 0usize); rings.len()],
    );
    for (k, x) in skin.iter().enumerate() {
        let (px, py) = ((k % w) as u32, (k / w) as u32);
        let r = (px as f64 - u).hypot(py as f64 - v);
        let b = ((r - 71.0) / 2.0).floor();
        if b < 0.0 || b as usize >= rings.len() || !x.is_finite() {
            continue;
        }
        let b = b as usize;
        let g = cap.get_pixel(px, py).0[0] as f64 - refc.get_pixel(px, py).0[0] as f64;
        bright[b] = (bright[b].0 + g, bright[b].1 + 1);
        rise[b] = (rise[b].0 + *x as f64, rise[b].1 + 1);
    }
    let mean = |v: &[(f64, usize)]| -> Vec<f64> { v.iter().map(|(s, n)| s / *n as f64).collect() };
    let (bright, rise) = (mean(&bright), mean(&rise));
    let corr = {
        let m = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let (mb, mr) = (m(&bright), m(&rise));
        let (mut sbr, mut sbb, mut srr) = (0.0, 0.0, 0.0);
        for (b, r) in bright.iter().zip(&rise) {
            sbr += (b - mb) * (r - mr);
            sbb += (b - mb) * (b - mb);
            srr += (r - mr) * (r - mr);
        }
        sbr / (sbb * srr).sqrt()
    };
    let peak = |v: &[f64]| rings[(0..v.len()).max_by(|&a, &b| v[a].total_cmp(&v[b])).unwrap()];
    assert!(corr > 0.95, "halo and bulge correlate {corr}");
    assert!(
        (peak(&bright) - peak(&rise)).abs() <= 6.0,
        "halo at {} px, bulge at {} px",
        peak(&bright),
        peak(&rise)
    );
    let e = &p["elastic"];
    assert_eq!(e["thickness_mm"].as_f64(), Some(2.8));
    assert_eq!(e["seen_depth_mm"].as_f64(), Some(0.3));

    // same input, same bytes (the output replaced in place)
    let first = snapshot(&gt);
    let o = run(d, &args, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(first == snapshot(&gt), "a second run wrote other bytes");
}

/// Bad input is refused naming the option and its file or value, with nothing written under
/// --out: a capture (or a reference) of another size than the camera's, no contact (the
/// reference given as the press), a radius that is not finite and above 0, --fixtures with a
/// press, a press without its reference.
#[test]
fn bad_presses_are_refused_by_option_with_nothing_written() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    setup(d);
    let small = d.join("small.png");
    image::open(ball("sample.png"))
        .unwrap()
        .crop_imm(0, 0, 320, 240)
        .save(&small)
        .unwrap();
    let small = small.display().to_string();
    let (image, reference) = (ball("sample.png"), ball("ref.png"));
    let refused = |args: &[&str], want: &[String]| {
        let o = run(d, args, &[]);
        let e = text(&o.stderr);
        assert!(!o.status.success(), "{args:?}");
        for w in want {
            assert!(e.contains(w.as_str()), "{args:?}: want {w:?} in\n{e}");
        }
        assert!(!d.join("gt").exists(), "{args:?} wrote gt");
    };
    refused(
        &press_args(&small, &reference, "4"),
        &[format!(
            "--press-image = {small}: the image is 320 x 240 px but the camera file board/camera.yaml says 640 x 480 px"
        )],
    );
    refused(
        &press_args(&image, &small, "4"),
        &[format!(
            "--press-reference = {small}: the image is 320 x 240 px"
        )],
    );
    refused(
        &press_args(&reference, &reference, "4"),
        &[
            format!(
                "--press-image = {reference} (against --press-reference = {reference}): no contact"
            ),
            "not the reference".to_string(),
        ],
    );
    for r in ["0", "-4", "nan", "inf", "1e9"] {
        refused(
            &press_args(&image, &reference, r),
            &[
                format!("'{r}' for '--sphere-radius-mm <MM>'"),
                "must be a finite length above 0 mm".to_string(),
            ],
        );
    }
    let mut with_fixtures = press_args(&image, &reference, "4");
    with_fixtures.extend(["--fixtures", "fx"]);
    refused(&with_fixtures, &["--fixtures".to_string()]);
    let mut no_reference = press_args(&image, &reference, "4");
    no_reference.drain(8..10);
    refused(&no_reference, &["--press-reference".to_string()]);
}
