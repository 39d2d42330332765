//! fabkit's outputs open in their users' default readers with default arguments
//! (tests/oracles/default_readers.py): every CSV starts with its header row (pandas.read_csv,
//! csv.DictReader and numpy.genfromtxt(names=True) agree on names and rows), the ground
//! truth's PLY keeps u and v in open3d.t.io.read_point_cloud, STL headers keep the unit word,
//! STEP products carry the part names.

use std::path::Path;

use serde_json::{json, Value};

use crate::common::*;

pub(crate) const POINT_TABLE_COLUMNS: [&str; 12] = [
    "id",
    "ring",
    "tip_x_mm",
    "tip_y_mm",
    "tip_z_mm",
    "contact_x_mm",
    "contact_y_mm",
    "contact_z_mm",
    "axis_x",
    "axis_y",
    "axis_z",
    "indentation_depth_mm",
];

/// A CSV entry of the oracle's spec: `path`, the expected `columns` and number of `rows`
/// (None: only the readers' agreement is checked).
pub(crate) fn csv_spec(path: &Path, columns: &[&str], rows: Option<usize>) -> Value {
    json!({"path": path, "columns": columns, "rows": rows})
}

/// Runs tests/oracles/default_readers.py on `spec` (written into `dir`); it must pass.
pub(crate) fn default_readers_check(dir: &Path, spec: &Value) {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (pandas, numpy, open3d)");
    };
    let spec_path = dir.join("default_readers_spec.json");
    std::fs::write(&spec_path, serde_json::to_vec_pretty(spec).unwrap()).unwrap();
    let o = std::process::Command::new(py)
        .arg(repo_root().join("tests/oracles/default_readers.py"))
        .arg(&spec_path)
        .output()
        .expect("python runs");
    let out = text(&o.stdout);
    assert!(
        o.status.success() && out.contains(" 0 failed"),
        "default_readers.py:\n{out}\n{}",
        text(&o.stderr)
    );
}

fn points_in(json_path: &Path) -> usize {
    let v: Value = serde_json::from_slice(&std::fs::read(json_path).unwrap()).unwrap();
    v["points"].as_array().unwrap().len()
}

#[test]
fn csv_ply_stl_and_step_open_in_default_readers_with_default_arguments() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path();
    // pin dome (rtac0) fixtures and the ground truth on them
    crate::groundtruth_cli::setup(d);
    let o = crate::groundtruth_cli::groundtruth(d, "gt", "2");
    assert!(o.status.success(), "{}", text(&o.stderr));
    // grid plate (soter_channels) fixtures
    let o = run(d, &["fixtures", "soter_channels", "--out", "fx_flat"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));

    let mut csvs = Vec::new();
    for fx in ["fx", "fx_flat"] {
        let points = d.join(fx).join("points");
        let table = std::fs::read_to_string(points.join("point_table.csv")).unwrap();
        assert!(table.starts_with("id,ring,"), "{fx}: {table:.60}");
        let n = points_in(&points.join("point_table.json"));
        csvs.push(csv_spec(
            &points.join("point_table.csv"),
            &POINT_TABLE_COLUMNS,
            Some(n),
        ));
        // the notes that were the `#` lines are in the sidecars
        let side: Value =
            serde_json::from_slice(&std::fs::read(points.join("point_table.json")).unwrap())
                .unwrap();
        assert!(side["notes"][0].as_str().unwrap().contains("point table"));
        let side: Value =
            serde_json::from_slice(&std::fs::read(points.join("capture_plan.json")).unwrap())
                .unwrap();
        assert!(side["notes"].as_str().unwrap().contains("capture plan"));
        let columns: Vec<String> = serde_json::from_value(side["columns"].clone()).unwrap();
        let columns: Vec<&str> = columns.iter().map(String::as_str).collect();
        let plan = std::fs::read_to_string(points.join("capture_plan.csv")).unwrap();
        assert!(plan.starts_with(&format!("{}\n", columns.join(","))));
        // rtac0: 8 captures of 5 pins (the pole pin in each)
        let rows = (fx == "fx").then_some(40);
        csvs.push(csv_spec(&points.join("capture_plan.csv"), &columns, rows));
    }
    let gt = d.join("gt");
    assert!(std::fs::read_to_string(gt.join("pairs.csv"))
        .unwrap()
        .starts_with("pair,"));
    csvs.push(csv_spec(
        &gt.join("pairs.csv"),
        &[
            "pair",
            "right_pattern",
            "right_dir",
            "left_pattern",
            "left_dir",
        ],
        Some(4),
    ));
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(gt.join("manifest.json")).unwrap()).unwrap();
    let pairs_entry = manifest["masks_and_pairs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["file"] == "pairs.csv")
        .unwrap();
    assert!(pairs_entry["notes"]
        .as_str()
        .unwrap()
        .starts_with("stitched pairs"));
    let ply: Vec<Value> = ["reference", "p001_0"]
        .iter()
        .filter(|c| gt.join(c).join("points.ply").exists())
        .map(|c| json!({"path": gt.join(c).join("points.ply"), "range_npy": gt.join(c).join("range_mm.npy")}))
        .collect();
    assert!(!ply.is_empty());

    // export: STL headers always; STEP product names with the CadQuery python, from the twins'
    // shared export of R-Tac0 (`--format stl,3mf,step`)
    let export = match crate::cad_twins::shared_step_export("rtac0") {
        Some(shared) => shared.to_path_buf(),
        None => {
            eprintln!("SKIPPED: STEP product names (set FABKIT_CADQUERY_PYTHON)");
            let o = run(
                d,
                &["export", "rtac0", "--format", "stl,3mf", "--out", "ex"],
                &[],
            );
            assert!(o.status.success(), "{}{}", text(&o.stdout), text(&o.stderr));
            d.join("ex")
        }
    };

    default_readers_check(d, &json!({"csv": csvs, "ply": ply, "export": export}));
}
