//! The user guide's tutorial (docs/src/tutorial.md) runs as written: every `sh` block, in
//! order, in one empty folder, with `fabkit` on the PATH and no other file: fabkit makes the
//! camera file and the pin captures the calibration reads (`calibrate nominal`, `groundtruth
//! --pin-captures --images`). The results are then checked: the design the tutorial writes
//! has its markers, the calibration finds the pins in the rendered captures and recovers the
//! camera they were rendered from, the ground truth and the sweep are complete.

use crate::common::{design_schema_path, repo_root, schema_check, text};
use std::path::Path;

/// The `sh` blocks of the tutorial's Markdown, in order.
fn steps(markdown: &str) -> Vec<String> {
    let mut steps = Vec::new();
    let mut block: Option<String> = None;
    for line in markdown.lines() {
        match &mut block {
            Some(b) if line.starts_with("```") => {
                steps.push(std::mem::take(b));
                block = None;
            }
            Some(b) => {
                b.push_str(line);
                b.push('\n');
            }
            None if line == "```sh" => block = Some(String::new()),
            None => {}
        }
    }
    steps
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn the_tutorial_runs_as_written() {
    let markdown = std::fs::read_to_string(repo_root().join("docs/src/tutorial.md")).unwrap();
    let steps = steps(&markdown);
    assert!(steps.len() >= 11, "{} sh blocks", steps.len());
    assert!(
        !markdown.contains("tutorial-test"),
        "no step is done by the test in the reader's place"
    );
    let bin = Path::new(env!("CARGO_BIN_EXE_fabkit"));
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for script in &steps {
        let o = std::process::Command::new("bash")
            .args(["-euo", "pipefail", "-c", script])
            .current_dir(dir)
            .env("PATH", &path)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "tutorial block failed:\n{script}\nstdout:\n{}\nstderr:\n{}",
            text(&o.stdout),
            text(&o.stderr)
        );
    }

    // Steps 2 and 3: the design is the tutorial's, with 1 + 6 (1 + 2 + ... + 6) = 127 dimples.
    let manifest = json(&dir.join("out/my_sensor/manifest.json"));
    let design = std::fs::read_to_string(dir.join("my_sensor.yaml")).unwrap();
    assert!(design.contains("name: my_sensor\n"), "{design}");
    // Step 1: the template's modeline names the schema written beside it, which is the
    // committed one, and the edited design is valid under it.
    assert!(design.starts_with("# yaml-language-server: $schema=design.schema.json\n"));
    assert_eq!(
        std::fs::read(dir.join("design.schema.json")).unwrap(),
        std::fs::read(design_schema_path()).unwrap()
    );
    if let Some((valid, out)) = schema_check(&[dir.join("my_sensor.yaml")]) {
        assert!(valid, "{out}");
    }
    assert!(manifest.to_string().contains("my_sensor"));
    // Steps 3 and 5: the dimples under the coat are formed by the translucent layer's master
    // pattern, 0.4 mm formers (0.6 mm less the 0.1 mm coat all round), and the sheet says so.
    let markers = manifest["summary"]["markers"].as_array().unwrap();
    assert_eq!(markers.len(), 1, "{markers:?}");
    assert_eq!(markers[0]["count"], 127);
    assert_eq!(
        markers[0]["formed_by"],
        serde_json::json!(["translucent_gel_master_pattern"])
    );
    assert!((markers[0]["former_diameter_mm"].as_f64().unwrap() - 0.4).abs() < 1e-9);
    let sheet = std::fs::read_to_string(dir.join("out/my_sensor/FABRICATION.md")).unwrap();
    assert!(
        sheet.contains("translucent_gel_master_pattern: 127 dimple formers, 0.400 mm"),
        "{sheet}"
    );
    // Step 8: the pins are found in the rendered captures (all 13 of the default dome; 21 of
    // the 24 presses: three outer imprints cut by the tube's mouth), the RMS reprojection error
    // is under 1 px (measured 0.09 px) and the pose is the nominal camera's (the lens's front on
    // the axis at z = -17.4 mm, looking along +z), within 0.3 mm (measured 0.17 mm nearer the
    // skin: the imprints' darkening centres outward of the tips) and 0.2 deg
    let e = json(&dir.join("calib/extrinsics.json"));
    let r = &e["residuals"];
    let rms = e["rms_reprojection_error_px"].as_f64().unwrap();
    assert!(rms < 1.0, "RMS {rms} px");
    assert!(r["inliers"].as_u64().unwrap() >= 10, "{r}");
    assert_eq!(r["inliers"], r["observations"], "{r}");
    let nominal = json(&dir.join("nominal/extrinsics.json"));
    assert!(nominal["description"]
        .as_str()
        .unwrap()
        .contains("not a calibration"));
    let c: Vec<f64> = (0..3)
        .map(|k| r["camera_centre_in_sensor_mm"][k].as_f64().unwrap())
        .collect();
    let off = (c[0].powi(2) + c[1].powi(2) + (c[2] + 17.4).powi(2)).sqrt();
    let rv: f64 = (0..3)
        .map(|k| e["rvec"][k].as_f64().unwrap().powi(2))
        .sum::<f64>()
        .sqrt();
    eprintln!(
        "camera centre {c:?} mm ({off:.3} mm off), turned {:.4} deg, RMS {rms:.3} px",
        rv.to_degrees()
    );
    assert!(off < 0.3 && rv.to_degrees() < 0.2, "{c:?}, {rv} rad");
    // the tutorial's design (R-Tac0's) has a filling gel: the rays bend at its surface
    assert!(
        e["optical_path_from"]
            .as_str()
            .is_some_and(|s| s.starts_with("design my_sensor, the point table's")),
        "{}",
        e["optical_path_from"]
    );
    // one overlay per capture, named by its pins
    assert!(dir.join("calib/overlays/01_02_06.png").is_file());
    // Step 9: ground truth for both semi-domes' protrusions, each in its two orientations, each
    // pressing the skin in somewhere the camera sees
    let gt = json(&dir.join("gt/manifest.json"));
    let configurations = gt["configurations"].as_array().unwrap();
    assert_eq!(configurations.len(), 4, "{gt}");
    for c in configurations {
        assert!(c["contact_pixels"].as_u64().unwrap() > 100, "{c}");
        assert!(c["max_range_decrease_mm"].as_f64().unwrap() > 0.1, "{c}");
    }
    // Step 10: four variants, all built, each with the 127 dimples.
    let csv = std::fs::read_to_string(dir.join("out/depths/results.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    let col = |name: &str| {
        rows[0]
            .iter()
            .position(|c| *c == name)
            .unwrap_or_else(|| panic!("no column {name} in {:?}", rows[0]))
    };
    let (status, count) = (col("status"), col("markers.translucent_gel.outer.count"));
    assert_eq!(rows.len(), 5, "{csv}");
    for r in &rows[1..] {
        assert_eq!((r[status], r[count]), ("ok", "127"), "{csv}");
    }
}
