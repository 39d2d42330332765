//! The `fabkit` Python package's native module (`fabkit._fabkit`): thin PyO3 bindings over the
//! library crates. No geometry and no orchestration lives here: every call goes to
//! fabkit-designs, fabkit-fixtures, fabkit-calibration or fabkit-export, the same functions the
//! `fabkit` command line calls, so that the same input gives the same bytes.
//!
//! Every entry point:
//! - releases the GIL while the library works ([`work`]);
//! - turns a library error into a Python exception carrying the message the CLI prints after
//!   `error: ` (with its `caused by:` lines), of a class that says what failed ([`errors`]);
//! - catches a Rust panic and raises `fabkit.InternalError`, so that no panic crosses into the
//!   interpreter.

use pyo3::prelude::*;

mod bench;
mod calibration;
mod design;
mod errors;
mod fixtures;
mod groundtruth;
mod kit;
mod sweep;

pub(crate) use errors::internal;

/// Runs `f` with the GIL released, catching a panic as `fabkit.InternalError`.
pub(crate) fn work<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)))
        .map_err(internal)
}

/// A JSON value as the Python object `json.loads` makes of it (dict, list, float, int, str,
/// bool, None).
pub(crate) fn to_py(py: Python<'_>, v: &serde_json::Value) -> PyResult<Py<PyAny>> {
    let text = serde_json::to_string(v).map_err(|e| errors::FabkitError::new_err(e.to_string()))?;
    let json = py.import("json")?;
    Ok(json.call_method1("loads", (text,))?.unbind())
}

/// The package version (the workspace's, as `fabkit --version`).
const VERSION: &str = env!("CARGO_PKG_VERSION");

#[pymodule]
fn _fabkit(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", VERSION)?;
    errors::register(m)?;
    design::register(m)?;
    kit::register(m)?;
    fixtures::register(m)?;
    calibration::register(m)?;
    groundtruth::register(m)?;
    bench::register(m)?;
    sweep::register(m)?;
    Ok(())
}
