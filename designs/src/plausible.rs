//! Values that are valid but implausible in their unit and plausible in another: a draft
//! angle of 0.035 (radians typed into a degree field), a thickness of 0.0025 (metres typed
//! into a millimetre field). They are warned about, not refused: a design may mean them.
//!
//! The rules, on every number the YAML text writes under a key whose name gives its unit:
//! - `..._deg`: between 0 and 0.2 degrees (exclusive, either sign), where radians would be
//!   0 to 11.5 degrees, the range of a draft angle or a tilt;
//! - `..._mm`: between 0 and 0.001 mm (a micrometre, below any printer's or mold's
//!   resolution), where metres would be 0 to 1 mm; or above 2000 mm (larger than any sensor
//!   or fixture), where micrometres would be under 2 mm.

use crate::yaml::{budget_options, yaml_location};

/// The warnings of the numbers in YAML `text` (named `origin` in them: a file or a library
/// design) that are implausible in their key's unit (module docs), each with its
/// `origin:line:column`, parameter path, value and the likely unit; in the text's order. A
/// text that does not parse has none (its errors are the loader's).
pub fn unit_warnings(text: &str, origin: &str) -> Vec<String> {
    let Ok(root) = serde_saphyr::from_str_with_options::<serde_json::Value>(text, budget_options())
    else {
        return Vec::new();
    };
    let mut found = Vec::new();
    walk(&root, String::new(), &mut found);
    found
        .into_iter()
        .map(|(path, why)| {
            let at = yaml_location(text, &path)
                .map(|(l, c)| format!(":{l}:{c}"))
                .unwrap_or_default();
            format!("{origin}{at}: {path} {why}")
        })
        .collect()
}

fn walk(v: &serde_json::Value, path: String, out: &mut Vec<(String, String)>) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, x) in m {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                if let Some(n) = x.as_f64() {
                    if let Some(why) = implausible(k, n) {
                        out.push((p.clone(), why));
                    }
                }
                walk(x, p, out);
            }
        }
        serde_json::Value::Array(items) => {
            for (i, x) in items.iter().enumerate() {
                walk(x, format!("{path}[{i}]"), out);
            }
        }
        _ => {}
    }
}

/// Why `value` under `key` is implausible in the key's unit, or `None`.
fn implausible(key: &str, value: f64) -> Option<String> {
    let a = value.abs();
    if key.ends_with("_deg") && a > 0.0 && a < 0.2 {
        return Some(format!(
            "= {value}: under a fifth of a degree; if it is in radians, that is {:.2} deg",
            value.to_degrees()
        ));
    }
    if key.ends_with("_mm") {
        if a > 0.0 && a < 0.001 {
            return Some(format!(
                "= {value}: under a micrometre; if it is in metres, that is {} mm",
                value * 1000.0
            ));
        }
        if a > 2000.0 {
            return Some(format!(
                "= {value}: over 2 m; if it is in micrometres, that is {} mm",
                value / 1000.0
            ));
        }
    }
    None
}
