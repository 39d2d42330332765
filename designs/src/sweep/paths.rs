//! Parameter paths of a design (`layers[0].markers[0].pattern.spacing_mm`): which exist, the
//! nearest ones to a path that does not, setting a value at a path, and the canonical JSON of a
//! design that variant ids hash.

use crate::markers::{Layout, MarkerSpec, Pattern};
use crate::schema::{value_at, Design};
use serde_json::Value;

/// Keys of the optional marker fields that a design only writes out when they are set
/// (`skip_serializing_if`): a path ending in one of them is valid on every pattern / marker
/// even when the base design leaves it out. Taken from a fully populated value, so a field
/// added to [`Pattern`] or [`MarkerSpec`] shows up here.
fn optional_marker_keys() -> (Vec<String>, Vec<String>, Vec<String>) {
    let pattern = Pattern {
        layout: Layout::List,
        rings: Some(1),
        pitch_arc_mm: Some(1.0),
        spacing_mm: Some(1.0),
        count: Some(1),
        points: Some(vec![]),
        csv_file: Some(String::new()),
        center_marker: true,
        max_polar_deg: Some(1.0),
        min_polar_deg: Some(1.0),
        polar_step_deg: Some(1.0),
        ring_azimuth_offset: Some(crate::markers::RingAzimuthOffset::PerRingDeg(vec![])),
    };
    let spec = MarkerSpec {
        surface: crate::markers::MarkerSurface::Outer,
        pattern: pattern.clone(),
        feature: crate::markers::FeatureShape {
            diameter_mm: 1.0,
            height_mm: 1.0,
            polarity: Some(crate::markers::Polarity::Raised),
            on_skin: Some(crate::markers::OnSkin::Bump),
        },
        tip_material: Some(String::new()),
    };
    let keys = |v: Value| match v {
        Value::Object(o) => o.keys().cloned().collect(),
        _ => Vec::new(),
    };
    (
        keys(serde_json::to_value(&pattern).unwrap_or(Value::Null)),
        keys(serde_json::to_value(&spec).unwrap_or(Value::Null)),
        keys(serde_json::to_value(&spec.feature).unwrap_or(Value::Null)),
    )
}

/// Every parameter path of `design` that can take a value: each leaf of its JSON form (numbers,
/// strings, booleans, nulls and lists of numbers such as `points`), in document order, plus the
/// optional marker fields the design leaves out. Paths use `.` between keys and `[i]` for list
/// items, as in the YAML of presets.
pub fn parameter_paths(design: &Design) -> Vec<String> {
    let v = serde_json::to_value(design).unwrap_or(Value::Null);
    let (pattern_keys, spec_keys, feature_keys) = optional_marker_keys();
    let mut out = Vec::new();
    walk(
        &v,
        String::new(),
        &mut out,
        &[&pattern_keys, &spec_keys, &feature_keys],
    );
    out
}

/// `keys`: the optional keys of a pattern, of a marker spec and of a feature.
fn walk(v: &Value, path: String, out: &mut Vec<String>, keys: &[&Vec<String>; 3]) {
    let [pk, sk, fk] = *keys;
    match v {
        Value::Object(o) => {
            if path == "presets" {
                return; // presets are not parameters of the built design
            }
            for (k, x) in o {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                walk(x, p, out, keys);
            }
            let missing = |keys: &[String], out: &mut Vec<String>| {
                for k in keys {
                    if !o.contains_key(k) {
                        out.push(format!("{path}.{k}"));
                    }
                }
            };
            if path.ends_with("].pattern") {
                missing(pk, out);
            } else if path.ends_with("].feature") {
                missing(fk, out);
            } else if o.contains_key("pattern") && o.contains_key("feature") {
                missing(sk, out);
            }
        }
        Value::Array(a) if a.iter().any(|x| x.is_object() || x.is_array()) => {
            for (i, x) in a.iter().enumerate() {
                walk(x, format!("{path}[{i}]"), out, keys);
            }
        }
        _ => out.push(path),
    }
}

/// Whether `path` names something in `design`: a parameter of [`parameter_paths`] or an
/// object or list that holds some (a whole `layers[0].markers[0].feature` may be replaced).
pub fn path_exists(design: &Design, path: &str) -> bool {
    let all = parameter_paths(design);
    all.iter().any(|p| {
        p == path
            || p.strip_prefix(path)
                .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
    })
}

/// The keys of a parameter path without its list indices: `layers[0].markers` -> [layers, markers].
fn path_keys(p: &str) -> Vec<String> {
    p.split(['.', '[', ']'])
        .filter(|k| !k.is_empty() && !k.chars().all(|c| c.is_ascii_digit()))
        .map(str::to_owned)
        .collect()
}

/// The one parameter path that a short path abbreviates, if there is exactly one: its keys
/// appear in order in the full path and the last keys are equal, so the issue's
/// `markers.spacing_mm` stands for `layers[0].markers[0].pattern.spacing_mm` on a design with
/// one marker pattern. A path with a list index (`layers[1]...`) is never short. `None` when
/// no path or several paths fit (then the path is an error whose hint lists the nearest ones).
pub fn expand_short_path(design: &Design, path: &str) -> Option<String> {
    if path.contains('[') {
        return None;
    }
    let asked = path_keys(path);
    let last = asked.last()?;
    let fits = |full: &str| {
        let k = path_keys(full);
        if k.last() != Some(last) {
            return false;
        }
        let mut it = k.iter();
        asked.iter().all(|a| it.any(|x| x == a))
    };
    let mut found = parameter_paths(design).into_iter().filter(|p| fits(p));
    let first = found.next()?;
    found.next().is_none().then_some(first)
}

/// Up to `n` valid paths nearest to the unknown `path`, best first: paths ending in the same
/// key come first (`markers.spacing_mm` finds `layers[0].markers[0].pattern.spacing_mm`), then
/// by similarity of the last key, then of the keys they share and of the whole string.
pub fn nearest_paths(design: &Design, path: &str, n: usize) -> Vec<String> {
    let asked = path_keys(path);
    let last = asked.last().cloned().unwrap_or_default();
    let mut scored: Vec<(f64, String)> = parameter_paths(design)
        .into_iter()
        .map(|p| {
            let k = path_keys(&p);
            let l = k.last().cloned().unwrap_or_default();
            let last_sim = strsim::normalized_damerau_levenshtein(&last, &l);
            let shared =
                asked.iter().filter(|a| k.contains(a)).count() as f64 / asked.len().max(1) as f64;
            let whole = strsim::normalized_levenshtein(path, &p);
            (2.0 * last_sim + shared + whole, p)
        })
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    scored
        .into_iter()
        .filter(|(s, _)| *s >= 1.5)
        .take(n)
        .map(|(_, p)| p)
        .collect()
}

/// `base` (a design's JSON form) with `value` at `path`; `None` when the path does not exist.
pub fn with_value(base: &Value, path: &str, value: &Value) -> Option<Value> {
    let mut v = base.clone();
    *value_at(&mut v, path)? = value.clone();
    Some(v)
}

/// The canonical text of a JSON value: object keys sorted, no spaces, numbers in serde_json's
/// shortest round-trip form. Independent of map ordering features, so that hashes of it are
/// stable.
pub fn canonical_json(v: &Value) -> String {
    let mut s = String::new();
    write_canonical(v, &mut s);
    s
}

fn write_canonical(v: &Value, s: &mut String) {
    match v {
        Value::Object(o) => {
            let mut keys: Vec<&String> = o.keys().collect();
            keys.sort();
            s.push('{');
            for (i, k) in keys.into_iter().enumerate() {
                if i > 0 {
                    s.push(',');
                }
                s.push_str(&Value::String(k.clone()).to_string());
                s.push(':');
                write_canonical(&o[k], s);
            }
            s.push('}');
        }
        Value::Array(a) => {
            s.push('[');
            for (i, x) in a.iter().enumerate() {
                if i > 0 {
                    s.push(',');
                }
                write_canonical(x, s);
            }
            s.push(']');
        }
        other => s.push_str(&other.to_string()),
    }
}
