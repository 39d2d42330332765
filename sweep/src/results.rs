//! One result per variant, and the results table (`results.csv`, `results.jsonl`).

use super::file::FileOutputs;
use fabkit_designs::variant::{Metrics, Verdict};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// How a variant ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Built and measured (and its files written, when asked).
    Ok,
    /// The design breaks a rule; `errors` lists every violation.
    Infeasible,
    /// The build or the writing failed; `errors` holds the message. Run again on resume.
    Error,
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Status::Ok => "ok",
            Status::Infeasible => "infeasible",
            Status::Error => "error",
        })
    }
}

/// Everything recorded about one variant: its line of `results.jsonl`, and
/// `variants/<id>.json` in the sweep folder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VariantResult {
    /// Position in the sweep, from 0.
    pub index: usize,
    /// Stable id ([`super::Variant::id`]); also names the variant's folder.
    pub id: String,
    /// The varied parameters' values, by path.
    pub params: serde_json::Map<String, Value>,
    pub status: Status,
    /// Every violated rule (infeasible) or the failure (error); empty when ok.
    pub errors: Vec<String>,
    /// `None` unless the status is ok.
    pub metrics: Option<Metrics>,
    /// One verdict per printer profile ([`fabkit_designs::variant::printability`]), for every status.
    pub printability: Vec<Verdict>,
    /// Which files the variant folder `variants/<id>/` holds (none: metrics only).
    pub files: FileOutputs,
    /// Wall-clock seconds to validate, build, measure and write the variant (while other
    /// variants ran beside it); `None` in tables written with build times left out.
    pub build_time_s: Option<f64>,
    /// fabkit version that computed the result.
    pub fabkit_version: String,
}

/// The results as JSON lines: one [`VariantResult`] per line, in the order given.
pub fn render_jsonl(rows: &[VariantResult]) -> Vec<u8> {
    let mut out = Vec::new();
    for r in rows {
        // A VariantResult always serialises (no maps with non-string keys, no NaN keys).
        if let Ok(s) = serde_json::to_string(r) {
            out.extend_from_slice(s.as_bytes());
            out.push(b'\n');
        }
    }
    out
}

/// The results as CSV (RFC 4180 quoting, `\n` line ends), one row per variant in the order
/// given. Columns:
///
/// `index, id`, one column per varied parameter (named by its path, in the sweep file's
/// order), `status`, then per part `part.<name>.volume_mm3` and `part.<name>.triangles`, per
/// pour `cast.<cast>.volume_ml` and `cast.<cast>.mass_g`, per marker pattern
/// `markers.<layer>.<surface>.count`, `.min_spacing_mm` and `.median_spacing_mm`, then
/// `min_wall_mm`, `min_wall_at`, `triangles`, `printable.<profile>` (`yes` / `no`) per printer
/// profile, `build_time_s` and `errors` (violations joined by ` | `).
///
/// Parts, pours and patterns are the union over the rows in order of first appearance; a
/// cell is empty where a variant has no such value. Numbers are written in their shortest
/// round-trip form, so the same rows give the same bytes.
pub fn render_csv(parameters: &[String], rows: &[VariantResult]) -> Vec<u8> {
    let mut parts: Vec<String> = Vec::new();
    let mut casts: Vec<String> = Vec::new();
    let mut patterns: Vec<(String, String)> = Vec::new();
    let mut profiles: Vec<String> = Vec::new();
    let push = |v: &mut Vec<String>, x: &str| {
        if !v.iter().any(|y| y == x) {
            v.push(x.to_string());
        }
    };
    for r in rows {
        if let Some(m) = &r.metrics {
            for p in &m.parts {
                push(&mut parts, &p.name);
            }
            for c in &m.casts {
                push(&mut casts, &c.cast);
            }
            for k in &m.markers {
                let key = (k.layer.clone(), surface_name(k));
                if !patterns.contains(&key) {
                    patterns.push(key);
                }
            }
        }
        for v in &r.printability {
            push(&mut profiles, &v.profile);
        }
    }
    let mut header: Vec<String> = vec!["index".into(), "id".into()];
    header.extend(parameters.iter().cloned());
    header.push("status".into());
    for p in &parts {
        header.push(format!("part.{p}.volume_mm3"));
        header.push(format!("part.{p}.triangles"));
    }
    for c in &casts {
        header.push(format!("cast.{c}.volume_ml"));
        header.push(format!("cast.{c}.mass_g"));
    }
    for (l, s) in &patterns {
        for what in ["count", "min_spacing_mm", "median_spacing_mm"] {
            header.push(format!("markers.{l}.{s}.{what}"));
        }
    }
    header.extend([
        "min_wall_mm".into(),
        "min_wall_at".into(),
        "triangles".into(),
    ]);
    for p in &profiles {
        header.push(format!("printable.{p}"));
    }
    header.extend(["build_time_s".into(), "errors".into()]);

    let mut w = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    let mut records = vec![header];
    for r in rows {
        let mut rec: Vec<String> = vec![r.index.to_string(), r.id.clone()];
        for p in parameters {
            rec.push(r.params.get(p).map(cell).unwrap_or_default());
        }
        rec.push(r.status.to_string());
        let m = r.metrics.as_ref();
        for p in &parts {
            let x = m.and_then(|m| m.parts.iter().find(|x| &x.name == p));
            rec.push(x.map(|x| num(x.volume_mm3)).unwrap_or_default());
            rec.push(x.map(|x| x.triangles.to_string()).unwrap_or_default());
        }
        for c in &casts {
            let x = m.and_then(|m| m.casts.iter().find(|x| &x.cast == c));
            rec.push(x.map(|x| num(x.cavity_volume_ml)).unwrap_or_default());
            rec.push(x.map(|x| num(x.total_mass_g)).unwrap_or_default());
        }
        for (l, s) in &patterns {
            let x = m.and_then(|m| {
                m.markers
                    .iter()
                    .find(|x| &x.layer == l && &surface_name(x) == s)
            });
            rec.push(x.map(|x| x.count.to_string()).unwrap_or_default());
            rec.push(x.map(|x| num(x.min_spacing_mm)).unwrap_or_default());
            rec.push(x.map(|x| num(x.median_spacing_mm)).unwrap_or_default());
        }
        rec.push(m.and_then(|m| m.min_wall_mm).map(num).unwrap_or_default());
        rec.push(m.and_then(|m| m.min_wall_at.clone()).unwrap_or_default());
        rec.push(m.map(|m| m.triangles.to_string()).unwrap_or_default());
        for p in &profiles {
            rec.push(
                r.printability
                    .iter()
                    .find(|v| &v.profile == p)
                    .map(|v| if v.printable { "yes" } else { "no" }.to_string())
                    .unwrap_or_default(),
            );
        }
        rec.push(r.build_time_s.map(num).unwrap_or_default());
        rec.push(r.errors.join(" | "));
        records.push(rec);
    }
    for rec in &records {
        // Writing into a Vec cannot fail.
        let _ = w.write_record(rec);
    }
    w.into_inner().unwrap_or_default()
}

fn surface_name(m: &fabkit_designs::variant::MarkerMetrics) -> String {
    match m.surface {
        fabkit_designs::markers::MarkerSurface::Outer => "outer".into(),
        fabkit_designs::markers::MarkerSurface::Inner => "inner".into(),
    }
}

fn num(x: f64) -> String {
    x.to_string()
}

/// A parameter value as a CSV cell: strings bare, everything else as JSON.
fn cell(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}
