//! Extreme but finite values given as a user gives them, under a 2 GiB address-space limit
//! (`ulimit -v`): each is refused by name (exit 2 for the CLI), or builds closed, consistently
//! oriented 2-manifolds, or is recorded as one variant's result while a sweep goes on; none
//! aborts, panics or is killed.
//!
//! The walks: every numeric field of every library design, written into the design's YAML
//! text directly and through a preset, and every numeric fixture parameter (the defaults with
//! two generated semi-domes or semi-plates and every library indenter, on R-Tac0's curved skin
//! and on the flat skin of Soter et al. with its grid plate, and R-Tac0's published pin dome),
//! written into a fixture parameter file: 1e-300, 5e-324, 1e-12, 1e12 and 1e300 in every
//! floating-point field, 2^31, 2^32 + 1, 2^63 and 2^64 in every integer field. Each walk runs
//! in a child process (this test binary, one ignored test) under the limit: a rule that
//! allocates before it refuses aborts the child, and the parent names the case. The work of a
//! case is bounded by triangles, not by time (a design builds under a limit of 4,000,000, a
//! fixture set is first asked to stop at one triangle and built only when that is its refusal),
//! so a fast or a slow machine gives the same result. What builds is exported (STL, 3MF and
//! the manifest) into a temporary folder.

use crate::common::{repo_root, run_program_limited, text};
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::schema::Design;
use fabkit_designs::values::{integer_paths, number_paths, NumberPath, Step};
use fabkit_designs::{build_kit_bounded, library, stack, ChordTolerance, DesignError};
use fabkit_fixtures::build_fixtures;
use fabkit_fixtures::params::{apply_pin_preset, from_yaml, FixtureParams};
use std::path::Path;
use std::process::Output;

/// Floating-point values of the walks.
const FLOATS: [&str; 5] = ["1e-300", "5e-324", "1e-12", "1e12", "1e300"];
/// Integer values of the walks: 2^31, 2^32 + 1, 2^63, 2^64.
const INTEGERS: [&str; 4] = [
    "2147483648",
    "4294967297",
    "9223372036854775808",
    "18446744073709551616",
];
/// The child's variable: which walk to run.
const WALK_ENV: &str = "FABKIT_EXTREME_VALUES_WALK";
/// A string no design holds, replaced by the literal value in the YAML text.
const MARK: &str = "@@extreme@@";
/// The fixture walks: (design, parameters).
const FIXTURE_WALKS: [(&str, &str); 3] = [
    ("rtac0", "defaults"),
    ("soter_channels", "defaults"),
    ("rtac0", "rtac0 pins"),
];

/// Runs the ignored test `walk` of this binary once per value of `walks` (in [`WALK_ENV`])
/// under the address-space limit; fails naming the case a child ended in.
fn walk_in_children(walk: &str, walks: &[String]) {
    let exe = std::env::current_exe().unwrap();
    let test = format!("extreme_values::{walk}");
    for w in walks {
        let out = run_program_limited(
            &exe,
            Path::new("."),
            &[
                "--exact",
                &test,
                "--ignored",
                "--nocapture",
                "--test-threads=1",
            ],
            &[(WALK_ENV, w)],
            ADDRESS_SPACE_KIB,
        );
        let stdout = text(&out.stdout);
        let last_case = stdout
            .lines()
            .rev()
            .find_map(|l| l.strip_prefix("case: "))
            .unwrap_or("(none started)");
        let tail = |s: &str| {
            let lines: Vec<&str> = s.lines().collect();
            lines[lines.len().saturating_sub(30)..].join("\n")
        };
        assert!(
            out.status.success() && stdout.contains("walked: "),
            "{w}: the walk ended with {} during case {last_case}\n{}\n{}",
            out.status,
            tail(&stdout),
            tail(&text(&out.stderr))
        );
        for l in stdout.lines().filter(|l| l.starts_with("walked: ")) {
            eprintln!("{l}");
        }
    }
}

/// Every (path, value) case of `value` (as serialized): the floats at its floating-point
/// fields, the integers at its integer fields.
fn cases_of(value: &serde_json::Value, skip: &[&str]) -> Vec<(NumberPath, &'static str)> {
    let mut cases = Vec::new();
    for p in number_paths(value, skip).unwrap() {
        cases.extend(FLOATS.iter().map(|x| (p.clone(), *x)));
    }
    for p in integer_paths(value, skip).unwrap() {
        cases.extend(INTEGERS.iter().map(|x| (p.clone(), *x)));
    }
    cases
}

/// `value` (serialized) as YAML text (JSON is YAML) with the number at `path` written as the literal `x`,
/// or, with `preset`, `value` unchanged and a preset of that name setting `path` to `x`.
fn yaml_with(
    value: &serde_json::Value,
    path: &NumberPath,
    x: &str,
    preset: Option<&str>,
) -> String {
    fn slot<'a>(v: &'a mut serde_json::Value, path: &[Step]) -> &'a mut serde_json::Value {
        match path.split_first() {
            None => v,
            Some((Step::Key(k), rest)) => slot(&mut v[k.as_str()], rest),
            Some((Step::Index(i), rest)) => slot(&mut v[*i], rest),
        }
    }
    let mut v = value.clone();
    match preset {
        None => *slot(&mut v, &path.0) = serde_json::Value::String(MARK.into()),
        Some(p) => v["presets"][p] = serde_json::json!({ path.to_string(): MARK }),
    }
    serde_json::to_string_pretty(&v)
        .unwrap()
        .replace(&format!("\"{MARK}\""), x)
}

/// An error of a YAML text: it names the parameter path and the file's line and column.
#[track_caller]
fn assert_names(e: &str, path: &str, origin: &str, case: &str) {
    assert!(
        e.contains(path) && e.contains(&format!("{origin}:")),
        "{case}: the error names neither the path nor file:line:col: {e}"
    );
}

/// Every part of `kit` is a closed, consistently oriented 2-manifold, and the kit exports as
/// STL and 3MF with its manifest.
#[track_caller]
fn export(
    kit: &fabkit_designs::kit::Kit,
    printers: &fabkit_designs::schema::PrinterProfiles,
    case: &str,
) {
    for part in &kit.parts {
        part.solid
            .mesh()
            .check_closed_manifold()
            .unwrap_or_else(|e| panic!("{case}: {}: {e}", part.name));
    }
    let tmp = tempfile::tempdir().unwrap();
    let opts = fabkit_export::ExportOptions::for_design(
        fabkit_export::Formats {
            stl: true,
            threemf: true,
            step: false,
            mjcf: false,
            urdf: false,
            usd: false,
        },
        vec!["extreme_values".into()],
        case,
        &"0".repeat(64),
        0.05,
        printers.clone(),
    );
    fabkit_export::write_kit(kit, &tmp.path().join("out"), &opts)
        .unwrap_or_else(|e| panic!("{case}: builds but does not export: {e}"));
}

#[test]
fn every_numeric_design_field_takes_extreme_values_under_a_memory_limit() {
    let names: Vec<String> = library::LIBRARY
        .iter()
        .map(|(n, _)| n.to_string())
        .collect();
    walk_in_children("walk_one_design", &names);
}

#[test]
fn every_fixture_parameter_takes_extreme_values_under_a_memory_limit() {
    let walks: Vec<String> = (0..FIXTURE_WALKS.len()).map(|i| i.to_string()).collect();
    walk_in_children("walk_one_fixture_set", &walks);
}

/// The walk of one library design.
#[test]
#[ignore = "run by every_numeric_design_field_takes_extreme_values_under_a_memory_limit"]
fn walk_one_design() {
    let Ok(name) = std::env::var(WALK_ENV) else {
        return;
    };
    let materials = MaterialsTable::embedded().unwrap();
    let tol = ChordTolerance::new(0.05).unwrap();
    let d = serde_json::to_value(library::load(&name).unwrap()).unwrap();
    let origin = format!("{name}.yaml");
    let cases = cases_of(&d, &["presets"]);
    let (mut refused, mut built) = (0, Vec::new());
    for (path, x) in &cases {
        let p = path.to_string();
        let case = format!("{name}: {p} = {x}");
        println!("case: {case}");
        let direct = Design::from_yaml(&yaml_with(&d, path, x, None), &origin);
        // through a preset: the same design, or an error naming the path in the preset
        let text = yaml_with(&d, path, x, Some("extreme"));
        let preset = Design::from_yaml(&text, &origin)
            .unwrap()
            .with_preset_in("extreme", &text, &origin);
        let m = match (direct, preset) {
            (Err(a), Err(b)) => {
                assert_names(&a.to_string(), &p, &origin, &case);
                assert_names(&b.to_string(), &p, &origin, &case);
                refused += 1;
                continue;
            }
            (Ok(mut a), Ok(b)) => {
                a.name = b.name.clone();
                a.presets = b.presets.clone();
                assert_eq!(a, b, "{case}: preset and direct designs differ");
                a
            }
            (a, b) => panic!(
                "{case}: direct {:?}, through a preset {:?}",
                a.err().map(|e| e.to_string()),
                b.err().map(|e| e.to_string())
            ),
        };
        let valid = if m.body.flat_outline().is_some() {
            stack::flat::validate(&m, &materials).map(|_| ())
        } else {
            stack::validate(&m, &materials, tol).map(|_| ())
        };
        match valid {
            Err(e) => {
                assert!(
                    e.0.iter().any(|e| e.path == p),
                    "{case}: refused, but no error names it: {e}"
                );
                refused += 1;
            }
            // the optics change no part: resolved (the lights as a render takes them), not built
            Ok(()) if p.starts_with("optics.") => {
                fabkit_designs::optics::of_design(&m, tol)
                    .unwrap_or_else(|e| panic!("{case} validates but its optics fail: {e}"));
                built.push(format!("{p} = {x}"));
            }
            Ok(()) => {
                let kit = build_kit_bounded(&m, tol, 4_000_000)
                    .unwrap_or_else(|e| panic!("{case} validates but fails: {e}"));
                export(&kit, &m.printers, &case);
                built.push(format!("{p} = {x}"));
            }
        }
    }
    println!(
        "walked: {name}: {} cases, {refused} refused by name, {} built: {}",
        cases.len(),
        built.len(),
        built.join(", ")
    );
}

/// The walk of one of [`FIXTURE_WALKS`].
#[test]
#[ignore = "run by every_fixture_parameter_takes_extreme_values_under_a_memory_limit"]
fn walk_one_fixture_set() {
    let Some((design, which)) = std::env::var(WALK_ENV)
        .ok()
        .and_then(|i| FIXTURE_WALKS.get(i.parse::<usize>().ok()?))
    else {
        return;
    };
    let d = library::load(design).unwrap();
    let tol = ChordTolerance::new(0.05).unwrap();
    let mut params = FixtureParams::default();
    if *which == "rtac0 pins" {
        apply_pin_preset(&mut params, "rtac0").unwrap();
    } else {
        params.semidomes.generate = 2;
        params.semiplates.generate = 2;
        params.indenters = Some(fabkit_fixtures::indenters::default_indenters());
    }
    let origin = "fixtures.yaml";
    let params = serde_json::to_value(&params).unwrap();
    let cases = cases_of(&params, &[]);
    let (mut refused, mut built) = (0, Vec::new());
    for (path, x) in &cases {
        let p = path.to_string();
        let case = format!("{design}, {which}: {p} = {x}");
        println!("case: {case}");
        match from_yaml(&yaml_with(&params, path, x, None), origin) {
            Err(e) => {
                assert_names(&e.to_string(), &p, origin, &case);
                refused += 1;
            }
            // a limit of one triangle: what validates stops at the work estimate
            Ok(m) => match build_fixtures(&d, &m, tol, 1, "test") {
                Err(DesignError::Params(e)) => {
                    assert!(
                        e.0.iter().any(|e| e.path == p),
                        "{case}: refused, but no error names it: {e}"
                    );
                    refused += 1;
                }
                Err(DesignError::WorkLimit(_)) => {
                    let set = build_fixtures(&d, &m, tol, 20_000_000, "test")
                        .unwrap_or_else(|e| panic!("{case} validates but fails: {e}"));
                    export(&set.kit, &d.printers, &case);
                    built.push(format!("{p} = {x}"));
                }
                Err(e) => panic!("{case}: {e}"),
                Ok(_) => panic!("{case}: built past a limit of one triangle"),
            },
        }
    }
    println!(
        "walked: {design}, {which}: {} cases, {refused} refused by name, {} built: {}",
        cases.len(),
        built.len(),
        built.join(", ")
    );
}

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
