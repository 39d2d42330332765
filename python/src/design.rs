//! `fabkit.Design`: load a design, read and set its parameters by path, apply presets,
//! validate.

use std::collections::BTreeMap;

use fabkit_designs::input_files::DataFileRules;
use fabkit_designs::values::{value_at_path, with_value_at, NumberPath};
use fabkit_designs::{library, ChordTolerance, Design as DesignData};
use fabkit_sweep as sweep;
use pyo3::exceptions::{PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_value::Value;

use crate::errors::{design_error, param_errors, ParamError};

/// A parametric sensor design (the YAML schema of `designs/library/*.yaml`).
///
/// Load one with `Design.load` (a library name or a YAML path), `Design.from_yaml` or
/// `Design.from_dict`. Parameters are read and set by the paths that presets and sweep files
/// use (`design["layers[1].outer_radius_mm"] = 12.5`); a short path that names one parameter
/// (`markers.spacing_mm`) also works.
#[pyclass(module = "fabkit")]
#[derive(Clone)]
pub struct Design {
    pub(crate) design: DesignData,
    /// The path as given, `embedded:<name>` for a library design, `<dict>` or `<yaml>`.
    pub(crate) source: String,
    /// sha256 of the design's text (and marker files) as loaded; parameters set later are in
    /// the design's name only through presets.
    pub(crate) sha256: String,
    /// The preset applied with `with_preset`, for a ground-truth dataset's claim.
    pub(crate) preset: Option<String>,
}

impl Design {
    pub(crate) fn of(design: DesignData, source: String, sha256: String) -> Design {
        Design {
            design,
            source,
            sha256,
            preset: None,
        }
    }

    /// The design as `fabkit` would be given it: a library design's name, a design file's
    /// path, or the design's name when it came from text or a dict.
    pub(crate) fn as_named(&self) -> String {
        match self.source.strip_prefix("embedded:") {
            Some(name) => name.to_string(),
            None if std::path::Path::new(&self.source).is_file() => self.source.clone(),
            None => self.design.name.clone(),
        }
    }
}

fn sha256_hex(text: &str) -> String {
    fabkit_calibration::groundtruth::inputs::sha256_hex(text.as_bytes())
}

/// A dict key as text; any other key is a TypeError `{at}: {refusal} {repr of the key}`.
pub(crate) fn text_key(k: &Bound<'_, PyAny>, at: &str, refusal: &str) -> PyResult<String> {
    k.extract().map_err(|_| {
        let shown = k.repr().map(|r| r.to_string()).unwrap_or_default();
        PyTypeError::new_err(format!("{at}: {refusal} {shown}"))
    })
}

/// A Python value (dict, list, tuple, str, bool, int, float, None) as a serialized value; NaN
/// and infinities kept (the design's rules refuse them by path).
pub(crate) fn value_of(obj: &Bound<'_, PyAny>, at: &str) -> PyResult<Value> {
    value_at_depth(obj, at, 0)
}

/// Deepest nesting of dicts and lists [`value_of`] reads (a design is a few levels deep); a
/// deeper value is refused instead of overflowing the native stack.
const MAX_VALUE_DEPTH: usize = 128;

fn value_at_depth(obj: &Bound<'_, PyAny>, at: &str, depth: usize) -> PyResult<Value> {
    if depth > MAX_VALUE_DEPTH {
        let shown = if at.is_empty() { "(value)" } else { at };
        return Err(PyValueError::new_err(format!(
            "{shown}: nested more than {MAX_VALUE_DEPTH} levels deep (not a design value)"
        )));
    }
    if obj.is_none() {
        return Ok(Value::Option(None));
    }
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return match obj.extract::<i64>() {
            Ok(i) => Ok(Value::I64(i)),
            Err(_) => Ok(Value::F64(obj.extract::<f64>()?)),
        };
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(Value::F64(obj.extract()?));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut m = BTreeMap::new();
        let shown = if at.is_empty() { "(value)" } else { at };
        for (k, v) in d.iter() {
            let key = text_key(&k, shown, "a key must be text, found")?;
            let here = if at.is_empty() {
                key.clone()
            } else {
                format!("{at}.{key}")
            };
            m.insert(Value::String(key), value_at_depth(&v, &here, depth + 1)?);
        }
        return Ok(Value::Map(m));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for (i, v) in obj.try_iter()?.enumerate() {
            items.push(value_at_depth(&v?, &format!("{at}[{i}]"), depth + 1)?);
        }
        return Ok(Value::Seq(items));
    }
    // numpy scalars and other numbers
    if let Ok(x) = obj.extract::<f64>() {
        return Ok(Value::F64(x));
    }
    let shown = if at.is_empty() { "(value)" } else { at };
    Err(PyTypeError::new_err(format!(
        "{shown}: {} is not a design value (dict, list, str, bool, int, float or None)",
        obj.get_type().name()?
    )))
}

/// `v` read as a `T` (a design, fixture parameters). A value that does not fit is a DesignError
/// whose one ParamError names its path (`layers[1].thickness_mm`), the value and the rule:
/// `<origin>: path = value: rule`.
pub(crate) fn typed_from<T: serde::de::DeserializeOwned>(v: Value, origin: &str) -> PyResult<T> {
    let kept = v.clone();
    serde_path_to_error::deserialize::<_, T>(v).map_err(|e| {
        let path = e.path().to_string();
        let rule = e.inner().to_string();
        let value = NumberPath::parse(&path)
            .and_then(|p| value_at_path(&kept, &p))
            .map_or_else(|| "(missing)".to_string(), |x| shown(&x));
        let item = ParamError {
            path: path.clone(),
            value: value.clone(),
            rule: rule.clone(),
        };
        param_errors(format!("{origin}: {path} = {value}: {rule}"), vec![item])
    })
}

/// A value as an error shows it: text quoted, numbers and booleans as written, lists and maps
/// in brief.
fn shown(v: &Value) -> String {
    match v {
        Value::String(s) => format!("{s:?}"),
        Value::F64(x) => x.to_string(),
        Value::I64(x) => x.to_string(),
        Value::U64(x) => x.to_string(),
        Value::Bool(b) => b.to_string(),
        Value::Option(None) | Value::Unit => "null".into(),
        Value::Option(Some(x)) | Value::Newtype(x) => shown(x),
        Value::Seq(items) => format!("a list of {}", items.len()),
        Value::Map(_) => "a mapping".into(),
        other => format!("{other:?}"),
    }
}

/// A serialized value as the Python value it reads as.
pub(crate) fn py_of(py: Python<'_>, v: &Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any().unbind(),
        Value::U8(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::U16(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::U32(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::U64(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::I8(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::I16(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::I32(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::I64(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::F32(x) => f64::from(*x).into_pyobject(py)?.into_any().unbind(),
        Value::F64(x) => x.into_pyobject(py)?.into_any().unbind(),
        Value::Char(c) => c.to_string().into_pyobject(py)?.into_any().unbind(),
        Value::String(s) => s.into_pyobject(py)?.into_any().unbind(),
        Value::Unit | Value::Option(None) => py.None(),
        Value::Option(Some(x)) | Value::Newtype(x) => py_of(py, x)?,
        Value::Seq(items) => {
            let l = PyList::empty(py);
            for x in items {
                l.append(py_of(py, x)?)?;
            }
            l.into_any().unbind()
        }
        Value::Map(m) => {
            let d = PyDict::new(py);
            for (k, x) in m {
                d.set_item(py_of(py, k)?, py_of(py, x)?)?;
            }
            d.into_any().unbind()
        }
        Value::Bytes(b) => b.clone().into_pyobject(py)?.into_any().unbind(),
    })
}

impl Design {
    /// The full parameter path `path` stands for (itself, or the one path a short path names).
    fn resolve_path(&self, path: &str) -> PyResult<String> {
        if sweep::path_exists(&self.design, path) {
            return Ok(path.to_string());
        }
        if let Some(full) = sweep::expand_short_path(&self.design, path) {
            return Ok(full);
        }
        let nearest = sweep::nearest_paths(&self.design, path, 3);
        let hint = if nearest.is_empty() {
            String::new()
        } else {
            format!(" (did you mean {}?)", nearest.join(", "))
        };
        Err(PyKeyError::new_err(format!(
            "'{path}' is not a parameter path of design '{}'{hint}; Design.parameter_paths() lists them",
            self.design.name
        )))
    }
}

#[pymethods]
impl Design {
    /// Loads a design: a library name (`rtac0`; `fabkit designs` lists them) or a YAML file.
    /// Marker CSV files are read relative to the design file, inside its folder or one of
    /// `allow_data_dirs`, each at most `max_data_file_bytes` (as `fabkit export`).
    ///
    /// Raises DesignError with the CLI's message (file:line:column for YAML errors), TypeError
    /// for a `source` that is not text or a path.
    #[staticmethod]
    #[pyo3(signature = (source=None, *, allow_data_dirs=Vec::new(), max_data_file_bytes=None))]
    fn load(
        py: Python<'_>,
        source: Option<std::path::PathBuf>,
        allow_data_dirs: Vec<std::path::PathBuf>,
        max_data_file_bytes: Option<u64>,
    ) -> PyResult<Design> {
        let arg = source.map_or_else(
            || library::DEFAULT_DESIGN.to_string(),
            |s| s.to_string_lossy().to_string(),
        );
        let mut rules = DataFileRules::default();
        for d in &allow_data_dirs {
            rules.allowed_dirs.push(
                DataFileRules::allow_dir(d)
                    .map_err(|e| PyValueError::new_err(format!("allow_data_dirs: {e}")))?,
            );
        }
        if let Some(n) = max_data_file_bytes {
            rules.max_bytes = DataFileRules::parse_max_bytes(&n.to_string())
                .map_err(|e| PyValueError::new_err(format!("max_data_file_bytes: {e}")))?;
        }
        let loaded = crate::work(py, || {
            library::load_source_with(&arg, std::path::Path::new(""), &rules)
        })?
        .map_err(|e| design_error(&e))?;
        Ok(Design::of(loaded.design, loaded.source, loaded.sha256))
    }

    /// Parses a design from YAML text; `origin` names it in error messages.
    #[staticmethod]
    #[pyo3(signature = (text, origin="<yaml>"))]
    fn from_yaml(text: &str, origin: &str) -> PyResult<Design> {
        let d = DesignData::from_yaml(text, origin).map_err(|e| design_error(&e))?;
        Ok(Design::of(d, origin.to_string(), sha256_hex(text)))
    }

    /// A design from a dict of the YAML's form (what `to_dict()` returns).
    #[staticmethod]
    fn from_dict(data: &Bound<'_, PyAny>) -> PyResult<Design> {
        let v = value_of(data, "")?;
        let text = format!("{:?}", v);
        let d: DesignData = typed_from(v, "<dict>")?;
        Ok(Design::of(d, "<dict>".into(), sha256_hex(&text)))
    }

    /// The design as a dict of the YAML's form (numbers in mm and degrees).
    fn to_dict(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let v = serde_value::to_value(&self.design)
            .map_err(|e| crate::errors::FabkitError::new_err(e.to_string()))?;
        py_of(py, &v)
    }

    /// The design's name (`rtac0`, `rtac0_soft` after a preset).
    #[getter]
    fn name(&self) -> String {
        self.design.name.clone()
    }

    /// Where the design was loaded from: its path, `embedded:<name>`, `<yaml>` or `<dict>`.
    #[getter]
    fn source(&self) -> String {
        self.source.clone()
    }

    /// sha256 of the design's text as loaded (64 hex digits), as in an export's manifest.
    #[getter]
    fn sha256(&self) -> String {
        self.sha256.clone()
    }

    /// The names of the design's presets.
    #[getter]
    fn presets(&self) -> Vec<String> {
        self.design.presets.keys().cloned().collect()
    }

    /// Every parameter path of the design, in document order (as `fabkit validate` lists them).
    fn parameter_paths(&self) -> Vec<String> {
        sweep::parameter_paths(&self.design)
    }

    /// The value at a parameter path (None for an unset optional parameter). KeyError for a
    /// path that names nothing, with the nearest paths.
    fn __getitem__(&self, py: Python<'_>, path: &str) -> PyResult<Py<PyAny>> {
        let full = self.resolve_path(path)?;
        let p = NumberPath::parse(&full)
            .ok_or_else(|| PyKeyError::new_err(format!("'{path}': not a parameter path")))?;
        match value_at_path(&self.design, &p) {
            Some(v) => py_of(py, &v),
            None => Ok(py.None()),
        }
    }

    /// Sets the value at a parameter path. KeyError for a path that names nothing; DesignError
    /// (path, value, rule) for a value that does not fit the schema there. The rules between
    /// parameters are checked by `validate()` and by every build.
    fn __setitem__(&mut self, path: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let full = self.resolve_path(path)?;
        let p = NumberPath::parse(&full)
            .ok_or_else(|| PyKeyError::new_err(format!("'{path}': not a parameter path")))?;
        let v = value_of(value, &full)?;
        let shown = value.repr()?.to_string();
        match with_value_at(&self.design, &p, v) {
            Ok(d) => {
                self.design = d;
                Ok(())
            }
            Err(None) => Err(PyKeyError::new_err(format!(
                "'{full}' is not a parameter path of design '{}'",
                self.design.name
            ))),
            Err(Some(rule)) => {
                let e = ParamError {
                    path: full.clone(),
                    value: shown.clone(),
                    rule: rule.clone(),
                };
                Err(param_errors(format!("{full} = {shown}: {rule}"), vec![e]))
            }
        }
    }

    /// A copy with the parameters `values` ({path: value}) set.
    fn with_values(&self, values: &Bound<'_, PyDict>) -> PyResult<Design> {
        let mut d = self.clone();
        for (k, v) in values.iter() {
            let path: String = k.extract()?;
            d.__setitem__(&path, &v)?;
        }
        Ok(d)
    }

    /// The design with preset `name` applied (as `--preset`): renamed `<name>_<preset>`.
    fn with_preset(&self, name: &str) -> PyResult<Design> {
        let d = self
            .design
            .with_preset(name)
            .map_err(|e| design_error(&e))?;
        Ok(Design {
            preset: Some(name.to_string()),
            ..Design::of(d, self.source.clone(), self.sha256.clone())
        })
    }

    /// Checks every rule of the design at once, as `fabkit validate`; returns the resolved layer
    /// stack (mm, inner to outer) as a dict. Raises DesignError whose `errors` lists every
    /// violation (path, value, rule).
    #[pyo3(signature = (chord_tolerance_mm=ChordTolerance::DEFAULT_MM))]
    fn validate(&self, py: Python<'_>, chord_tolerance_mm: f64) -> PyResult<Py<PyAny>> {
        let tol = crate::kit::tolerance(chord_tolerance_mm)?;
        let stack = crate::work(py, || fabkit_designs::validate_design(&self.design, tol))?
            .map_err(|e| design_error(&e))?;
        crate::to_py(py, &stack)
    }

    /// The design as YAML-compatible JSON text (the form `from_yaml` reads).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.design)
            .map_err(|e| crate::errors::FabkitError::new_err(e.to_string()))
    }

    fn __repr__(&self) -> String {
        format!("Design({:?}, source={:?})", self.design.name, self.source)
    }

    fn __copy__(&self) -> Design {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Design {
        self.clone()
    }
}

/// The library designs (name, description), as `fabkit designs` lists them.
#[pyfunction]
fn library_designs() -> PyResult<Vec<(String, String)>> {
    let mut out = Vec::new();
    for (name, _) in library::LIBRARY {
        let d = library::load(name).map_err(|e| design_error(&e))?;
        out.push((name.to_string(), d.description.clone()));
    }
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Design>()?;
    m.add_function(wrap_pyfunction!(library_designs, m)?)?;
    m.add("DEFAULT_DESIGN", library::DEFAULT_DESIGN)?;
    Ok(())
}
