//! The native side of `fabkit.sweep` (python/fabkit/sweep.py): plan a list of variants as
//! `fabkit sweep` plans a sweep file's, evaluate one variant from plain text (what an executor
//! ships to a worker process), evaluate them all on threads here, and render the results table.
//! Everything is fabkit-designs' sweep code ([`fabkit_designs::sweep`]).

use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::{ChordTolerance, Design as DesignData};
use fabkit_sweep::{
    evaluate_variant, plan_variants, render_csv, render_jsonl, resolve_variant, ExportWriter,
    FileOutputs, FilesJob, KitWriter, Output, Variant, VariantResult,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use serde_json::Value;

use crate::design::Design;
use crate::errors::{err, DesignError, FabkitError};
use crate::kit::report_progress;

/// A Python value as JSON (what a sweep file's value reads as); `at` names it in errors. A
/// non-finite number is refused as a sweep file's is.
fn json_of(obj: &Bound<'_, PyAny>, at: &str) -> PyResult<Value> {
    let json = obj.py().import("json")?;
    let kwargs = PyDict::new(obj.py());
    kwargs.set_item("allow_nan", false)?;
    let text: String = json
        .call_method("dumps", (obj,), Some(&kwargs))
        .map_err(|e| {
            let why = e.value(obj.py()).to_string();
            if why.contains("Out of range float values") {
                DesignError::new_err(format!(
                    "{at} = {}: must be a finite number",
                    obj.repr().map(|r| r.to_string()).unwrap_or_default()
                ))
            } else {
                PyTypeError::new_err(format!("{at}: {why}"))
            }
        })?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| PyTypeError::new_err(format!("{at}: {e}")))
}

/// One planned variant, as text an executor can ship: (index, id, params as JSON
/// `[[path, value], ...]`).
type PlannedVariant = (usize, String, String);

/// Checks and plans `variants` (an iterable of {parameter path: value} dicts) of `design` at
/// `chord_tolerance_mm`, as `fabkit sweep` checks a sweep file: returns (parameters, variants),
/// the parameters the results table's columns (full paths, in order of first appearance), each
/// variant (index, id, params JSON). Raises DesignError with the CLI's message for an unknown
/// path or a value of the wrong type (`variants[3]: vary.<path> = <value>: <rule>`).
#[pyfunction]
pub fn _sweep_plan(
    design: &Design,
    variants: &Bound<'_, PyAny>,
    chord_tolerance_mm: f64,
) -> PyResult<(Vec<String>, Vec<PlannedVariant>)> {
    let tol = crate::kit::tolerance(chord_tolerance_mm)?;
    let mut given: Vec<Vec<(String, Value)>> = Vec::new();
    for (i, item) in variants.try_iter()?.enumerate() {
        let item = item?;
        let at = format!("variants[{i}]");
        let d = item.cast::<PyDict>().map_err(|_| {
            PyTypeError::new_err(format!(
                "{at}: a variant is a dict {{parameter path: value}}, not {}",
                item.get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ))
        })?;
        let mut params = Vec::new();
        for (k, v) in d.iter() {
            let path = crate::design::text_key(&k, &at, "a parameter path is text, not")?;
            let value = json_of(&v, &format!("{at}: vary.{path}"))?;
            params.push((path, value));
        }
        given.push(params);
    }
    let list = plan_variants(&design.design, "variants", &given, tol)
        .map_err(|e| err::<DesignError>(&e))?;
    let planned = list
        .variants
        .iter()
        .map(|v| {
            let params: Vec<(&String, &Value)> = v.params.iter().map(|(p, x)| (p, x)).collect();
            (
                v.index,
                v.id.clone(),
                serde_json::to_string(&params).unwrap_or_default(),
            )
        })
        .collect();
    Ok((list.parameters, planned))
}

/// The base design as the text `_sweep_evaluate` reads (its JSON form).
#[pyfunction]
pub fn _sweep_base(design: &Design) -> PyResult<String> {
    serde_json::to_string(&design.design).map_err(|e| FabkitError::new_err(e.to_string()))
}

fn variant_of(index: usize, id: String, params_json: &str) -> PyResult<Variant> {
    let params: Vec<(String, Value)> = serde_json::from_str(params_json)
        .map_err(|e| PyValueError::new_err(format!("params: {e}")))?;
    Ok(Variant { index, id, params })
}

/// Where a Python sweep writes its variants' files (`outputs` with files, stl or 3mf): the
/// export of variant `<id>` into `<out>/<id>/`, its manifest naming the base design's source.
struct FilesTarget {
    out: std::path::PathBuf,
    files: FileOutputs,
    source: String,
    writer: ExportWriter,
}

/// The files target of `outputs` (names as a sweep file's) into `out`; `None` for metrics
/// only.
fn files_target(
    outputs: &[String],
    out: Option<std::path::PathBuf>,
    source: String,
    command_line: Vec<String>,
) -> PyResult<Option<FilesTarget>> {
    let outputs = outputs
        .iter()
        .map(|o| Output::from_name(o))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| PyValueError::new_err(format!("outputs: {e}")))?;
    if !outputs.contains(&Output::Metrics) {
        return Err(PyValueError::new_err(
            "outputs must include metrics (the results table is always returned): ['metrics'] or ['metrics', 'files']",
        ));
    }
    let files = FileOutputs::of(&outputs);
    if !files.any() {
        return Ok(None);
    }
    let out = out.ok_or_else(|| {
        PyValueError::new_err("out: a folder is needed for outputs with files, stl or 3mf")
    })?;
    Ok(Some(FilesTarget {
        out,
        files,
        source,
        writer: ExportWriter { command_line },
    }))
}

fn evaluate(
    base: &DesignData,
    v: &Variant,
    materials: &MaterialsTable,
    tol: ChordTolerance,
    max_triangles: u64,
    target: Option<&FilesTarget>,
) -> VariantResult {
    let write = |design: &DesignData, kit: &fabkit_designs::kit::Kit| -> Result<(), String> {
        let Some(t) = target else { return Ok(()) };
        let job = FilesJob::new(
            t.out.join(&v.id),
            t.files,
            v,
            design,
            format!("{} variant {} of fabkit.sweep", t.source, v.id),
            tol.mm(),
        );
        t.writer.write(kit, &job)
    };
    evaluate_variant(
        v,
        resolve_variant(base, "variants", &v.params).map_err(|e| e.to_string()),
        materials,
        tol,
        max_triangles,
        env!("CARGO_PKG_VERSION"),
        target.map(|t| t.files).unwrap_or_default(),
        target
            .is_some()
            .then_some(&write as fabkit_sweep::WriteFiles<'_>),
    )
}

fn materials() -> PyResult<MaterialsTable> {
    MaterialsTable::embedded().map_err(FabkitError::new_err)
}

fn base_of(base_json: &str) -> PyResult<DesignData> {
    serde_json::from_str(base_json).map_err(|e| PyValueError::new_err(format!("base: {e}")))
}

/// Builds and measures one planned variant of the base design `base_json` (from
/// `_sweep_base`), as `fabkit sweep` does; returns its result as JSON (a line of
/// results.jsonl). With `outputs` naming files (`files`, `stl`, `3mf`) it also writes the
/// variant's export into `<out>/<id>/`, its manifest naming `source` and `command_line`.
/// Runs in whatever process an executor gives it; the GIL is released.
#[pyfunction]
#[pyo3(signature = (base_json, chord_tolerance_mm, max_triangles, index, id, params_json,
                    outputs=vec!["metrics".to_string()], out=None, source=String::new(),
                    command_line=Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub fn _sweep_evaluate(
    py: Python<'_>,
    base_json: &str,
    chord_tolerance_mm: f64,
    max_triangles: u64,
    index: usize,
    id: String,
    params_json: &str,
    outputs: Vec<String>,
    out: Option<std::path::PathBuf>,
    source: String,
    command_line: Vec<String>,
) -> PyResult<String> {
    let tol = crate::kit::tolerance(chord_tolerance_mm)?;
    let base = base_of(base_json)?;
    let v = variant_of(index, id, params_json)?;
    let materials = materials()?;
    let target = files_target(&outputs, out, source, command_line)?;
    let r = crate::work(py, || {
        evaluate(&base, &v, &materials, tol, max_triangles, target.as_ref())
    })?;
    serde_json::to_string(&r).map_err(|e| FabkitError::new_err(e.to_string()))
}

/// Every planned variant evaluated here on `jobs` threads (the GIL released), in any order,
/// writing their files as `_sweep_evaluate` does; `progress(done, total, id)` as each
/// finishes. Returns the results as JSON, in plan order.
#[pyfunction]
#[pyo3(signature = (base_json, chord_tolerance_mm, max_triangles, variants, jobs, progress=None,
                    outputs=vec!["metrics".to_string()], out=None, source=String::new(),
                    command_line=Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub fn _sweep_run_threads(
    py: Python<'_>,
    base_json: &str,
    chord_tolerance_mm: f64,
    max_triangles: u64,
    variants: Vec<PlannedVariant>,
    jobs: usize,
    progress: Option<Py<PyAny>>,
    outputs: Vec<String>,
    out: Option<std::path::PathBuf>,
    source: String,
    command_line: Vec<String>,
) -> PyResult<Vec<String>> {
    let tol = crate::kit::tolerance(chord_tolerance_mm)?;
    let target = files_target(&outputs, out, source, command_line)?;
    let base = base_of(base_json)?;
    let vs: Vec<Variant> = variants
        .into_iter()
        .map(|(i, id, p)| variant_of(i, id, &p))
        .collect::<PyResult<_>>()?;
    let materials = materials()?;
    let total = vs.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
        .map_err(|e| FabkitError::new_err(e.to_string()))?;
    let rows: Vec<VariantResult> = crate::work(py, || {
        pool.install(|| {
            vs.par_iter()
                .map(|v| {
                    let r = evaluate(&base, v, &materials, tol, max_triangles, target.as_ref());
                    let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    report_progress(&progress, k, total, &v.id);
                    r
                })
                .collect()
        })
    })?;
    rows.iter()
        .map(|r| serde_json::to_string(r).map_err(|e| FabkitError::new_err(e.to_string())))
        .collect()
}

/// The results table of `fabkit sweep` from the results (JSON, plan order): (results.csv,
/// results.jsonl) as text. Without `build_time` the build_time_s cells are empty, as
/// `--no-build-time` leaves them.
#[pyfunction]
pub fn _sweep_tables(
    parameters: Vec<String>,
    results: &Bound<'_, PyList>,
    build_time: bool,
) -> PyResult<(String, String)> {
    let mut rows: Vec<VariantResult> = Vec::with_capacity(results.len());
    for r in results.iter() {
        let text: String = r.extract()?;
        let mut row: VariantResult = serde_json::from_str(&text)
            .map_err(|e| PyValueError::new_err(format!("results: {e}")))?;
        if !build_time {
            row.build_time_s = None;
        }
        rows.push(row);
    }
    let csv = String::from_utf8(render_csv(&parameters, &rows))
        .map_err(|e| FabkitError::new_err(e.to_string()))?;
    let jsonl =
        String::from_utf8(render_jsonl(&rows)).map_err(|e| FabkitError::new_err(e.to_string()))?;
    Ok((csv, jsonl))
}

/// Checks `outputs` (names as a sweep file's) and `out` before anything is planned or built:
/// ValueError naming what is wrong.
#[pyfunction]
#[pyo3(signature = (outputs, out=None))]
pub fn _sweep_check_outputs(outputs: Vec<String>, out: Option<std::path::PathBuf>) -> PyResult<()> {
    files_target(&outputs, out, String::new(), Vec::new()).map(|_| ())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(_sweep_check_outputs, m)?)?;
    m.add_function(wrap_pyfunction!(_sweep_plan, m)?)?;
    m.add_function(wrap_pyfunction!(_sweep_base, m)?)?;
    m.add_function(wrap_pyfunction!(_sweep_evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(_sweep_run_threads, m)?)?;
    m.add_function(wrap_pyfunction!(_sweep_tables, m)?)?;
    Ok(())
}
