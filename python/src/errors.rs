//! The package's exceptions and the conversion of library errors into them.
//!
//! Every exception's message is what the `fabkit` command line prints after `error: ` for the
//! same failure, including its `caused by:` lines ([`report`]).

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::PyList;

create_exception!(
    fabkit,
    FabkitError,
    PyException,
    "Base class of every fabkit error."
);
create_exception!(
    fabkit,
    DesignError,
    FabkitError,
    "A design (or fixture parameters) that does not load or breaks its rules. `errors` lists \
     every violated rule at once as ParamError items (path, value, rule); empty for a YAML \
     error, whose message gives file:line:column."
);
create_exception!(
    fabkit,
    ExportError,
    FabkitError,
    "An export that cannot be written (nothing is written then)."
);
create_exception!(
    fabkit,
    CalibrationError,
    FabkitError,
    "A camera file, point table or observation set that cannot be read, or a pose that cannot \
     be solved."
);
create_exception!(
    fabkit,
    GroundTruthError,
    FabkitError,
    "Ground-truth inputs that cannot be read or rendered."
);
create_exception!(
    fabkit,
    InternalError,
    FabkitError,
    "A defect in fabkit (a Rust panic, caught before it reached the interpreter): please report \
     it with the message."
);

/// One violated rule of a design parameter: `path = value: rule`.
#[pyclass(module = "fabkit", frozen, get_all)]
#[derive(Clone)]
pub struct ParamError {
    /// Path of the parameter, as in the YAML (`layers[2].thickness_mm`).
    pub path: String,
    /// The offending value, as written.
    pub value: String,
    /// The rule it breaks.
    pub rule: String,
}

#[pymethods]
impl ParamError {
    fn __repr__(&self) -> String {
        format!(
            "ParamError(path={:?}, value={:?}, rule={:?})",
            self.path, self.value, self.rule
        )
    }
    fn __str__(&self) -> String {
        format!("{} = {}: {}", self.path, self.value, self.rule)
    }
}

/// The CLI's error text without its `error: ` prefix ([`fabkit_designs::error_report`]).
pub fn report(e: &(dyn std::error::Error + 'static)) -> String {
    fabkit_designs::error_report(e)
}

/// A `DesignError` with its parameter errors (empty for other kinds) in `errors`.
pub fn design_error(e: &fabkit_designs::DesignError) -> PyErr {
    let items: Vec<ParamError> = match e {
        fabkit_designs::DesignError::Params(p) => {
            p.0.iter()
                .map(|x| ParamError {
                    path: x.path.clone(),
                    value: x.value.clone(),
                    rule: x.rule.clone(),
                })
                .collect()
        }
        _ => Vec::new(),
    };
    param_errors(report(e), items)
}

/// A `DesignError` with `message` and the parameter errors `items`.
pub fn param_errors(message: String, items: Vec<ParamError>) -> PyErr {
    let err = DesignError::new_err(message);
    Python::attach(|py| {
        let list = PyList::empty(py);
        for i in items {
            if let Ok(obj) = Bound::new(py, i) {
                let _ = list.append(obj);
            }
        }
        let _ = err.value(py).setattr("errors", list);
    });
    err
}

/// An error of class `E` with the CLI's text of `e`.
pub fn err<E: pyo3::type_object::PyTypeInfo>(e: &(dyn std::error::Error + 'static)) -> PyErr {
    PyErr::new::<E, _>(report(e))
}

/// A caught panic as `InternalError`.
pub fn internal(payload: Box<dyn std::any::Any + Send>) -> PyErr {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_string());
    InternalError::new_err(format!(
        "internal error (a fabkit defect, please report it): {what}"
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("FabkitError", py.get_type::<FabkitError>())?;
    m.add("DesignError", py.get_type::<DesignError>())?;
    m.add("ExportError", py.get_type::<ExportError>())?;
    m.add("CalibrationError", py.get_type::<CalibrationError>())?;
    m.add("GroundTruthError", py.get_type::<GroundTruthError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add_class::<ParamError>()?;
    Ok(())
}
