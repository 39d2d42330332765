//! `fabkit schema`: the design JSON Schema is the committed designs/design.schema.json, every
//! library design (with each of its presets) validates against it with an independent validator
//! (tests/oracles/schema_check.py, the `jsonschema` package), and where the schema and
//! `fabkit validate` differ, the difference is a rule between parameters that `validate` names.

use crate::common::*;
use std::path::PathBuf;

const REGENERATE: &str = "cargo run -p fabkit -- schema > designs/design.schema.json";

/// The first line of every library design: editors (the YAML language server) check the file
/// against the committed schema.
const MODELINE: &str = "# yaml-language-server: $schema=../design.schema.json";

fn schema_output() -> Vec<u8> {
    let o = fabkit().arg("schema").output().expect("fabkit runs");
    assert!(o.status.success(), "fabkit schema: {}", text(&o.stderr));
    o.stdout
}

#[test]
fn schema_command_prints_the_committed_schema() {
    let out = schema_output();
    assert_eq!(out, schema_output(), "fabkit schema is not deterministic");
    let committed = std::fs::read(design_schema_path()).unwrap_or_else(|e| {
        panic!("designs/design.schema.json: {e}; regenerate it with `{REGENERATE}`")
    });
    assert!(
        out == committed,
        "designs/design.schema.json differs from `fabkit schema` (the design types changed); \
         regenerate it with `{REGENERATE}` and commit it"
    );
    let v: serde_json::Value = serde_json::from_slice(&out).expect("the schema is JSON");
    assert_eq!(
        v["$schema"], "https://json-schema.org/draft/2020-12/schema",
        "draft 2020-12"
    );
    assert_eq!(v["title"], "fabkit design");
    assert_eq!(v["$id"], "urn:fabkit:design");
    assert_eq!(
        v["additionalProperties"], false,
        "unknown top-level keys refused"
    );
    assert!(out.ends_with(b"}\n"), "one final newline");
}

/// Every library design, the crate tests' flat design, and every library design with each of
/// its presets applied (as fabkit writes it back, JSON) validate against the committed schema.
#[test]
fn library_designs_and_presets_validate_against_the_schema() {
    let lib = repo_root().join("designs/library");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&lib)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    assert_eq!(
        files.len(),
        fabkit_designs::library::LIBRARY.len(),
        "{files:?}"
    );
    for f in &files {
        let t = std::fs::read_to_string(f).unwrap();
        assert_eq!(
            t.lines().next(),
            Some(MODELINE),
            "{}: the first line names the schema for editors",
            f.display()
        );
    }
    files.push(repo_root().join("designs/tests/it/data/flat_channels.yaml"));
    let tmp = tempfile::tempdir().unwrap();
    let mut presets = 0;
    for (name, _) in fabkit_designs::library::LIBRARY {
        let d = fabkit_designs::library::load(name).unwrap();
        for p in d.presets.keys() {
            let v = d
                .with_preset(p)
                .unwrap_or_else(|e| panic!("{name} --preset {p}: {e}"));
            let f = tmp.path().join(format!("{name}_{p}.yaml"));
            std::fs::write(&f, serde_json::to_string_pretty(&v).unwrap()).unwrap();
            files.push(f);
            presets += 1;
        }
    }
    assert!(presets >= 5, "{presets} presets");
    let Some((valid, out)) = schema_check(&files) else {
        return;
    };
    assert!(valid, "designs the schema refuses:\n{out}");
    assert!(
        out.contains(&format!(" {} passed, 0 failed", files.len())),
        "{out}"
    );
}

/// `fabkit validate` on `file` in `dir`: (exit code, stderr).
fn validate(dir: &std::path::Path, file: &str) -> (Option<i32>, String) {
    let o = run(dir, &["validate", file], &[]);
    (o.status.code(), text(&o.stderr))
}

/// The schema and `fabkit validate` cannot silently disagree: a wrong type and a bound on one
/// parameter are refused by both, each naming the parameter's path (fabkit also its
/// file:line:column, or its value and rule); a design refused only by a rule between
/// parameters (markers closer than their diameter, a layer stack the core cannot hold) is
/// accepted by the schema and refused by `validate` with the parameter path, its value and
/// the rule.
#[test]
fn schema_and_validate_differ_only_by_named_rules_between_parameters() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let lib = |n: &str| {
        std::fs::read_to_string(repo_root().join(format!("designs/library/{n}.yaml"))).unwrap()
    };
    struct Case {
        what: &'static str,
        design: &'static str,
        from: &'static str,
        to: &'static str,
        verdict: SchemaVerdict,
        /// What the oracle prints: `file: path: message`.
        schema_says: &'static str,
        /// What `fabkit validate` prints on stderr (exit 2).
        fabkit_says: Vec<String>,
    }
    let cases = [
        Case {
            what: "a string where a number is",
            design: "rtac0",
            from: "  wall_thickness_mm: 1.0 ",
            to: "  wall_thickness_mm: thick ",
            verdict: SchemaVerdict::Rejects,
            schema_says: "core.wall_thickness_mm: 'thick' is not of type 'number'",
            fabkit_says: vec![
                "d.yaml:19:22: ".into(),
                "(at core.wall_thickness_mm)".into(),
            ],
        },
        Case {
            what: "a bound on one parameter",
            design: "rtac0",
            from: "draft_angle_deg: 2.0",
            to: "draft_angle_deg: 12.0",
            verdict: SchemaVerdict::Rejects,
            schema_says: "mold.draft_angle_deg: 12.0 is greater than or equal to the maximum of 10",
            fabkit_says: vec!["mold.draft_angle_deg = 12: must be in [0, 10)".into()],
        },
        Case {
            what: "markers closer than their diameter",
            design: "tactip_dualmodal",
            from: "          spacing_mm: 3.0 ",
            to: "          spacing_mm: 1.0 ",
            verdict: SchemaVerdict::Accepts,
            schema_says: "",
            fabkit_says: vec![
                "layers[0].markers[0].pattern = concentric: markers ".into(),
                "features of 1 mm overlap".into(),
            ],
        },
        Case {
            what: "a layer stack the core cannot hold",
            design: "rtac0",
            from: "outer_radius_mm: 15.0 ",
            to: "outer_radius_mm: 14.8 ",
            verdict: SchemaVerdict::Accepts,
            schema_says: "",
            fabkit_says: vec![
                "layers[2].outer_radius_mm = 14.8: must be above the outer radius of".into(),
            ],
        },
    ];
    for c in cases {
        let base = lib(c.design);
        assert_eq!(base.matches(c.from).count(), 1, "{}: {:?}", c.what, c.from);
        let file = dir.join("d.yaml");
        let yaml = base.replacen(c.from, c.to, 1);
        write_design(&file, &yaml, c.verdict);
        if let Some((valid, out)) = schema_check(std::slice::from_ref(&file)) {
            assert_eq!(
                valid,
                c.verdict == SchemaVerdict::Accepts,
                "{}: {out}",
                c.what
            );
            let said = format!("{}: {}", file.display(), c.schema_says);
            assert!(
                valid || out.contains(&said),
                "{}: expected {said:?} in\n{out}",
                c.what
            );
        }
        let (code, err) = validate(dir, "d.yaml");
        assert_eq!(
            code,
            Some(2),
            "{}: fabkit validate accepted it: {err}",
            c.what
        );
        for s in &c.fabkit_says {
            assert!(
                err.contains(s.as_str()),
                "{}: expected {s:?} in\n{err}",
                c.what
            );
        }
        assert!(!err.contains("panicked"), "{err}");
    }
    // the baselines themselves are accepted by both
    for d in ["rtac0", "tactip_dualmodal"] {
        write_design(&dir.join("d.yaml"), &lib(d), SchemaVerdict::Accepts);
        let (code, err) = validate(dir, "d.yaml");
        assert_eq!(code, Some(0), "{d}: {err}");
    }
}
