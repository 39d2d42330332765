//! Cross-verification twins: every part of every library design and of its
//! fixtures, against the manifold3d twin (fast tier, every test run) and the exact CadQuery
//! twin (full tier: when `FABKIT_CADQUERY_PYTHON` is set, as `.ci/run` does after
//! `scripts/setup-cadquery`), plus `fabkit export --format step` read back by CadQuery.
//!
//! The Markdown report (one row per part) goes to `$FABKIT_TWIN_REPORT_DIR` (default
//! `<temp dir>/fabkit-twins`), outside the repository; any row out of bounds fails the test.

use crate::common::{missing, oracle_python, repo_root, run, text};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The exports the twins check: (output folder, fabkit arguments).
const CASES: &[(&str, &[&str])] = &[
    // the slowest first: check_twins spreads the exports over the CPUs in this order
    ("shadowtac", &["export", "shadowtac"]),
    ("uvdtact", &["export", "uvdtact"]),
    ("rtac0", &["export", "rtac0"]),
    // the direct molds with the other housing arrangement (square split halves)
    (
        "rtac0_direct",
        &[
            "export",
            "rtac0",
            "--mold-strategy",
            "direct",
            "--preset",
            "square_split",
        ],
    ),
    ("tactip_dualmodal", &["export", "tactip_dualmodal"]),
    (
        "rtac0_fixtures",
        &[
            "fixtures",
            "rtac0",
            "--pins-preset",
            "rtac0",
            "--semidomes",
            "3",
        ],
    ),
    // the default fixtures of the other bodies (spherical cap, half-ellipsoid, TacTip dome)
    ("shadowtac_fixtures", &["fixtures", "shadowtac"]),
    ("uvdtact_fixtures", &["fixtures", "uvdtact"]),
    (
        "tactip_dualmodal_fixtures",
        &["fixtures", "tactip_dualmodal"],
    ),
];

/// Every case exported under `dir` with its CSG tree beside it (`<case>.csg.json`).
fn export_all(dir: &Path, extra: &[&str]) -> Vec<PathBuf> {
    CASES
        .iter()
        .map(|(name, args)| {
            let csg = format!("{name}.csg.json");
            let mut a: Vec<&str> = args.to_vec();
            a.extend(["--out", name, "--csg", &csg]);
            a.extend(extra);
            let o = run(dir, &a, &[]);
            assert!(
                o.status.success(),
                "fabkit {a:?}:\n{}{}",
                text(&o.stdout),
                text(&o.stderr)
            );
            dir.join(name)
        })
        .collect()
}

fn report_dir() -> PathBuf {
    let d = std::env::var_os("FABKIT_TWIN_REPORT_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("fabkit-twins"));
    std::fs::create_dir_all(&d).expect("report directory");
    d
}

fn check_twins(py: &Path, tier: &str, exports: &[PathBuf]) -> PathBuf {
    let report = report_dir().join(format!("twins-{tier}.md"));
    let json = report_dir().join(format!("twins-{tier}.json"));
    let o = Command::new(py)
        .current_dir(repo_root().join("tests/oracles"))
        .arg("twins/check_twins.py")
        .args(exports)
        .args(["--tier", tier, "--report"])
        .arg(&report)
        .arg("--json")
        .arg(&json)
        .output()
        .expect("python runs");
    let out = text(&o.stdout);
    eprintln!("twin report ({tier} tier): {}", report.display());
    assert!(
        o.status.success() && out.contains(" 0 failed"),
        "check_twins.py --tier {tier} failed (report {}):\n{out}\n{}",
        report.display(),
        text(&o.stderr)
    );
    // one row per part of every export
    let rows = std::fs::read_to_string(&report).expect("report written");
    for d in exports {
        let m: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("manifest.json")).unwrap()).unwrap();
        for p in m["parts"].as_array().unwrap() {
            let name = p["name"].as_str().unwrap();
            assert!(
                rows.contains(&format!("| {name} |")),
                "no report row for {name}"
            );
        }
    }
    json
}

/// Fast tier: the manifold3d twin redoes every part's booleans (volume within 1e-6
/// relative, genus, bounding box, Hausdorff distance to the written mesh).
#[test]
fn manifold3d_twin_agrees_on_every_part() {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (manifold3d + trimesh + libigl)");
    };
    let t = tempfile::tempdir().unwrap();
    let exports = export_all(t.path(), &[]);
    check_twins(&py, "fast", &exports);
}

/// The CadQuery python of the full tier, if configured.
fn cadquery_python() -> Option<PathBuf> {
    let p = std::env::var_os("FABKIT_CADQUERY_PYTHON").map(PathBuf::from);
    if p.is_none() && std::env::var("FABKIT_REQUIRE_CADQUERY").is_ok_and(|v| v == "1") {
        panic!("FABKIT_REQUIRE_CADQUERY=1 but FABKIT_CADQUERY_PYTHON is not set (scripts/setup-cadquery)");
    }
    p
}

/// Full tier: the exact CadQuery twin of every part (volume within the chord bound, Hausdorff
/// distance, bounding box, genus), and STEP export of every part read back by CadQuery with
/// the exact solid's volume.
#[test]
fn cadquery_twin_agrees_on_every_part_and_step_reads_back() {
    let Some(py) = cadquery_python() else {
        eprintln!("SKIPPED: full twin tier (set FABKIT_CADQUERY_PYTHON; .ci/run does)");
        return;
    };
    let t = tempfile::tempdir().unwrap();
    let exports = export_all(t.path(), &["--format", "stl,3mf,step"]);
    let json = check_twins(&py, "full", &exports);
    for d in &exports {
        let o = Command::new(&py)
            .current_dir(repo_root().join("tests/oracles"))
            .arg("twins/check_step.py")
            .arg(d)
            .arg("--exact-json")
            .arg(&json)
            .output()
            .expect("python runs");
        let out = text(&o.stdout);
        assert!(
            o.status.success() && out.contains(" 0 failed"),
            "check_step.py {}:\n{out}\n{}",
            d.display(),
            text(&o.stderr)
        );
    }
}

/// Without the CadQuery environment, `--format step` fails (exit 2), says how to install it,
/// and writes nothing.
#[test]
fn step_without_cadquery_says_how_to_install() {
    let t = tempfile::tempdir().unwrap();
    let o = run(
        t.path(),
        &["export", "rtac0", "--format", "stl,step", "--out", "kit"],
        &[("FABKIT_CADQUERY_PYTHON", "/nonexistent/python")],
    );
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(
        err.contains("STEP export is not available") && err.contains("scripts/setup-cadquery"),
        "{err}"
    );
    assert!(!t.path().join("kit").exists());
}
