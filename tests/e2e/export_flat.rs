//! End-to-end: `fabkit export soter_channels` and `fabkit fixtures soter_channels`, the flat
//! skin of Soter et al. (Sec. II-A): its two casting trays read back by the independent oracle and sliced by PrusaSlicer, its pours
//! against the layers' exact volumes, the filling procedure on the sheet, and bad channel and
//! grid values refused by path with nothing written; its indenter grid plate, pin, point table
//! and capture plan.

use crate::common::*;
use serde_json::Value;
use std::f64::consts::PI;

/// The kit: a tray per layer (the channel layer's with 16 ribs, the marker layer's with 100
/// holes), closed and printable; the channel layer poured first, each pour the layer's exact
/// volume (80 x 80 mm less the four 5 mm corners; 3 mm less 16 channels of 1.5 x 1.5 x 70 mm;
/// 2 mm plus 100 markers of 1.5 mm ending in hemispheres, 2 mm long); the liquid per channel
/// on the sheet; the `one_closed` preset leaves the tubes' display ends open.
#[test]
fn soter_channels_kit() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(
        tmp.path(),
        &["export", "soter_channels", "--out", "out/s"],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let dir = tmp.path().join("out/s");
    let m: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    let parts = m["parts"].as_array().unwrap();
    let names: Vec<&str> = parts.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["marker_layer_tray", "channel_layer_tray"]);
    assert!(parts
        .iter()
        .all(|p| p["role"] == "casting_tray" && p["genus"] == 0));
    let area = 80.0 * 80.0 - (4.0 - PI) * 25.0;
    let marker = PI * 0.75f64.powi(2) * (2.0 - 0.75) + 2.0 / 3.0 * PI * 0.75f64.powi(3);
    let casts = m["casts"].as_array().unwrap();
    assert_eq!(casts[0]["cast"], "channel_layer");
    assert_eq!(casts[1]["cast"], "marker_layer");
    let ml = |i: usize| casts[i]["cavity_volume_ml"].as_f64().unwrap();
    assert!((ml(0) - (area * 3.0 - 16.0 * 1.5 * 1.5 * 70.0) / 1000.0).abs() < 1e-9);
    assert!((ml(1) - (area * 2.0 + 100.0 * marker) / 1000.0).abs() < 1e-9);
    let per = m["summary"]["flat"]["channels"][0]["liquid_per_channel_ml"]
        .as_f64()
        .unwrap();
    let want = (157.5 - PI * 5.0 + PI * 0.25 * 300.0) / 1000.0;
    assert!((per - want).abs() < 1e-12, "{per}");
    let sheet = std::fs::read_to_string(dir.join("FABRICATION.md")).unwrap();
    assert!(
        sheet.contains(&format!("{want:.3} mL per channel")),
        "{sheet}"
    );
    assert!(sheet.contains("close each tube's display end"), "{sheet}");
    oracle_check(&dir);
    let mut files: Vec<std::path::PathBuf> = parts
        .iter()
        .map(|p| dir.join(p["file"].as_str().unwrap()))
        .collect();
    files.push(dir.join(m["kit_3mf"]["file"].as_str().unwrap()));
    printcheck_all(&files);

    let o = run(
        tmp.path(),
        &[
            "export",
            "soter_channels",
            "--preset",
            "one_closed",
            "--out",
            "out/o",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let sheet = std::fs::read_to_string(tmp.path().join("out/o/FABRICATION.md")).unwrap();
    assert!(
        sheet.contains("the tubes' display ends stay open"),
        "{sheet}"
    );
}

/// Channels wider than their pitch allows, channels that break through the skin's face and a
/// marker grid that does not fit the outline are refused by path (exit 2), nothing written.
#[test]
fn bad_flat_values_write_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml =
        std::fs::read_to_string(repo_root().join("designs/library/soter_channels.yaml")).unwrap();
    for (from, to, expect) in [
        (
            "      width_mm: 1.5 ",
            "      width_mm: 3.8 ",
            "layers[1].channels.width_mm = 3.8: channels 3.8 mm wide at a 4 mm pitch leave less than min_wall_mm",
        ),
        (
            "      height_mm: 1.5 ",
            "      height_mm: 2.8 ",
            "layers[1].channels.height_mm = 2.8: the channel breaks through the skin's face",
        ),
        (
            "      pitch_mm: 6.5 ",
            "      pitch_mm: 8.5 ",
            "layers[0].marker_grid.pitch_mm = 8.5: a 10 x 10 grid at this pitch does not fit the 80 x 80 mm outline",
        ),
    ] {
        let bad = yaml.replacen(from, to, 1);
        assert!(bad.contains(to), "{to}");
        std::fs::write(tmp.path().join("bad.yaml"), &bad).unwrap();
        let o = run(tmp.path(), &["export", "bad.yaml", "--out", "out/bad"], &[]);
        assert_eq!(o.status.code(), Some(2), "{to}");
        let err = text(&o.stderr);
        assert!(err.contains(expect), "{expect}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!tmp.path().join("out").exists());
    }
}

/// `fabkit fixtures soter_channels`: the indenter grid plate and its pin, closed and
/// printable, and the point table (49 holes on the 10 mm grid, their contact points on the
/// face 5 mm up and the tips 1 mm under it) with the capture plan covering every pin once,
/// read back as CSV by pandas.
#[test]
fn soter_channels_grid_plate() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(
        tmp.path(),
        &["fixtures", "soter_channels", "--out", "fx"],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("grid plate: 49 holes in 13 captures"),
        "{}",
        text(&o.stdout)
    );
    let dir = tmp.path().join("fx");
    oracle_check(&dir);
    printcheck_all(&[dir.join("parts/grid_plate.stl"), dir.join("parts/pin.stl")]);
    let Some(py) = oracle_python() else {
        return missing("the oracle python (pandas)");
    };
    let script = r##"
import sys, json
import pandas as pd
t = pd.read_csv(sys.argv[1] + "/points/point_table.csv", comment="#")
c = pd.read_csv(sys.argv[1] + "/points/capture_plan.csv")
print(json.dumps({"n": len(t), "contact_z": sorted(set(t.contact_z_mm)), "tip_z": sorted(set(t.tip_z_mm)),
    "xs": sorted(set(t.contact_x_mm)), "ids": sorted(c.id.tolist()), "captures": int(c.capture.max())}))
"##;
    let o = std::process::Command::new(py)
        .arg("-c")
        .arg(script)
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["n"], 49, "{v}");
    assert_eq!(v["contact_z"], serde_json::json!([5.0]), "{v}");
    assert_eq!(v["tip_z"], serde_json::json!([4.0]), "{v}");
    assert_eq!(
        v["xs"],
        serde_json::json!([-30.0, -20.0, -10.0, 0.0, 10.0, 20.0, 30.0]),
        "{v}"
    );
    assert_eq!(
        v["ids"],
        serde_json::json!((1..=49).collect::<Vec<_>>()),
        "{v}"
    );
    assert_eq!(v["captures"], 13, "{v}");
}
