//! `fabkit groundtruth --images` end to end (R-Tac0, 2 patterns): an RGB image per frame on
//! the depth maps' pixel grid, the same bytes with 1 and 2 threads, the exposure set on the
//! reference, the imprint where the contact mask is and nowhere else, counted in the output
//! bound, the lights and what is not modelled in the manifest, and bad optics refused by their
//! path with nothing written.

use std::path::Path;

use crate::common::*;
use crate::groundtruth_cli::setup;

fn images(dir: &Path, out: &str, threads: &str, design: &str) -> std::process::Output {
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
            "fx",
            "--format",
            "png",
            "--images",
            "--out",
            out,
        ],
        &[("RAYON_NUM_THREADS", threads)],
    )
}

fn rgb(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .into_rgb8()
}

fn gray(path: &Path) -> image::GrayImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .into_luma8()
}

#[test]
fn every_frame_gets_its_image_the_same_bytes_with_any_thread_count() {
    let (d1, d2) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    setup(d1.path());
    setup(d2.path());
    let o = images(d1.path(), "gt", "1", "rtac0");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let o = images(d2.path(), "gt", "2", "rtac0");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (a, b) = (d1.path().join("gt"), d2.path().join("gt"));
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("manifest.json")).unwrap()).unwrap();
    let dirs: Vec<String> = std::iter::once("reference".to_string())
        .chain(
            m["configurations"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| c["dir"].as_str().unwrap().to_string()),
        )
        .collect();
    assert_eq!(dirs.len(), 5);
    for d in &dirs {
        let f = format!("{d}/image.png");
        assert_eq!(
            std::fs::read(a.join(&f)).unwrap(),
            std::fs::read(b.join(&f)).unwrap(),
            "{f}: other bytes with 2 threads"
        );
    }

    // The manifest: R-Tac0's eight LEDs from its housing, the exposure set on the reference,
    // what is left out.
    let im = &m["images"];
    let lights = im["lights"].as_array().unwrap();
    assert_eq!(lights.len(), 8);
    assert!(lights.iter().all(|l| l["source"] == "housing"));
    assert!(im["gain"].as_f64().unwrap() > 0.0);
    assert!(im["exposure"].as_str().unwrap().contains("reference"));
    for gap in ["refraction", "penumbrae", "deformation"] {
        assert!(im["not_modelled"].as_str().unwrap().contains(gap), "{gap}");
    }
    let files = m["files"].as_array().unwrap();
    let entry = |f: &str| files.iter().find(|e| e["file"] == f).unwrap().clone();
    for d in &dirs {
        let e = entry(&format!("{d}/image.png"));
        let bytes = std::fs::read(a.join(format!("{d}/image.png"))).unwrap();
        assert_eq!(e["bytes"].as_u64().unwrap(), bytes.len() as u64);
    }

    // Same grid as the depth maps; black where the ray misses the skin, the exposure puts the
    // reference's bright pixels at 0.8 of full scale.
    let reference = rgb(&a.join("reference/image.png"));
    let range = gray(&a.join("reference/range_preview.png"));
    assert_eq!(reference.dimensions(), (640, 480));
    let mask = gray(&a.join("right_mask.png"));
    let left = gray(&a.join("left_mask.png"));
    let on_skin = |x: u32, y: u32| mask.get_pixel(x, y)[0] > 0 || left.get_pixel(x, y)[0] > 0;
    let (mut off, mut on): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    for (x, y, p) in reference.enumerate_pixels() {
        let v = f64::from(p[1]);
        if on_skin(x, y) {
            on.push(v);
        } else if range.get_pixel(x, y)[0] == 0 {
            off.push(v);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    // measured 1.1e-5
    assert!(mean(&off) < 1.0, "off the skin: {}", mean(&off));
    on.sort_by(f64::total_cmp);
    let p99 = on[(on.len() as f64 * 0.99) as usize];
    // measured 204 (= 0.8 x 255, the exposure's target, to the count)
    assert!((p99 - 0.8 * 255.0).abs() <= 6.0, "99th percentile {p99}");

    // The imprint: the indented frame differs from the reference by the noise away from the
    // contact, and by much more on it.
    let cfg = &dirs[1];
    let pressed = rgb(&a.join(format!("{cfg}/image.png")));
    let contact = gray(&a.join(format!("{cfg}/contact_mask.png")));
    let (mut d_on, mut d_off) = (Vec::new(), Vec::new());
    for (x, y, p) in pressed.enumerate_pixels() {
        if !on_skin(x, y) {
            continue;
        }
        let d = (f64::from(p[1]) - f64::from(reference.get_pixel(x, y)[1])).abs();
        if contact.get_pixel(x, y)[0] > 0 {
            d_on.push(d);
        } else {
            d_off.push(d);
        }
    }
    // measured 1,215 contact pixels; a mean change of 35.9 there and 2.3 away
    assert!(d_on.len() > 100, "{} contact pixels", d_on.len());
    // photon noise of a pixel at 0.5 of full scale, 10^4 electrons: sigma 0.7 %, 1.8 counts;
    // the difference of two frames sqrt(2) times that
    assert!(
        mean(&d_off) < 3.0,
        "away from the contact: {}",
        mean(&d_off)
    );
    assert!(
        mean(&d_on) > 4.0 * mean(&d_off),
        "on the contact {} against {} away",
        mean(&d_on),
        mean(&d_off)
    );

    // Counted in the output bound.
    let bytes: u64 = files
        .iter()
        .map(|f| f["bytes"].as_u64().unwrap())
        .sum::<u64>()
        + std::fs::metadata(a.join("manifest.json")).unwrap().len();
    let (n_files, bound) = fabkit::calibration::groundtruth::dataset::output_bound(
        640,
        480,
        4,
        2,
        fabkit::calibration::groundtruth::dataset::DataFormat::Png,
        Some(8),
    );
    assert_eq!(files.len() as u64 + 1, n_files);
    assert!(bytes <= bound, "{bytes} bytes over the bound {bound}");
}

/// The library's R-Tac0 with its `optics` section replaced by `optics:` and the lines `extra`.
fn rtac0_with_optics(extra: &str) -> String {
    let base = std::fs::read_to_string(repo_root().join("designs/library/rtac0.yaml")).unwrap();
    let (head, rest) = base
        .split_once("\noptics:\n")
        .expect("rtac0.yaml has optics");
    let (_, tail) = rest
        .split_once("\n\n")
        .expect("a blank line ends the section");
    format!("{head}\n{tail}\noptics:\n{extra}")
}

/// Another seed, 16 bits, a given gain: other noise, 16-bit PNGs, the gain as given.
#[test]
fn the_design_sets_seed_bit_depth_and_gain() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let design = |extra: &str| rtac0_with_optics(extra);
    write_design(
        &d.path().join("a.yaml"),
        &design("  camera:\n    seed: 1\n"),
        SchemaVerdict::Accepts,
    );
    write_design(
        &d.path().join("b.yaml"),
        &design("  camera:\n    seed: 2\n    bit_depth: 16\n    gain: 20.0\n"),
        SchemaVerdict::Accepts,
    );
    for (f, out) in [("a.yaml", "ga"), ("b.yaml", "gb")] {
        let o = images(d.path(), out, "2", f);
        assert!(o.status.success(), "{f}: {}", text(&o.stderr));
    }
    let a = image::open(d.path().join("ga/reference/image.png")).unwrap();
    let b = image::open(d.path().join("gb/reference/image.png")).unwrap();
    assert_eq!(a.color(), image::ColorType::Rgb8);
    assert_eq!(b.color(), image::ColorType::Rgb16);
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("gb/manifest.json")).unwrap()).unwrap();
    assert_eq!(m["images"]["gain"].as_f64(), Some(20.0));
    assert!(m["images"]["exposure"]
        .as_str()
        .unwrap()
        .contains("optics.camera.gain"));
}

/// Each bad optics value is refused by its path before anything is written.
#[test]
fn bad_optics_are_refused_by_path_and_nothing_is_written() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    for (i, (extra, path)) in [
        ("  surface:\n    roughness: 0\n", "optics.surface.roughness"),
        ("  camera:\n    bit_depth: 12\n", "optics.camera.bit_depth"),
        ("  lights: []\n", "optics.lights"),
    ]
    .into_iter()
    .enumerate()
    {
        let f = format!("bad{i}.yaml");
        std::fs::write(d.path().join(&f), rtac0_with_optics(extra)).unwrap();
        let out = format!("gt{i}");
        let o = images(d.path(), &out, "2", &f);
        assert!(!o.status.success(), "{path}");
        assert!(
            text(&o.stderr).contains(path),
            "{path}: {}",
            text(&o.stderr)
        );
        assert!(!d.path().join(&out).exists(), "{path}: {out} written");
    }
}

/// The pins of a real `fabkit fixtures` folder (R-Tac0's published pin dome) as the
/// photometric fit reads them: 29 pins, each tip on the skin's sphere (R = 15 mm about the
/// origin) pushed in by its indentation depth along its axis, which is radial; the pin's tip
/// radius and shaft from the manifest.
#[test]
fn the_photometric_fit_reads_the_pins_of_a_fixtures_folder() {
    let d = tempfile::tempdir().unwrap();
    setup(d.path());
    let pins = fabkit_calibration::photometric::read_pins(&d.path().join("fx")).unwrap();
    assert_eq!(pins.rows.len(), 29);
    let table = std::fs::read_to_string(d.path().join("fx/points/point_table.csv")).unwrap();
    let depth: f64 = table
        .lines()
        .nth(1)
        .unwrap()
        .rsplit(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    for (id, tip, axis) in &pins.rows {
        let r = tip.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((r - (15.0 - depth)).abs() < 1e-6, "pin {id}: |tip| = {r}");
        for k in 0..3 {
            assert!(
                (axis[k] - tip[k] / r).abs() < 1e-6,
                "pin {id}: axis {axis:?}"
            );
        }
    }
    assert!(pins.tip_radius_mm > 0.0 && pins.shaft_radius_mm >= pins.tip_radius_mm);
    assert!(pins.length_mm > depth);
}
