//! The check a refactor runs: every library design exported as is and with each of its
//! presets (`fabkit export NAME [--preset P] --out kit`), and `fabkit fixtures NAME --out fx`
//! for each design, every file written hashed (sha256) against the list committed in
//! `tests/e2e/output_hashes.txt`. A change meant to keep every output byte-identical (a
//! restructuring of the designs crate, a faster kernel) shows here as "no difference"; a
//! change meant to alter outputs re-blesses the list and shows, in the list's diff, exactly
//! which files changed.
//!
//! It runs with the suite (`scripts/test`, so in CI): a refactor that changes an output fails
//! before it lands. It writes 21 outputs (about 40 s with the quick profile). The hashes are of
//! one platform's floating point, the one CI and the development machines use (recorded in
//! the list's first line, `# platform: x86_64-linux`); on another the test says so and checks
//! nothing. Run it before and after a refactor, and bless the list in the commit that changes
//! outputs on purpose:
//!
//! ```sh
//! cargo test --profile quick -p fabkit --test e2e outputs_are_byte_identical
//! FABKIT_BLESS=1 cargo test --profile quick -p fabkit --test e2e outputs_are_byte_identical
//! ```
//!
//! `step_files_are_byte_identical_to_the_committed_hashes` does the same with `--format step`
//! for the STEP files, against `tests/e2e/output_hashes_step.txt` (CadQuery's OCCT writes the
//! same bytes every run for most files, whatever the size of its thread pool: no time stamp in
//! the header, booleans that give the same B-rep on any number of threads; not for a compound
//! of many holes or tips, the pin domes', DIGIT Pinki's `semidome_empty` and the TacTip's skin
//! tips', which differ between runs single-threaded too). It takes about 4 minutes (214 s on
//! 2 cores, 2026-11-30), so it is ignored; the suite checks the default design's STEP files
//! (`the_default_designs_step_files_are_byte_identical_to_the_committed_hashes`):
//!
//! ```sh
//! cargo test --profile quick -p fabkit --test e2e -- --ignored step_files_are_byte_identical
//! ```
//!
//! The commands run as `fabkit` from the PATH in an empty folder with relative `--out`
//! folders, so that the command lines the outputs record are the same in every checkout.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use sha2::{Digest, Sha256};

use crate::common::{repo_root, text};

/// The committed list, relative to the repository.
const LIST: &str = "tests/e2e/output_hashes.txt";

/// The committed list of the STEP files' hashes (`--format step`), relative to the repository.
const STEP_LIST: &str = "tests/e2e/output_hashes_step.txt";

/// `fabkit ARGS` in `cwd`, the binary found on the PATH as `fabkit`; panics unless it succeeds.
fn fabkit_on_path(cwd: &Path, args: &[&str]) {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_fabkit"));
    let path = std::env::join_paths(std::iter::once(bin.parent().unwrap().to_path_buf()).chain(
        std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()),
    ))
    .unwrap();
    let o = Command::new("fabkit")
        .args(args)
        .current_dir(cwd)
        .env("PATH", path)
        .output()
        .expect("fabkit runs");
    assert!(
        o.status.success(),
        "fabkit {}: {}{}",
        args.join(" "),
        text(&o.stdout),
        text(&o.stderr)
    );
}

/// The library's designs and their presets, as `fabkit designs` lists them.
fn designs(cwd: &Path) -> Vec<(String, Vec<String>)> {
    let o = crate::common::run(cwd, &["designs"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    text(&o.stdout)
        .lines()
        .map(|l| {
            let name = l.split_whitespace().next().unwrap().to_string();
            let presets = l
                .split("presets: ")
                .nth(1)
                .map(|p| p.split(", ").map(|s| s.trim().to_string()).collect())
                .unwrap_or_default();
            (name, presets)
        })
        .collect()
}

/// Every file under `dir`, by its path relative to `root` ('/'-separated), with its sha256.
fn hash_tree(root: &Path, dir: &Path, out: &mut BTreeMap<String, String>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            hash_tree(root, &p, out);
        } else {
            let rel = p.strip_prefix(root).unwrap();
            let key = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect::<Vec<_>>()
                .join("/");
            let digest = Sha256::digest(std::fs::read(&p).unwrap());
            let hex: String = digest.iter().map(|b| format!("{b:02x}")).collect();
            out.insert(key, hex);
        }
    }
}

/// Hashes of every output of every library design, its presets and its fixtures, written
/// with `extra` arguments (`--format step`), the files kept by `keep` (by their relative path).
fn library_outputs(extra: &[&str], keep: impl Fn(&str) -> bool) -> BTreeMap<String, String> {
    let dir = tempfile::tempdir().unwrap();
    let mut hashes = BTreeMap::new();
    for (name, presets) in designs(dir.path()) {
        let mut jobs: Vec<(String, Vec<String>)> = vec![(
            format!("export/{name}"),
            vec!["export".into(), name.clone()],
        )];
        for p in &presets {
            jobs.push((
                format!("export/{name}_{p}"),
                vec!["export".into(), name.clone(), "--preset".into(), p.clone()],
            ));
        }
        // A design's default fixtures are its paper's: R-Tac0's are its published dome and 100
        // semi-domes, 100 parts of one generator; two of them keep the STEP run bounded.
        let mut fixtures = vec!["fixtures".to_string(), name.clone()];
        if fabkit_fixtures::params::PAPER_KITS
            .iter()
            .any(|(d, _)| *d == name)
        {
            fixtures.extend(["--semidomes".into(), "2".into()]);
        }
        jobs.push((format!("fixtures/{name}"), fixtures));
        for (out, mut args) in jobs {
            args.extend(["--out".into(), out.clone()]);
            args.extend(extra.iter().map(|a| (*a).to_string()));
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            fabkit_on_path(dir.path(), &args);
            hash_tree(dir.path(), &dir.path().join(&out), &mut hashes);
        }
    }
    hashes.retain(|f, _| keep(f));
    hashes
}

/// Asserts that `hashes` are the ones listed in `list` (relative to the repository), every
/// file that is new, changed or gone named; with `FABKIT_BLESS=1` the list is rewritten first.
fn assert_listed(hashes: &BTreeMap<String, String>, list: &str) {
    let listed: String = std::iter::once(format!("# platform: {}\n", platform()))
        .chain(hashes.iter().map(|(f, h)| format!("{h}  {f}\n")))
        .collect();
    let path = repo_root().join(list);
    if std::env::var("FABKIT_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(&path, &listed).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    let parse = |t: &str| -> BTreeMap<String, String> {
        t.lines()
            .filter_map(|l| l.split_once("  "))
            .map(|(h, f)| (f.to_string(), h.to_string()))
            .collect()
    };
    let before = parse(&committed);
    let mut differ = Vec::new();
    for (f, h) in hashes {
        match before.get(f) {
            None => differ.push(format!("new: {f}")),
            Some(b) if b != h => differ.push(format!("changed: {f}")),
            _ => {}
        }
    }
    differ.extend(
        before
            .keys()
            .filter(|f| !hashes.contains_key(*f))
            .map(|f| format!("gone: {f}")),
    );
    assert!(
        differ.is_empty(),
        "{} of {} files differ from {list} (FABKIT_BLESS=1 rewrites it):\n{}",
        differ.len(),
        hashes.len(),
        differ.join("\n")
    );
}

#[test]
fn outputs_are_byte_identical_to_the_committed_hashes() {
    if !on_listed_platform(LIST) {
        return;
    }
    assert_listed(&library_outputs(&[], |_| true), LIST);
}

/// In the suite (so in CI, where `FABKIT_CADQUERY_PYTHON` is set): the STEP files of the
/// default design's export against their lines of the committed STEP list. The whole list
/// takes about 4 minutes and is run by hand; R-Tac0's export is the twins' shared one
/// ([`crate::cad_twins::shared_step_export`]), and OCCT writes its files the same every run
/// (four runs measured, and four more with parallel booleans). The pin dome's `pin_dome.step`
/// (fixtures) is
/// not held to it: OCCT writes its compound of many holes differently from run to run (one run
/// in three measured), as it does the TacTip's `skin_tips`.
#[test]
fn the_default_designs_step_files_are_byte_identical_to_the_committed_hashes() {
    if crate::common::cadquery_python().is_none() {
        eprintln!("SKIPPED: STEP hashes (set FABKIT_CADQUERY_PYTHON; .ci/run does)");
        return;
    }
    if !on_listed_platform(STEP_LIST) {
        return;
    }
    // R-Tac0's STEP export of the twins' shared exports (`--format stl,3mf,step`: the same
    // STEP files as `--format step`, whose hashes the list holds under `export/rtac0/`)
    let out = "export/rtac0";
    let shared = crate::cad_twins::shared_step_export("rtac0").expect("CadQuery is set");
    let mut found = BTreeMap::new();
    hash_tree(shared, shared, &mut found);
    let hashes: BTreeMap<String, String> = found
        .into_iter()
        .filter(|(f, _)| f.ends_with(".step"))
        .map(|(f, h)| (format!("{out}/{f}"), h))
        .collect();
    let committed = std::fs::read_to_string(repo_root().join(STEP_LIST)).unwrap();
    let listed: BTreeMap<String, String> = committed
        .lines()
        .filter_map(|l| l.split_once("  "))
        .filter(|(_, f)| f.starts_with(&format!("{out}/")))
        .map(|(h, f)| (f.to_string(), h.to_string()))
        .collect();
    assert!(listed.len() >= 10, "{} files of {out} listed", listed.len());
    assert_eq!(
        hashes, listed,
        "the STEP files of {out} differ from {STEP_LIST} (bless the list with the ignored full test)"
    );
}

/// This build's platform, as the lists record it: `<arch>-<os>` (`x86_64-linux`).
fn platform() -> String {
    format!("{}-{}", std::env::consts::ARCH, std::env::consts::OS)
}

/// Whether `list` (relative to the repository) holds this platform's hashes (its first line,
/// `# platform: <arch>-<os>`); says so on stderr when not.
fn on_listed_platform(list: &str) -> bool {
    let text = std::fs::read_to_string(repo_root().join(list)).unwrap_or_default();
    let listed = text
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("# platform: "))
        .unwrap_or("")
        .trim()
        .to_string();
    let ours = platform();
    let bless = std::env::var("FABKIT_BLESS").is_ok_and(|v| v == "1");
    if listed != ours && !bless {
        eprintln!("{list}: the hashes are of platform '{listed}', this is '{ours}': not compared (floating point differs between platforms)");
        return false;
    }
    true
}

/// The same for the STEP files (`--format step`, through the CadQuery twins): the exact solids
/// of every part, fixture and assembly. Needs the CadQuery environment
/// (`scripts/setup-cadquery` or `FABKIT_CADQUERY_PYTHON`); about 4 minutes. OCCT does not always
/// write a compound of many solids with the same bytes (the TacTip's `skin_tips`, over a
/// hundred tips): rerun before believing a change in one such file alone.
#[test]
#[ignore = "a refactor's check: writes every library design's STEP files (see the module docs)"]
fn step_files_are_byte_identical_to_the_committed_hashes() {
    if !on_listed_platform(STEP_LIST) {
        return;
    }
    let hashes = library_outputs(&["--format", "step"], |f| f.ends_with(".step"));
    assert!(!hashes.is_empty(), "no STEP file written");
    assert_listed(&hashes, STEP_LIST);
}
