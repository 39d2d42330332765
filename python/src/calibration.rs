//! `fabkit.Camera`, `fabkit.solve_extrinsics` and `fabkit.calibrate_board`: camera models, the
//! PnP extrinsics solve of `fabkit calibrate extrinsics` from numpy arrays, and the flat sensor's
//! camera from a board press of `fabkit calibrate board`.

use fabkit_calibration::nalgebra::{Vector2, Vector3};
use fabkit_calibration::refraction::OpticalLayers;
use fabkit_calibration::report::Provenance;
use fabkit_calibration::tables::Pairs;
use fabkit_calibration::{
    read_camera_file_as, CameraModel, Distortion, DistortionModelHint, ExtrinsicsReport,
    Intrinsics, PnpOptions, PnpSolution, RansacOptions,
};
use fabkit_designs::optics::OpticalPath;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{err, CalibrationError};

/// `model` (`fisheye`, `plumb_bob`, `rational_polynomial`) as the CLI's `--camera-model`.
fn model_hint(model: Option<&str>) -> PyResult<Option<DistortionModelHint>> {
    Ok(match model {
        None => None,
        Some("fisheye") => Some(DistortionModelHint::Fisheye),
        Some("plumb_bob") => Some(DistortionModelHint::PlumbBob),
        Some("rational_polynomial") => Some(DistortionModelHint::RationalPolynomial),
        Some(other) => {
            let models = "fisheye, plumb_bob, rational_polynomial";
            return Err(PyValueError::new_err(format!(
                "model: '{other}' is not a distortion model ({models})"
            )));
        }
    })
}

/// A camera model: intrinsics (fx, fy, cx, cy in px), image size and lens distortion
/// (`fisheye` Kannala-Brandt k1..k4, `plumb_bob` k1 k2 p1 p2 [k3], `rational_polynomial`
/// k1 k2 p1 p2 k3..k6, as OpenCV). Pixel (0, 0) is the centre of the top-left pixel; camera
/// frame x right, y down, z forward (docs/conventions.md).
#[pyclass(module = "fabkit", frozen)]
#[derive(Clone)]
pub struct Camera {
    pub(crate) model: CameraModel,
    /// The camera file it was read from (`<arrays>` when built from numbers).
    pub(crate) source: String,
}

impl Camera {
    /// Reads a camera file (as `--camera`, with `--camera-model` `model`).
    pub(crate) fn read(path: std::path::PathBuf, model: Option<&str>) -> PyResult<Camera> {
        let hint = model_hint(model)?;
        let model = read_camera_file_as(&path, hint).map_err(|e| err::<CalibrationError>(&e))?;
        Ok(Camera {
            model,
            source: path.display().to_string(),
        })
    }

    /// A Camera, or the camera file (whose model it names) at the path `obj`.
    pub(crate) fn of(obj: &Bound<'_, PyAny>) -> PyResult<Camera> {
        match obj.cast::<Camera>() {
            Ok(c) => Ok(c.get().clone()),
            Err(_) => Camera::read(obj.extract()?, None),
        }
    }
}

#[pymethods]
impl Camera {
    /// A camera from its numbers. Raises CalibrationError for a model that does not hold
    /// (non-positive focal length, wrong coefficient count, ...).
    #[new]
    #[pyo3(signature = (fx_px, fy_px, cx_px, cy_px, width_px, height_px, distortion_model="plumb_bob", coefficients=vec![0.0; 5]))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        fx_px: f64,
        fy_px: f64,
        cx_px: f64,
        cy_px: f64,
        width_px: u32,
        height_px: u32,
        distortion_model: &str,
        coefficients: Vec<f64>,
    ) -> PyResult<Camera> {
        let distortion = Distortion::from_name(distortion_model, &coefficients).map_err(|e| {
            CalibrationError::new_err(format!("distortion_model {distortion_model}: {e}"))
        })?;
        let model = CameraModel::new(Intrinsics {
            image_width_px: width_px,
            image_height_px: height_px,
            fx_px,
            fy_px,
            cx_px,
            cy_px,
            distortion,
        })
        .map_err(|e| err::<CalibrationError>(&e))?;
        Ok(Camera {
            model,
            source: "<arrays>".into(),
        })
    }

    /// Reads a camera file (OpenCV FileStorage YAML or XML, ROS camera_info YAML or fabkit
    /// JSON), as `--camera`; `model` as `--camera-model` for a file that names no distortion
    /// model. Raises CalibrationError naming the file, line and field.
    #[staticmethod]
    #[pyo3(signature = (path, model=None))]
    fn from_file(path: std::path::PathBuf, model: Option<&str>) -> PyResult<Camera> {
        Camera::read(path, model)
    }

    /// The intrinsics as a dict: image_width_px, image_height_px, fx_px, fy_px, cx_px, cy_px,
    /// distortion_model, distortion_coefficients.
    #[getter]
    fn intrinsics(&self, py: Python<'_>) -> PyResult<Py<PyDict>> {
        let i = self.model.intrinsics();
        let d = PyDict::new(py);
        d.set_item("image_width_px", i.image_width_px)?;
        d.set_item("image_height_px", i.image_height_px)?;
        d.set_item("fx_px", i.fx_px)?;
        d.set_item("fy_px", i.fy_px)?;
        d.set_item("cx_px", i.cx_px)?;
        d.set_item("cy_px", i.cy_px)?;
        d.set_item("distortion_model", i.distortion.name())?;
        d.set_item(
            "distortion_coefficients",
            i.distortion.coefficients().to_vec(),
        )?;
        Ok(d.unbind())
    }

    /// (height, width) of the image, px.
    #[getter]
    fn shape(&self) -> (u32, u32) {
        let i = self.model.intrinsics();
        (i.image_height_px, i.image_width_px)
    }

    /// Projects camera-frame points (n, 3) mm to pixels (n, 2) px; NaN for a point the lens
    /// does not image (behind the camera, past the field of view).
    fn project<'py>(
        &self,
        py: Python<'py>,
        points_mm: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let p = rows::<3>(points_mm, "points_mm")?;
        let out: Vec<f64> = p
            .iter()
            .flat_map(|q| match self.model.project(&Vector3::from(*q)) {
                Some(uv) => [uv.x, uv.y],
                None => [f64::NAN, f64::NAN],
            })
            .collect();
        Ok(Array2::from_shape_vec((p.len(), 2), out)
            .map_err(|e| PyValueError::new_err(e.to_string()))?
            .into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        let i = self.model.intrinsics();
        format!(
            "Camera({} x {} px, fx={}, fy={}, cx={}, cy={}, {} {:?}, source={:?})",
            i.image_width_px,
            i.image_height_px,
            i.fx_px,
            i.fy_px,
            i.cx_px,
            i.cy_px,
            i.distortion.name(),
            i.distortion.coefficients(),
            self.source
        )
    }
}

/// `obj` (an array-like of numbers) as a float64 numpy array, `numpy.asarray(obj, float64)`;
/// ValueError naming `name` when it does not convert.
pub(crate) fn float64_array<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let np = obj.py().import("numpy")?;
    let a = np
        .call_method1("asarray", (obj, "float64"))
        .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    Ok(a.cast_into::<PyArrayDyn<f64>>()?)
}

/// A numpy shape as Python prints it: `(5, 2)`, `(3,)`, `()`.
pub(crate) fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The rows of an (n, N) array-like; ValueError for another shape, CalibrationError naming the
/// first non-finite entry as `name[i, j] = value: must be finite` (the rule of the CLI's tables).
pub(crate) fn rows<const N: usize>(a: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[f64; N]>> {
    let a = float64_array(a, name)?;
    if a.ndim() != 2 || a.shape()[1] != N {
        return Err(PyValueError::new_err(format!(
            "{name}: shape {} where (n, {N}) is needed",
            shape_text(a.shape())
        )));
    }
    let a = a.readonly();
    let v = a.as_array();
    let mut out = Vec::with_capacity(v.shape()[0]);
    for (i, r) in v.outer_iter().enumerate() {
        let mut row = [0.0; N];
        for (j, x) in r.iter().enumerate() {
            if !x.is_finite() {
                return Err(CalibrationError::new_err(format!(
                    "{name}[{i}, {j}] = {x}: must be finite"
                )));
            }
            row[j] = *x;
        }
        out.push(row);
    }
    Ok(out)
}

/// Solves the camera pose T_cam_sensor from sensor-frame points (n, 3) mm and their observed
/// pixels (n, 2) px through `camera` (a Camera or a camera file path), as `fabkit calibrate
/// extrinsics` does (SQPnP + Levenberg-Marquardt; with `ransac`, outliers rejected at
/// `threshold_px`, or a threshold from the data when it is None: sqrt(2 ln(n / 0.002))
/// robust standard deviations by least median of squares (4.4 for 30 pins), at least 3 px, at most a tenth of the pixels' spread). The RANSAC
/// samples are a fixed schedule over the pairs in a canonical order: the same pairs in any order
/// give the same pose; `seed` is accepted for older scripts and has no effect (a
/// DeprecationWarning).
///
/// Returns a dict: `T_cam_sensor` (4, 4) float64 (sensor frame -> camera frame, mm),
/// `residuals_px` (n, 2) (reprojected minus observed, NaN where a point does not project),
/// `inliers` and `outliers` (n,) bool, `rms_reprojection_error_px`, and `report`: the dict
/// `extrinsics.json` holds (rvec, tvec, pose uncertainty, per-point residuals by id; ids are
/// `ids` or the row numbers). With `design` (a `Design`), the rays bend by Snell's law at the
/// design's interfaces (its filling gel's free surface, a window's or a plate's faces, a
/// spherical core's faces; indices from the materials table), as `calibrate extrinsics
/// --design` does, and the report lists them (`optical_path`). Raises CalibrationError with the CLI's message (fewer than 4
/// points, a non-finite value, a degenerate layout, too few inliers, ...).
#[pyfunction]
#[pyo3(signature = (points_mm, pixels_px, camera, *, ids=None, ransac=true, threshold_px=None, seed=None, design=None))]
#[allow(clippy::too_many_arguments)]
pub fn solve_extrinsics<'py>(
    py: Python<'py>,
    points_mm: &Bound<'py, PyAny>,
    pixels_px: &Bound<'py, PyAny>,
    camera: &Bound<'py, PyAny>,
    ids: Option<Vec<String>>,
    ransac: bool,
    threshold_px: Option<f64>,
    seed: Option<u64>,
    design: Option<PyRef<'py, crate::design::Design>>,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(t) = threshold_px {
        if !(t.is_finite() && t > 0.0) {
            return Err(PyValueError::new_err(format!(
                "threshold_px = {t}: must be finite and > 0 (or None: from the data)"
            )));
        }
    }
    let camera = Camera::of(camera)?;
    let pairs = pairs_of(points_mm, pixels_px, ids)?;
    if seed.is_some() {
        pyo3::PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyDeprecationWarning>(),
            c"seed has no effect: RANSAC samples on a fixed schedule, so the pose depends on the data only",
            1,
        )?;
    }
    let ransac = ransac.then(|| RansacOptions {
        threshold_px,
        ..RansacOptions::default()
    });
    let opts = PnpOptions {
        ransac,
        ..PnpOptions::default()
    };
    let design = design.as_deref();
    let (optical_path, layers) = optical_path_of(design)?;
    let imaging = fabkit_calibration::refraction::Imaging::new(&camera.model, layers.as_ref());
    let sol = crate::work(py, || {
        fabkit_calibration::pnp::solve_pnp_through(
            &imaging,
            &pairs.points_mm,
            &pairs.pixels_px,
            &opts,
        )
    })?
    .map_err(|e| err::<CalibrationError>(&e))?;
    let (sol, report) = compare_and_report(py, &camera, layers, optical_path, design, &pairs, sol)?;
    result_dict(py, &sol, &report, pairs.ids.len())
}

/// The pairs of `points_mm` (n, 3) and `pixels_px` (n, 2) by row, named by `ids` or their row
/// numbers.
fn pairs_of(
    points_mm: &Bound<'_, PyAny>,
    pixels_px: &Bound<'_, PyAny>,
    ids: Option<Vec<String>>,
) -> PyResult<Pairs> {
    let points = rows::<3>(points_mm, "points_mm")?;
    let pixels = rows::<2>(pixels_px, "pixels_px")?;
    let n = points.len();
    if pixels.len() != n {
        return Err(PyValueError::new_err(format!(
            "pixels_px: {} rows for {n} points (points_mm (n, 3) and pixels_px (n, 2) pair up by row)",
            pixels.len()
        )));
    }
    let ids = match ids {
        Some(ids) if ids.len() != n => {
            return Err(PyValueError::new_err(format!(
                "ids: {} ids for {n} points",
                ids.len()
            )))
        }
        Some(ids) => ids,
        None => (0..n).map(|i| i.to_string()).collect(),
    };
    Ok(Pairs {
        ids,
        points_mm: points.iter().map(|p| Vector3::from(*p)).collect(),
        pixels_px: pixels.iter().map(|p| Vector2::from(*p)).collect(),
    })
}

/// The optical path of `design` (none without one) and its layers, that the rays bend at.
fn optical_path_of(
    design: Option<&crate::design::Design>,
) -> PyResult<(Option<OpticalPath>, Option<OpticalLayers>)> {
    let optical_path = match design {
        None => None,
        Some(d) => {
            let tol =
                fabkit_designs::ChordTolerance::new(fabkit_designs::ChordTolerance::DEFAULT_MM)
                    .map_err(|e| CalibrationError::new_err(e.to_string()))?;
            Some(
                fabkit_designs::optics::optical_path_of_design(&d.design, tol)
                    .map_err(|e| CalibrationError::new_err(format!("design: {e}")))?,
            )
        }
    };
    let layers = optical_path
        .as_ref()
        .map(OpticalLayers::from_optical_path)
        .transpose()
        .map_err(|e| CalibrationError::new_err(format!("design: {e}")))?;
    Ok((optical_path, layers))
}

/// Compares the models that might explain the pins `sol` left out, as the CLI does (taking
/// the gel surface's fit when it explains every pin), and reports the solution taken as
/// `extrinsics.json` does.
fn compare_and_report(
    py: Python<'_>,
    camera: &Camera,
    layers: Option<OpticalLayers>,
    optical_path: Option<OpticalPath>,
    design: Option<&crate::design::Design>,
    pairs: &Pairs,
    sol: PnpSolution,
) -> PyResult<(PnpSolution, serde_json::Value)> {
    let model = &camera.model;
    let provenance = Provenance {
        fabkit_version: env!("CARGO_PKG_VERSION").into(),
        command_line: "fabkit.solve_extrinsics".into(),
        camera_file: camera.source.clone(),
        points_file: "<arrays>".into(),
        points_from: "xyz".into(),
        observation_files: vec!["<arrays>".into()],
        capture_plan: None,
        unobserved_ids: Vec::new(),
        reference_image: None,
    };
    // pins left out: the models that might explain them compared first, as the CLI does
    let mut compared = crate::work(py, || {
        fabkit_calibration::models::compare_if_rejected(
            model,
            layers.as_ref(),
            optical_path.as_ref(),
            &pairs.points_mm,
            &pairs.pixels_px,
            &sol,
        )
    })?;
    let (sol, layers, path_fit) = match compared.as_mut().and_then(|c| c.taken.take()) {
        Some((fit, every)) => {
            let what = optical_path
                .as_ref()
                .and_then(fabkit_calibration::models::gel_prior)
                .map_or(String::new(), |g| g.1);
            let report = fabkit_calibration::report::PlaneFitReport::new(&fit, &what);
            (every, Some(fit.layers), Some(report))
        }
        None => (sol, layers, None),
    };
    let imaging = fabkit_calibration::refraction::Imaging::new(model, layers.as_ref());
    let mut report = ExtrinsicsReport::new(&imaging, pairs, &sol, provenance);
    if let (Some(path), Some(d)) = (optical_path, design) {
        report.optical_path = Some(path);
        report.optical_path_from = Some(format!("design {} ({})", d.design.name, d.source));
    }
    report.optical_path_fit = path_fit;
    if let Some(c) = compared {
        report.warnings.extend(c.warning);
        report.model_comparison = Some(c.report);
    }
    let report: serde_json::Value = serde_json::from_str(&report.to_json())
        .map_err(|e| CalibrationError::new_err(e.to_string()))?;
    Ok((sol, report))
}

/// The dict `solve_extrinsics` returns for the solution `sol` of `n` pairs and its `report`.
fn result_dict<'py>(
    py: Python<'py>,
    sol: &PnpSolution,
    report: &serde_json::Value,
    n: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let h = sol.t_cam_sensor.to_homogeneous();
    let t = Array2::from_shape_fn((4, 4), |(r, c)| h[(r, c)]);
    let res: Vec<f64> = sol
        .residuals_px
        .iter()
        .flat_map(|r| r.map_or([f64::NAN, f64::NAN], |v| [v.x, v.y]))
        .collect();
    let out = PyDict::new(py);
    out.set_item("T_cam_sensor", t.into_pyarray(py))?;
    out.set_item(
        "residuals_px",
        Array2::from_shape_vec((n, 2), res)
            .map_err(|e| PyValueError::new_err(e.to_string()))?
            .into_pyarray(py),
    )?;
    out.set_item(
        "inliers",
        Array1::from_vec(sol.inliers.clone()).into_pyarray(py),
    )?;
    out.set_item(
        "outliers",
        Array1::from_iter(sol.inliers.iter().map(|x| !x)).into_pyarray(py),
    )?;
    out.set_item("rms_reprojection_error_px", sol.rms_reprojection_error_px)?;
    out.set_item("report", crate::to_py(py, report)?)?;
    Ok(out)
}

/// `images`: one path (str or os.PathLike) or a sequence of them.
fn paths_of(images: &Bound<'_, PyAny>) -> PyResult<Vec<std::path::PathBuf>> {
    if images.is_instance_of::<pyo3::types::PyString>()
        || images.hasattr("__fspath__").unwrap_or(false)
    {
        return Ok(vec![images.extract()?]);
    }
    images.extract().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(
            "images: a path or a sequence of paths (str or os.PathLike), one per capture",
        )
    })
}

/// The plane's distance and where it comes from, as `fabkit calibrate board` takes it:
/// `plane_distance_mm`, else the flat housing of `design` (a Design, or a library name or YAML
/// path), else of the design the point table's sidecar names.
fn board_plane_distance(
    py: Python<'_>,
    plane_distance_mm: Option<f64>,
    design: Option<&Bound<'_, PyAny>>,
    points: &std::path::Path,
) -> PyResult<(f64, String)> {
    use fabkit_calibration::board::{plane_distance_of_design, point_table_design};
    if let Some(d) = plane_distance_mm {
        return Ok((d, "plane_distance_mm".to_string()));
    }
    let (loaded, named) = match design.map(|d| d.cast::<crate::design::Design>()) {
        Some(Ok(d)) => {
            let d = d.borrow();
            (d.design.clone(), d.as_named())
        }
        given => {
            let arg: String = match (given, design) {
                (Some(Err(_)), Some(d)) => {
                    let p: std::path::PathBuf = d.extract().map_err(|_| {
                        pyo3::exceptions::PyTypeError::new_err(
                            "design: a Design, or a library name or YAML path",
                        )
                    })?;
                    p.to_string_lossy().to_string()
                }
                _ => point_table_design(points).map(|(_, arg, _)| arg).ok_or_else(|| {
                    CalibrationError::new_err(format!(
                        "plane_distance_mm: not given, and no design to take it from: give it, or design (the point table {} names none)",
                        points.display()
                    ))
                })?,
            };
            let rules = fabkit_designs::input_files::DataFileRules::default();
            let loaded = crate::work(py, || {
                fabkit_designs::library::load_source_with(&arg, std::path::Path::new(""), &rules)
            })?
            .map_err(|e| crate::errors::design_error(&e))?;
            (loaded.design, arg)
        }
    };
    let materials =
        fabkit_designs::materials::MaterialsTable::embedded().map_err(CalibrationError::new_err)?;
    plane_distance_of_design(&loaded, &materials).ok_or_else(|| {
        CalibrationError::new_err(format!(
            "plane_distance_mm: not given, and the design {named} has no flat_housing to take it from: give it"
        ))
    })
}

/// Calibrates a flat sensor's camera from a press of its calibration board (or a grid plate
/// pressed over several captures) and writes the calibration into the folder `out`, as
/// `fabkit calibrate board` does (the same files, the same bytes but the command line):
/// `extrinsics.json` and `.yaml`, `camera.yaml` (OpenCV), `camera_info.yaml` (ROS),
/// `camera.json`, `observations.csv`, `pixel_to_plane_mm.npy` and `overlay.png`.
///
/// `points`: the board's point table (points/board_table.csv of `fabkit fixtures`);
/// `reference`: the skin with no contact; `images`: the press, one path or a list (one per
/// capture, in `capture_plan`'s order). `plane_distance_mm`: the plane's distance from the lens
/// in air, mm; when None, from the flat housing of `design` (a Design, a library name or a
/// YAML path) or of the design the point table names. `board_turn_deg`: the board's grid
/// turned in the image, 0, 90, 180 or 270 (the camera turned about its optical axis; the
/// sensor's +x runs along the image's u turned this much towards v). `points_from`: `contact`
/// or `tip`. `out` is replaced only when it holds a calibration of the same inputs (or with
/// `force`); files appear only when all are written.
///
/// Returns a dict: `T_cam_sensor` (4, 4) float64 (sensor frame -> camera frame, mm),
/// `camera` (a Camera read back from the written camera.json), `ids` (found bumps, grid
/// order), `observed_px` and `residuals_px` (n, 2) (reprojected minus observed),
/// `rms_reprojection_error_px`, `report` (extrinsics.json as a dict), `files` (the files
/// written, sorted), `warnings`. Raises CalibrationError with the CLI's message (a table that is
/// no grid, an image of another size, too few imprints, a lattice larger than the board, a
/// turn other than a quarter turn, an output folder that is not this calibration's, ...),
/// DesignError for a design that does not load, ValueError or TypeError for a bad argument.
#[pyfunction]
#[pyo3(signature = (points, reference, images, out, *, plane_distance_mm=None, design=None,
                    capture_plan=None, board_turn_deg=0.0, points_from="contact", force=false,
                    command_line=None))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate_board<'py>(
    py: Python<'py>,
    points: std::path::PathBuf,
    reference: std::path::PathBuf,
    images: &Bound<'py, PyAny>,
    out: std::path::PathBuf,
    plane_distance_mm: Option<f64>,
    design: Option<&Bound<'py, PyAny>>,
    capture_plan: Option<std::path::PathBuf>,
    board_turn_deg: f64,
    points_from: &str,
    force: bool,
    command_line: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    use fabkit_calibration::board::{board_claim, calibrate_board, BoardJob, BoardTurn};
    use fabkit_calibration::tables::PointsFrom;
    let points_from = match points_from {
        "contact" => PointsFrom::Contact,
        "tip" => PointsFrom::Tip,
        other => {
            return Err(PyValueError::new_err(format!(
                "points_from = '{other}': must be 'contact' or 'tip'"
            )))
        }
    };
    let images = paths_of(images)?;
    let board_turn =
        BoardTurn::from_deg(board_turn_deg).map_err(|e| err::<CalibrationError>(&e))?;
    let (plane_distance_mm, plane_distance_from) =
        board_plane_distance(py, plane_distance_mm, design, &points)?;
    let command_line = match command_line {
        Some(c) => c,
        None => py.import("sys")?.getattr("argv")?.extract()?,
    };
    let job = BoardJob {
        points,
        points_from,
        reference,
        images,
        capture_plan,
        plane_distance_mm,
        plane_distance_from,
        board_turn,
        command_line: command_line.join(" "),
    };
    let claim = board_claim(&job, force);
    let (output, mut files, warnings) = crate::work(py, || -> Result<_, PyErr> {
        let staged =
            fabkit_export::StagedDir::new(&out, claim).map_err(|e| err::<CalibrationError>(&e))?;
        let output = calibrate_board(&job).map_err(|e| err::<CalibrationError>(&e))?;
        for (name, bytes) in &output.files {
            staged
                .write(name, bytes)
                .map_err(|e| err::<CalibrationError>(&e))?;
        }
        let warnings = staged.commit().map_err(|e| err::<CalibrationError>(&e))?;
        let files: Vec<String> = output.files.iter().map(|(n, _)| n.clone()).collect();
        Ok((output, files, warnings))
    })??;
    files.sort();
    let r = &output.report;
    let camera = Camera::read(out.join("camera.json"), None)?;
    let t = Array2::from_shape_fn((4, 4), |(i, j)| r.t_cam_sensor[i][j]);
    let n = r.bumps.len();
    let observed: Vec<f64> = r.bumps.iter().flat_map(|b| b.observed_px).collect();
    let residuals: Vec<f64> = r
        .bumps
        .iter()
        .flat_map(|b| {
            [
                b.reprojected_px[0] - b.observed_px[0],
                b.reprojected_px[1] - b.observed_px[1],
            ]
        })
        .collect();
    let shaped = |v: Vec<f64>| {
        Array2::from_shape_vec((n, 2), v).map_err(|e| PyValueError::new_err(e.to_string()))
    };
    let report = serde_json::to_value(r).map_err(|e| CalibrationError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item("T_cam_sensor", t.into_pyarray(py))?;
    d.set_item("camera", Bound::new(py, camera)?)?;
    d.set_item(
        "ids",
        r.bumps.iter().map(|b| b.id.clone()).collect::<Vec<_>>(),
    )?;
    d.set_item("observed_px", shaped(observed)?.into_pyarray(py))?;
    d.set_item("residuals_px", shaped(residuals)?.into_pyarray(py))?;
    d.set_item("rms_reprojection_error_px", r.rms_reprojection_error_px)?;
    d.set_item("report", crate::to_py(py, &report)?)?;
    d.set_item("files", files)?;
    d.set_item("warnings", warnings)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Camera>()?;
    m.add_function(wrap_pyfunction!(solve_extrinsics, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_board, m)?)?;
    Ok(())
}
