//! End to end: extreme but finite values given as a user gives them, in a preset and in a
//! sweep, with the fabkit binary under a 2 GiB address-space limit (`ulimit -v`): each is
//! refused by name with exit 2, or recorded as one variant's result while the sweep goes on;
//! none aborts, panics or is killed.

use crate::common::{repo_root, text};
use std::path::Path;
use std::process::Output;

/// Address space of the fabkit process, KiB (`ulimit -v`).
const ADDRESS_SPACE_KIB: u64 = 2 << 20;

/// fabkit `args` in `cwd` under the address-space limit.
fn run_limited(cwd: &Path, args: &[&str]) -> Output {
    crate::common::run_limited(cwd, args, &[], ADDRESS_SPACE_KIB)
}

/// ShadowTac's YAML with the first line holding `from` replaced by `to`.
fn shadowtac_with(dir: &Path, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(repo_root().join("designs/library/shadowtac.yaml"))
        .unwrap()
        .replacen(from, to, 1);
    std::fs::write(dir.join("shadowtac.yaml"), &text).unwrap();
    text
}

/// A concentric spacing of 1e-300 mm in a preset grew `fabkit validate --preset` to 24 GB
/// before it was killed; a preset value out of an integer's range was reported without its
/// path or place in the file.
#[test]
fn extreme_preset_values_are_refused_by_path() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    shadowtac_with(d, "pattern.spacing_mm: 1.4", "pattern.spacing_mm: 1.0e-300");
    let o = run_limited(d, &["validate", "shadowtac.yaml", "--preset", "paper_text"]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("layers[0].markers[0].pattern.spacing_mm = 1e-300: must be 0 or a length of at least 0.001 mm"),
        "{err}"
    );

    let yaml = shadowtac_with(
        d,
        "pattern.rings: null",
        "pattern.rings: 18446744073709551616",
    );
    let line = 1 + yaml
        .lines()
        .position(|l| l.contains("rings: 18446744073709551616"))
        .unwrap();
    let o = run_limited(d, &["validate", "shadowtac.yaml", "--preset", "paper_text"]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!(
            "shadowtac.yaml:{line}:41: presets.paper_text: layers[0].markers[0].pattern.rings = 18446744073709551616"
        )),
        "{err}"
    );
}

/// One variant of a vanishing marker spacing aborted a whole sweep, and nothing was recorded:
/// it is recorded with the rule it breaks, and the other variant is built.
#[test]
fn a_sweep_with_one_extreme_variant_records_it_and_finishes() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::write(
        d.join("sweep.yaml"),
        "base: shadowtac
preset: paper_text
chord_tolerance_mm: 0.05
vary:
  layers[0].markers[0].pattern.spacing_mm: [1.0e-300, 1.8]
mode: grid
outputs: [metrics]
",
    )
    .unwrap();
    let o = run_limited(d, &["sweep", "sweep.yaml", "--out", "out"]);
    assert!(
        o.status.success(),
        "{}\n{}",
        text(&o.stdout),
        text(&o.stderr)
    );
    let rows: Vec<serde_json::Value> = std::fs::read_to_string(d.join("out/results.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["status"], "infeasible", "{}", rows[0]);
    let errors = rows[0]["errors"].to_string();
    assert!(
        errors.contains("layers[0].markers[0].pattern.spacing_mm = 1e-300"),
        "{errors}"
    );
    assert_eq!(rows[1]["status"], "ok", "{}", rows[1]);
}
