//! Parameter paths of a design (`layers[0].markers[0].pattern.spacing_mm`): which exist, a
//! short path expanded, setting a value at a path, and the canonical JSON of a design that
//! variant ids hash.

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
pub fn path_keys(p: &str) -> Vec<String> {
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
    let mut s = Vec::new();
    write_canonical(v, &mut s);
    // serde_json writes valid UTF-8 and every other byte is ASCII punctuation
    String::from_utf8(s).unwrap_or_default()
}

/// Writes the canonical text into a byte buffer: serde_json's escaping for keys and scalars,
/// without a temporary string per node.
fn write_canonical(v: &Value, s: &mut Vec<u8>) {
    match v {
        Value::Object(o) => {
            let mut keys: Vec<&String> = o.keys().collect();
            keys.sort();
            s.push(b'{');
            for (i, k) in keys.into_iter().enumerate() {
                if i > 0 {
                    s.push(b',');
                }
                // writing into a Vec cannot fail, nor can serializing a string
                let _ = serde_json::to_writer(&mut *s, k);
                s.push(b':');
                write_canonical(&o[k], s);
            }
            s.push(b'}');
        }
        Value::Array(a) => {
            s.push(b'[');
            for (i, x) in a.iter().enumerate() {
                if i > 0 {
                    s.push(b',');
                }
                write_canonical(x, s);
            }
            s.push(b']');
        }
        other => {
            let _ = serde_json::to_writer(&mut *s, other);
        }
    }
}

/// The keys and list indices of a parameter path, as [`crate::schema::value_at`] reads them:
/// `layers[0].markers` -> [layers, 0, markers].
fn path_steps(path: &str) -> Option<Vec<&str>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        match part.find('[') {
            None => out.push(part),
            Some(i) => {
                out.push(&part[..i]);
                let mut rest = &part[i..];
                while let Some(stripped) = rest.strip_prefix('[') {
                    let j = stripped.find(']')?;
                    out.push(&stripped[..j]);
                    rest = &stripped[j + 1..];
                }
                if !rest.is_empty() {
                    return None;
                }
            }
        }
    }
    Some(out)
}

fn skip_ws(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i].is_ascii_whitespace() {
        i += 1;
    }
    i
}

/// The end of the JSON string that starts at `b[i]` (a `"`), after its closing quote.
fn string_end(b: &[u8], mut i: usize) -> Option<usize> {
    i += 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            b'"' => return Some(i + 1),
            _ => i += 1,
        }
    }
    None
}

/// The end of the JSON value that starts at `b[i]`.
fn value_end(b: &[u8], i: usize) -> Option<usize> {
    match *b.get(i)? {
        b'"' => string_end(b, i),
        b'{' | b'[' => {
            let mut depth = 0usize;
            let mut j = i;
            while j < b.len() {
                match b[j] {
                    b'"' => {
                        j = string_end(b, j)?;
                        continue;
                    }
                    b'{' | b'[' => depth += 1,
                    b'}' | b']' => {
                        depth -= 1;
                        if depth == 0 {
                            return Some(j + 1);
                        }
                    }
                    _ => {}
                }
                j += 1;
            }
            None
        }
        _ => {
            let mut j = i;
            while j < b.len() && !matches!(b[j], b',' | b'}' | b']') && !b[j].is_ascii_whitespace()
            {
                j += 1;
            }
            (j > i).then_some(j)
        }
    }
}

/// The byte range of the value at parameter path `path` in the JSON text `text` (as serde_json
/// writes it), found by scanning the text without building its tree; `None` when the path
/// names nothing there.
pub fn span_of(text: &str, path: &str) -> Option<(usize, usize)> {
    let b = text.as_bytes();
    let mut i = skip_ws(b, 0);
    for step in path_steps(path)? {
        match *b.get(i)? {
            b'{' => {
                i = skip_ws(b, i + 1);
                loop {
                    if b.get(i) != Some(&b'"') {
                        return None;
                    }
                    let key_end = string_end(b, i)?;
                    let raw = &text[i + 1..key_end - 1];
                    let found = if raw.contains('\\') {
                        serde_json::from_str::<String>(&text[i..key_end]).ok()? == step
                    } else {
                        raw == step
                    };
                    i = skip_ws(b, key_end);
                    if b.get(i) != Some(&b':') {
                        return None;
                    }
                    i = skip_ws(b, i + 1);
                    if found {
                        break;
                    }
                    i = skip_ws(b, value_end(b, i)?);
                    if b.get(i) != Some(&b',') {
                        return None;
                    }
                    i = skip_ws(b, i + 1);
                }
            }
            b'[' => {
                let k: usize = step.parse().ok()?;
                i = skip_ws(b, i + 1);
                if b.get(i) == Some(&b']') {
                    return None;
                }
                for _ in 0..k {
                    i = skip_ws(b, value_end(b, i)?);
                    if b.get(i) != Some(&b',') {
                        return None;
                    }
                    i = skip_ws(b, i + 1);
                }
            }
            _ => return None,
        }
    }
    Some((i, value_end(b, i)?))
}
