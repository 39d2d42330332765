//! `fabkit calibrate photometric` end to end: R-Tac0's published pin dome (`fabkit fixtures
//! --pins-preset rtac0`), the captures of its first five capture-plan rows rendered by
//! `fabkit groundtruth --pin-captures --images` (the physical image model: R-Tac0's LED ring,
//! the pins' shadows, camera noise) at the pose of extrinsics.json and copied as 8-bit PNGs
//! named by their pins; the command fits the model, re-renders each capture from the others
//! within a count of the fit, and refuses a capture whose name lists no pins, or a pin the
//! table does not have, with nothing written. And the pin captures themselves: one frame per
//! capture-plan row, named by its pins, each pin's tip where the point table puts it.

use std::path::Path;

use crate::common::*;
use crate::groundtruth_cli::setup;
use fabkit_calibration::groundtruth::inputs::read_extrinsics;
use fabkit_calibration::nalgebra::{Point3, Vector3};
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::CameraModel;

fn pin_captures(dir: &Path, out: &str, format: &str) -> std::process::Output {
    pin_captures_of(dir, "fx", out, format)
}

/// The pin captures of the pin dome in the fixtures folder `fixtures`.
fn pin_captures_of(dir: &Path, fixtures: &str, out: &str, format: &str) -> std::process::Output {
    pin_captures_in(dir, "rtac0", fixtures, out, format)
}

/// [`pin_captures_of`] rendered with the design `design` (a library name or a YAML file).
fn pin_captures_in(
    dir: &Path,
    design: &str,
    fixtures: &str,
    out: &str,
    format: &str,
) -> std::process::Output {
    run(
        dir,
        &[
            "groundtruth",
            design,
            "--camera",
            "cam.yaml",
            "--extrinsics",
            "extrinsics.json",
            "--fixtures",
            fixtures,
            "--pin-captures",
            "--images",
            "--format",
            format,
            "--out",
            out,
        ],
        &[],
    )
}

/// Writes ref.png and the first five pin captures; returns their file names.
fn captures(dir: &Path) -> Vec<String> {
    captures_in(dir, "rtac0")
}

/// [`captures`] rendered with the design `design`.
fn captures_in(dir: &Path, design: &str) -> Vec<String> {
    render_caps(dir, design);
    std::fs::copy(dir.join("caps/reference/image.png"), dir.join("ref.png")).unwrap();
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("caps/manifest.json")).unwrap()).unwrap();
    let mut names = Vec::new();
    for c in m["configurations"].as_array().unwrap().iter().take(5) {
        let folder = c["dir"].as_str().unwrap();
        let name = format!("{folder}.png");
        std::fs::copy(
            dir.join("caps").join(folder).join("image.png"),
            dir.join(&name),
        )
        .unwrap();
        names.push(name);
    }
    names
}

/// The pin captures of `design` (a library name or a design file in `dir`) with `dir`'s camera,
/// extrinsics and fixtures `fx`, in `dir/caps` ([`pin_captures_in`]), rendered once per run for
/// each distinct set of those inputs (most tests [`setup`] the same folder): the first test to
/// need them renders them and keeps a copy in `<target>/tmp/shared-pin-captures`, the others
/// copy it (each render took about 1.5 s).
fn render_caps(dir: &Path, design: &str) {
    use sha2::{Digest, Sha256};
    use std::sync::{Arc, Mutex, OnceLock};
    type Renders = (
        std::path::PathBuf,
        Mutex<std::collections::BTreeMap<String, Arc<OnceLock<std::path::PathBuf>>>>,
    );
    static RENDERS: OnceLock<Renders> = OnceLock::new();
    let mut h = Sha256::new();
    h.update(design.as_bytes());
    h.update([0]);
    for input in [design, "cam.yaml", "extrinsics.json"] {
        let bytes = std::fs::read(dir.join(input)).unwrap_or_default();
        h.update((bytes.len() as u64).to_le_bytes());
        h.update(&bytes);
    }
    for (path, bytes) in snapshot(&dir.join("fx")) {
        h.update(path.as_bytes());
        h.update([0]);
        h.update((bytes.len() as u64).to_le_bytes());
        h.update(&bytes);
    }
    let key: String = h.finalize()[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let (root, renders) =
        RENDERS.get_or_init(|| (shared_dir("shared-pin-captures"), Mutex::default()));
    let cell = renders
        .lock()
        .unwrap()
        .entry(key.clone())
        .or_default()
        .clone();
    let mut rendered_here = false;
    let shared = cell.get_or_init(|| {
        let o = pin_captures_in(dir, design, "fx", "caps", "png");
        assert!(o.status.success(), "{}", text(&o.stderr));
        rendered_here = true;
        let shared = root.join(&key);
        copy_tree(&dir.join("caps"), &shared);
        shared
    });
    if !rendered_here {
        let caps = dir.join("caps");
        if caps.exists() {
            std::fs::remove_dir_all(&caps).unwrap();
        }
        copy_tree(shared, &caps);
    }
}

#[test]
fn groundtruth_renders_one_frame_per_pin_capture_with_the_pins_at_their_tips() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let o = pin_captures(d.path(), "gt", "npy");
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("reference + 8 pin captures")
            && text(&o.stdout).contains("camera: camera_matrix (intrinsics), distortion_coefficients (distortion) read from cam.yaml"),
        "{}",
        text(&o.stdout)
    );
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("gt/manifest.json")).unwrap()).unwrap();
    // the frames are the plan's rows, in order, each named by its pins
    let plan = std::fs::read_to_string(d.path().join("fx/points/capture_plan.csv")).unwrap();
    let mut rows: Vec<(String, Vec<String>)> = Vec::new();
    for line in plan.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        match rows.last_mut() {
            Some((k, ids)) if k == c[0] => ids.push(c[1].to_string()),
            _ => rows.push((c[0].to_string(), vec![c[1].to_string()])),
        }
    }
    let cfgs = m["configurations"].as_array().unwrap();
    assert_eq!(cfgs.len(), rows.len());
    assert!(!d.path().join("gt/pairs.csv").exists());
    // each pin's tip is where the camera sees the skin pressed in: the range at the pixel the
    // tip projects to is the tip's distance from the camera centre (the pixel's ray passes
    // within half a pixel of the tip; the hemisphere there is about square to the ray)
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    let (pose, _) = read_extrinsics(&d.path().join("extrinsics.json")).unwrap();
    let table = std::fs::read_to_string(d.path().join("fx/points/point_table.csv")).unwrap();
    let tip_of = |id: &str| -> [f64; 3] {
        let row: Vec<f64> = table
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect::<Vec<_>>())
            .find(|c| c[0] == id)
            .unwrap()[2..5]
            .iter()
            .map(|x| x.parse().unwrap())
            .collect();
        [row[0], row[1], row[2]]
    };
    let centre = pose.inverse() * Point3::origin();
    for (c, (_, ids)) in cfgs.iter().zip(&rows) {
        let names: Vec<String> = ids
            .iter()
            .map(|i| format!("{:02}", i.parse::<u32>().unwrap()))
            .collect();
        assert_eq!(c["name"].as_str().unwrap(), names.join("_"));
        assert_eq!(c["pins"], serde_json::json!(ids));
        let dir = d.path().join("gt").join(c["dir"].as_str().unwrap());
        let range = read_npy_f32(&dir.join("range_mm.npy"));
        let delta = read_npy_f32(&dir.join("delta_range_mm.npy"));
        assert!(dir.join("image.png").is_file());
        let pole = &ids[0];
        assert_eq!(pole, "1");
        for id in ids {
            let tip = tip_of(id);
            let p = pose * Point3::new(tip[0], tip[1], tip[2]);
            let uv = cam.project(&Vector3::new(p.x, p.y, p.z)).unwrap();
            let px = uv.y.round() as usize * 640 + uv.x.round() as usize;
            let want = (Point3::new(tip[0], tip[1], tip[2]) - centre).norm();
            let tol = if id == pole { 0.005 } else { 0.05 };
            // measured up to 0.00024 mm at the pole and 0.023 mm elsewhere (the nearest pixel
            // centre is up to 0.7 px from the tip, on a slope away from the pole)
            assert!(
                (f64::from(range[px]) - want).abs() < tol,
                "capture {}, pin {id}: range {} mm at ({:.1}, {:.1}) px, tip at {want:.4} mm",
                c["name"],
                range[px],
                uv.x,
                uv.y
            );
            // pressed in by about the pin's indentation depth (1.54 mm along its axis)
            assert!(delta[px] < -1.0, "pin {id}: delta {}", delta[px]);
        }
    }
    // a plan naming a pin the table lacks is refused by file, line and rule, nothing written
    std::fs::write(
        d.path().join("fx/points/capture_plan.csv"),
        format!("{plan}9,99,4\n"),
    )
    .unwrap();
    let o = pin_captures(d.path(), "gt2", "png");
    assert!(!o.status.success());
    let e = text(&o.stderr);
    assert!(
        e.contains("capture_plan.csv") && e.contains("\"99\"") && e.contains("point_table.csv"),
        "{e}"
    );
    assert!(!d.path().join("gt2").exists());
    // Issue 95: a plan with two captures of the same pins ran, then failed on a folder that
    // existed; refused up front by file and capture
    let header: Vec<&str> = plan.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| h.trim() == name).unwrap();
    let (cap, first) = (
        col("capture"),
        plan.lines()
            .nth(1)
            .unwrap()
            .split(',')
            .nth(col("capture"))
            .unwrap()
            .to_string(),
    );
    let again: String = plan
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(cap) == Some(first.as_str()))
        .map(|l| {
            let mut c: Vec<&str> = l.split(',').collect();
            c[cap] = "99";
            c.join(",") + "\n"
        })
        .collect();
    std::fs::write(
        d.path().join("fx/points/capture_plan.csv"),
        format!("{plan}{again}"),
    )
    .unwrap();
    let o = pin_captures(d.path(), "gt2", "png");
    let e = text(&o.stderr);
    assert!(
        !o.status.success()
            && e.contains("capture 99")
            && e.contains(&format!("presses the same pins as capture {first}")),
        "{e}"
    );
    std::fs::write(d.path().join("fx/points/capture_plan.csv"), &plan).unwrap();
    // Issue 95: fixture files read back with a pin tip radius of 1e-300 mm, a shaft of 1e300 mm
    // or a tip at x = 1e300 mm were accepted; the design's bounds apply, by file and field
    let manifest = std::fs::read_to_string(d.path().join("fx/manifest.json")).unwrap();
    let table = std::fs::read_to_string(d.path().join("fx/points/point_table.csv")).unwrap();
    let mut m: serde_json::Value = serde_json::from_str(&manifest).unwrap();
    let pin = m["parts"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|p| p["name"] == "pin")
        .unwrap();
    pin["params"]["pin"]["tip_radius_mm"] = serde_json::json!(1e-300);
    std::fs::write(d.path().join("fx/manifest.json"), m.to_string()).unwrap();
    let o = pin_captures(d.path(), "gt2", "png");
    let e = text(&o.stderr);
    assert!(
        !o.status.success()
            && e.contains("parts[pin].params.pin.tip_radius_mm")
            && e.contains("must be a length from 0.001"),
        "{e}"
    );
    std::fs::write(d.path().join("fx/manifest.json"), &manifest).unwrap();
    let mut lines: Vec<String> = table.lines().map(str::to_string).collect();
    let x = lines[0]
        .split(',')
        .position(|c| c.trim() == "tip_x_mm")
        .unwrap();
    let mut cells: Vec<String> = lines[1].split(',').map(str::to_string).collect();
    cells[x] = "1e300".into();
    lines[1] = cells.join(",");
    std::fs::write(
        d.path().join("fx/points/point_table.csv"),
        lines.join("\n") + "\n",
    )
    .unwrap();
    let o = pin_captures(d.path(), "gt2", "png");
    let e = text(&o.stderr);
    assert!(
        !o.status.success() && e.contains("tip_x_mm") && e.contains("must be within +-1000 mm"),
        "{e}"
    );
    assert!(!d.path().join("gt2").exists());
}

fn args<'a>(names: &'a [String], out: &'a str) -> Vec<&'a str> {
    args_in("rtac0", names, out)
}

/// [`args`] with the design `design`.
fn args_in<'a>(design: &'a str, names: &'a [String], out: &'a str) -> Vec<&'a str> {
    let mut a = vec![
        "calibrate",
        "photometric",
        design,
        "--camera",
        "cam.yaml",
        "--extrinsics",
        "extrinsics.json",
        "--fixtures",
        "fx",
        "--reference",
        "ref.png",
        "--out",
        out,
        "--images",
    ];
    a.extend(names.iter().map(String::as_str));
    a
}

#[test]
fn the_photometric_model_re_renders_each_capture_from_the_others() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let names = captures(d.path());
    let o = run(d.path(), &args(&names, "ph"), &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    // issue 102: its progress on stderr, plain lines off a terminal, each stage in order with
    // its count and the time it took
    let err = text(&o.stderr);
    let at = |prefix: &str| line_starting(&err, prefix);
    let stages = [
        "calibrate photometric: reading and posing 5 captures",
        "calibrate photometric: 5/5 (",
        "calibrate photometric: fitting the model to 5 captures (seating round 1 of 2)",
        "calibrate photometric: seating the pin dome of each of 5 captures",
        "calibrate photometric: fitting the model to 5 captures (seating round 2 of 2)",
        "calibrate photometric: fitting the model to 5 seated captures",
        "calibrate photometric: re-rendering each of 5 captures from the model fitted on the others",
        "calibrate photometric: writing ph",
    ];
    let lines: Vec<usize> = stages.iter().map(|s| at(s)).collect();
    assert!(lines.windows(2).all(|w| w[0] < w[1]), "{err}");
    // issue 102: which keys of the camera file were read
    assert!(
        text(&o.stdout).contains(
            "camera: camera_matrix (intrinsics), distortion_coefficients (distortion) read from cam.yaml"
        ),
        "{}",
        text(&o.stdout)
    );
    assert!(
        text(&o.stdout).contains("photometric model from 5 captures"),
        "{}",
        text(&o.stdout)
    );
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("ph/photometric.json")).unwrap())
            .unwrap();
    let caps = m["captures"].as_array().unwrap();
    assert_eq!(caps.len(), 5);
    for c in caps {
        // R-Tac0's pins (0.8 mm tips pressed 1.54 mm: the shaft enters the skin) shadow the
        // skin beside their imprints from the LED ring; with the shadow term the model fits
        // these five within about 2.2 counts and re-renders each from the other four within
        // about 2.8 (without it 3.7 and 4.1); the leave-one-out stays within a count of the
        // fit (no overfitting: about 0.55 apart); the re-renderings are judged from the files
        // below
        let loo = c["leave_one_out_rms_counts"].as_f64().unwrap();
        let fit = c["fit_rms_counts"].as_f64().unwrap();
        assert!(
            loo < fit + 1.0,
            "{}: {loo} grey levels RMS, fit {fit}",
            c["file"]
        );
        assert_eq!(c["pins"].as_array().unwrap().len(), 5);
    }
    // Issue 101: the report leads with the contact region: per capture the RMS within 15 px of
    // its imprints beside the whole skin's, and per imprint (named by its pin) the offset
    // between the centroids of the real and the re-rendered darkening, with their median
    let stdout = text(&o.stdout);
    eprintln!("{stdout}");
    let lead = stdout
        .find("within 15 px of the imprints")
        .unwrap_or(usize::MAX);
    assert!(
        lead < stdout.find("over the whole skin").unwrap_or(0),
        "{stdout}"
    );
    assert_eq!(
        m["contact_region"]
            .as_str()
            .map(|t| t.contains("reach_px = 15 px")),
        Some(true)
    );
    assert_eq!(m["gain"].as_str().map(|t| t.contains("30 px")), Some(true));
    for c in caps {
        let r = &c["contact_region"];
        assert_eq!(r["reach_px"].as_f64(), Some(15.0));
        let loo = r["leave_one_out_rms_counts"].as_f64().unwrap();
        let fit = r["fit_rms_counts"].as_f64().unwrap();
        let median = r["median_centroid_offset_px"].as_f64().unwrap();
        let imprints = r["imprints"].as_array().unwrap();
        let mut pins: Vec<&str> = imprints
            .iter()
            .map(|i| i["pin"].as_str().unwrap())
            .collect();
        pins.sort_unstable();
        let mut want: Vec<&str> = c["pins"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p.as_str().unwrap())
            .collect();
        want.sort_unstable();
        eprintln!(
            "{}: within 15 px {loo:.3} counts RMS (fit {fit:.3}), whole skin {:.3}; centroid offsets {:?} px, median {median:.3}",
            c["file"],
            c["leave_one_out_rms_counts"],
            imprints
                .iter()
                .map(|i| i["centroid_offset_px"].as_f64().unwrap())
                .collect::<Vec<_>>()
        );
        // one imprint per pin, each its own
        assert_eq!(pins, want, "{}", c["file"]);
        // as on the library's synthetic captures (calibration/tests/it/photometric.rs:
        // 4.4 to 4.7 counts within 15 px, centroids within 0.17 px); measured here 5.1 to 5.5
        // (fit 4.9 to 5.2; 2.5 over the whole skin), offsets up to 0.45 px and medians of
        // 0.12 to 0.21 px
        assert!(
            loo < 6.0 && fit <= loo + 0.5,
            "{}: {loo}, fit {fit}",
            c["file"]
        );
        assert!(median < 0.3, "{}: median offset {median} px", c["file"]);
        assert!(
            c["leave_one_out_gain"]
                .as_f64()
                .is_some_and(|g| (g - 1.0).abs() < 0.05),
            "{}",
            c["file"]
        );
    }
    // a reach that is no distance is refused naming the option, nothing written
    let mut bad = args(&names, "ph0");
    bad.extend(["--contact-reach-px", "0"]);
    let o = run(d.path(), &bad, &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("--contact-reach-px = 0: must be a distance from 1 to 100 px"),
        "{}",
        text(&o.stderr)
    );
    assert!(!d.path().join("ph0").exists());
    let appearance = read_npy_f32(&d.path().join("ph/appearance.npy"));
    assert_eq!(appearance.len(), 640 * 480 * 3);
    // Issue 96: the figures above are the command's own; the test computes them again from
    // the files: each capture against its re-rendering from the other four, over the skin
    // (where the appearance is not NaN), all channels, in counts
    let reference_png = image::open(d.path().join("ref.png")).unwrap().into_rgb8();
    for c in caps {
        let capture = image::open(d.path().join(c["file"].as_str().unwrap()))
            .unwrap()
            .into_rgb8();
        // the camera's noise in the capture (the re-rendering has none): from its difference
        // with the reference, a frame of independent noise, over the skin (1.4826 x the median
        // absolute difference over sqrt 2; the few pressed pixels do not move a median)
        let mut diff: Vec<f64> = capture
            .pixels()
            .zip(reference_png.pixels())
            .enumerate()
            .filter(|(k, _)| !appearance[3 * k].is_nan())
            .flat_map(|(_, (a, b))| {
                (0..3).map(move |ch| (f64::from(a[ch]) - f64::from(b[ch])).abs())
            })
            .collect();
        diff.sort_by(f64::total_cmp);
        let noise = 1.4826 * diff[diff.len() / 2] / 2f64.sqrt();
        let again = image::open(d.path().join("ph").join(c["rerendered"].as_str().unwrap()))
            .unwrap()
            .into_rgb8();
        assert_eq!(again.dimensions(), (640, 480));
        let (mut sq, mut n) = (0.0, 0usize);
        for (k, (a, b)) in capture.pixels().zip(again.pixels()).enumerate() {
            if appearance[3 * k].is_nan() {
                continue;
            }
            for ch in 0..3 {
                sq += (f64::from(a[ch]) - f64::from(b[ch])).powi(2);
                n += 1;
            }
        }
        let rms = (sq / n as f64).sqrt();
        let reported = c["leave_one_out_rms_counts"].as_f64().unwrap();
        // what the model misses, the noise taken out in quadrature: within an error budget of
        // 2.5 counts (1 % of full scale)
        let model = (rms * rms - noise * noise).max(0.0).sqrt();
        eprintln!(
            "{}: {rms:.3} counts RMS from the files ({reported:.3} reported), noise {noise:.3}, model {model:.3}",
            c["file"]
        );
        assert!(
            model < 2.5,
            "{}: {rms} counts RMS, noise {noise}",
            c["file"]
        );
        // the report's figure is of the unrounded re-rendering: within the rounding's
        // 1 / sqrt(12) count of the file's
        assert!(
            (rms - reported).abs() < 0.3,
            "{}: {rms} from the files, {reported} reported",
            c["file"]
        );
    }
    // A parameter the test chose, recovered: the third capture at 0.9 of its exposure (its
    // counts scaled and rounded, as a camera's gain drift would) is fitted with a gain 0.9 of
    // the first fit's, within the rounding's effect on a median ratio of counts near 100
    std::fs::create_dir(d.path().join("dim")).unwrap();
    let dimmed = image::open(d.path().join(&names[2])).unwrap().into_rgb8();
    let dimmed = image::RgbImage::from_fn(640, 480, |x, y| {
        image::Rgb(
            dimmed
                .get_pixel(x, y)
                .0
                .map(|v| (f64::from(v) * 0.9).round() as u8),
        )
    });
    dimmed.save(d.path().join("dim").join(&names[2])).unwrap();
    let mut with_dimmed = names.clone();
    with_dimmed[2] = format!("dim/{}", names[2]);
    let o = run(d.path(), &args(&with_dimmed, "phd"), &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let md: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("phd/photometric.json")).unwrap())
            .unwrap();
    let gain = |m: &serde_json::Value, k: usize| m["captures"][k]["gain"].as_f64().unwrap();
    let ratio = gain(&md, 2) / gain(&m, 2);
    eprintln!("gain ratio {ratio:.5}");
    assert!(
        (ratio - 0.9).abs() < 0.005,
        "gain ratio {ratio}, chosen 0.9"
    );
    for k in [0, 1, 3, 4] {
        assert!(
            (gain(&md, k) / gain(&m, k) - 1.0).abs() < 0.005,
            "capture {k}"
        );
    }
    assert_eq!(m["model"]["coefficients_rgb"].as_array().unwrap().len(), 3);

    // Issue 95, data loss: captures inside the folder a fit replaces (here its own re-rendered
    // captures) were deleted with it under --force. Refused before anything is written.
    let inside: Vec<String> = caps
        .iter()
        .map(|c| format!("ph/{}", c["rerendered"].as_str().unwrap()))
        .collect();
    let before = std::fs::read(d.path().join(&inside[0])).unwrap();
    let mut again = args(&inside, "ph");
    again.push("--force");
    let o = run(d.path(), &again, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stdout));
    let e = text(&o.stderr);
    assert!(
        e.contains(&format!(
            "{} is an input of this command and lies inside its output directory ph",
            inside[0]
        )),
        "{e}"
    );
    assert_eq!(std::fs::read(d.path().join(&inside[0])).unwrap(), before);

    // The ground truth's images in the sensor's own appearance: the reference is the fitted
    // appearance, a pressed frame differs from it where the protrusions press.
    let gt = |out: &str, ph: &str| {
        run(
            d.path(),
            &[
                "groundtruth",
                "rtac0",
                "--camera",
                "cam.yaml",
                "--extrinsics",
                "extrinsics.json",
                "--fixtures",
                "fx",
                "--format",
                "png",
                "--images",
                "--photometric",
                ph,
                "--out",
                out,
            ],
            &[],
        )
    };
    let o = gt("gt", "ph");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let reference = image::open(d.path().join("gt/reference/image.png"))
        .unwrap()
        .into_rgb8();
    for (i, p) in reference.pixels().enumerate() {
        for c in 0..3 {
            let a = appearance[3 * i + c];
            let want = if a.is_finite() {
                a.round().clamp(0.0, 255.0) as u8
            } else {
                0
            };
            assert_eq!(p[c], want, "pixel {i} channel {c}");
        }
    }
    let pressed = image::open(d.path().join("gt/p001_0/image.png"))
        .unwrap()
        .into_rgb8();
    let contact = image::open(d.path().join("gt/p001_0/contact_mask.png"))
        .unwrap()
        .into_luma8();
    // it differs on the contact and in the shadows beside it, nowhere else
    let touched: Vec<(f64, f64)> = (0..640 * 480)
        .filter(|&i| contact.as_raw()[i] > 0)
        .map(|i| ((i % 640) as f64, (i / 640) as f64))
        .collect();
    let (mut on, mut beside, mut far) = (0, 0, 0);
    for (i, (p, q)) in pressed.pixels().zip(reference.pixels()).enumerate() {
        if p == q {
            continue;
        }
        let (u, v) = ((i % 640) as f64, (i / 640) as f64);
        if contact.as_raw()[i] > 0 {
            on += 1;
        } else if touched.iter().any(|t| (t.0 - u).hypot(t.1 - v) < 20.0) {
            beside += 1;
        } else {
            far += 1;
        }
    }
    assert!(
        on > 100 && beside > 0 && far == 0,
        "{on} contact pixels differ, {beside} within 20 px of the contact, {far} farther"
    );
    let gm: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("gt/manifest.json")).unwrap()).unwrap();
    assert!(gm["images"]["model"]
        .as_str()
        .unwrap()
        .contains("photometric"));

    // Issue 95: a model used with another pose (or design, or camera) gave images with no
    // word; refused naming the file it was fitted with
    let mut pose: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("extrinsics.json")).unwrap()).unwrap();
    let t = pose["T_cam_sensor"][0][3].as_f64().unwrap();
    pose["T_cam_sensor"][0][3] = serde_json::json!(t + 0.5);
    let x = pose["tvec_mm"][0].as_f64().unwrap();
    pose["tvec_mm"][0] = serde_json::json!(x + 0.5);
    std::fs::write(
        d.path().join("moved.json"),
        serde_json::to_vec(&pose).unwrap(),
    )
    .unwrap();
    let o = run(
        d.path(),
        &[
            "groundtruth",
            "rtac0",
            "--camera",
            "cam.yaml",
            "--extrinsics",
            "moved.json",
            "--fixtures",
            "fx",
            "--format",
            "png",
            "--images",
            "--photometric",
            "ph",
            "--out",
            "gt3",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2));
    let e = text(&o.stderr);
    assert!(
        e.contains("the model was fitted with another extrinsics") && e.contains("moved.json"),
        "{e}"
    );
    assert!(!d.path().join("gt3").exists());

    // a model of another camera is refused naming the option, nothing written
    std::fs::create_dir(d.path().join("ph2")).unwrap();
    std::fs::copy(
        d.path().join("ph/photometric.json"),
        d.path().join("ph2/photometric.json"),
    )
    .unwrap();
    std::fs::write(
        d.path().join("ph2/appearance.npy"),
        fabkit_export::raster::npy_f32(&[2, 2, 3], &[0.0; 12]),
    )
    .unwrap();
    let o = gt("gt2", "ph2");
    assert!(!o.status.success());
    let e = text(&o.stderr);
    assert!(
        e.contains("--photometric") && e.contains("[480, 640, 3]"),
        "{e}"
    );
    assert!(!d.path().join("gt2").exists());
}

#[test]
fn a_capture_without_pins_in_its_name_is_refused_and_nothing_is_written() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let mut names = captures(d.path());
    std::fs::copy(d.path().join(&names[0]), d.path().join("capture.png")).unwrap();
    names[0] = "capture.png".into();
    let o = run(d.path(), &args(&names, "ph"), &[]);
    assert!(!o.status.success());
    let e = text(&o.stderr);
    assert!(
        e.contains("--images = capture.png") && e.contains("ring order"),
        "{e}"
    );
    assert!(!d.path().join("ph").exists());
    // a pin that is not in the point table
    std::fs::copy(d.path().join("capture.png"), d.path().join("01_99.png")).unwrap();
    names[0] = "01_99.png".into();
    let o = run(d.path(), &args(&names, "ph"), &[]);
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("pin 99 is not in"),
        "{}",
        text(&o.stderr)
    );
    assert!(!d.path().join("ph").exists());
    // Issue 95: a pin listed twice, the same capture twice, two files of the same pins: the
    // fit ran to its end, then failed on a file that existed. Refused up front.
    let names = captures(d.path());
    let first = names[0].clone();
    std::fs::copy(d.path().join(&first), d.path().join("01_01_01_01_01.png")).unwrap();
    std::fs::create_dir(d.path().join("sub")).unwrap();
    std::fs::copy(d.path().join(&first), d.path().join("sub").join(&first)).unwrap();
    for (extra, message) in [
        (
            // issue 102: a folder of captures given as one, named as a folder
            vec!["sub".to_string()],
            "--images = sub: is a folder, not an image: give the capture images themselves (as sub/*.png".to_string(),
        ),
        (
            vec!["01_01_01_01_01.png".to_string()],
            "--images = 01_01_01_01_01.png: pin 1 listed 5 times".to_string(),
        ),
        (
            vec![first.clone()],
            format!("--images = {first}: given twice"),
        ),
        (
            vec![format!("./{first}")],
            format!("--images = ./{first}: given twice"),
        ),
        (
            vec![format!("sub/{first}")],
            format!("--images = sub/{first}: given twice (as {first}, the same pins)"),
        ),
    ] {
        let mut images = names.clone();
        images.extend(extra);
        let o = run(d.path(), &args(&images, "ph"), &[]);
        assert_eq!(o.status.code(), Some(2), "{images:?}");
        assert!(
            text(&o.stderr).contains(&message),
            "{message}: {}",
            text(&o.stderr)
        );
        assert!(!d.path().join("ph").exists());
    }
    // Issue 95: R-Tac0's pin dome with another design was fitted anyway; refused as
    // groundtruth refuses it
    let o = run(d.path(), &["show", "rtac0", "--out", "other.yaml"], &[]);
    assert!(o.status.success());
    let yaml = std::fs::read_to_string(d.path().join("other.yaml")).unwrap();
    std::fs::write(
        d.path().join("other.yaml"),
        yaml.replace("name: rtac0", "name: other"),
    )
    .unwrap();
    let mut other = args(&names, "ph");
    other[2] = "other.yaml";
    let o = run(d.path(), &other, &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("the pin dome was made for another design than 'other'"),
        "{}",
        text(&o.stderr)
    );
    assert!(!d.path().join("ph").exists());
}

/// Issue 95: a 16384 x 16384 camera (allowed by the camera rule) made `calibrate photometric`
/// allocate its per-pixel arrays before anything else: exit 134 at 3.9 GB. Under a 2 GB
/// address-space limit it now exits 2 naming the camera file and the pixel limit, before
/// reading a capture, and writes nothing.
#[test]
fn a_camera_past_the_pixel_limit_is_refused_before_allocating_under_a_2_gb_limit() {
    use fabkit_calibration::{write_camera, CameraFileFormat};
    let d = tempfile::tempdir().unwrap();
    let mut i = benchmark_intrinsics();
    let side = 16384u32;
    (i.image_width_px, i.image_height_px) = (side, side);
    (i.cx_px, i.cy_px) = (side as f64 / 2.0 - 0.5, side as f64 / 2.0 - 0.5);
    std::fs::write(
        d.path().join("cam.yaml"),
        write_camera(&i, CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    std::fs::write(
        d.path().join("extrinsics.json"),
        r#"{"rvec": [0, 0, 0], "tvec_mm": [0, 0, 10]}"#,
    )
    .unwrap();
    let names = vec!["01_02.png".to_string(), "01_03.png".to_string()];
    let o = run_limited(d.path(), &args(&names, "ph"), &[], 2_000_000);
    let e = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("cam.yaml: the camera image is 16384 x 16384 = 268435456 pixels, over the limit of 4194304 pixels"),
        "{e}"
    );
    assert!(!d.path().join("ph").exists());
}

/// Issue 95: captures that are copies of the reference, all black or all white "fitted within
/// 0.00 counts RMS" to an all-zero model with exit 0. Each is refused by file with what it
/// lacks, before the fit, with nothing written; a black reference is refused as dark; the
/// real captures beside them fit.
#[test]
fn a_capture_that_shows_no_imprint_is_refused_by_file() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let names = captures(d.path());
    let reference = image::open(d.path().join("ref.png")).unwrap().to_rgb8();
    let (w, h) = reference.dimensions();
    let flat = |v: u8| image::RgbImage::from_pixel(w, h, image::Rgb([v, v, v]));
    // the reference pressed nowhere (its exact copy), and the same with one count of noise
    // (an unpressed frame): no imprint at the pins
    let mut noisy = reference.clone();
    for (k, p) in noisy.pixels_mut().enumerate() {
        let step = [0u8, 1, 0, 2][k % 4];
        p.0 = p.0.map(|x| x.saturating_add(step).saturating_sub(1));
    }
    for (image, message) in [
        (reference.clone(), "no imprint at its pins"),
        (noisy, "no imprint at its pins"),
        (flat(0), "dark"),
        (flat(255), "saturated"),
    ] {
        let mut images = names.clone();
        image.save(d.path().join(&images[2])).unwrap();
        images.truncate(3);
        let says = format!("--images = {}: {message}", images[2]);
        refused(d.path(), &args(&images, "ph"), &says, "ph");
    }
    // every capture a copy of the reference: no fit from no imprint
    for n in &names[..2] {
        reference.save(d.path().join(n)).unwrap();
    }
    refused(
        d.path(),
        &args(&names[..2], "ph"),
        "no imprint at its pins",
        "ph",
    );
    // a black reference
    let names = captures(d.path());
    flat(0).save(d.path().join("ref.png")).unwrap();
    refused(
        d.path(),
        &args(&names, "ph"),
        "--reference = ref.png: dark",
        "ph",
    );
}

/// `fabkit ARGV` in `dir` exits 2 saying `says`, and `out` is not there.
#[track_caller]
fn refused(dir: &Path, argv: &[&str], says: &str, out: &str) {
    let o = run(dir, argv, &[]);
    let e = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{says}: {e}");
    assert!(e.contains(says), "{says}: {e}");
    assert!(!dir.join(out).exists(), "{says}: {out} written");
}

/// Issue 95: R-Tac0's pin dome with a design of the same name whose skin is R15.3 (not 15.0)
/// was fitted by `calibrate photometric`: the fixtures were matched by name only. Both
/// commands that press the dome's pins now check its geometry: each pin's recorded contact
/// point must be where its axis meets this design's skin. Refused naming the point table's
/// line and the distance, with nothing written; the R15.0 design still passes.
#[test]
fn a_pin_dome_of_another_skin_under_the_same_name_is_refused() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let names = captures(d.path());
    let o = run(d.path(), &["show", "rtac0", "--out", "r153.yaml"], &[]);
    assert!(o.status.success());
    let yaml = std::fs::read_to_string(d.path().join("r153.yaml")).unwrap();
    let yaml = yaml
        .replacen("  radius_mm: 15.0", "  radius_mm: 15.3", 1)
        .replacen("outer_radius_mm: 15.0", "outer_radius_mm: 15.3", 1);
    assert!(yaml.contains("name: rtac0"));
    std::fs::write(d.path().join("r153.yaml"), yaml).unwrap();
    let mut photometric = args(&names, "ph");
    photometric[2] = "r153.yaml";
    let groundtruth = [
        "groundtruth",
        "r153.yaml",
        "--camera",
        "cam.yaml",
        "--extrinsics",
        "extrinsics.json",
        "--fixtures",
        "fx",
        "--pin-captures",
        "--out",
        "gt",
    ];
    for (argv, out) in [(&photometric[..], "ph"), (&groundtruth[..], "gt")] {
        let o = run(d.path(), argv, &[]);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{argv:?}: {e}");
        assert!(
            e.contains("point_table.csv")
                && e.contains("line 2 contact_mm")
                && e.contains("lies 0.3000 mm from where pin 1's axis meets the design's skin")
                && e.contains("built for another skin"),
            "{e}"
        );
        assert!(!d.path().join(out).exists());
    }
    let o = run(
        d.path(),
        &groundtruth.map(|a| if a == "r153.yaml" { "rtac0" } else { a }),
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// The geometry check above holds for every library pin dome against its own design: each
/// pin's contact point lies on the design's closed-form skin within a micron (the dome is
/// built from that surface), so the check refuses no dome built from its design.
#[test]
fn every_library_pin_dome_lies_on_its_designs_skin() {
    use fabkit_calibration::groundtruth::pins::{check_on_skin, read_pins};
    use fabkit_calibration::groundtruth::surface::ReferenceSurface;
    let d = tempfile::tempdir().unwrap();
    for name in ["rtac0", "uvdtact", "shadowtac", "digit_pinki"] {
        let o = run(
            d.path(),
            &[
                "fixtures",
                name,
                "--semidomes",
                "0",
                "--format",
                "stl",
                "--out",
                name,
            ],
            &[],
        );
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let design = fabkit_designs::library::load(name).unwrap();
        let surface = ReferenceSurface::of(&design.body).unwrap();
        let dir = d.path().join(name);
        let pins = read_pins(&dir).unwrap();
        assert!(pins.rows.len() >= 5, "{name}: {} pins", pins.rows.len());
        check_on_skin(&dir, &pins, &surface).unwrap_or_else(|e| panic!("{name}: {e}"));
        // and a skin 0.01 mm larger is another skin
        let larger = match surface {
            ReferenceSurface::Cap {
                radius_mm,
                base_z_mm,
            } => ReferenceSurface::Cap {
                radius_mm: radius_mm + 0.01,
                base_z_mm,
            },
            ReferenceSurface::HemisphereOnCylinder {
                radius_mm,
                base_z_mm,
            } => ReferenceSurface::HemisphereOnCylinder {
                radius_mm: radius_mm + 0.01,
                base_z_mm,
            },
            ReferenceSurface::HalfEllipsoid { a_mm, c_mm } => ReferenceSurface::HalfEllipsoid {
                a_mm: a_mm + 0.01,
                c_mm: c_mm + 0.01,
            },
            ReferenceSurface::Flat { .. } => panic!("{name}: a pin dome on a flat skin"),
        };
        assert!(check_on_skin(&dir, &pins, &larger).is_err(), "{name}");
    }
}

/// Issue 95, done when: `calibrate photometric` fits a model under a 2 GB address-space limit,
/// and `groundtruth --images --photometric` reads it with every numeric field of its model
/// (the first and last number of each list) set to 0, -1, 1e-300, 1e300, NaN and infinity (as
/// Python's json writes them), one at a time, and with a skin pixel of its appearance.npy set
/// to each: each run exits 2 naming the file and the field, or renders its frames; none
/// panics, aborts or exits otherwise, and no refused run leaves its output folder.
#[test]
fn every_model_value_is_refused_by_name_or_renders_under_a_2_gb_limit() {
    const LIMIT_KIB: u64 = 2 << 20;
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let names = captures(d.path());
    let o = run_limited(d.path(), &args(&names, "ph"), &[], LIMIT_KIB);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("ph/photometric.json")).unwrap())
            .unwrap();
    // every numeric leaf of the model, lists by their first and last number
    fn leaves(v: &serde_json::Value, path: Vec<String>, out: &mut Vec<Vec<String>>) {
        match v {
            serde_json::Value::Number(_) => out.push(path),
            serde_json::Value::Object(m) => {
                for (k, x) in m {
                    let mut p = path.clone();
                    p.push(k.clone());
                    leaves(x, p, out);
                }
            }
            serde_json::Value::Array(a) => {
                let mut ends = vec![0];
                if a.len() > 1 {
                    ends.push(a.len() - 1);
                }
                for i in ends {
                    let mut p = path.clone();
                    p.push(i.to_string());
                    leaves(&a[i], p, out);
                }
            }
            _ => {}
        }
    }
    let mut fields = Vec::new();
    leaves(&record["model"], vec!["model".into()], &mut fields);
    assert!(fields.len() >= 30, "{}", fields.len());
    let appearance = std::fs::read(d.path().join("ph/appearance.npy")).unwrap();
    let values = ["0", "-1", "1e-300", "1e300", "NaN", "Infinity"];
    // one semi-dome pattern: the reference and two frames per run
    let o = run(
        d.path(),
        &[
            "fixtures",
            "rtac0",
            "--semidomes",
            "1",
            "--seed",
            "3",
            "--format",
            "stl",
            "--out",
            "fx1",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let mut outcomes = (0, 0);
    let mut check = |dir: &str, field: &str, what: &str| {
        let o = run_limited(
            d.path(),
            &[
                "groundtruth",
                "rtac0",
                "--camera",
                "cam.yaml",
                "--extrinsics",
                "extrinsics.json",
                "--fixtures",
                "fx1",
                "--format",
                "png",
                "--images",
                "--photometric",
                dir,
                "--out",
                "gt",
            ],
            &[],
            LIMIT_KIB,
        );
        let e = text(&o.stderr);
        match o.status.code() {
            Some(0) => {
                assert!(d.path().join("gt/reference/image.png").is_file(), "{what}");
                std::fs::remove_dir_all(d.path().join("gt")).unwrap();
                outcomes.0 += 1;
            }
            Some(2) => {
                assert!(e.contains(field), "{what}: {e}");
                assert!(!d.path().join("gt").exists(), "{what}");
                outcomes.1 += 1;
            }
            c => panic!("{what}: exit {c:?}: {e}"),
        }
    };
    for path in &fields {
        // the message names the model's key (and the file)
        let key: Vec<&str> = path
            .iter()
            .map(String::as_str)
            .filter(|k| k.parse::<usize>().is_err())
            .take(2)
            .collect();
        for v in values {
            let mut bad = record.clone();
            let mut at = &mut bad;
            for p in path {
                at = match p.parse::<usize>() {
                    Ok(i) => &mut at[i],
                    Err(_) => &mut at[p.as_str()],
                };
            }
            *at = serde_json::json!("__VALUE__");
            let body = serde_json::to_string_pretty(&bad)
                .unwrap()
                .replace("\"__VALUE__\"", v);
            let dir = d.path().join("bad");
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir(&dir).unwrap();
            std::fs::write(dir.join("photometric.json"), body).unwrap();
            std::fs::write(dir.join("appearance.npy"), &appearance).unwrap();
            check(
                "bad",
                &format!("photometric.json: {}", key.join(".")),
                &format!("{path:?} = {v}"),
            );
        }
    }
    // a pixel of the skin in appearance.npy
    let (shape, mut data) = fabkit_export::raster::read_npy_f32(&appearance).unwrap();
    let k = data.iter().position(|x| x.is_finite()).unwrap();
    for v in [0.0f32, -1.0, 1e-30, f32::MAX, f32::NAN, f32::INFINITY] {
        data[k + 1] = v;
        let dir = d.path().join("bad");
        std::fs::write(
            dir.join("photometric.json"),
            serde_json::to_vec(&record).unwrap(),
        )
        .unwrap();
        std::fs::write(
            dir.join("appearance.npy"),
            fabkit_export::raster::npy_f32(&shape, &data),
        )
        .unwrap();
        check("bad", "appearance.npy: pixel", &format!("appearance = {v}"));
    }
    eprintln!("{} rendered, {} refused by name", outcomes.0, outcomes.1);
    assert!(outcomes.1 > outcomes.0, "{outcomes:?}");
}

/// The point table of `from`'s pin dome turned by `deg` about the sensor's z axis (tips and
/// axes), written as `to`'s (a copy of the fixtures folder): R-Tac0's skin is round about that
/// axis, so the turned pins press it as deep as before, a dome seated a little turned.
fn turned_fixtures(dir: &Path, from: &str, to: &str, deg: f64) {
    let (src, dst) = (dir.join(from), dir.join(to));
    for entry in walk(&src) {
        let rel = entry.strip_prefix(&src).unwrap();
        std::fs::create_dir_all(dst.join(rel).parent().unwrap()).unwrap();
        std::fs::copy(&entry, dst.join(rel)).unwrap();
    }
    let table = std::fs::read_to_string(src.join("points/point_table.csv")).unwrap();
    let mut lines = table.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').map(str::trim).collect();
    let col = |name: &str| head.iter().position(|c| *c == name).unwrap();
    let (c, s) = (deg.to_radians().cos(), deg.to_radians().sin());
    let mut out = vec![head.join(",")];
    for line in lines {
        let mut cells: Vec<String> = line.split(',').map(str::to_string).collect();
        // every point and direction of the row: each x column with its y
        let pairs = head
            .iter()
            .filter(|h| h.contains("_x"))
            .map(|h| (col(h), col(&h.replacen("_x", "_y", 1))));
        for (i, j) in pairs {
            let (a, b): (f64, f64) = (cells[i].parse().unwrap(), cells[j].parse().unwrap());
            cells[i] = format!("{:.9}", c * a - s * b);
            cells[j] = format!("{:.9}", s * a + c * b);
        }
        out.push(cells.join(","));
    }
    std::fs::write(dst.join("points/point_table.csv"), out.join("\n") + "\n").unwrap();
}

fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// Issue 101: each capture's dome is seated from its own imprints. Of five synthetic R-Tac0
/// pin captures, the second and fourth are rendered with the dome turned 1.5 deg about the
/// skin's axis (its pins 0.1 to 0.3 mm along the skin); `calibrate photometric` with the
/// dome where the extrinsics put it finds those two turned 1.5 deg about z (within 0.15 deg,
/// the other rotations and the translation held near 0 by the prior: within 0.2 deg and 0.05
/// mm), the other three not turned (within 0.15 deg), and re-renders every capture with its
/// imprints' centroids within 0.3 px (median) as for unturned captures; with `--no-seating`
/// the turned captures' centroids are more than a pixel off.
#[test]
fn each_captures_dome_is_seated_from_its_imprints() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    // R-Tac0 with an opaque coat shaded by its slope (its optics section left out): the
    // pins' imprints sharp. R-Tac0's own darkness-mapping skin darkens 0.11 of its grey under
    // a 0.5 mm pin, and the seating finds half of the 1.5 deg turn from such faint imprints
    let library = std::fs::read_to_string(repo_root().join("designs/library/rtac0.yaml")).unwrap();
    let (head, rest) = library.split_once("\noptics:\n").unwrap();
    let (_, tail) = rest.split_once("\n\n").unwrap();
    std::fs::write(d.path().join("coat.yaml"), format!("{head}\n{tail}")).unwrap();
    let names = captures_in(d.path(), "coat.yaml");
    turned_fixtures(d.path(), "fx", "fx_turned", 1.5);
    let o = pin_captures_in(d.path(), "coat.yaml", "fx_turned", "caps_turned", "png");
    assert!(o.status.success(), "{}", text(&o.stderr));
    for name in [&names[1], &names[3]] {
        let folder = name.trim_end_matches(".png");
        std::fs::copy(
            d.path().join("caps_turned").join(folder).join("image.png"),
            d.path().join(name),
        )
        .unwrap();
    }
    let read = |out: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(d.path().join(out).join("photometric.json")).unwrap())
            .unwrap()
    };
    let o = run(d.path(), &args_in("coat.yaml", &names, "seated"), &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    eprintln!("{}", text(&o.stdout));
    assert!(
        text(&o.stdout).contains("dome seated"),
        "{}",
        text(&o.stdout)
    );
    let m = read("seated");
    assert!(m["seating"].as_str().unwrap().contains("Gaussian prior"));
    for (k, c) in m["captures"].as_array().unwrap().iter().enumerate() {
        let s = &c["seating"];
        let rot: Vec<f64> = (0..3)
            .map(|i| s["rotation_deg"][i].as_f64().unwrap())
            .collect();
        let shift: f64 = (0..3)
            .map(|i| s["translation_mm"][i].as_f64().unwrap().powi(2))
            .sum::<f64>()
            .sqrt();
        let median = c["contact_region"]["median_centroid_offset_px"]
            .as_f64()
            .unwrap();
        eprintln!(
            "{}: rotation {rot:?} deg, shift {shift:.4} mm, median offset {median:.3} px",
            c["file"]
        );
        let turn = if k == 1 || k == 3 { 1.5 } else { 0.0 };
        assert!((rot[2] - turn).abs() < 0.15, "{}: {rot:?}", c["file"]);
        assert!(
            rot[0].abs() < 0.2 && rot[1].abs() < 0.2,
            "{}: {rot:?}",
            c["file"]
        );
        assert!(shift < 0.05, "{}: {shift} mm", c["file"]);
        assert_eq!(s["bounded"], false);
        assert!(median < 0.3, "{}: {median} px", c["file"]);
    }
    let mut plain = args_in("coat.yaml", &names, "unseated");
    plain.push("--no-seating");
    let o = run(d.path(), &plain, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (m, seated) = (read("unseated"), read("seated"));
    for k in [1, 3] {
        let c = &m["captures"][k];
        let median = c["contact_region"]["median_centroid_offset_px"]
            .as_f64()
            .unwrap();
        assert!(median > 1.0, "{}: {median} px", c["file"]);
        assert_eq!(c["seating"]["rotation_deg"][2].as_f64(), Some(0.0));
        // and the imprints re-render better seated (measured 6.5 and 8.3 counts RMS within
        // 15 px, leave-one-out, against 19.2 and 19.6 unseated)
        let rms = |m: &serde_json::Value| {
            m["captures"][k]["contact_region"]["leave_one_out_rms_counts"]
                .as_f64()
                .unwrap()
        };
        assert!(
            rms(&seated) < 0.6 * rms(&m),
            "{} against {}",
            rms(&seated),
            rms(&m)
        );
    }
}

/// Captures given where `fabkit groundtruth --pin-captures --images` wrote them
/// (`caps/01_02_06_14_22/image.png`): each takes its pins from its folder's name and its
/// re-rendered image is named by it.
#[test]
fn captures_in_their_ground_truth_folders_are_named_by_them() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let names = captures(d.path());
    let folders: Vec<String> = names[..3]
        .iter()
        .map(|n| format!("caps/{}/image.png", n.trim_end_matches(".png")))
        .collect();
    let mut a = args(&folders, "ph");
    let r = a.iter().position(|x| *x == "ref.png").unwrap();
    a[r] = "caps/reference/image.png";
    let o = run(d.path(), &a, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    for n in &names[..3] {
        assert!(d.path().join("ph/rerendered").join(n).is_file(), "{n}");
    }
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("ph/photometric.json")).unwrap())
            .unwrap();
    assert_eq!(m["captures"][0]["file"], folders[0].as_str());
}
