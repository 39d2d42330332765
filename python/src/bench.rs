//! The library side of the Python package's overhead benchmark (python/benches/build_overhead.py):
//! the same kit build as `fabkit.build_kit`, timed in Rust, without the Python call around it.

use std::time::Instant;

use fabkit_designs::{build_kit_bounded, ChordTolerance};
use pyo3::prelude::*;

use crate::design::Design;
use crate::errors::design_error;

/// Builds `design`'s kit `repeats` times by the library call alone (no Python objects made,
/// the GIL released), as `build_kit` does; returns each build's wall time, s.
#[pyfunction]
#[pyo3(signature = (design, repeats, *, chord_tolerance_mm=ChordTolerance::DEFAULT_MM))]
pub fn _library_build_seconds(
    py: Python<'_>,
    design: &Design,
    repeats: usize,
    chord_tolerance_mm: f64,
) -> PyResult<Vec<f64>> {
    let tol = crate::kit::tolerance(chord_tolerance_mm)?;
    let mut out = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let t0 = Instant::now();
        let kit = py.detach(|| {
            build_kit_bounded(
                &design.design,
                tol,
                fabkit_designs::estimate::DEFAULT_MAX_TRIANGLES,
            )
        });
        out.push(t0.elapsed().as_secs_f64());
        kit.map_err(|e| design_error(&e))?;
    }
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(_library_build_seconds, m)?)?;
    Ok(())
}
