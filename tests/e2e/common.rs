//! Helpers shared by the end-to-end tests: run the fabkit binary, find the oracles.
#![allow(dead_code)]

use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
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

/// `fabkit fixtures DESIGN --pins-preset rtac0 --semidomes 0 --out OUT` in `cwd`: R-Tac0's
/// published pin dome with its point table and capture plan, for tests that calibrate from the
/// tables, without the paper's 100 semi-domes (R-Tac0's default, 9 of the command's 10
/// CPU-seconds). Panics naming stderr when the command fails; returns its output.
/// R-Tac0's into `fx`, which about ten tests ask for, is made once per test run (in
/// `<target>/tmp/shared-published-pin-dome`) and copied.
pub fn published_pin_dome(cwd: &Path, design: &str, out: &str) -> Output {
    if (design, out) == ("rtac0", "fx") {
        static SHARED: std::sync::OnceLock<(PathBuf, Output)> = std::sync::OnceLock::new();
        let (dir, o) = SHARED.get_or_init(|| {
            let dir = shared_dir("shared-published-pin-dome");
            let o = published_pin_dome_run(&dir, design, out);
            (dir.join(out), o)
        });
        copy_tree(dir, &cwd.join(out));
        return o.clone();
    }
    published_pin_dome_run(cwd, design, out)
}

fn published_pin_dome_run(cwd: &Path, design: &str, out: &str) -> Output {
    let o = run(
        cwd,
        &[
            "fixtures",
            design,
            "--pins-preset",
            "rtac0",
            "--semidomes",
            "0",
            "--out",
            out,
        ],
        &[],
    );
    assert!(
        o.status.success(),
        "fixtures {design}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Runs fabkit with `args` in `cwd` under an address-space limit of `limit_kib` KiB
/// (`ulimit -v`), with `envs`: an allocation past the limit fails as it would on a machine of
/// that memory.
pub fn run_limited(cwd: &Path, args: &[&str], envs: &[(&str, &str)], limit_kib: u64) -> Output {
    run_program_limited(
        Path::new(env!("CARGO_BIN_EXE_fabkit")),
        cwd,
        args,
        envs,
        limit_kib,
    )
}

/// [`run_limited`] for any `program` (a test binary running one of its own tests).
pub fn run_program_limited(
    program: &Path,
    cwd: &Path,
    args: &[&str],
    envs: &[(&str, &str)],
    limit_kib: u64,
) -> Output {
    let mut c = Command::new("bash");
    c.current_dir(cwd)
        .arg("-c")
        .arg(format!("ulimit -v {limit_kib} && exec \"$@\""))
        .arg("bash")
        .arg(program)
        .args(args);
    for (k, v) in envs {
        c.env(k, v);
    }
    c.output().expect("bash runs the program")
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

/// The CadQuery python of the full twin tier and of STEP export tests: $FABKIT_CADQUERY_PYTHON
/// (scripts/setup-cadquery prints it; .ci/run sets it), or None (the test skips). Panics when
/// it is unset but FABKIT_REQUIRE_CADQUERY=1.
pub fn cadquery_python() -> Option<PathBuf> {
    let p = std::env::var_os("FABKIT_CADQUERY_PYTHON")
        .filter(|p| !p.is_empty())
        .map(PathBuf::from);
    if p.is_none() && std::env::var("FABKIT_REQUIRE_CADQUERY").is_ok_and(|v| v == "1") {
        panic!("FABKIT_REQUIRE_CADQUERY=1 but FABKIT_CADQUERY_PYTHON is not set (scripts/setup-cadquery)");
    }
    p
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

/// `printcheck --strict` on each file, two at a time, every failure reported together.
/// - Every file is sliced for SLA, whose sliced volume must match the mesh's (printcheck's check
///   for overlapping or inverted shells), with tests/printcheck/sla.ini (unless
///   `PRINTCHECK_SLA_INI` is set): printcheck's own settings with smaller layer images, which
///   nothing reads.
/// - A file is sliced for FDM when a part in it is printed by FDM (`print_technology` in the
///   manifest), or when the manifest does not say: an FDM slice of a resin or PolyJet part
///   checks a print nobody makes (no bed adhesion, no empty-layer rule there).
///
/// The slicer runs once per distinct part:
/// - a file whose bytes (and flags) already passed in this test run passes again without
///   slicing, since the slicer's verdict depends on nothing else; a file another test is
///   slicing right now waits for that verdict;
/// - a kit 3MF whose objects are single parts, each of them in `files` as its own STL, holds no
///   print the STLs do not: PrusaSlicer loads it (`--no-fdm --no-sla`: manifold, nothing
///   repaired, positive volume, units) rather than slicing it again, and its build items are
///   checked not to overlap on the plate (what slicing the plate would catch). That the 3MF
///   holds the very parts (volume to 1e-5, box) is `check_parts.py`'s check, which
///   every export folder passes. A 3MF with a multi-part object (a multi-material group) is a
///   print of its own and is sliced.
pub fn printcheck_all(files: &[PathBuf]) {
    printcheck_all_with(files, &[]);
}

/// A printcheck job: a file and its flags.
type Job = (PathBuf, Vec<&'static str>);

/// The flags of a kit 3MF in `files`: `--no-fdm --no-sla` when every object of it is one part
/// whose STL is in `files` (after asserting the build items do not overlap), else none.
fn kit_3mf_flags(kit: &Path, files: &[PathBuf]) -> Vec<&'static str> {
    let Some(dir) = kit.parent() else {
        return vec![];
    };
    let Ok(bytes) = std::fs::read(dir.join("manifest.json")) else {
        return vec![];
    };
    let m: serde_json::Value = serde_json::from_slice(&bytes).expect("manifest.json parses");
    let k = &m["kit_3mf"];
    if k["file"].as_str().map(|f| dir.join(f)) != Some(kit.to_path_buf()) {
        return vec![];
    }
    let Some(objects) = k["objects"].as_array() else {
        return vec![];
    };
    let parts = m["parts"].as_array().expect("parts");
    let part = |name: &str| parts.iter().find(|p| p["name"] == name);
    let mut boxes = Vec::new();
    for o in objects {
        // a multi-part object (a multi-material group) is a print of its own: sliced, on the FDM
        // slicer too unless no part of the 3MF is printed by FDM
        if o["volumes"].as_array().map_or(0, Vec::len) != 1 {
            return if no_fdm_part(kit) {
                vec!["--no-fdm"]
            } else {
                vec![]
            };
        }
        let Some(p) = part(o["volumes"][0]["part"].as_str().unwrap_or("")) else {
            return vec![];
        };
        let stl = dir.join(p["file"].as_str().unwrap_or(""));
        if !files.contains(&stl) {
            return vec![];
        }
        let f = |v: &serde_json::Value| v.as_f64().expect("a number");
        let t = &o["translation_mm"];
        let b = &p["bbox_mm"];
        boxes.push((
            o["name"].to_string(),
            [0, 1].map(|i| f(&b["min"][i]) + f(&t[i])),
            [0, 1].map(|i| f(&b["max"][i]) + f(&t[i])),
        ));
    }
    for (i, (na, lo_a, hi_a)) in boxes.iter().enumerate() {
        for (nb, lo_b, hi_b) in &boxes[i + 1..] {
            let apart = (0..2).any(|j| hi_a[j] <= lo_b[j] || hi_b[j] <= lo_a[j]);
            assert!(
                apart,
                "{}: objects {na} {lo_a:?}..{hi_a:?} and {nb} {lo_b:?}..{hi_b:?} overlap on the plate",
                kit.display()
            );
        }
    }
    vec!["--no-fdm", "--no-sla"]
}

/// Whether the manifest says that no part in an exported file is printed by FDM (its
/// `print_technology` is SLA or PolyJet): false when it does not say.
fn no_fdm_part(file: &Path) -> bool {
    technologies(file).is_some_and(|t| !t.iter().any(|t| t == "FDM"))
}

/// The print technologies (`print_technology` in manifest.json: FDM, SLA, PolyJet) of the parts
/// in an exported file: the part whose `file` it is, or every part of the kit 3MF. None when the
/// file is not listed in a manifest.json of its export folder.
fn technologies(file: &Path) -> Option<Vec<String>> {
    let dir = file
        .ancestors()
        .skip(1)
        .take(2)
        .find(|d| d.join("manifest.json").is_file())?;
    let bytes = std::fs::read(dir.join("manifest.json")).ok()?;
    let m: serde_json::Value = serde_json::from_slice(&bytes).expect("manifest.json parses");
    let parts = m["parts"].as_array()?;
    let is = |f: &serde_json::Value| f.as_str().is_some_and(|f| dir.join(f) == file);
    let chosen: Vec<&serde_json::Value> = if is(&m["kit_3mf"]["file"]) {
        parts.iter().collect()
    } else {
        parts.iter().filter(|p| is(&p["file"])).collect()
    };
    let t: Option<Vec<String>> = chosen
        .iter()
        .map(|p| p["print_technology"].as_str().map(str::to_owned))
        .collect();
    t.filter(|t| !t.is_empty())
}

/// What this test run knows of a printcheck key.
#[derive(Clone, Copy, PartialEq)]
enum Verdict {
    Running,
    Passed,
}

/// Content hashes (sha256 of the file, then the flags) being checked or passed in this run.
static PRINTCHECK: (Mutex<BTreeMap<[u8; 32], Verdict>>, Condvar) =
    (Mutex::new(BTreeMap::new()), Condvar::new());

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

/// Claims `key` for checking: false when it passed already (after waiting for a test that is
/// checking the same bytes); true when the caller must check it (and then call [`settle`]).
fn claim(key: Option<[u8; 32]>) -> bool {
    let Some(key) = key else { return true };
    let (lock, cv) = &PRINTCHECK;
    let mut map = lock.lock().unwrap_or_else(|e| e.into_inner());
    loop {
        match map.get(&key) {
            Some(Verdict::Passed) => return false,
            Some(Verdict::Running) => map = cv.wait(map).unwrap_or_else(|e| e.into_inner()),
            None => {
                map.insert(key, Verdict::Running);
                return true;
            }
        }
    }
}

/// Records the verdict of a claimed key (a failure frees it: another test checks it again).
fn settle(key: Option<[u8; 32]>, passed: bool) {
    let Some(key) = key else { return };
    let (lock, cv) = &PRINTCHECK;
    let mut map = lock.lock().unwrap_or_else(|e| e.into_inner());
    if passed {
        map.insert(key, Verdict::Passed);
    } else {
        map.remove(&key);
    }
    cv.notify_all();
}

/// [`printcheck_all`] with extra printcheck flags (e.g. `--no-fdm` for resin and PolyJet parts).
pub fn printcheck_all_with(files: &[PathBuf], flags: &'static [&'static str]) {
    let Some(pc) = printcheck() else {
        return missing(&format!(
            "printcheck (prusa-slicer on PATH, and $FABKIT_PRINTCHECK or {}: the shared/ folder \
             cloned beside the repository)",
            repo_root().join("../shared/tools/printcheck").display()
        ));
    };
    let jobs: Vec<Job> = files
        .iter()
        .map(|f| {
            let mut fl = flags.to_vec();
            if flags.is_empty() {
                if f.extension().is_some_and(|e| e == "3mf") {
                    fl = kit_3mf_flags(f, files);
                } else if no_fdm_part(f) {
                    fl = vec!["--no-fdm"];
                }
            }
            (f.clone(), fl)
        })
        .collect();
    let queue = Mutex::new(jobs);
    let results = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let Some((f, fl)) = queue.lock().unwrap().pop() else {
                    break;
                };
                let key = printcheck_key(&f, &fl);
                if !claim(key) {
                    continue;
                }
                let slot = SlicerSlot::take();
                let mut c = std::process::Command::new("bash");
                if std::env::var_os("PRINTCHECK_SLA_INI").is_none() {
                    c.env(
                        "PRINTCHECK_SLA_INI",
                        repo_root().join("tests/printcheck/sla.ini"),
                    );
                }
                let o = c.arg(&pc).arg("--strict").args(&fl).arg(&f).output();
                drop(slot);
                let passed = o
                    .as_ref()
                    .is_ok_and(|o| o.status.success() && text(&o.stdout).contains("result=PASS"));
                settle(key, passed);
                results.lock().unwrap().push((f, fl, o));
            });
        }
    });
    let failures: Vec<String> = results
        .into_inner()
        .unwrap()
        .into_iter()
        .filter_map(|(f, fl, o)| match o {
            Ok(o) if o.status.success() && text(&o.stdout).contains("result=PASS") => None,
            Ok(o) => Some(format!(
                "{} {}:\n{}{}",
                fl.join(" "),
                f.display(),
                text(&o.stdout),
                text(&o.stderr)
            )),
            Err(e) => Some(format!("{}: printcheck did not run: {e}", f.display())),
        })
        .collect();
    assert!(
        failures.is_empty(),
        "printcheck --strict failed on {} of {} files:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

/// Reads a float32 NPY file (C order) as its values.
pub fn read_npy_f32(path: &std::path::Path) -> Vec<f32> {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..6], b"\x93NUMPY");
    let (hlen, start) = match b[6] {
        1 => (u16::from_le_bytes([b[8], b[9]]) as usize, 10),
        _ => (u32::from_le_bytes([b[8], b[9], b[10], b[11]]) as usize, 12),
    };
    let header = std::str::from_utf8(&b[start..start + hlen]).unwrap();
    assert!(header.contains("'<f4'"), "{header}");
    b[start + hlen..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// What the design JSON Schema (designs/design.schema.json, `fabkit schema`) must say of a
/// design file a test writes ([`write_design`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SchemaVerdict {
    /// The schema accepts the file: every design fabkit accepts, and a design fabkit refuses
    /// only by a rule between parameters (a fit, a layer stack, a rule that depends on another
    /// section), which the schema leaves to `fabkit validate`.
    Accepts,
    /// The schema refuses the file too: an unknown key, a wrong type, a value out of the bounds
    /// fabkit checks on that parameter alone.
    Rejects,
}

/// The committed design JSON Schema.
pub fn design_schema_path() -> PathBuf {
    repo_root().join("designs/design.schema.json")
}

/// Runs tests/oracles/schema_check.py (the `jsonschema` package, draft 2020-12) on `designs`
/// against the committed schema: (exit status 0, its stdout and stderr); None when the oracle
/// python is missing (after [`missing`]).
pub fn schema_check(designs: &[PathBuf]) -> Option<(bool, String)> {
    let Some(py) = oracle_python() else {
        missing("the oracle python (jsonschema + PyYAML)");
        return None;
    };
    let o = Command::new(py)
        .arg(repo_root().join("tests/oracles/schema_check.py"))
        .arg(design_schema_path())
        .args(designs)
        .output()
        .expect("python runs");
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "schema_check.py did not run: {}{}",
        text(&o.stdout),
        text(&o.stderr)
    );
    Some((
        o.status.success(),
        format!("{}{}", text(&o.stdout), text(&o.stderr)),
    ))
}

/// Design texts whose schema verdict this test run has checked already (sha256 of the text).
static SCHEMA_CHECKED: Mutex<BTreeMap<[u8; 32], bool>> = Mutex::new(BTreeMap::new());

/// Writes the design YAML `text` to `path` and checks that the design JSON Schema says of it
/// what `verdict` says (with the oracle, [`schema_check`]; each distinct text once per test
/// run), so that the schema editors use and fabkit cannot silently disagree: every design the
/// end-to-end tests write goes through here. Panics, naming the schema's errors, when the
/// schema disagrees; skips the check as [`missing`] does without the oracle.
pub fn write_design(path: &Path, text: &str, verdict: SchemaVerdict) {
    std::fs::write(path, text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let key: [u8; 32] = Sha256::digest(text.as_bytes()).into();
    let accepts = verdict == SchemaVerdict::Accepts;
    if SCHEMA_CHECKED
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .get(&key)
        == Some(&accepts)
    {
        return;
    }
    let Some((valid, out)) = schema_check(&[path.to_path_buf()]) else {
        return;
    };
    assert_eq!(
        valid,
        accepts,
        "design.schema.json {} {} but the test says it should {}:\n{out}",
        if valid { "accepts" } else { "rejects" },
        path.display(),
        if accepts { "accept it" } else { "reject it" },
    );
    SCHEMA_CHECKED
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, accepts);
}

/// Every file under `dir` (relative path, bytes), or an empty map for a missing folder.
pub fn snapshot(dir: &std::path::Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    let mut files = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                files.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    files
}

/// `<target>/tmp/<name>`, emptied of a previous run's files: where an output that several tests
/// read is made once per test run (called once, from the `OnceLock` that holds the output; a
/// static is never dropped, so a temporary folder would outlive the run).
pub fn shared_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    if dir.exists() {
        std::fs::remove_dir_all(&dir)
            .unwrap_or_else(|e| panic!("the previous run's {}: {e}", dir.display()));
    }
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Copies the folder `from` with everything in it to `to` (which must not exist): a test's own
/// copy of an output made once per run, which it may change.
pub fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir(to).unwrap_or_else(|e| panic!("{}: {e}", to.display()));
    let mut entries: Vec<_> = std::fs::read_dir(from)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        let target = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_tree(&p, &target);
        } else {
            std::fs::copy(&p, &target).unwrap();
        }
    }
}

/// Spawns fabkit with `args` in `cwd`, held at the `n`-th arrival at the hold point `point`
/// (`fabkit_export::hold`): returns the child once it holds there (it sleeps until killed).
/// No time limit: the child either reaches the point or exits, which panics naming the point.
pub fn spawn_held(cwd: &Path, args: &[&str], point: &str, n: usize) -> std::process::Child {
    let held = cwd.join(format!(".held-{point}-{n}"));
    let _ = std::fs::remove_file(&held);
    let mut child = fabkit()
        .current_dir(cwd)
        .args(args)
        .env("FABKIT_TEST_HOLD", format!("{point}:{n}"))
        .env("FABKIT_TEST_HOLD_FILE", &held)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("fabkit starts");
    while !held.exists() {
        if let Some(status) = child.try_wait().unwrap() {
            panic!(
                "fabkit {} exited ({status}) before holding at {point}:{n}",
                args.join(" ")
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    std::fs::remove_file(&held).unwrap();
    child
}

/// The seed set of the seeded tests (`FABKIT_TEST_SEED_SET`, 0 unless set; `.ci/run` cycles
/// 0, 1 and 2): their seeds start at `1000 x set`, so a bound must hold on every set.
pub fn seed_set() -> u64 {
    let set = std::env::var("FABKIT_TEST_SEED_SET").ok();
    set.and_then(|s| s.parse().ok()).unwrap_or(0)
}

/// The index of the first line of `text` that starts with `prefix` (a progress stage in a
/// command's stderr); panics naming the prefix and the text when there is none.
pub fn line_starting(text: &str, prefix: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no `{prefix}` line: {text}"))
}
