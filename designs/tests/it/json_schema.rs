//! The design JSON Schema generated from the design types ([`design_json_schema`], `fabkit
//! schema`): unknown keys refused everywhere, every length and angle bounded as
//! `values::check_values` bounds it, deterministic text. Validating designs against it is the
//! end-to-end tests' part (tests/e2e/schema.rs, with an independent validator).

use fabkit_designs::schema::{
    design_json_schema, design_json_schema_text, plain_text, DESIGN_SIGNED_MM,
};
use fabkit_designs::values::{MAX_ANGLE_DEG, MAX_LENGTH_MM};
use serde_json::Value;

/// A visitor of subschemas: (the property name that leads to the schema, the nearest one above
/// for list items and branches, "" at the top and for definitions; whether the schema is the
/// property's own; the schema).
type Visit<'a> = &'a mut dyn FnMut(&str, bool, &serde_json::Map<String, Value>);

/// Calls `f` for every subschema of `v`.
fn each_schema(v: &Value, key: &str, own: bool, f: Visit) {
    let Value::Object(m) = v else { return };
    f(key, own, m);
    if let Some(Value::Object(props)) = m.get("properties") {
        for (k, sub) in props {
            each_schema(sub, k, true, f);
        }
    }
    for k in ["items", "additionalProperties"] {
        if let Some(sub) = m.get(k) {
            each_schema(sub, key, false, f);
        }
    }
    for k in ["prefixItems", "anyOf", "oneOf", "allOf"] {
        if let Some(Value::Array(subs)) = m.get(k) {
            for sub in subs {
                each_schema(sub, key, false, f);
            }
        }
    }
    if let Some(Value::Object(defs)) = m.get("$defs") {
        for sub in defs.values() {
            each_schema(sub, "", false, f);
        }
    }
}

fn is_number(m: &serde_json::Map<String, Value>) -> bool {
    match m.get("type") {
        Some(Value::String(t)) => t == "number",
        Some(Value::Array(ts)) => ts.iter().any(|t| t == "number"),
        _ => false,
    }
}

fn num(m: &serde_json::Map<String, Value>, k: &str) -> Option<f64> {
    m.get(k).and_then(Value::as_f64)
}

#[test]
fn the_schema_is_draft_2020_12_with_its_id_and_deterministic() {
    let v = design_json_schema();
    assert_eq!(v["$schema"], "https://json-schema.org/draft/2020-12/schema");
    assert_eq!(v["$id"], "urn:fabkit:design");
    assert_eq!(v["title"], "fabkit design");
    let text = design_json_schema_text();
    assert_eq!(text, design_json_schema_text());
    assert!(text.ends_with("}\n"));
    assert_eq!(serde_json::from_str::<Value>(&text).unwrap(), v);
}

/// The descriptions are plain text for a design's author: no rustdoc link brackets
/// (`` [`Name`] ``) and no Rust paths (`crate::`), which an editor would show as they are.
#[test]
fn the_schema_descriptions_are_plain_text() {
    let text = design_json_schema_text();
    let v = design_json_schema();
    let mut descriptions = Vec::new();
    fn walk(v: &Value, out: &mut Vec<String>) {
        match v {
            Value::Object(m) => {
                if let Some(Value::String(d)) = m.get("description") {
                    out.push(d.clone());
                }
                m.values().for_each(|x| walk(x, out));
            }
            Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            _ => {}
        }
    }
    walk(&v, &mut descriptions);
    assert!(
        descriptions.len() > 100,
        "{} descriptions",
        descriptions.len()
    );
    for d in &descriptions {
        assert!(
            !d.contains("[`") && !d.contains("](") && !d.contains("crate::"),
            "{d}"
        );
    }
    assert!(!text.contains("crate::"));
}

/// The schema's descriptions pass through `plain_text`, which turns rustdoc's links into plain
/// text and leaves other brackets alone.
#[test]
fn rustdoc_links_read_as_plain_text() {
    for (doc, plain) in [
        ("a [`Foo`] b", "a `Foo` b"),
        ("[`Foo::bar`]", "`Foo::bar`"),
        (
            "[`crate::profile::BodyProfile::outer`]",
            "`BodyProfile::outer`",
        ),
        ("[`crate::values::check_values`]", "`check_values`"),
        ("[`crate::lasercut`]", "`lasercut`"),
        ("[`fn@shipped_printers`]", "`shipped_printers`"),
        ("[`x`](crate::y)", "`x`"),
        ("[`x`][crate::y]", "`x`"),
        ("[`crate::a::B`](crate::a::B)", "`B`"),
        (
            "[`crate::a::B`](https://docs.rs/a)",
            "`B` (https://docs.rs/a)",
        ),
        (
            "[the paper](https://example.org/p?a=1)",
            "the paper (https://example.org/p?a=1)",
        ),
        // several links, across a line break
        ("[`A`] and\n[`B`](crate::b::B).", "`A` and\n`B`."),
        // not links
        ("degrees, [0, 10).", "degrees, [0, 10)."),
        ("names `[a-z0-9_]+`", "names `[a-z0-9_]+`"),
        ("in [0, 1) or [`Foo`]", "in [0, 1) or `Foo`"),
        ("x in [0, 10) (mm)", "x in [0, 10) (mm)"),
        ("[a, b](c d)", "[a, b](c d)"),
        ("[`two words`]", "[`two words`]"),
        ("unclosed [`Foo", "unclosed [`Foo"),
        ("[]", "[]"),
    ] {
        assert_eq!(plain_text(doc), plain, "{doc:?}");
    }
}

/// Every section of a design refuses unknown keys (`deny_unknown_fields` on every design type),
/// except the presets' maps of parameter paths, which take any path.
#[test]
fn every_section_refuses_unknown_keys() {
    let v = design_json_schema();
    let mut sections = 0;
    each_schema(&v, "", false, &mut |key, _, m| {
        // a section given as branches (the body's profiles) is closed by each branch
        let branches_closed = m.get("oneOf").and_then(Value::as_array).is_some_and(|b| {
            b.iter()
                .all(|b| b.get("additionalProperties") == Some(&Value::Bool(false)))
        });
        if m.contains_key("properties") && !branches_closed {
            sections += 1;
            assert_eq!(
                m.get("additionalProperties"),
                Some(&Value::Bool(false)),
                "the section under `{key}` takes unknown keys: {m:?}"
            );
        }
    });
    assert!(sections > 50, "{sections} sections");
    assert_eq!(
        v["properties"]["presets"]["additionalProperties"]["additionalProperties"],
        true
    );
}

/// Every number under a `_mm` key is a length from 0 (or above 0; from -1000 for the signed
/// lengths of `DESIGN_SIGNED_MM`) to 1000 mm, every number
/// under a `_deg` key an angle within +-360 deg, as `values::check_values` refuses otherwise.
#[test]
fn every_length_and_angle_is_bounded_as_the_validator_bounds_it() {
    let v = design_json_schema();
    let (mut lengths, mut angles) = (0, 0);
    each_schema(&v, "", false, &mut |key, own, m| {
        if !is_number(m) {
            return;
        }
        let lo = num(m, "minimum").or(num(m, "exclusiveMinimum"));
        let hi = num(m, "maximum").or(num(m, "exclusiveMaximum"));
        let (Some(lo), Some(hi)) = (lo, hi) else {
            panic!("`{key}` is not bounded: {m:?}");
        };
        if key.ends_with("_mm") {
            lengths += 1;
            // a length the validator lets be negative (a light's position) is signed
            let floor = if DESIGN_SIGNED_MM.iter().any(|k| key.contains(k)) {
                -MAX_LENGTH_MM
            } else {
                0.0
            };
            assert!(lo >= floor && hi <= MAX_LENGTH_MM, "`{key}`: {m:?}");
            assert!(
                !own || m
                    .get("description")
                    .and_then(Value::as_str)
                    .is_some_and(|d| d.contains("mm")),
                "`{key}` does not say its unit: {m:?}"
            );
        } else if key.ends_with("_deg") {
            angles += 1;
            assert!(
                lo >= -MAX_ANGLE_DEG && hi <= MAX_ANGLE_DEG,
                "`{key}`: {m:?}"
            );
        }
    });
    assert!(
        lengths > 100 && angles > 5,
        "{lengths} lengths, {angles} angles"
    );
}

/// The subschemas `steps` lead to from `s` (several where `oneOf` branches share a key), behind
/// `$ref`s into `root`'s `$defs`.
fn schemas_at<'a>(
    root: &'a Value,
    s: &'a Value,
    steps: &[fabkit_designs::values::Step],
) -> Vec<&'a serde_json::Map<String, Value>> {
    use fabkit_designs::values::Step;
    let Value::Object(m) = s else {
        return Vec::new();
    };
    if let Some(r) = m.get("$ref").and_then(Value::as_str) {
        let name = r.trim_start_matches("#/$defs/");
        return schemas_at(root, &root["$defs"][name], steps);
    }
    let mut out = Vec::new();
    for k in ["anyOf", "oneOf", "allOf"] {
        if let Some(Value::Array(subs)) = m.get(k) {
            for sub in subs {
                out.extend(schemas_at(root, sub, steps));
            }
        }
    }
    match steps.split_first() {
        None => out.push(m),
        Some((Step::Key(k), rest)) => {
            if let Some(sub) = m.get("properties").and_then(|p| p.get(k.as_str())) {
                out.extend(schemas_at(root, sub, rest));
            } else if let Some(sub) = m.get("additionalProperties") {
                out.extend(schemas_at(root, sub, rest));
            }
        }
        Some((Step::Index(_), rest)) => {
            if let Some(sub) = m.get("items") {
                out.extend(schemas_at(root, sub, rest));
            }
        }
    }
    out
}

/// The schema and the validator agree on "above 0": every number of every library design whose
/// schema bound is only `exclusiveMinimum: 0` (no range of its own), set to 0, is refused by
/// `validate` under its own path. The families read that bound back from the schema
/// (`parts::check_above_zero`), so a field marked in the schema cannot go unchecked.
#[test]
fn every_number_the_schema_marks_above_0_is_refused_at_0_under_its_path() {
    use fabkit_designs::values::{number_paths, with_number};
    let schema = design_json_schema();
    let mut checked = 0;
    for (name, _) in fabkit_designs::library::LIBRARY {
        let design = fabkit_designs::library::load(name).unwrap();
        for path in number_paths(&design, &["presets"]).unwrap() {
            let at = schemas_at(&schema, &schema, &path.0);
            let above_zero_only = !at.is_empty()
                && at.iter().all(|m| {
                    num(m, "exclusiveMinimum") == Some(0.0) && !m.contains_key("exclusiveMaximum")
                });
            if !above_zero_only {
                continue;
            }
            let zero = with_number(&design, &path, 0.0).unwrap();
            let named = path.to_string();
            let errs = match fabkit_designs::validate_design(&zero, Default::default()) {
                Ok(_) => Vec::new(),
                Err(fabkit_designs::DesignError::Params(e)) => e.0,
                Err(e) => panic!("{name}: {named} = 0: {e}"),
            };
            assert!(
                errs.iter().any(|e| e.path == named),
                "{name}: {named} = 0 is not refused under its path: {errs:?}"
            );
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked} numbers checked");
}

#[derive(serde::Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
enum ProbeShape {
    Disc {
        #[schemars(extend("exclusiveMinimum" = 0))]
        diameter_mm: f64,
    },
    Square {
        #[schemars(extend("exclusiveMinimum" = 0))]
        side_mm: f64,
    },
}

#[derive(serde::Serialize, schemars::JsonSchema)]
struct ProbeInner {
    #[schemars(extend("exclusiveMinimum" = 0))]
    a_mm: f64,
    /// No bound: never this rule's.
    b_mm: f64,
}

#[derive(serde::Serialize, schemars::JsonSchema)]
struct Probe {
    shape: ProbeShape,
    #[schemars(extend("exclusiveMinimum" = 0, "exclusiveMaximum" = 180))]
    view_angle_deg: f64,
    #[schemars(extend("items" = {"type": "number", "exclusiveMinimum": 0}))]
    spacing_mm: [f64; 2],
    nested: Option<ProbeInner>,
    absent: Option<ProbeInner>,
    skipped: ProbeInner,
}

/// `check_above_zero` follows the schema into enum variants, optional fields and array items,
/// leaves a number with a range of its own (an angle in (0, 180)) and the skipped keys to their
/// own rules, and names each path under the prefix in the schema's order.
#[test]
fn above_zero_follows_the_schema_into_variants_options_and_items() {
    let p = Probe {
        shape: ProbeShape::Square { side_mm: 0.0 },
        view_angle_deg: 0.0,
        spacing_mm: [1.0, -1.0],
        nested: Some(ProbeInner {
            a_mm: -2.0,
            b_mm: -2.0,
        }),
        absent: None,
        skipped: ProbeInner {
            a_mm: 0.0,
            b_mm: 0.0,
        },
    };
    let mut errs = Vec::new();
    assert!(fabkit_designs::parts::check_above_zero(
        "probe.",
        &p,
        &["skipped"],
        &mut errs
    ));
    let named: Vec<String> = errs.iter().map(|e| e.to_string()).collect();
    assert_eq!(
        named,
        [
            "probe.nested.a_mm = -2: must be above 0",
            "probe.shape.square.side_mm = 0: must be above 0",
            "probe.spacing_mm[1] = -1: must be above 0",
        ]
    );
    let fine = Probe {
        shape: ProbeShape::Disc { diameter_mm: 3.0 },
        spacing_mm: [1.0, 1.0],
        nested: None,
        ..p
    };
    let mut errs = Vec::new();
    assert!(!fabkit_designs::parts::check_above_zero(
        "probe.",
        &fine,
        &["skipped"],
        &mut errs
    ));
    assert!(errs.is_empty(), "{errs:?}");
}
