//! Cross-verification twins: every part of every library design and of its
//! fixtures, against the manifold3d twin (fast tier, every test run) and the exact CadQuery
//! twin (full tier: when `FABKIT_CADQUERY_PYTHON` is set, as `.ci/run` does after
//! `scripts/setup-cadquery`), which is `fabkit export --format step` read back by CadQuery.
//!
//! The Markdown report (one row per part) goes to `$FABKIT_TWIN_REPORT_DIR` (default
//! `<temp dir>/fabkit-twins`), outside the repository; any row out of bounds fails the test.

use crate::common::{
    cadquery_python, fabkit, missing, oracle_python, repo_root, run, shared_dir, text,
};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The exports the twins check: (output folder, fabkit arguments).
const CASES: &[(&str, &[&str])] = &[
    // the slowest first: check_twins spreads the exports over the CPUs in this order
    ("shadowtac", &["export", "shadowtac"]),
    ("uvdtact", &["export", "uvdtact"]),
    // the no-marker variant: one mixed layer cast at once (Sec. V-B)
    (
        "uvdtact_no_markers",
        &["export", "uvdtact", "--preset", "no_markers"],
    ),
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
    // the flat skin's casting trays (Soter et al. Sec. II-A)
    ("soter_channels", &["export", "soter_channels"]),
    // a solid gel with its optic's seat: the open mold's block and the seat's insert
    ("digit_pinki", &["export", "digit_pinki"]),
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
    // the pin dome and semi-domes of the small hemisphere-on-cylinder tip (R7.5)
    (
        "digit_pinki_fixtures",
        &["fixtures", "digit_pinki", "--semidomes", "2"],
    ),
    // the flat skin's indenter grid plate and pin, semi-plate holder and halves
    (
        "soter_channels_fixtures",
        &["fixtures", "soter_channels", "--semidomes", "3"],
    ),
    // a wrapped gel stack in its published laser-cut plates with its shell, base and isolation
    // ring (9DTact), and its calibration board fitted over the shell by default
    ("ninedtact", &["export", "ninedtact"]),
    ("ninedtact_fixtures", &["fixtures", "ninedtact"]),
];

/// Every case exported under `dir` with its CSG tree beside it (`<case>.csg.json`), two
/// exports at a time (the machine has two cores; a STEP export waits on CadQuery).
fn export_all(dir: &Path, extra: &[&str]) -> Vec<PathBuf> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some((name, args)) = CASES.get(i) else {
                    break;
                };
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
            });
        }
    });
    CASES.iter().map(|(name, _)| dir.join(name)).collect()
}

/// The exports both tiers check, made once per test run: the first tier to ask makes them
/// (two at a time), the other waits for them. With CadQuery (`FABKIT_CADQUERY_PYTHON`) they are
/// `--format stl,3mf,step`, whose STL and 3MF files are those of the default formats (the full
/// tier checks so on R-Tac0), else the default formats. Returns the folder holding them and
/// each case's folder. The folder is `<target>/tmp/cad_twins-exports` (a static is never
/// dropped, so a temporary folder would outlive the run): emptied first, left for a look after.
fn shared_exports() -> (&'static Path, &'static [PathBuf]) {
    static EXPORTS: std::sync::OnceLock<(PathBuf, Vec<PathBuf>)> = std::sync::OnceLock::new();
    let (dir, exports) = EXPORTS.get_or_init(|| {
        let dir = shared_dir("cad_twins-exports");
        let extra: &[&str] = if cadquery_python().is_some() {
            &["--format", "stl,3mf,step"]
        } else {
            &[]
        };
        let exports = export_all(&dir, extra);
        (dir, exports)
    });
    (dir, exports)
}

/// The folder of the shared export of case `name` (one of [`CASES`]) when it holds STEP files
/// (the CadQuery Python is set; `None` without it), waiting for the shared exports if they are
/// being made: the tests that read a design's STEP files take them from here, so that each
/// design's STEP export is made once per run, not once per test.
pub(crate) fn shared_step_export(name: &str) -> Option<&'static Path> {
    cadquery_python()?;
    let (_, exports) = shared_exports();
    let found = exports
        .iter()
        .find(|d| d.file_name().is_some_and(|n| n == name))
        .map(PathBuf::as_path);
    assert!(found.is_some(), "{name} is no case of the shared exports");
    found
}

fn report_dir() -> PathBuf {
    let d = std::env::var_os("FABKIT_TWIN_REPORT_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("fabkit-twins"));
    std::fs::create_dir_all(&d).expect("report directory");
    d
}

fn check_twins(py: &Path, tier: &str, extra: &[&str], exports: &[PathBuf]) -> PathBuf {
    let report = report_dir().join(format!("twins-{tier}.md"));
    let json = report_dir().join(format!("twins-{tier}.json"));
    let o = Command::new(py)
        .arg(repo_root().join("export/python/twins/check_twins.py"))
        .args(exports)
        .args(["--tier", tier])
        .args(extra)
        .arg("--report")
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
    check_twins(&py, "fast", &[], shared_exports().1);
}

/// Full tier: the exact CadQuery twin of every part (volume within the chord bound, Hausdorff
/// distance, bounding box, genus), as the STEP export built and wrote it: every part's STEP
/// file read back by CadQuery (the file the manifest hashes, a valid shape) is the exact solid
/// its mesh is compared with, so each export's twins are built once (by the STEP export, which
/// checks each against fabkit's volume and box before writing it). A machined part's STEP file
/// against the exact shape the manifest gives (volume within 1e-6 relative, one solid). The
/// TacTip's filling gel goes into its assembly STEP from its exact shape.
#[test]
fn cadquery_twin_agrees_on_every_part_and_step_reads_back() {
    let Some(py) = cadquery_python() else {
        eprintln!("SKIPPED: full twin tier (set FABKIT_CADQUERY_PYTHON; .ci/run does)");
        return;
    };
    // with CadQuery, the shared exports are STL, 3MF and STEP
    let (dir, exports) = shared_exports();
    // The manifold3d twin of these parts is the fast tier's test (same input, same bytes: the
    // STL files do not depend on --format step, checked here on R-Tac0).
    let t = tempfile::tempdir().unwrap();
    let plain = run(t.path(), &["export", "rtac0", "--out", "rtac0_stl"], &[]);
    assert!(plain.status.success(), "{}", text(&plain.stderr));
    let stls = |d: &Path| -> Vec<(std::ffi::OsString, Vec<u8>)> {
        let mut v: Vec<_> = std::fs::read_dir(d.join("parts"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "stl"))
            .map(|p| {
                (
                    p.file_name().unwrap().to_owned(),
                    std::fs::read(&p).unwrap(),
                )
            })
            .collect();
        v.sort();
        v
    };
    let with_step = stls(&dir.join("rtac0"));
    assert!(!with_step.is_empty());
    assert!(
        with_step == stls(&t.path().join("rtac0_stl")),
        "the STL files of `export rtac0` differ with --format stl,3mf,step"
    );
    let json = check_twins(
        &py,
        "full",
        &["--skip-manifold3d", "--exact-from-step"],
        exports,
    );
    // every part's exact solid was its STEP file, and every machined part has its row
    let rows: Vec<serde_json::Value> =
        serde_json::from_slice(&std::fs::read(&json).expect("rows written")).unwrap();
    for d in exports {
        let name = d.file_name().unwrap().to_str().unwrap();
        let m: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("manifest.json")).unwrap()).unwrap();
        let machined = m["machined_parts"]
            .as_array()
            .map_or(&[][..], |v| v.as_slice());
        for p in m["parts"].as_array().unwrap().iter().chain(machined) {
            let part = p["name"].as_str().unwrap();
            let row = rows
                .iter()
                .find(|r| r["design"] == name && r["part"] == part)
                .unwrap_or_else(|| panic!("no row for {name}/{part}"));
            assert!(
                row["exact_source"] == "step" && row["step_solids"].as_u64() >= Some(1),
                "{name}/{part}: the exact solid was not its STEP file read back: {row}"
            );
        }
    }
    assert!(
        rows.iter().any(|r| r["role"] == "machined"),
        "no machined part's STEP file was read back"
    );
    // the TacTip's filling gel is written from its exact shape (sewn from its mesh, it was a
    // faceted solid of 59,000 faces and 145 MB)
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("tactip_dualmodal/manifest.json")).unwrap())
            .unwrap();
    let gel = m["assembly_step"]["members"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["name"] == "filling_gel")
        .expect("the TacTip's assembly STEP has its filling gel");
    assert_eq!(gel["geometry"], "exact_inner_cavity");
}

/// Without the CadQuery environment, `--format step` fails (exit 2), says why (naming the
/// variable, its value and the rule, or the default location it looked in), says how to
/// install it, and writes nothing: FABKIT_CADQUERY_PYTHON naming no file, a file that is not
/// executable, a Python without cadquery (the system's), or unset with no venv in the XDG data
/// directory (absolute XDG_DATA_HOME, or HOME when XDG_DATA_HOME is relative). The data
/// directories are temporary ones, so the result depends on neither the repository nor the
/// user's own installation.
#[test]
fn step_without_cadquery_says_how_to_install() {
    let no_cadquery = Command::new("python3")
        .args(["-c", "import cadquery"])
        .output()
        .is_ok_and(|o| !o.status.success());
    let t = tempfile::tempdir().unwrap();
    let data = t.path().join("data");
    let home = t.path().join("home");
    let plain = t.path().join("plain-file");
    std::fs::write(&plain, "").unwrap();
    let (data_s, home_s, plain_s) = (
        data.to_str().unwrap(),
        home.to_str().unwrap(),
        plain.to_str().unwrap(),
    );
    let default_py = format!("{data_s}/fabkit/venv-cadquery/bin/python");
    let home_py = format!("{home_s}/.local/share/fabkit/venv-cadquery/bin/python");
    let unset = "FABKIT_CADQUERY_PYTHON is not set";
    // (FABKIT_CADQUERY_PYTHON, XDG_DATA_HOME, what the message must hold)
    let mut cases: Vec<(Option<&str>, &str, Vec<String>)> = vec![
        (
            Some("/nonexistent/python"),
            data_s,
            vec![
                "FABKIT_CADQUERY_PYTHON=/nonexistent/python: no such file".into(),
                "it must name an executable Python with CadQuery".into(),
            ],
        ),
        (
            Some(plain_s),
            data_s,
            vec![format!("FABKIT_CADQUERY_PYTHON={plain_s}: not executable")],
        ),
        (
            None,
            data_s,
            vec![
                format!("{default_py}: no CadQuery Python there"),
                unset.into(),
            ],
        ),
        (
            None,
            "relative/data",
            vec![
                format!("{home_py}: no CadQuery Python there"),
                "XDG_DATA_HOME=relative/data is ignored".into(),
            ],
        ),
    ];
    if no_cadquery {
        cases.push((
            Some("python3"),
            data_s,
            vec!["cannot import cadquery (FABKIT_CADQUERY_PYTHON=python3)".into()],
        ));
    }
    for (python, xdg, reasons) in cases {
        let mut c = fabkit();
        c.current_dir(t.path())
            .args(["export", "rtac0", "--format", "stl,step", "--out", "kit"])
            .env("XDG_DATA_HOME", xdg)
            .env("HOME", home_s)
            .env_remove("FABKIT_CADQUERY_PYTHON");
        if let Some(p) = python {
            c.env("FABKIT_CADQUERY_PYTHON", p);
        }
        let o = c.output().expect("fabkit runs");
        assert_eq!(o.status.code(), Some(2), "{python:?}");
        let err = text(&o.stderr);
        assert!(
            err.contains("STEP export is not available")
                && reasons.iter().all(|r| err.contains(r.as_str()))
                && err.contains("scripts/setup-cadquery")
                && err.contains("$XDG_DATA_HOME/fabkit/venv-cadquery"),
            "{python:?}, XDG_DATA_HOME={xdg}: {err}"
        );
        assert!(!t.path().join("kit").exists(), "{python:?}");
    }
}
