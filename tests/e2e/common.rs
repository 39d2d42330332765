//! Helpers shared by the end-to-end tests: run the fabkit binary, find the oracles.
#![allow(dead_code)]

use sha2::{Digest, Sha256};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::{Condvar, Mutex};

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

/// Runs tests/oracles/check_parts.py on an export folder; it must pass.
pub fn oracle_check(dir: &Path) {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (manifold3d + trimesh)");
    };
    let o = std::process::Command::new(py)
        .arg(repo_root().join("tests/oracles/check_parts.py"))
        .arg(dir)
        .output()
        .expect("python runs");
    let out = text(&o.stdout);
    assert!(
        o.status.success() && out.contains(" 0 failed"),
        "check_parts.py {}:\n{out}\n{}",
        dir.display(),
        text(&o.stderr)
    );
}

/// Two slicer runs at a time across every end-to-end test (the machine has two cores).
static SLICER_SLOTS: (Mutex<usize>, Condvar) = (Mutex::new(2), Condvar::new());

struct SlicerSlot;

impl SlicerSlot {
    fn take() -> Self {
        let (lock, cv) = &SLICER_SLOTS;
        let mut free = lock.lock().unwrap_or_else(|e| e.into_inner());
        while *free == 0 {
            free = cv.wait(free).unwrap_or_else(|e| e.into_inner());
        }
        *free -= 1;
        SlicerSlot
    }
}

impl Drop for SlicerSlot {
    fn drop(&mut self) {
        let (lock, cv) = &SLICER_SLOTS;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) += 1;
        cv.notify_one();
    }
}

/// `printcheck --strict` on each file, two at a time, every failure reported together. The slicer
/// runs once per distinct part: a file whose bytes (and flags) already passed in this test run
/// passes again without slicing, since the slicer's verdict depends on nothing else.
pub fn printcheck_all(files: &[PathBuf]) {
    printcheck_all_with(files, &[]);
}

/// Content hashes (sha256 of the file, then the flags) that passed printcheck in this run.
static PRINTCHECK_PASSED: Mutex<BTreeSet<[u8; 32]>> = Mutex::new(BTreeSet::new());

fn printcheck_key(file: &Path, flags: &[&str]) -> Option<[u8; 32]> {
    let bytes = std::fs::read(file).ok()?;
    let mut h = Sha256::new();
    h.update(&bytes);
    for f in flags {
        h.update([0u8]);
        h.update(f.as_bytes());
    }
    Some(h.finalize().into())
}

/// [`printcheck_all`] with extra printcheck flags (e.g. `--no-fdm` for resin and PolyJet parts).
pub fn printcheck_all_with(files: &[PathBuf], flags: &[&str]) {
    let Some(pc) = printcheck() else {
        return missing("printcheck (prusa-slicer + admesh)");
    };
    let passed = |f: &PathBuf| {
        printcheck_key(f, flags).is_some_and(|k| {
            PRINTCHECK_PASSED
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .contains(&k)
        })
    };
    let queue = Mutex::new(
        files
            .iter()
            .filter(|f| !passed(f))
            .cloned()
            .collect::<Vec<_>>(),
    );
    let results = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let Some(f) = queue.lock().unwrap().pop() else {
                    break;
                };
                let slot = SlicerSlot::take();
                let o = std::process::Command::new("bash")
                    .arg(&pc)
                    .arg("--strict")
                    .args(flags)
                    .arg(&f)
                    .output();
                drop(slot);
                results.lock().unwrap().push((f, o));
            });
        }
    });
    let failures: Vec<String> = results
        .into_inner()
        .unwrap()
        .into_iter()
        .filter_map(|(f, o)| match o {
            Ok(o) if o.status.success() && text(&o.stdout).contains("result=PASS") => {
                if let Some(k) = printcheck_key(&f, flags) {
                    PRINTCHECK_PASSED
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .insert(k);
                }
                None
            }
            Ok(o) => Some(format!(
                "{}:\n{}{}",
                f.display(),
                text(&o.stdout),
                text(&o.stderr)
            )),
            Err(e) => Some(format!("{}: printcheck did not run: {e}", f.display())),
        })
        .collect();
    assert!(
        failures.is_empty(),
        "printcheck --strict {} failed on {} of {} files:\n{}",
        flags.join(" "),
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}
