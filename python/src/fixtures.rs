//! `fabkit.build_fixtures` and `fabkit.Fixtures`: a design's calibration fixtures (pin dome or
//! grid plate with its point table, protrusion semi-domes or semi-plates, indenters).

use std::sync::{Arc, Mutex};

use fabkit_designs::ChordTolerance;
use fabkit_fixtures::params::{from_yaml, given_in, resolve, FixtureOptions, FixtureParams, Given};
use fabkit_fixtures::pindome::PointRow;
use fabkit_fixtures::FixtureProgress;
use numpy::ndarray::{Array1, Array2};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyString};

use crate::design::{typed_from, value_of, Design};
use crate::errors::design_error;
use crate::kit::{report_progress, Kit};

/// A design's fixtures: the printable parts (`kit`, written by `export` as `fabkit fixtures`
/// writes them) and the data files (point table, capture plan, protrusion descriptions).
#[pyclass(module = "fabkit", frozen)]
pub struct Fixtures {
    kit: Py<Kit>,
    table: Vec<PointRow>,
    capture_plan: Vec<Vec<u32>>,
    files: Arc<Vec<(String, Vec<u8>)>>,
}

#[pymethods]
impl Fixtures {
    /// The printable fixture parts as a Kit (its `export` writes the data files too).
    #[getter]
    fn kit(&self, py: Python<'_>) -> Py<Kit> {
        self.kit.clone_ref(py)
    }

    /// The point table (`point_table.csv`) as a dict of numpy arrays, one row per pin hole,
    /// sensor frame, mm: `id` (n,) uint32, `ring` (n,) uint32 (the capture group), `tip_mm`
    /// (n, 3) float64 (the seated pin's tip), `contact_mm` (n, 3) (where the hole's axis meets
    /// the undeformed surface), `axis` (n, 3) (unit, out of the surface), and
    /// `indentation_depth_mm` (n,). Empty arrays for a fixture set without pins.
    #[getter]
    fn point_table(&self, py: Python<'_>) -> PyResult<Py<PyDict>> {
        let n = self.table.len();
        let d = PyDict::new(py);
        let col3 = |f: &dyn Fn(&PointRow) -> [f64; 3]| {
            let v: Vec<f64> = self.table.iter().flat_map(f).collect();
            Array2::from_shape_vec((n, 3), v).expect("n x 3")
        };
        d.set_item(
            "id",
            Array1::from_iter(self.table.iter().map(|r| r.id)).into_pyarray(py),
        )?;
        d.set_item(
            "ring",
            Array1::from_iter(self.table.iter().map(|r| r.ring)).into_pyarray(py),
        )?;
        d.set_item("tip_mm", col3(&|r| r.tip_mm).into_pyarray(py))?;
        d.set_item("contact_mm", col3(&|r| r.contact_mm).into_pyarray(py))?;
        d.set_item("axis", col3(&|r| r.axis).into_pyarray(py))?;
        d.set_item(
            "indentation_depth_mm",
            Array1::from_iter(self.table.iter().map(|r| r.indentation_depth_mm)).into_pyarray(py),
        )?;
        Ok(d.unbind())
    }

    /// The captures (`capture_plan.csv`): the ids of the pins inserted together, per capture.
    #[getter]
    fn capture_plan(&self) -> Vec<Vec<u32>> {
        self.capture_plan.clone()
    }

    /// The data files `fabkit fixtures` writes beside the meshes: {relative path: bytes}.
    #[getter]
    fn files(&self, py: Python<'_>) -> PyResult<Py<PyDict>> {
        let d = PyDict::new(py);
        for (name, bytes) in self.files.iter() {
            d.set_item(name, PyBytes::new(py, bytes))?;
        }
        Ok(d.unbind())
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let k = self.kit.borrow(py);
        format!(
            "Fixtures({:?}, {} parts, {} pins, {} data files)",
            k.kit.design,
            k.kit.parts.len(),
            self.table.len(),
            self.files.len()
        )
    }
}

/// Builds the calibration fixtures of `design`, as `fabkit fixtures` does.
///
/// `params`: fixture parameters as a dict (the `--params` YAML's form: pin_dome, semidomes,
/// grid_plate, semiplates, indenters), a path to such a YAML file, or None for the defaults;
/// `pins_preset`, `semidomes` (generated patterns) and `seed` as the CLI's options of those
/// names. What neither `params` nor those set is the paper's the design reproduces (R-Tac0:
/// its published dome and 100 semi-domes; `pins_preset="default"` for fabkit's own dome,
/// `semidomes=0` for none). Refused before anything is built when estimated at more than `max_triangles`.
/// `progress(done, total, message)` is called as parts finish (from worker threads, with the
/// GIL taken for the call). Raises DesignError naming every violated parameter.
#[pyfunction]
#[pyo3(signature = (design, *, params=None, pins_preset=None, semidomes=None, seed=None, chord_tolerance_mm=ChordTolerance::DEFAULT_MM, max_triangles=fabkit_designs::estimate::DEFAULT_MAX_TRIANGLES as i128, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn build_fixtures(
    py: Python<'_>,
    design: &Design,
    params: Option<&Bound<'_, PyAny>>,
    pins_preset: Option<String>,
    semidomes: Option<u32>,
    seed: Option<u64>,
    chord_tolerance_mm: f64,
    max_triangles: i128,
    progress: Option<Py<PyAny>>,
) -> PyResult<Fixtures> {
    let tol = crate::kit::tolerance(chord_tolerance_mm)?;
    let limit = crate::kit::max_triangles(max_triangles)?;
    let (base, given): (Option<FixtureParams>, Given) = match params {
        None => (None, Given::default()),
        Some(p) if p.is_instance_of::<PyDict>() => {
            let value = value_of(p, "")?;
            let key = |v: &serde_value::Value, k: &str| match v {
                serde_value::Value::Map(m) => m.get(&serde_value::Value::String(k.into())).cloned(),
                _ => None,
            };
            let sets = |k: &str| {
                key(&value, k)
                    .is_some_and(|s| key(&s, "generate").is_some() || key(&s, "patterns").is_some())
            };
            let given = Given {
                pin_dome: key(&value, "pin_dome").is_some(),
                patterns: sets("semidomes") || sets("semiplates"),
            };
            (Some(typed_from::<FixtureParams>(value, "params")?), given)
        }
        Some(p) => {
            let path: std::path::PathBuf = if p.is_instance_of::<PyString>() {
                p.extract::<String>()?.into()
            } else {
                p.extract()?
            };
            let text = fabkit_designs::input_files::read_design_file(&path)
                .map_err(|e| design_error(&e))?;
            let params =
                from_yaml(&text, &path.display().to_string()).map_err(|e| design_error(&e))?;
            (Some(params), given_in(&text))
        }
    };
    let options = FixtureOptions {
        pins_preset: pins_preset.as_deref(),
        patterns: semidomes,
        seed,
    };
    let params = resolve(&design.design, base, given, &options)
        .map_err(|e| design_error(&e))?
        .params;
    let provenance =
        fabkit_fixtures::provenance(&design.design.name, &design.source, &design.sha256);
    let total = Mutex::new(0usize);
    let on = |p: FixtureProgress| match p {
        FixtureProgress::Started { parts, triangles } => {
            *total.lock().unwrap_or_else(|e| e.into_inner()) = parts;
            report_progress(
                &progress,
                0,
                parts,
                &format!(
                    "building the {parts} parts of {} (about {triangles} triangles)",
                    design.design.name
                ),
            );
        }
        FixtureProgress::Built { done, parts } => {
            report_progress(&progress, done, parts, "built");
        }
    };
    let set = crate::work(py, || {
        fabkit_fixtures::build_fixtures_reporting(
            &design.design,
            &params,
            tol,
            limit,
            &provenance,
            &on,
        )
    })?
    .map_err(|e| design_error(&e))?;
    let (table, capture_plan) = match (&set.pin_dome, &set.grid_plate) {
        (Some(d), _) => (d.table.clone(), d.capture_plan.clone()),
        (None, Some(g)) => (g.table.clone(), g.capture_plan.clone()),
        (None, None) => (Vec::new(), Vec::new()),
    };
    let files = Arc::new(set.files);
    let kit = Kit {
        kit: Arc::new(set.kit),
        design: design.clone(),
        tol,
        files: files.clone(),
        command: fabkit_export::OutputCommand::Fixtures,
    };
    Ok(Fixtures {
        kit: Py::new(py, kit)?,
        table,
        capture_plan,
        files,
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Fixtures>()?;
    m.add_function(wrap_pyfunction!(build_fixtures, m)?)?;
    Ok(())
}
