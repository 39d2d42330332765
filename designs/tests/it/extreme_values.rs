//! Extreme but finite values in every numeric field of every library design, written into the
//! design's YAML text directly and through a preset, as a user would: 1e-300, 5e-324, 1e-12,
//! 1e12 and 1e300 in every floating-point field, 2^31, 2^32 + 1, 2^63 and 2^64 in every
//! integer field. Each case either is refused with an error that names the field's path, or
//! validates and builds into closed, consistently oriented 2-manifolds. The walk runs in a
//! child process under a 2 GiB address-space limit, each case within 20 s: a rule that
//! allocates before it refuses aborts the child, and the parent names the case.

use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::values::{integer_paths, number_paths, NumberPath, Step};
use fabkit_designs::{build_kit_bounded, flat, library, stack, ChordTolerance, Design};
use std::time::{Duration, Instant};

/// Floating-point values of the walk.
const FLOATS: [&str; 5] = ["1e-300", "5e-324", "1e-12", "1e12", "1e300"];
/// Integer values of the walk: 2^31, 2^32 + 1, 2^63, 2^64.
const INTEGERS: [&str; 4] = [
    "2147483648",
    "4294967297",
    "9223372036854775808",
    "18446744073709551616",
];
/// Address space of the child, bytes.
const ADDRESS_SPACE_BYTES: u64 = 2 << 30;
/// Longest one case may take.
const CASE_LIMIT: Duration = Duration::from_secs(20);
/// The child's variable: the design to walk.
const CHILD_ENV: &str = "FABKIT_EXTREME_VALUES_DESIGN";
/// A string no design holds, replaced by the literal value in the YAML text.
const MARK: &str = "@@extreme@@";

#[test]
fn every_numeric_field_takes_extreme_values_under_a_memory_limit() {
    use std::os::unix::process::CommandExt;
    let exe = std::env::current_exe().unwrap();
    for (name, _) in library::LIBRARY {
        let mut cmd = std::process::Command::new(&exe);
        cmd.args([
            "--exact",
            "extreme_values::walk_one_design",
            "--ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(CHILD_ENV, name);
        // SAFETY: setrlimit is async-signal-safe and touches no state of the parent.
        unsafe {
            cmd.pre_exec(|| {
                let lim = libc::rlimit {
                    rlim_cur: ADDRESS_SPACE_BYTES,
                    rlim_max: ADDRESS_SPACE_BYTES,
                };
                if libc::setrlimit(libc::RLIMIT_AS, &lim) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let out = cmd.output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let last_case = stdout
            .lines()
            .rev()
            .find_map(|l| l.strip_prefix("case: "))
            .unwrap_or("(none started)");
        assert!(
            out.status.success() && stdout.contains("walked: "),
            "{name}: the walk ended with {} during case {last_case}\n{}\n{}",
            out.status,
            tail(&stdout),
            tail(&stderr)
        );
        eprintln!(
            "{}",
            stdout
                .lines()
                .filter(|l| l.starts_with("walked: ") || l.starts_with("built: "))
                .collect::<Vec<_>>()
                .join("\n")
        );
    }
}

fn tail(s: &str) -> String {
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(30)..].join("\n")
}

/// `d` as YAML text (JSON is YAML) with the value at `path` written as the literal `x`, or,
/// with `preset`, the design unchanged and a preset of that name setting `path` to `x`.
fn yaml_with(d: &Design, path: &NumberPath, x: &str, preset: Option<&str>) -> String {
    let mut v = serde_json::to_value(d).unwrap();
    match preset {
        None => *slot(&mut v, &path.0) = serde_json::Value::String(MARK.into()),
        Some(p) => {
            v["presets"][p] = serde_json::json!({ path.to_string(): MARK });
        }
    }
    serde_json::to_string_pretty(&v)
        .unwrap()
        .replace(&format!("\"{MARK}\""), x)
}

fn slot<'a>(v: &'a mut serde_json::Value, path: &[Step]) -> &'a mut serde_json::Value {
    match path.split_first() {
        None => v,
        Some((Step::Key(k), rest)) => slot(&mut v[k.as_str()], rest),
        Some((Step::Index(i), rest)) => slot(&mut v[*i], rest),
    }
}

/// The walk of one library design (run by the test above in a child process).
#[test]
#[ignore = "run by every_numeric_field_takes_extreme_values_under_a_memory_limit"]
fn walk_one_design() {
    let Ok(name) = std::env::var(CHILD_ENV) else {
        return;
    };
    let materials = MaterialsTable::embedded().unwrap();
    let tol = ChordTolerance::new(0.05).unwrap();
    let d = library::load(&name).unwrap();
    let origin = format!("{name}.yaml");
    let mut cases = Vec::new();
    for p in number_paths(&d, &["presets"]).unwrap() {
        cases.extend(FLOATS.iter().map(|x| (p.clone(), *x)));
    }
    for p in integer_paths(&d, &["presets"]).unwrap() {
        cases.extend(INTEGERS.iter().map(|x| (p.clone(), *x)));
    }
    let (mut refused, mut built) = (0, Vec::new());
    for (path, x) in &cases {
        let p = path.to_string();
        println!("case: {name}: {p} = {x}");
        let t0 = Instant::now();
        // directly
        let direct = Design::from_yaml(&yaml_with(&d, path, x, None), &origin);
        // through a preset: the same design, or an error naming the path in the preset
        let text = yaml_with(&d, path, x, Some("extreme"));
        let preset = Design::from_yaml(&text, &origin)
            .unwrap()
            .with_preset_in("extreme", &text, &origin);
        let m = match (direct, preset) {
            (Err(a), Err(b)) => {
                for e in [a.to_string(), b.to_string()] {
                    assert!(
                        e.contains(&p) && e.contains(&format!("{origin}:")),
                        "{name}: {p} = {x}: the error names neither the path nor file:line:col: {e}"
                    );
                }
                refused += 1;
                continue;
            }
            (Ok(mut a), Ok(b)) => {
                a.name = b.name.clone();
                a.presets = b.presets.clone();
                assert_eq!(a, b, "{name}: {p} = {x}: preset and direct designs differ");
                a
            }
            (a, b) => panic!(
                "{name}: {p} = {x}: direct {:?}, through a preset {:?}",
                a.err().map(|e| e.to_string()),
                b.err().map(|e| e.to_string())
            ),
        };
        let valid = if m.body.flat_outline().is_some() {
            flat::validate(&m, &materials).map(|_| ())
        } else {
            stack::validate(&m, &materials, tol).map(|_| ())
        };
        match valid {
            Err(e) => {
                assert!(
                    e.0.iter().any(|e| e.path == p),
                    "{name}: {p} = {x}: refused, but no error names it: {e}"
                );
                refused += 1;
            }
            Ok(()) => {
                let kit = build_kit_bounded(&m, tol, 4_000_000)
                    .unwrap_or_else(|e| panic!("{name}: {p} = {x} validates but fails: {e}"));
                for part in &kit.parts {
                    part.solid
                        .mesh()
                        .check_closed_manifold()
                        .unwrap_or_else(|e| panic!("{name}: {p} = {x}: {}: {e}", part.name));
                }
                built.push(format!("{p} = {x}"));
            }
        }
        assert!(
            t0.elapsed() < CASE_LIMIT,
            "{name}: {p} = {x} took {:?}",
            t0.elapsed()
        );
    }
    println!(
        "walked: {name}: {} cases, {refused} refused by name, {} built",
        cases.len(),
        built.len()
    );
    println!("built: {name}: {}", built.join(", "));
}
