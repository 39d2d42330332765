//! STEP export from an installed fabkit: the binary copied out of the build tree, run from a
//! directory outside the repository, finds the CadQuery venv where `scripts/setup-cadquery`
//! installs it (`$XDG_DATA_HOME/fabkit/venv-cadquery`, no FABKIT_CADQUERY_PYTHON), and reports
//! its progress on stderr one plain line per part. Needs a CadQuery Python
//! (FABKIT_CADQUERY_PYTHON, as for the full twin tier; FABKIT_REQUIRE_CADQUERY=1 makes it
//! required).

use crate::common::{cadquery_python, repo_root, text};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Installs a stand-in for the venv of `scripts/setup-cadquery` under `data`:
/// `<data>/fabkit/venv-cadquery/bin/python`, a script that records each run in
/// `<data>/fabkit/venv-cadquery/runs` and runs `python` by its own path (a venv's python finds
/// its packages through the path it is run by, so a symbolic link to the file would run the
/// bare interpreter). Returns the record's path.
fn install_venv(data: &Path, python: &Path) -> PathBuf {
    use std::os::unix::fs::PermissionsExt as _;
    let venv = data.join("fabkit/venv-cadquery");
    let bin = venv.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let runs = venv.join("runs");
    let script = bin.join("python");
    // a path from this directory, or a command name for the script's PATH lookup
    let real = if python.components().count() > 1 {
        std::path::absolute(python).unwrap()
    } else {
        python.to_path_buf()
    };
    let quote = |p: &Path| format!("'{}'", p.display().to_string().replace('\'', "'\\''"));
    std::fs::write(
        &script,
        format!(
            "#!/bin/sh\necho run >> {}\nexec {} \"$@\"\n",
            quote(&runs),
            quote(&real)
        ),
    )
    .unwrap();
    std::fs::set_permissions(&script, std::fs::Permissions::from_mode(0o755)).unwrap();
    runs
}

/// `fabkit export rtac0 --format step` by a copy of the binary, from a directory
/// outside the repository, with the CadQuery venv only in the XDG data directory: every part's
/// STEP file is written (ISO 10303-21, listed in manifest.json), and stderr holds one
/// `STEP i/n: <part>` line per part, in kit order, as the parts are built.
#[test]
fn installed_fabkit_exports_step_with_the_user_venv_and_reports_each_part() {
    let Some(python) = cadquery_python() else {
        eprintln!("SKIPPED: STEP export of an installed fabkit (set FABKIT_CADQUERY_PYTHON; .ci/run does)");
        return;
    };
    let t = tempfile::tempdir().unwrap();
    let repo = repo_root().canonicalize().unwrap();
    assert!(
        !t.path().canonicalize().unwrap().starts_with(&repo),
        "the temporary directory must be outside the repository"
    );
    let bin = t.path().join("bin/fabkit");
    std::fs::create_dir_all(bin.parent().unwrap()).unwrap();
    std::fs::copy(env!("CARGO_BIN_EXE_fabkit"), &bin).unwrap();
    let data = t.path().join("data");
    let runs = install_venv(&data, &python);
    let work = t.path().join("work");
    std::fs::create_dir(&work).unwrap();
    let o = Command::new(&bin)
        .current_dir(&work)
        .args([
            "export",
            // nine parts (the TacTip's five took 15 CPU-s, most of them its cast gel's
            // 59,000-face assembly member)
            "rtac0", "--format", "step", "--out", "kit",
        ])
        .env_remove("FABKIT_CADQUERY_PYTHON")
        .env("XDG_DATA_HOME", &data)
        .env("HOME", t.path().join("home"))
        .output()
        .expect("the installed fabkit runs");
    let err = text(&o.stderr);
    assert!(
        o.status.success(),
        "installed fabkit, --format step:\n{}{err}",
        text(&o.stdout)
    );
    let kit = work.join("kit");
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(kit.join("manifest.json")).unwrap()).unwrap();
    let names: Vec<&str> = m["parts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert!(!names.is_empty());
    for p in m["parts"].as_array().unwrap() {
        let rel = p["step_file"].as_str().expect("step_file in manifest.json");
        let bytes = std::fs::read(kit.join(rel)).unwrap();
        assert!(
            bytes.starts_with(b"ISO-10303-21;"),
            "{rel} is not a STEP file"
        );
    }
    // one progress line per part, in order, plain text (stderr is a pipe here)
    let progress: Vec<&str> = err.lines().filter(|l| l.starts_with("STEP ")).collect();
    let n = names.len();
    let want: Vec<String> = names
        .iter()
        .enumerate()
        .map(|(i, name)| format!("STEP {}/{n}: {name}", i + 1))
        .collect();
    assert_eq!(progress, want, "stderr:\n{err}");
    assert!(!err.contains('\r') && !err.contains('\u{1b}'), "{err:?}");
    // and the Python that built them was the one in the XDG data directory
    assert!(
        runs.is_file(),
        "fabkit did not run {}",
        data.join("fabkit/venv-cadquery/bin/python").display()
    );
}
