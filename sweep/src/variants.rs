//! Sweeps given as a list of variants, each a list of (parameter path, value), rather than a
//! sweep file: what the Python package's `fabkit.sweep` runs on any executor. The checks, the
//! ids and the results are those of a sweep file ([`super::SweepSpec`]), so the same variants
//! give the same results table as `fabkit sweep`.

use super::file::FileOutputs;
use super::plan::{variant_id, Variant, MAX_VARIANTS};
use super::results::{Status, VariantResult};
use super::SweepError;
use crate::nearest::nearest_paths;
use fabkit_designs::build::AssemblyScope;
use fabkit_designs::geometry::ChordTolerance;
use fabkit_designs::kit::Kit;
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::schema::{value_at, Design};
use fabkit_designs::variant::{evaluate_scoped, printability, Outcome};
use fabkit_designs::variant::{expand_short_path, path_exists, with_value};
use serde_json::Value;

/// The full parameter path of `design` that `given` names: itself, or the one path a short
/// path (`markers.spacing_mm`) stands for. `at` locates `given` in errors.
///
/// # Errors
/// [`SweepError::UnknownPath`] with the nearest paths; [`SweepError::File`] for a marker CSV
/// file path (read once, when the base design loads).
pub fn checked_path(design: &Design, given: &str, at: &str) -> Result<String, SweepError> {
    let mut path = given.trim().to_string();
    if !path_exists(design, &path) {
        if let Some(full) = expand_short_path(design, &path) {
            path = full;
        }
    }
    if !path_exists(design, &path) {
        return Err(SweepError::UnknownPath {
            at: at.to_string(),
            path,
            design: design.name.clone(),
            nearest: nearest_paths(design, given.trim(), 3),
        });
    }
    if path.ends_with(".csv_file") {
        return Err(SweepError::File {
            at: at.to_string(),
            message: format!("vary.{path}: marker CSV files are read once, when the base design loads; vary the pattern's `points` instead"),
        });
    }
    Ok(path)
}

/// The design `base_json` (a design's JSON form, of `design`) with `value` at the full path
/// `path`. `at` locates the value in errors.
///
/// # Errors
/// [`SweepError::WrongValue`] with the path, the value and the schema's rule.
pub fn checked_value(
    design: &Design,
    base_json: &Value,
    path: &str,
    value: &Value,
    at: &str,
) -> Result<Design, SweepError> {
    let replaced = with_value(base_json, path, value).ok_or_else(|| SweepError::UnknownPath {
        at: at.to_string(),
        path: path.to_string(),
        design: design.name.clone(),
        nearest: nearest_paths(design, path, 3),
    })?;
    serde_json::from_value::<Design>(replaced).map_err(|e| SweepError::WrongValue {
        at: at.to_string(),
        path: path.to_string(),
        value: value.to_string(),
        message: e.to_string(),
    })
}

/// A sweep given as variants: its parameters (the union of the variants' paths, full paths in
/// order of first appearance: the results table's parameter columns) and its variants (index,
/// id, values by full path).
#[derive(Debug, Clone, PartialEq)]
pub struct VariantList {
    pub parameters: Vec<String>,
    pub variants: Vec<Variant>,
}

/// Checks and plans the variants `given` of `base` built at `tol`: every path a parameter path
/// (short paths expanded), every value of the parameter's type, no path twice in a variant, no
/// two variants the same design. `origin` names the list in errors: variant `i` is at
/// `<origin>[i]` (`variants[3]`).
///
/// # Errors
/// [`SweepError::UnknownPath`], [`SweepError::WrongValue`] naming the variant, the path and
/// the value; [`SweepError::File`] for an empty list, more than [`MAX_VARIANTS`] variants, a
/// variant without parameters, a path given twice or two variants that resolve to the same
/// design.
pub fn plan_variants(
    base: &Design,
    origin: &str,
    given: &[Vec<(String, Value)>],
    tol: ChordTolerance,
) -> Result<VariantList, SweepError> {
    let file_err = |at: String, message: String| SweepError::File { at, message };
    if given.is_empty() {
        return Err(file_err(
            origin.to_string(),
            "no variants: give at least one {parameter path: value}".into(),
        ));
    }
    if given.len() as u64 > MAX_VARIANTS {
        return Err(file_err(
            origin.to_string(),
            format!(
                "the sweep has {} variants, more than the {MAX_VARIANTS} allowed",
                given.len()
            ),
        ));
    }
    let base_json = serde_json::to_value(base).map_err(|e| SweepError::File {
        at: origin.to_string(),
        message: e.to_string(),
    })?;
    let mut parameters: Vec<String> = Vec::new();
    let mut listed: std::collections::HashSet<String> = Default::default();
    // each given path is checked once, not once per variant that names it
    let mut full_paths: std::collections::HashMap<&str, String> = Default::default();
    let mut variants = Vec::with_capacity(given.len());
    let mut seen: std::collections::HashMap<String, usize> = Default::default();
    for (index, values) in given.iter().enumerate() {
        let at = format!("{origin}[{index}]");
        if values.is_empty() {
            return Err(file_err(
                at,
                "a variant without parameters: give at least one {parameter path: value}".into(),
            ));
        }
        let mut params: Vec<(String, Value)> = Vec::with_capacity(values.len());
        for (given_path, value) in values {
            let path = match full_paths.get(given_path.as_str()) {
                Some(p) => p.clone(),
                None => {
                    let p = checked_path(base, given_path, &at)?;
                    full_paths.insert(given_path, p.clone());
                    p
                }
            };
            if params.iter().any(|(p, _)| *p == path) {
                return Err(file_err(
                    at,
                    format!("'{given_path}' names {path}, which this variant sets already: give each parameter once"),
                ));
            }
            // each value checked on its own against the base, as a sweep file's values are
            checked_value(base, &base_json, &path, value, &at)?;
            params.push((path, value.clone()));
        }
        let design = resolve_in(&base_json, base, &at, &params)?;
        let id = variant_id(&design, tol.mm());
        if let Some(other) = seen.insert(id.clone(), index) {
            return Err(file_err(
                origin.to_string(),
                format!(
                    "variants {other} and {index} resolve to the same design (id {id}); remove the duplicate value"
                ),
            ));
        }
        for (p, _) in &params {
            if listed.insert(p.clone()) {
                parameters.push(p.clone());
            }
        }
        variants.push(Variant { index, id, params });
    }
    Ok(VariantList {
        parameters,
        variants,
    })
}

/// The base design `base_json` (JSON form) with the values of `params` set.
///
/// # Errors
/// [`SweepError::UnknownPath`] or [`SweepError::WrongValue`] (checked when the variants were
/// planned, so only a defect reaches this), located at `origin`.
pub fn resolve_variant(
    base: &Design,
    origin: &str,
    params: &[(String, Value)],
) -> Result<Design, SweepError> {
    let v = serde_json::to_value(base).unwrap_or(Value::Null);
    resolve_in(&v, base, origin, params)
}

/// [`resolve_variant`] with the base design's JSON form `base_json` computed once by the caller.
pub(crate) fn resolve_in(
    base_json: &Value,
    base: &Design,
    origin: &str,
    params: &[(String, Value)],
) -> Result<Design, SweepError> {
    let mut v = base_json.clone();
    for (path, value) in params {
        *value_at(&mut v, path).ok_or_else(|| SweepError::UnknownPath {
            at: origin.to_string(),
            path: path.clone(),
            design: base.name.clone(),
            nearest: vec![],
        })? = value.clone();
    }
    serde_json::from_value(v).map_err(|e| SweepError::WrongValue {
        at: origin.to_string(),
        path: params
            .iter()
            .map(|p| p.0.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        value: params
            .iter()
            .map(|p| p.1.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        message: e.to_string(),
    })
}

/// Whether every key and index of the parameter path `path` exists in `v` (nothing inserted).
fn exists_at(v: &Value, path: &str) -> bool {
    let mut cur = v;
    for part in path.split('.') {
        let (key, mut rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        fn step<'v>(cur: &'v Value, k: &str) -> Option<&'v Value> {
            match cur {
                Value::Object(o) => o.get(k),
                Value::Array(a) => a.get(k.parse::<usize>().ok()?),
                _ => None,
            }
        }
        let Some(next) = step(cur, key) else {
            return false;
        };
        cur = next;
        while let Some(stripped) = rest.strip_prefix('[') {
            let Some(j) = stripped.find(']') else {
                return false;
            };
            let Some(next) = step(cur, &stripped[..j]) else {
                return false;
            };
            cur = next;
            rest = &stripped[j + 1..];
        }
    }
    true
}

/// The design `base_json` (a design's JSON form) with `value` at `path`, deserialized without
/// copying the whole form: the value is swapped in and `base_json` is restored afterwards.
/// `None` when `path` names nothing in `base_json`.
pub(crate) fn design_with(
    base_json: &mut Value,
    path: &str,
    value: &Value,
) -> Option<Result<Design, serde_json::Error>> {
    use serde::Deserialize as _;
    if !exists_at(base_json, path) {
        // a key the form leaves out: set it on a copy, so that `base_json` keeps it absent
        let v = with_value(base_json, path, value)?;
        return Some(serde_json::from_value(v));
    }
    let old = std::mem::replace(value_at(base_json, path)?, value.clone());
    let design = Design::deserialize(&*base_json);
    if let Some(slot) = value_at(base_json, path) {
        *slot = old;
    }
    Some(design)
}

/// Writes the files of an ok variant (its resolved design and kit); the error is the variant's.
pub type WriteFiles<'a> = &'a dyn Fn(&Design, &Kit) -> Result<(), String>;

/// Builds and measures one variant (`design`: the base with `v`'s values set, or why it could
/// not be resolved), as `fabkit sweep` does: status, violations or failure, metrics and
/// printability verdicts; a kernel panic is this variant's error, not the sweep's end. `write`
/// writes the files of an ok variant (`None`: metrics only); its error is the variant's.
/// `build_time_s` is the wall time of it all.
#[allow(clippy::too_many_arguments)]
pub fn evaluate_variant(
    v: &Variant,
    design: Result<Design, String>,
    materials: &MaterialsTable,
    tol: ChordTolerance,
    max_triangles: u64,
    fabkit_version: &str,
    files: FileOutputs,
    write: Option<WriteFiles<'_>>,
) -> VariantResult {
    let t0 = std::time::Instant::now();
    let mut result = VariantResult {
        index: v.index,
        id: v.id.clone(),
        params: v.params.iter().cloned().collect(),
        status: Status::Error,
        errors: vec![],
        metrics: None,
        printability: vec![],
        files: FileOutputs::default(),
        build_time_s: None,
        fabkit_version: fabkit_version.to_string(),
    };
    let design = match design {
        Ok(d) => d,
        Err(e) => {
            result.errors = vec![e];
            return result;
        }
    };
    // A panic in the kernel must not end the sweep: record it as this variant's error.
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        // a variant only measured needs of its assembly what the fit check needs
        let scope = if write.is_some() {
            AssemblyScope::Whole
        } else {
            AssemblyScope::FitCheck
        };
        let outcome = evaluate_scoped(&design, materials, tol, max_triangles, scope);
        let verdicts = printability(&design, materials, tol);
        (outcome, verdicts)
    }));
    match outcome {
        Err(panic) => {
            let msg = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            result.errors = vec![format!("the build panicked (a fabkit defect): {msg}")];
        }
        Ok((outcome, verdicts)) => {
            result.printability = verdicts;
            match outcome {
                Outcome::Infeasible(e) => {
                    result.status = Status::Infeasible;
                    result.errors = e;
                }
                Outcome::Error(e) => result.errors = vec![e],
                Outcome::Ok { metrics, kit } => {
                    let written = match write {
                        None => Ok(()),
                        Some(w) => w(&design, &kit),
                    };
                    match written {
                        Ok(()) => {
                            result.status = Status::Ok;
                            result.metrics = Some(metrics);
                            result.files = files;
                        }
                        Err(e) => result.errors = vec![format!("writing the files: {e}")],
                    }
                }
            }
        }
    }
    result.build_time_s = Some(t0.elapsed().as_secs_f64());
    result
}
