//! Helpers shared by the end-to-end tests: run the fabkit binary, find the oracles.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The fabkit binary built for this test run.
pub fn fabkit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_fabkit"))
}

/// Runs fabkit with `args` in `cwd`, returning the output.
pub fn run(cwd: &Path, args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut c = fabkit();
    c.current_dir(cwd).args(args);
    for (k, v) in envs {
        c.env(k, v);
    }
    c.output().expect("fabkit binary runs")
}

pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// The repository root (tests live in <root>/tests).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

/// Whether a missing oracle or printcheck must fail the test (scripts/test and CI set this)
/// rather than skip it with a message.
pub fn oracles_required() -> bool {
    std::env::var("FABKIT_REQUIRE_ORACLES").is_ok_and(|v| v == "1")
        || std::env::var("CI").is_ok_and(|v| v == "true")
}

/// Python of the oracle venv: $FABKIT_ORACLE_PYTHON or <root>/.venv-oracles/bin/python.
pub fn oracle_python() -> Option<PathBuf> {
    if let Ok(p) = std::env::var("FABKIT_ORACLE_PYTHON") {
        return Some(PathBuf::from(p));
    }
    let p = repo_root().join(".venv-oracles/bin/python");
    p.exists().then_some(p)
}

/// printcheck: $FABKIT_PRINTCHECK or <root>/../shared/tools/printcheck, if prusa-slicer is on PATH.
pub fn printcheck() -> Option<PathBuf> {
    let p = std::env::var("FABKIT_PRINTCHECK")
        .map(PathBuf::from)
        .unwrap_or_else(|_| repo_root().join("../shared/tools/printcheck"));
    let slicer = Command::new("prusa-slicer").arg("--help").output().is_ok();
    (p.exists() && slicer).then_some(p)
}

/// Skips (with a message) or fails, depending on [`oracles_required`].
pub fn missing(what: &str) {
    if oracles_required() {
        panic!("{what} is required (FABKIT_REQUIRE_ORACLES=1 or CI=true) but missing; run scripts/setup-system and scripts/setup-oracles");
    }
    eprintln!("SKIPPED: {what} not available; run scripts/test to include it");
}
