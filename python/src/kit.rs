//! `fabkit.Kit` and `fabkit.Part`: build a design's kit, read its parts' numbers and meshes as
//! numpy arrays, write it as `fabkit export` does.

use std::path::PathBuf;
use std::sync::Arc;

use fabkit_designs::{build_kit_bounded, ChordTolerance, Kit as KitData};
use fabkit_export::{ExportOptions, Formats, OutputCommand};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::design::Design;
use crate::errors::{design_error, err, ExportError};

/// `chord_tolerance_mm` as a tolerance, with the CLI's message for a bad one.
pub(crate) fn tolerance(mm: f64) -> PyResult<ChordTolerance> {
    ChordTolerance::new(mm).map_err(|e| PyValueError::new_err(format!("chord_tolerance_mm: {e}")))
}

/// `max_triangles` within the CLI's range, with the CLI's message otherwise.
pub(crate) fn max_triangles(n: i128) -> PyResult<u64> {
    fabkit_designs::estimate::parse_max_triangles(&n.to_string())
        .map_err(|e| PyValueError::new_err(format!("max_triangles: {e}")))
}

/// Calls a Python progress callback `progress(done, total, message)` from any thread; an
/// exception it raises is reported as unraisable (the work goes on).
pub(crate) fn report_progress(
    progress: &Option<Py<PyAny>>,
    done: usize,
    total: usize,
    message: &str,
) {
    if let Some(cb) = progress {
        Python::attach(|py| {
            if let Err(e) = cb.call1(py, (done, total, message)) {
                e.write_unraisable(py, Some(cb.bind(py)));
            }
        });
    }
}

/// The formats named in `formats` (`stl`, `3mf`, `step`, and the simulators' `mjcf`, `urdf`,
/// `usd`), as `--format`.
pub(crate) fn formats(names: &[String]) -> PyResult<Formats> {
    let mut f = Formats {
        stl: false,
        threemf: false,
        step: false,
        mjcf: false,
        urdf: false,
        usd: false,
    };
    for n in names {
        match n.as_str() {
            "stl" => f.stl = true,
            "3mf" => f.threemf = true,
            "step" => f.step = true,
            "mjcf" => f.mjcf = true,
            "urdf" => f.urdf = true,
            "usd" => f.usd = true,
            other => {
                return Err(PyValueError::new_err(format!(
                    "formats: '{other}' is not an export format (stl, 3mf, step, mjcf, urdf, usd)"
                )))
            }
        }
    }
    Ok(f)
}

/// A mesh as numpy arrays: vertices (n, 3) float64 mm, triangles (m, 3) uint32.
type MeshArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<u32>>);

/// A built kit: the printable parts of a design and its pours.
#[pyclass(module = "fabkit", frozen)]
pub struct Kit {
    pub(crate) kit: Arc<KitData>,
    pub(crate) design: Design,
    pub(crate) tol: ChordTolerance,
    /// Data files written beside the meshes (fixtures: point tables, descriptions).
    pub(crate) files: Arc<Vec<(String, Vec<u8>)>>,
    /// The command whose output `export` writes (an export or fixtures), as the CLI's.
    pub(crate) command: OutputCommand,
}

/// One printable part of a kit, in print orientation (resting on z = 0), mm.
#[pyclass(module = "fabkit", frozen)]
pub struct Part {
    kit: Arc<KitData>,
    index: usize,
}

impl Part {
    fn part(&self) -> &fabkit_designs::Part {
        &self.kit.parts[self.index]
    }
}

#[pymethods]
impl Part {
    /// File stem and 3MF object name, `[a-z0-9_]+`.
    #[getter]
    fn name(&self) -> String {
        self.part().name.clone()
    }
    /// What the part is for (`mold_half`, `core_holder`, ...).
    #[getter]
    fn role(&self) -> String {
        self.part().role.clone()
    }
    /// Material key in the materials table (`pla_black`, ...).
    #[getter]
    fn material(&self) -> String {
        self.part().material.clone()
    }
    /// `FDM` or `SLA`.
    #[getter]
    fn technology(&self) -> String {
        self.part().print_technology.to_string()
    }

    /// The mesh that `fabkit export` writes (coordinates rounded to float32, shared vertices):
    /// `(vertices, triangles)`, vertices (n, 3) float64 mm in print orientation, triangles
    /// (m, 3) uint32 vertex indices, counter-clockwise seen from outside.
    fn mesh<'py>(&self, py: Python<'py>) -> PyResult<MeshArrays<'py>> {
        let mesh = crate::work(py, || self.part().written_mesh())?;
        let nv = mesh.vertices.len();
        let nt = mesh.triangles.len();
        let v: Vec<f64> = mesh.vertices.iter().flatten().copied().collect();
        let t: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let v =
            Array2::from_shape_vec((nv, 3), v).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let t =
            Array2::from_shape_vec((nt, 3), t).map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok((v.into_pyarray(py), t.into_pyarray(py)))
    }

    /// The part's numbers as in the export's manifest.json `parts[]` entry (without the file
    /// and its sha256): volume_mm3, mass_g, surface_area_mm2, bbox_mm ([min, max], mm),
    /// vertices, triangles, genus, role, material, material_name, print_technology, params.
    fn numbers(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let entry = crate::work(py, || {
            let materials = fabkit_designs::materials::MaterialsTable::embedded().ok();
            fabkit_export::part_entry(self.part(), &self.part().written_mesh(), materials.as_ref())
        })?
        .map_err(|e| err::<ExportError>(&e))?;
        let mut v = serde_json::to_value(entry).map_err(|e| ExportError::new_err(e.to_string()))?;
        // no file is written here: the entry without `file` and its `sha256` (both null)
        if let Some(m) = v.as_object_mut() {
            m.remove("file");
            m.remove("sha256");
        }
        crate::to_py(py, &v)
    }

    fn __repr__(&self) -> String {
        let p = self.part();
        format!(
            "Part({:?}, role={:?}, material={:?}, technology={:?})",
            p.name,
            p.role,
            p.material,
            p.print_technology.to_string()
        )
    }
}

#[pymethods]
impl Kit {
    /// The design's name (the kit's).
    #[getter]
    fn name(&self) -> String {
        self.kit.design.clone()
    }

    /// The design the kit was built from.
    #[getter]
    fn design(&self) -> Design {
        self.design.clone()
    }

    /// The chord tolerance the kit was built at, mm.
    #[getter]
    fn chord_tolerance_mm(&self) -> f64 {
        self.tol.mm()
    }

    /// The printable parts, in kit order (as in the manifest).
    #[getter]
    fn parts(&self) -> Vec<Part> {
        (0..self.kit.parts.len())
            .map(|index| Part {
                kit: self.kit.clone(),
                index,
            })
            .collect()
    }

    /// The part named `name`; KeyError naming the kit's parts otherwise.
    fn part(&self, name: &str) -> PyResult<Part> {
        match self.kit.parts.iter().position(|p| p.name == name) {
            Some(index) => Ok(Part {
                kit: self.kit.clone(),
                index,
            }),
            None => Err(pyo3::exceptions::PyKeyError::new_err(format!(
                "no part named '{name}' in kit '{}' (its parts: {})",
                self.kit.design,
                self.kit
                    .parts
                    .iter()
                    .map(|p| p.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
        }
    }

    /// The pour table: one dict per pour in casting order, as the manifest's `casts[]` (step,
    /// cast, material, cavity_volume_ml, components with mass_g, ...).
    fn casts(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let v = serde_json::to_value(&self.kit.casts)
            .map_err(|e| ExportError::new_err(e.to_string()))?;
        crate::to_py(py, &v)
    }

    /// Sensor-frame facts of the kit (envelope, derived radii, markers), as the manifest's
    /// `summary`.
    fn summary(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        crate::to_py(py, &self.kit.summary)
    }

    /// Writes the kit into the folder `out` as `fabkit export` (or `fabkit fixtures`) does:
    /// the same files, byte for byte, for the same design, options and `command_line` (which
    /// the manifest records; default: this process's arguments). `out` may be missing, empty or
    /// an earlier export (or fixtures) of the same kit and tolerance as fabkit wrote it
    /// (replaced as a whole; another kit or tolerance only with `force`); anything else (a
    /// folder of your own, an edited output, another command's output) is refused and nothing
    /// is written. Returns the manifest
    /// as a dict. `progress(done, total, message)` is called as each STEP part starts.
    ///
    /// Raises ExportError with the CLI's message.
    #[pyo3(signature = (out, *, formats=vec!["stl".to_string(), "3mf".to_string()], force=false, command_line=None, progress=None))]
    fn export(
        &self,
        py: Python<'_>,
        out: PathBuf,
        formats: Vec<String>,
        force: bool,
        command_line: Option<Vec<String>>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Py<PyAny>> {
        let f = crate::kit::formats(&formats)?;
        let mut opts = ExportOptions::for_design(
            f,
            command_line.unwrap_or_else(|| std::env::args().collect()),
            &self.design.source,
            &self.design.sha256,
            self.tol.mm(),
            self.design.design.printers.clone(),
        );
        opts.command = self.command;
        opts.force = force;
        if self.command == OutputCommand::Fixtures && (f.mjcf || f.urdf || f.usd) {
            return Err(PyValueError::new_err(
                "formats: the simulators' files (mjcf, urdf, usd) are of the sensor (build_kit(design).export), not of its fixtures; fixtures take stl, 3mf and step",
            ));
        }
        if f.mjcf || f.urdf || f.usd {
            // the design's nominal camera and its lights, as `fabkit export --format mjcf`
            opts.sim = fabkit_calibration::nominal::sim_scene(&self.design.design, self.tol);
        }
        let step = |i: usize, n: usize, part: &str| {
            report_progress(&progress, i, n, &format!("STEP {i}/{n}: {part}"))
        };
        let summary = crate::work(py, || {
            fabkit_export::write_kit_reporting(&self.kit, &self.files, &out, &opts, Some(&step))
        })?
        .map_err(|e| err::<ExportError>(&e))?;
        let v = serde_json::to_value(&summary.manifest)
            .map_err(|e| ExportError::new_err(e.to_string()))?;
        crate::to_py(py, &v)
    }

    fn __len__(&self) -> usize {
        self.kit.parts.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Kit({:?}, {} parts, {} casts, chord_tolerance_mm={})",
            self.kit.design,
            self.kit.parts.len(),
            self.kit.casts.len(),
            self.tol.mm()
        )
    }
}

/// Builds the kit of `design` (validated first; every violated rule at once in DesignError),
/// refusing before anything is built a kit estimated at more than `max_triangles` triangles.
/// The GIL is released while it builds; `progress(done, total, message)` is called when the
/// build starts and when it ends.
#[pyfunction]
#[pyo3(signature = (design, *, chord_tolerance_mm=ChordTolerance::DEFAULT_MM, max_triangles=fabkit_designs::estimate::DEFAULT_MAX_TRIANGLES as i128, progress=None))]
pub fn build_kit(
    py: Python<'_>,
    design: &Design,
    chord_tolerance_mm: f64,
    max_triangles: i128,
    progress: Option<Py<PyAny>>,
) -> PyResult<Kit> {
    let tol = tolerance(chord_tolerance_mm)?;
    let limit = crate::kit::max_triangles(max_triangles)?;
    let what = format!(
        "building {} at {} mm chord tolerance",
        design.design.name,
        tol.mm()
    );
    report_progress(&progress, 0, 1, &what);
    let kit = crate::work(py, || build_kit_bounded(&design.design, tol, limit))?
        .map_err(|e| design_error(&e))?;
    report_progress(&progress, 1, 1, &format!("built {}", design.design.name));
    Ok(Kit {
        kit: Arc::new(kit),
        design: design.clone(),
        tol,
        files: Arc::new(Vec::new()),
        command: OutputCommand::Export,
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Kit>()?;
    m.add_class::<Part>()?;
    m.add_function(wrap_pyfunction!(build_kit, m)?)?;
    m.add("DEFAULT_CHORD_TOLERANCE_MM", ChordTolerance::DEFAULT_MM)?;
    Ok(())
}
