//! The sweep file: which design, which parameters take which values, how they combine and
//! what to write. Every problem is reported before anything runs, at its `file:line:column`.

use super::variants::{checked_path, checked_value};
use super::SweepError;
use fabkit_designs::input_files::{read_text_file, DataFileRules, MAX_DESIGN_FILE_BYTES};
use fabkit_designs::library::{load_source_with, LoadedDesign};
use fabkit_designs::schema::yaml_error;
use fabkit_designs::ChordTolerance;
use serde::de::{MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};
use serde_json::Value;
use serde_saphyr::Spanned;
use std::path::Path;

/// How the values of the varied parameters combine into variants.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Every combination (cartesian product); the first parameter in the file varies slowest.
    Grid,
    /// The lists in step: variant k takes the k-th value of every parameter (equal lengths).
    Zip,
    /// `count` distinct combinations of the grid drawn without replacement, seeded by `seed`,
    /// listed in grid order.
    Random,
}

/// What a sweep writes for each variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Output {
    /// The row of the results table (always written).
    Metrics,
    /// The files of `fabkit export` (STL per part and the kit 3MF, manifest, sheet).
    Files,
    /// As `files`, STL only.
    Stl,
    /// As `files`, 3MF only.
    #[serde(rename = "3mf")]
    ThreeMf,
}

/// One varied parameter and its values, in the order they are tried.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Path in the design, e.g. `layers[0].markers[0].pattern.spacing_mm`.
    pub path: String,
    /// The values, as JSON (numbers keep the integer / float distinction of the file).
    pub values: Vec<Value>,
    /// `file:line:column` of the parameter's key in the sweep file.
    pub at: String,
}

/// Which formats the variant folders get, if any.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct FileOutputs {
    pub stl: bool,
    pub threemf: bool,
}

impl FileOutputs {
    pub fn any(self) -> bool {
        self.stl || self.threemf
    }

    /// The files `outputs` ask for: `files` both formats, `stl` or `3mf` one; `metrics` none.
    pub fn of(outputs: &[Output]) -> FileOutputs {
        let mut files = FileOutputs::default();
        for x in outputs {
            match x {
                Output::Metrics => {}
                Output::Files => {
                    files.stl = true;
                    files.threemf = true;
                }
                Output::Stl => files.stl = true,
                Output::ThreeMf => files.threemf = true,
            }
        }
        files
    }
}

impl Output {
    /// The output a sweep file names `name` (`metrics`, `files`, `stl`, `3mf`).
    ///
    /// # Errors
    /// A message naming the value and the names allowed.
    pub fn from_name(name: &str) -> Result<Output, String> {
        // the names a sweep file's `outputs` takes (the serde names)
        Output::deserialize(serde_json::Value::from(name))
            .map_err(|_| format!("'{name}' is not one of metrics, files, stl, 3mf"))
    }
}

/// A parsed and checked sweep file.
#[derive(Debug, Clone)]
pub struct SweepSpec {
    /// Where the sweep file was read from (for messages and provenance).
    pub origin: String,
    /// sha256 of the sweep file's text.
    pub sha256: String,
    /// The base design (preset applied) and its source.
    pub base: LoadedDesign,
    /// The preset applied to the base, if any.
    pub preset: Option<String>,
    pub chord_tolerance: ChordTolerance,
    pub parameters: Vec<Parameter>,
    pub mode: Mode,
    /// Seed of the random mode.
    pub seed: u64,
    /// Number of variants of the random mode.
    pub count: Option<u64>,
    pub files: FileOutputs,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSweep {
    base: Spanned<String>,
    #[serde(default)]
    preset: Option<Spanned<String>>,
    #[serde(default)]
    chord_tolerance_mm: Option<Spanned<f64>>,
    vary: Spanned<RawVary>,
    #[serde(default)]
    mode: Option<Spanned<Mode>>,
    #[serde(default)]
    seed: Option<Spanned<u64>>,
    #[serde(default)]
    count: Option<Spanned<u64>>,
    #[serde(default)]
    outputs: Option<Spanned<Vec<Output>>>,
}

/// The `vary` map in file order, each key with its location.
struct RawVary(Vec<(Spanned<String>, Spanned<Value>)>);

impl<'de> Deserialize<'de> for RawVary {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawVary;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a map from parameter paths to values")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut m: A) -> Result<RawVary, A::Error> {
                let mut out: Vec<(Spanned<String>, Spanned<Value>)> = Vec::new();
                while let Some(k) = m.next_key::<Spanned<String>>()? {
                    if out.iter().any(|(o, _)| o.value == k.value) {
                        return Err(serde::de::Error::custom(format!(
                            "parameter `{}` is listed twice",
                            k.value
                        )));
                    }
                    let v = m.next_value::<Spanned<Value>>()?;
                    out.push((k, v));
                }
                Ok(RawVary(out))
            }
        }
        d.deserialize_map(V)
    }
}

fn at<T>(origin: &str, s: &Spanned<T>) -> String {
    format!("{origin}:{}:{}", s.referenced.line(), s.referenced.column())
}

impl SweepSpec {
    /// Reads and checks the sweep file at `path`. The base design is read relative to the
    /// sweep file's folder.
    ///
    /// # Errors
    /// See [`SweepSpec::parse`]; [`SweepError::Io`] when the file cannot be read.
    pub fn from_file(path: &Path) -> Result<SweepSpec, SweepError> {
        Self::from_file_with(path, &DataFileRules::default())
    }

    /// [`SweepSpec::from_file`] with the rules for the data files the base design reads (see
    /// [`fabkit_designs::input_files`]). The sweep file must be a regular file of at most
    /// [`fabkit_designs::input_files::MAX_DESIGN_FILE_BYTES`].
    ///
    /// # Errors
    /// As [`SweepSpec::from_file`].
    pub fn from_file_with(path: &Path, rules: &DataFileRules) -> Result<SweepSpec, SweepError> {
        let text = read_text_file(path, MAX_DESIGN_FILE_BYTES).map_err(|e| SweepError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let dir = path.parent().unwrap_or(Path::new(""));
        Self::parse_with(&text, &path.display().to_string(), dir, rules)
    }

    /// Parses and checks a sweep file's text; `origin` names it in messages, `dir` is the folder
    /// a relative `base` path is read from.
    ///
    /// The number of variants is counted first, from the numbers of values
    /// ([`super::variant_count`]): a sweep of more than [`super::MAX_VARIANTS`] is refused
    /// before any value is looked at. Then every value of every parameter is checked against
    /// the schema in the base design, so that a wrong type is found before anything runs
    /// (for a parameter that takes any number, a plain `f64`, the design is probed once with
    /// extreme numbers and only its other values are set into it one by one). Whether a
    /// combination of values makes a feasible design is not checked here: an infeasible
    /// variant is a result. A parameter the design ignores is refused
    /// ([`SweepSpec::refuse_ignored_parameters`]: a few of its values are built).
    ///
    /// # Errors
    /// [`SweepError::File`] (YAML syntax, unknown keys, bad `range`, zip lists of different
    /// lengths, random mode without `count`, duplicate values...), [`SweepError::UnknownPath`]
    /// with the nearest valid paths, [`SweepError::WrongValue`], [`SweepError::Design`] for a
    /// base design that does not load; each with `file:line:column`.
    pub fn parse(text: &str, origin: &str, dir: &Path) -> Result<SweepSpec, SweepError> {
        Self::parse_with(text, origin, dir, &DataFileRules::default())
    }

    /// [`SweepSpec::parse`] with the rules for the data files the base design reads.
    ///
    /// # Errors
    /// As [`SweepSpec::parse`].
    pub fn parse_with(
        text: &str,
        origin: &str,
        dir: &Path,
        rules: &DataFileRules,
    ) -> Result<SweepSpec, SweepError> {
        use sha2::{Digest, Sha256};
        let raw: RawSweep =
            fabkit_designs::schema::yaml_from_str(text).map_err(|e| SweepError::File {
                at: String::new(),
                message: yaml_error(origin, &e),
            })?;
        let base = read_base(&raw, origin, dir, rules)?;
        let preset = raw.preset.as_ref().map(|p| p.value.clone());
        let chord_tolerance = match &raw.chord_tolerance_mm {
            None => ChordTolerance::default(),
            Some(t) => ChordTolerance::new(t.value).map_err(|e| file_err(at(origin, t), e))?,
        };
        let mode = check_mode(&raw, origin)?;
        let files = file_outputs(&raw, origin)?;
        if raw.vary.value.0.is_empty() {
            return Err(file_err(
                at(origin, &raw.vary),
                "vary: give at least one parameter path and its values".into(),
            ));
        }
        let base_json = serde_json::to_value(&base.design).map_err(|e| SweepError::File {
            at: origin.to_string(),
            message: e.to_string(),
        })?;
        let materials = fabkit_designs::materials::MaterialsTable::embedded().map_err(|e| {
            SweepError::File {
                at: origin.to_string(),
                message: e,
            }
        })?;
        // First the paths and the number of values: a sweep of too many variants is refused
        // before any value is looked at.
        let (parameters, values_at) = listed_parameters(&raw, &base.design, origin)?;
        super::plan::variant_count(
            &parameters,
            mode,
            raw.count.as_ref().map(|c| c.value),
            origin,
        )?;
        check_every_value(
            &parameters,
            &values_at,
            mode,
            &base.design,
            &base_json,
            &materials,
            chord_tolerance,
        )?;
        if mode == Mode::Zip {
            check_zip_rows(&parameters)?;
        }
        let sha256 = Sha256::digest(text.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        let spec = SweepSpec {
            origin: origin.to_string(),
            sha256,
            base,
            preset,
            chord_tolerance,
            parameters,
            mode,
            seed: raw.seed.map(|s| s.value).unwrap_or(0),
            count: raw.count.map(|c| c.value),
            files,
        };
        spec.refuse_ignored_parameters(&materials)?;
        Ok(spec)
    }
}

/// A [`SweepError::File`] at `at`.
fn file_err(at: String, message: String) -> SweepError {
    SweepError::File { at, message }
}

/// Reads the sweep's base design (relative to `dir`) and applies its preset, if any.
fn read_base(
    raw: &RawSweep,
    origin: &str,
    dir: &Path,
    rules: &DataFileRules,
) -> Result<LoadedDesign, SweepError> {
    let mut base =
        load_source_with(&raw.base.value, dir, rules).map_err(|e| SweepError::Design {
            at: at(origin, &raw.base),
            error: e,
        })?;
    if let Some(p) = &raw.preset {
        base.apply_preset(&p.value)
            .map_err(|e| SweepError::Design {
                at: at(origin, p),
                error: e,
            })?;
    }
    Ok(base)
}

/// The varied parameters in file order, each path checked against `design` and given once,
/// with their values; and where each one's values are listed.
fn listed_parameters(
    raw: &RawSweep,
    design: &fabkit_designs::schema::Design,
    origin: &str,
) -> Result<(Vec<Parameter>, Vec<String>), SweepError> {
    let mut parameters: Vec<Parameter> = Vec::new();
    let mut values_at: Vec<String> = Vec::new();
    for (key, spec) in &raw.vary.value.0 {
        let here = at(origin, key);
        // A short path (`markers.spacing_mm`) stands for the one full path it fits.
        let path = checked_path(design, &key.value, &here)?;
        if let Some(other) = parameters.iter().find(|p: &&Parameter| p.path == path) {
            return Err(file_err(
                here,
                format!(
                    "vary: '{}' names {path}, which is varied already (at {}): give each parameter once",
                    key.value.trim(),
                    other.at
                ),
            ));
        }
        let values = values_of(&spec.value)
            .map_err(|m| file_err(at(origin, spec), format!("vary.{path}: {m}")))?;
        parameters.push(Parameter {
            path,
            values,
            at: here,
        });
        values_at.push(at(origin, spec));
    }
    Ok((parameters, values_at))
}

/// Checks every value of every parameter against the schema in the base design
/// ([`check_values`]), and that the design does not ignore the parameter.
fn check_every_value(
    parameters: &[Parameter],
    values_at: &[String],
    mode: Mode,
    design: &fabkit_designs::schema::Design,
    base_json: &Value,
    materials: &fabkit_designs::materials::MaterialsTable,
    chord_tolerance: ChordTolerance,
) -> Result<(), SweepError> {
    for (p, spec_at) in parameters.iter().zip(values_at) {
        // in a zip a value may repeat in one list: only a repeated row is one variant twice
        let refuse_repeats = mode != Mode::Zip;
        check_values(p, spec_at, design, base_json, refuse_repeats, |variant| {
            // A parameter the rest of the design ignores would give identical variants.
            if let Err(errs) = fabkit_designs::stack::validate(variant, materials, chord_tolerance)
            {
                if let Some(e) = errs.0.iter().find(|e| {
                    e.path == p.path && e.rule.starts_with(fabkit_designs::markers::NO_EFFECT)
                }) {
                    return Err(file_err(
                        p.at.clone(),
                        format!(
                            "vary.{}: {} (every variant would be the same design)",
                            p.path, e.rule
                        ),
                    ));
                }
            }
            Ok(())
        })?;
    }
    Ok(())
}

/// Checks the lists of a zip sweep: of one length, and no row repeated (the same variant
/// twice).
fn check_zip_rows(parameters: &[Parameter]) -> Result<(), SweepError> {
    let n = parameters[0].values.len();
    if let Some(p) = parameters.iter().find(|p| p.values.len() != n) {
        return Err(file_err(
            p.at.clone(),
            format!(
                "mode zip takes the lists in step, but vary.{} has {} values and vary.{} has {n}",
                p.path,
                p.values.len(),
                parameters[0].path
            ),
        ));
    }
    // a row repeated is the same variant twice
    let mut rows: std::collections::HashMap<String, usize> =
        std::collections::HashMap::with_capacity(n);
    for i in 0..n {
        let key = parameters
            .iter()
            .map(|p| equality_key(&p.values[i]))
            .collect::<Vec<_>>()
            .join("\u{1f}");
        if let Some(&j) = rows.get(&key) {
            return Err(file_err(
                parameters[0].at.clone(),
                format!(
                    "mode zip: rows {j} and {i} of the lists are the same variant ({}); give each row once",
                    parameters
                        .iter()
                        .map(|p| format!("{} = {}", p.path, p.values[i]))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        rows.insert(key, i);
    }
    Ok(())
}

/// Checks the values of `p` (listed at `spec_at`) in order, as one loop would: the first value
/// set into the base design (`base_json`, its JSON form) must fit the schema and pass
/// `first_design`, then each further value must not repeat an earlier one and must fit the
/// schema. The first problem in that order is the error. Linear: repeats are found by hashing,
/// and the values are set into the base design in parallel.
fn check_values(
    p: &Parameter,
    spec_at: &str,
    design: &fabkit_designs::schema::Design,
    base_json: &Value,
    refuse_repeats: bool,
    first_design: impl FnOnce(&fabkit_designs::schema::Design) -> Result<(), SweepError>,
) -> Result<(), SweepError> {
    use rayon::prelude::*;
    let values = &p.values;
    let mut seen: std::collections::HashSet<String> =
        std::collections::HashSet::with_capacity(values.len());
    let repeated = values
        .iter()
        .position(|v| !seen.insert(equality_key(v)))
        .filter(|_| refuse_repeats);
    drop(seen);
    let first = checked_value(design, base_json, &p.path, &values[0], spec_at)?;
    first_design(&first)?;
    let end = repeated.unwrap_or(values.len());
    // a plain number parameter takes any number: only its other values are set into the design
    let numbers = super::plan::takes_any_number(base_json, &p.path);
    let bad = (1..end)
        .into_par_iter()
        .map_init(
            || None,
            |json: &mut Option<Value>, i| {
                if numbers && values[i].is_number() {
                    return None;
                }
                let json = json.get_or_insert_with(|| base_json.clone());
                let fits = super::variants::design_with(json, &p.path, &values[i])
                    .is_some_and(|d| d.is_ok());
                (!fits).then_some(i)
            },
        )
        .find_first(Option::is_some)
        .flatten();
    if let Some(i) = bad {
        // the error exactly as the value alone gives it
        checked_value(design, base_json, &p.path, &values[i], spec_at)?;
    }
    if let Some(i) = repeated {
        return Err(SweepError::File {
            at: spec_at.to_string(),
            message: format!("vary.{}: the value {} is listed twice", p.path, values[i]),
        });
    }
    Ok(())
}

/// A text equal for two values exactly when they are equal as JSON values (`==`): the
/// canonical JSON, with a negative zero written as zero (`-0.0 == 0.0`).
fn equality_key(v: &Value) -> String {
    fn has_negative_zero(v: &Value) -> bool {
        match v {
            Value::Number(n) => n.as_f64().is_some_and(|f| f == 0.0 && f.is_sign_negative()),
            Value::Array(a) => a.iter().any(has_negative_zero),
            Value::Object(o) => o.values().any(has_negative_zero),
            _ => false,
        }
    }
    fn positive_zero(v: &Value) -> Value {
        match v {
            Value::Number(n) if n.as_f64().is_some_and(|f| f == 0.0 && f.is_sign_negative()) => {
                Value::from(0.0)
            }
            Value::Array(a) => Value::Array(a.iter().map(positive_zero).collect()),
            Value::Object(o) => Value::Object(
                o.iter()
                    .map(|(k, x)| (k.clone(), positive_zero(x)))
                    .collect(),
            ),
            other => other.clone(),
        }
    }
    if has_negative_zero(v) {
        fabkit_designs::variant::canonical_json(&positive_zero(v))
    } else {
        fabkit_designs::variant::canonical_json(v)
    }
}

/// The values a `vary` entry stands for: a list `[a, b, ...]`, `{list: [...]}` or
/// `{range: [start, stop, step]}` (stop included when it falls on the grid; integers when all
/// three are integers, else numbers rounded to the decimals written in the file).
///
/// # Errors
/// A message naming the rule that the entry breaks.
pub fn values_of(spec: &Value) -> Result<Vec<Value>, String> {
    let values = match spec {
        Value::Array(a) => a.clone(),
        Value::Object(o) if o.len() == 1 && o.contains_key("list") => match &o["list"] {
            Value::Array(a) => a.clone(),
            other => return Err(format!("list must be a list of values, found {other}")),
        },
        Value::Object(o) if o.len() == 1 && o.contains_key("range") => range(&o["range"])?,
        other => {
            return Err(format!(
                "expected a list of values, {{list: [...]}} or {{range: [start, stop, step]}}, found {other}"
            ))
        }
    };
    if values.is_empty() {
        return Err("no values".into());
    }
    Ok(values)
}

/// Most values a single range may produce.
const MAX_RANGE_VALUES: f64 = 1_000_000.0;

fn range(r: &Value) -> Result<Vec<Value>, String> {
    let a = r
        .as_array()
        .filter(|a| a.len() == 3 && a.iter().all(Value::is_number))
        .ok_or_else(|| format!("range must be three numbers [start, stop, step], found {r}"))?;
    let ints: Option<Vec<i64>> = a.iter().map(Value::as_i64).collect();
    if let Some(i) = ints {
        let (start, stop, step) = (i[0], i[1], i[2]);
        if step <= 0 || stop < start {
            return Err(format!(
                "range [{start}, {stop}, {step}]: needs step > 0 and stop >= start"
            ));
        }
        // In i128: neither the count nor any value can overflow (start + k step <= stop).
        let n = (i128::from(stop) - i128::from(start)) / i128::from(step) + 1;
        if n as f64 > MAX_RANGE_VALUES {
            return Err(format!(
                "range {r} has {n} values, more than {MAX_RANGE_VALUES}"
            ));
        }
        return Ok((0..n)
            .map(|k| Value::from((i128::from(start) + k * i128::from(step)) as i64))
            .collect());
    }
    let f: Vec<f64> = a.iter().filter_map(Value::as_f64).collect();
    let (start, stop, step) = (f[0], f[1], f[2]);
    if !(step > 0.0 && stop >= start && start.is_finite() && stop.is_finite()) {
        return Err(format!(
            "range [{start}, {stop}, {step}]: needs step > 0 and stop >= start"
        ));
    }
    let n = ((stop - start) / step + 1e-9).floor() + 1.0;
    if n > MAX_RANGE_VALUES {
        return Err(format!("range {r} has more than {MAX_RANGE_VALUES} values"));
    }
    // Values are start + k step rounded to the decimals written (0.2 -> 1 decimal), so that
    // [1.2, 2.0, 0.2] gives 1.2, 1.4, 1.6, 1.8, 2.0 exactly as typed, not 1.5999999999999999.
    let decimals = f
        .iter()
        .map(|x| {
            let s = x.to_string();
            s.split_once('.').map(|(_, d)| d.len()).unwrap_or(0)
        })
        .max()
        .unwrap_or(0);
    (0..n as usize)
        .map(|k| {
            let v = start + k as f64 * step;
            format!("{v:.decimals$}")
                .parse::<f64>()
                .map_err(|e| e.to_string())
                .map(Value::from)
        })
        .collect()
}

/// The sweep's mode (default grid), with `count` and `seed` given only to, and `count` above
/// 0 for, mode random.
///
/// # Errors
/// [`SweepError::File`] at the key that breaks the rule.
fn check_mode(raw: &RawSweep, origin: &str) -> Result<Mode, SweepError> {
    let file_err = |s: String, message: String| SweepError::File { at: s, message };
    let mode = raw.mode.as_ref().map(|m| m.value).unwrap_or(Mode::Grid);
    match (&raw.count, &raw.seed, mode) {
        (None, _, Mode::Random) => {
            return Err(file_err(
                raw.mode.as_ref().map(|m| at(origin, m)).unwrap_or_default(),
                "mode random needs `count` (and takes `seed`, default 0)".into(),
            ))
        }
        (Some(c), _, m) if m != Mode::Random => {
            return Err(file_err(
                at(origin, c),
                "`count` only applies to mode random".into(),
            ))
        }
        (_, Some(s), m) if m != Mode::Random => {
            return Err(file_err(
                at(origin, s),
                "`seed` only applies to mode random".into(),
            ))
        }
        (Some(c), _, _) if c.value == 0 => {
            return Err(file_err(at(origin, c), "`count` must be above 0".into()))
        }
        _ => {}
    }
    Ok(mode)
}

/// Which files each variant writes besides its metrics row (`outputs`, which must include
/// `metrics`).
///
/// # Errors
/// [`SweepError::File`] at `outputs` when it leaves out `metrics`.
fn file_outputs(raw: &RawSweep, origin: &str) -> Result<FileOutputs, SweepError> {
    let file_err = |s: String, message: String| SweepError::File { at: s, message };
    let mut files = FileOutputs::default();
    if let Some(o) = &raw.outputs {
        if !o.value.contains(&Output::Metrics) {
            return Err(file_err(
                at(origin, o),
                "outputs must include metrics (the results table is always written): [metrics] or [metrics, files]".into(),
            ));
        }
        files = FileOutputs::of(&o.value);
    }
    Ok(files)
}
