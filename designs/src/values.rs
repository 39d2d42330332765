//! Every number and text of a design or fixture file checked in one place, numbers by the unit
//! their names carry (`docs/conventions.md`: `_mm`, `_deg`), so that no field can be forgotten:
//! a new field is checked by its name alone.
//!
//! The rules, for every number (integers are typed `u32` / `u64` by the schema and refused by
//! the parser past their type's range):
//!
//! - every value is finite (YAML `.nan`, `.inf` and numbers past `f64` are refused);
//! - a length (`_mm`, or an element or field of a `_mm` parameter such as
//!   `hole_compensation_mm.fdm`) is at most [`MAX_LENGTH_MM`] and not negative, except the few
//!   lengths a caller names as signed, and 0 or at least [`MIN_LENGTH_MM`] in magnitude;
//! - an angle (`_deg`) is from -[`MAX_ANGLE_DEG`] to [`MAX_ANGLE_DEG`], and 0 or at least
//!   [`MIN_ANGLE_DEG`] in magnitude;
//! - any other number (a ratio such as `waste_allowance`) is within +-[`MAX_PLAIN`];
//! - an integer (a count) is within +-[`MAX_PLAIN`], except a `seed`;
//! - text (names, descriptions, keys) holds no control characters but line breaks and tabs.
//!
//! Each parameter's own range (above 0, below a radius, within a body's polar range) is checked
//! after these by the validation of the part it builds ([`crate::stack::validate`]).

use crate::error::ParamError;
use serde::Serialize;
use serde_value::Value;

/// Largest length of any parameter, mm: larger than any print bed, mold or sensor.
pub const MAX_LENGTH_MM: f64 = 1000.0;
/// Smallest magnitude of a length that is not 0, mm: the finest chord tolerance
/// ([`crate::ChordTolerance::MIN_MM`]), 25 times finer than the finest SLA layer. A nonzero
/// length below it is below anything a printer, a mold or a camera resolves, and the geometry
/// kernel cannot build it.
pub const MIN_LENGTH_MM: f64 = 0.001;
/// Longest name that becomes part of a file name (a design, layer, part, stock, printer bed
/// or pattern name), characters: with the design's name and a suffix, a file name stays well
/// inside the 255 bytes file systems allow.
pub const MAX_NAME_CHARS: usize = 64;

/// Whether `s` can name a file: 1 to [`MAX_NAME_CHARS`] characters of `[a-z0-9_]`.
pub fn is_file_stem(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= MAX_NAME_CHARS
        && s.bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_')
}

/// Smallest magnitude of an angle that is not 0, degrees: [`MIN_LENGTH_MM`] /
/// [`MAX_LENGTH_MM`] radians (5.7e-5 deg), rounded down. A smaller nonzero angle moves no point
/// of a part by as much as the smallest length, so it can only be a typing error (or 0).
pub const MIN_ANGLE_DEG: f64 = 5e-5;
/// Largest magnitude of any angle, degrees (one full turn).
pub const MAX_ANGLE_DEG: f64 = 360.0;
/// Largest magnitude of any other number.
pub const MAX_PLAIN: f64 = 1e6;

/// The unit a parameter name carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Unit {
    Mm,
    Deg,
    Plain,
}

pub(crate) fn unit_of(key: &str) -> Option<Unit> {
    if key.ends_with("_mm") {
        Some(Unit::Mm)
    } else if key.ends_with("_deg") {
        Some(Unit::Deg)
    } else {
        None
    }
}

/// What [`check_values`] found, in two kinds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ValueErrors {
    /// Values no rule can compute with: not finite, or past the unit's magnitude; text with
    /// control characters. The caller reports these alone, before any other rule.
    pub unusable: Vec<ParamError>,
    /// Negative lengths. The caller reports these beside its own rules, except where one of its
    /// rules already names the same parameter (its rule is the more specific).
    pub negative: Vec<ParamError>,
}

impl ValueErrors {
    /// Whether every number is in range.
    pub fn is_empty(&self) -> bool {
        self.unusable.is_empty() && self.negative.is_empty()
    }

    /// `errs` (the caller's own rules) with the negative lengths they do not already name.
    pub fn merge_negative(self, mut errs: Vec<ParamError>) -> Vec<ParamError> {
        for n in self.negative {
            if !errs.iter().any(|e| e.path == n.path) {
                errs.push(n);
            }
        }
        errs
    }
}

/// Checks every floating-point number and every text of `value` (a whole design or fixture
/// parameter file, as serialized) against the rules of the module documentation. `signed_mm`
/// names the length parameters (by their last key) that may be negative.
///
/// Each error names the value's path (`layers[0].thickness_mm`, `hole_compensation_mm.fdm`),
/// the value and the rule.
pub fn check_values<T: Serialize + ?Sized>(value: &T, signed_mm: &[&str]) -> ValueErrors {
    let mut errs = ValueErrors::default();
    match serde_value::to_value(value) {
        Ok(v) => walk(&v, "", None, false, signed_mm, &mut errs),
        // Serialize of a schema type does not fail; say so rather than pass silently.
        Err(e) => errs.unusable.push(ParamError::new(
            "(file)",
            "?",
            format!("cannot be read as numbers: {e}"),
        )),
    }
    errs
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else if key.starts_with('[') {
        format!("{prefix}{key}")
    } else {
        format!("{prefix}.{key}")
    }
}

fn walk(
    v: &Value,
    path: &str,
    unit: Option<Unit>,
    signed: bool,
    signed_mm: &[&str],
    errs: &mut ValueErrors,
) {
    match v {
        Value::String(t) => check_text(t, path, errs),
        Value::F64(x) => check_one(*x, path, unit.unwrap_or(Unit::Plain), signed, errs),
        Value::F32(x) => check_one(
            f64::from(*x),
            path,
            unit.unwrap_or(Unit::Plain),
            signed,
            errs,
        ),
        n if is_integer(n) => check_integer(n, path, errs),
        Value::Option(Some(inner)) | Value::Newtype(inner) => {
            walk(inner, path, unit, signed, signed_mm, errs)
        }
        Value::Seq(items) => {
            for (i, x) in items.iter().enumerate() {
                walk(x, &format!("{path}[{i}]"), unit, signed, signed_mm, errs);
            }
        }
        Value::Map(m) => {
            for (k, x) in m {
                let key = match k {
                    Value::String(s) => s.clone(),
                    other => format!("{other:?}"),
                };
                check_text(&key, &join(path, "(key)"), errs);
                // A key with a unit sets it for everything under it; one without keeps the
                // parent's (`hole_compensation_mm.fdm`, `bed_size_mm[0]`).
                let (u, s) = match unit_of(&key) {
                    Some(u) => (Some(u), signed_mm.contains(&key.as_str())),
                    None => (unit, signed),
                };
                walk(x, &join(path, &key), u, s, signed_mm, errs);
            }
        }
        _ => {}
    }
}

/// An integer (a count) is within +-[`MAX_PLAIN`], except a random generator's `seed`: a count
/// that no part of the design reads would otherwise take any value (2^31 vents on a mold
/// without vents); the counts that are read have their own, smaller bounds.
fn check_integer(v: &Value, path: &str, errs: &mut ValueErrors) {
    let n: i128 = match *v {
        Value::U8(n) => n.into(),
        Value::U16(n) => n.into(),
        Value::U32(n) => n.into(),
        Value::U64(n) => n.into(),
        Value::I8(n) => n.into(),
        Value::I16(n) => n.into(),
        Value::I32(n) => n.into(),
        Value::I64(n) => n.into(),
        _ => return,
    };
    let seed = path
        .rsplit(['.', '['])
        .next()
        .is_some_and(|k| k.ends_with("seed"));
    if !seed && n.unsigned_abs() > MAX_PLAIN as u128 {
        let path = if path.is_empty() { "(value)" } else { path };
        let signed = matches!(
            v,
            Value::I8(_) | Value::I16(_) | Value::I32(_) | Value::I64(_)
        );
        let least = if signed { -MAX_PLAIN } else { 0.0 };
        errs.unusable.push(ParamError::new(
            path,
            n,
            format!("{PAST_ANY_COUNT} from {least} to {MAX_PLAIN}"),
        ));
    }
}

/// The start of the rule [`check_values`] gives a count past +-[`MAX_PLAIN`] (before the
/// field's own rule is known: [`with_field_count_rules`]).
pub const PAST_ANY_COUNT: &str = "must be a count";

/// `errs` (from [`check_values`] of `value`) with each count past [`MAX_PLAIN`] said by its
/// field's own rule: `rules` (the checks of `value`'s type, every error) is run on `value` with
/// those counts set to [`MAX_PLAIN`], where its work is bounded, and the rule it gives at each
/// such path replaces the generic range, marked as checked at [`MAX_PLAIN`]. A count whose
/// field has no rule of its own there keeps the generic range.
pub fn with_field_count_rules<T: Serialize + serde::de::DeserializeOwned>(
    value: &T,
    errs: Vec<ParamError>,
    rules: impl FnOnce(&T) -> Vec<ParamError>,
) -> Vec<ParamError> {
    let counts: Vec<usize> = (0..errs.len())
        .filter(|&k| {
            errs[k].rule.starts_with(PAST_ANY_COUNT) && errs[k].value.parse::<u64>().is_ok()
        })
        .collect();
    if counts.is_empty() {
        return errs;
    }
    let mut clamped = None;
    for &k in &counts {
        let Some(path) = NumberPath::parse(&errs[k].path) else {
            continue;
        };
        match with_integer(clamped.as_ref().unwrap_or(value), &path, MAX_PLAIN as u64) {
            Ok(c) => clamped = Some(c),
            Err(_) => continue,
        }
    }
    let Some(clamped) = clamped else {
        return errs;
    };
    let found = rules(&clamped);
    let mut errs = errs;
    for k in counts {
        if let Some(e) = found.iter().find(|e| e.path == errs[k].path) {
            errs[k].rule = format!(
                "{} (checked at {MAX_PLAIN}, the most any count may be)",
                e.rule
            );
        }
    }
    errs
}

/// Text holds no control characters other than line breaks and tabs: an escape sequence in a
/// name or a description would reach the fabrication sheet and the terminal.
fn check_text(t: &str, path: &str, errs: &mut ValueErrors) {
    if t.chars().any(|c| c.is_control() && c != '\n' && c != '\t') {
        let path = if path.is_empty() { "(value)" } else { path };
        errs.unusable.push(ParamError::new(
            path,
            format!("{t:?}"),
            "must not hold control characters (such as terminal escape sequences)",
        ));
    }
}

/// A value as a reader wants it in an error: `1e300`, not 301 digits.
fn shown(x: f64) -> String {
    if x.is_finite() && x != 0.0 && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

fn check_one(x: f64, path: &str, unit: Unit, signed: bool, errs: &mut ValueErrors) {
    let path = if path.is_empty() { "(value)" } else { path };
    if !x.is_finite() {
        errs.unusable
            .push(ParamError::new(path, shown(x), "must be a finite number"));
        return;
    }
    let rule = match unit {
        Unit::Mm if x.abs() > MAX_LENGTH_MM => {
            format!("must be a length of at most {MAX_LENGTH_MM} mm")
        }
        Unit::Deg if x.abs() > MAX_ANGLE_DEG => {
            format!("must be an angle from -{MAX_ANGLE_DEG} to {MAX_ANGLE_DEG} deg")
        }
        Unit::Deg if x != 0.0 && x.abs() < MIN_ANGLE_DEG => format!(
            "must be 0 or an angle of at least {MIN_ANGLE_DEG:e} deg (smaller moves no point of a part by {MIN_LENGTH_MM} mm)"
        ),
        Unit::Plain if x.abs() > MAX_PLAIN => format!("must be from -{MAX_PLAIN} to {MAX_PLAIN}"),
        Unit::Mm if x != 0.0 && x.abs() < MIN_LENGTH_MM => format!(
            "must be 0 or a length of at least {MIN_LENGTH_MM} mm (finer than any printer, mold or camera resolves)"
        ),
        Unit::Mm if x < 0.0 && !signed => {
            errs.negative.push(ParamError::new(
                path,
                shown(x),
                "must not be negative (a length, mm)",
            ));
            return;
        }
        _ => return,
    };
    errs.unusable.push(ParamError::new(path, shown(x), rule));
}

/// One step into a serialized value: a field or map key, or a list index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step {
    Key(String),
    Index(usize),
}

/// Where one number sits in a serialized value; prints as the error paths do
/// (`layers[0].markers[0].pattern.spacing_mm`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NumberPath(pub Vec<Step>);

impl std::fmt::Display for NumberPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, st) in self.0.iter().enumerate() {
            match st {
                Step::Key(k) if i == 0 => write!(f, "{k}")?,
                Step::Key(k) => write!(f, ".{k}")?,
                Step::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

/// The path of every floating-point number of `value` as serialized (the numbers
/// [`check_values`] checks), leaving out the top-level maps named in `skip` (a design's
/// `presets`, paths into its own fields). For tools and tests that vary every parameter.
///
/// # Errors
/// The serializer's message (a schema type does not fail).
pub fn number_paths<T: Serialize + ?Sized>(
    value: &T,
    skip: &[&str],
) -> Result<Vec<NumberPath>, String> {
    paths_where(value, skip, |v| matches!(v, Value::F64(_) | Value::F32(_)))
}

/// The path of every integer of `value` as serialized (counts, seeds), leaving out the
/// top-level maps named in `skip`, like [`number_paths`] for floating-point numbers.
///
/// # Errors
/// The serializer's message (a schema type does not fail).
pub fn integer_paths<T: Serialize + ?Sized>(
    value: &T,
    skip: &[&str],
) -> Result<Vec<NumberPath>, String> {
    paths_where(value, skip, is_integer)
}

/// Whether `v` is an integer of any width.
fn is_integer(v: &Value) -> bool {
    matches!(
        v,
        Value::U8(_)
            | Value::U16(_)
            | Value::U32(_)
            | Value::U64(_)
            | Value::I8(_)
            | Value::I16(_)
            | Value::I32(_)
            | Value::I64(_)
    )
}

/// The path of every leaf of `value` (as serialized) for which `leaf` holds, leaving out the
/// top-level maps named in `skip`.
fn paths_where<T: Serialize + ?Sized>(
    value: &T,
    skip: &[&str],
    leaf: fn(&Value) -> bool,
) -> Result<Vec<NumberPath>, String> {
    fn walk(
        v: &Value,
        path: &mut Vec<Step>,
        skip: &[&str],
        leaf: fn(&Value) -> bool,
        out: &mut Vec<NumberPath>,
    ) {
        match v {
            v if leaf(v) => out.push(NumberPath(path.clone())),
            Value::Option(Some(x)) | Value::Newtype(x) => walk(x, path, skip, leaf, out),
            Value::Seq(items) => {
                for (i, x) in items.iter().enumerate() {
                    path.push(Step::Index(i));
                    walk(x, path, skip, leaf, out);
                    path.pop();
                }
            }
            Value::Map(m) => {
                for (k, x) in m {
                    let Value::String(k) = k else { continue };
                    if path.is_empty() && skip.contains(&k.as_str()) {
                        continue;
                    }
                    path.push(Step::Key(k.clone()));
                    walk(x, path, skip, leaf, out);
                    path.pop();
                }
            }
            _ => {}
        }
    }
    let v = serde_value::to_value(value).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    walk(&v, &mut Vec::new(), skip, leaf, &mut out);
    Ok(out)
}

/// The value at `path` in a serialized value, through options and newtypes; `None` when the
/// path leads nowhere.
fn at_path_mut<'a>(v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    let Some((first, rest)) = path.split_first() else {
        return Some(v);
    };
    match (first, v) {
        (_, Value::Option(Some(x))) | (_, Value::Newtype(x)) => at_path_mut(x, path),
        (Step::Key(k), Value::Map(m)) => at_path_mut(m.get_mut(&Value::String(k.clone()))?, rest),
        (Step::Index(i), Value::Seq(items)) => at_path_mut(items.get_mut(*i)?, rest),
        _ => None,
    }
}

/// `value` with the number at `path` (from [`number_paths`]) set to `x`, any `f64` (NaN
/// included), read back through the type's own deserializer.
///
/// # Errors
/// A path that does not lead to a value, or the deserializer's message.
pub fn with_number<T: Serialize + serde::de::DeserializeOwned>(
    value: &T,
    path: &NumberPath,
    x: f64,
) -> Result<T, String> {
    with_value(value, path, Value::F64(x))
}

/// `value` with the serialized value at `path` replaced by `x`, read back through the type's
/// own deserializer ([`with_number`], [`with_integer`]).
fn with_value<T: Serialize + serde::de::DeserializeOwned>(
    value: &T,
    path: &NumberPath,
    x: Value,
) -> Result<T, String> {
    let mut v = serde_value::to_value(value).map_err(|e| e.to_string())?;
    *at_path_mut(&mut v, &path.0).ok_or_else(|| format!("no value at {path}"))? = x;
    T::deserialize(v).map_err(|e| e.to_string())
}

/// `value` with the integer at `path` (from [`integer_paths`]) set to `n`, read back through
/// the type's own deserializer.
///
/// # Errors
/// A path that does not lead to a value, or the deserializer's message (`n` past the field's
/// type).
pub fn with_integer<T: Serialize + serde::de::DeserializeOwned>(
    value: &T,
    path: &NumberPath,
    n: u64,
) -> Result<T, String> {
    with_value(value, path, Value::U64(n))
}

impl NumberPath {
    /// Parses a parameter path as presets and sweeps write it: keys joined by `.`, list items
    /// as `[i]` (`layers[1].outer_radius_mm`; `layers.1.outer_radius_mm` also reads). `None`
    /// for an empty path, an empty key or a malformed index.
    pub fn parse(path: &str) -> Option<NumberPath> {
        let mut steps = Vec::new();
        for part in path.split('.') {
            let (key, mut rest) = match part.find('[') {
                Some(i) => (&part[..i], &part[i..]),
                None => (part, ""),
            };
            if key.is_empty() && steps.is_empty() {
                return None;
            }
            if !key.is_empty() {
                match key.parse::<usize>() {
                    Ok(i) if !steps.is_empty() => steps.push(Step::Index(i)),
                    _ => steps.push(Step::Key(key.to_string())),
                }
            } else if rest.is_empty() {
                return None;
            }
            while let Some(s) = rest.strip_prefix('[') {
                let j = s.find(']')?;
                steps.push(Step::Index(s[..j].parse().ok()?));
                rest = &s[j + 1..];
            }
            if !rest.is_empty() {
                return None;
            }
        }
        Some(NumberPath(steps))
    }
}

/// The value at `path` in `value`'s serialized form (NaN kept); `None` when the path leads
/// nowhere. An optional field that is unset reads as `Value::Option(None)`.
pub fn value_at_path<T: Serialize>(value: &T, path: &NumberPath) -> Option<Value> {
    let mut v = serde_value::to_value(value).ok()?;
    at_path_mut(&mut v, &path.0).cloned()
}

/// `value` with the value at `path` replaced by `new` (any value: NaN kept, a list, a whole
/// object), read back through the type's own deserializer. The last key may name an optional
/// field the value leaves unset.
///
/// # Errors
/// `Err(None)` when the path leads nowhere; `Err(Some(message))` with the deserializer's
/// message when `new` does not fit the schema there.
pub fn with_value_at<T: Serialize + serde::de::DeserializeOwned>(
    value: &T,
    path: &NumberPath,
    new: Value,
) -> Result<T, Option<String>> {
    fn slot<'a>(v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
        let Some((first, rest)) = path.split_first() else {
            return Some(v);
        };
        match (first, v) {
            (_, Value::Option(Some(x))) | (_, Value::Newtype(x)) => slot(x, path),
            (Step::Key(k), Value::Map(m)) => {
                let key = Value::String(k.clone());
                if rest.is_empty() && !m.contains_key(&key) {
                    m.insert(key.clone(), Value::Option(None));
                }
                slot(m.get_mut(&key)?, rest)
            }
            (Step::Index(i), Value::Seq(items)) => slot(items.get_mut(*i)?, rest),
            _ => None,
        }
    }
    let mut v = serde_value::to_value(value).map_err(|e| Some(e.to_string()))?;
    *slot(&mut v, &path.0).ok_or(None)? = new;
    T::deserialize(v).map_err(|e| Some(e.to_string()))
}

/// The paths where `typed` (a value as parsed into its schema type) holds a number that its
/// YAML `text` wrote quoted (`radius_mm: "15.0"`): the parser converts a quoted scalar to the
/// number the schema expects, which hides a value meant as text or typed in a spreadsheet.
/// Empty when `text` does not parse as YAML (the schema parse reports that).
pub fn quoted_numbers<T: Serialize + ?Sized>(typed: &T, text: &str) -> Vec<(String, String)> {
    // The untyped reading keeps quoted scalars as strings.
    let Ok(untyped) =
        serde_saphyr::from_str_with_options::<Value>(text, crate::yaml::budget_options())
    else {
        return Vec::new();
    };
    let Ok(typed) = serde_value::to_value(typed) else {
        return Vec::new();
    };
    fn unwrap(v: &Value) -> &Value {
        match v {
            Value::Option(Some(x)) | Value::Newtype(x) => unwrap(x),
            v => v,
        }
    }
    fn walk(t: &Value, u: &Value, path: &str, out: &mut Vec<(String, String)>) {
        match (unwrap(t), unwrap(u)) {
            (n, Value::String(s))
                if matches!(n, Value::F64(_) | Value::F32(_)) || is_integer(n) =>
            {
                out.push((path.to_string(), s.clone()))
            }
            (Value::Seq(a), Value::Seq(b)) => {
                for (i, (x, y)) in a.iter().zip(b).enumerate() {
                    walk(x, y, &format!("{path}[{i}]"), out);
                }
            }
            (Value::Map(a), Value::Map(b)) => {
                for (k, x) in a {
                    if let (Value::String(name), Some(y)) = (k, b.get(k)) {
                        walk(x, y, &join(path, name), out);
                    }
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(&typed, &untyped, "", &mut out);
    out
}
