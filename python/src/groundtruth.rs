//! `fabkit.DepthRenderer` and `fabkit.read_protrusions`: ground-truth depth of the reference
//! and indented skin rendered straight into numpy arrays, as `fabkit groundtruth` renders the
//! frames it writes (R-Tac0 Sec. IV-B, Fig. 6, Eq. (2)-(3)).

use std::sync::Arc;

use fabkit_calibration::groundtruth::dataset::{
    self, DataFormat, FrameInputs, ImageSource, ManifestInputs, DEFAULT_MAX_OUTPUT_BYTES,
};
use fabkit_calibration::groundtruth::inputs::{
    isometry_of, read_extrinsics, read_fixtures, read_with_hash, Configuration, Fixtures,
};
use fabkit_calibration::groundtruth::shading::Imaging;
use fabkit_calibration::groundtruth::{
    half_masks, indented_hits, reference_hits, DepthFrame, Scene, SurfaceHits,
};
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::calibration::Camera;
use crate::design::Design;
use crate::errors::{err, GroundTruthError};
use crate::kit::report_progress;

use fabkit_calibration::groundtruth::budget::{
    min_skin_pixels, DEFAULT_MAX_PIXELS, MAX_PIXELS_LIMIT, MEMORY_BUDGET_BYTES, MIN_SKIN_FRACTION,
};

/// The protrusions of one semi-dome (or semi-plate) configuration of a fixtures folder: a
/// pattern at orientation 0 deg (on the +x half) or 180 deg (on the -x half); or the pins of
/// one capture of a pin dome ([`read_pin_captures`]).
#[pyclass(module = "fabkit", frozen)]
pub struct ProtrusionSet {
    cfg: Arc<Configuration>,
}

#[pymethods]
impl ProtrusionSet {
    /// `<pattern>_<orientation_deg>`, the frame's folder name in a ground-truth output.
    #[getter]
    fn name(&self) -> String {
        self.cfg.name.clone()
    }
    #[getter]
    fn pattern(&self) -> String {
        self.cfg.pattern.clone()
    }
    #[getter]
    fn orientation_deg(&self) -> u32 {
        self.cfg.orientation_deg
    }
    /// The ids of a pin capture's pins, in the capture plan's order; empty for a pattern.
    #[getter]
    fn pins(&self) -> Vec<String> {
        self.cfg.pins.clone()
    }
    /// Number of primitives (spheres, cylinders, ridges) in the set.
    fn __len__(&self) -> usize {
        self.cfg.geometry.primitives.len()
    }
    fn __repr__(&self) -> String {
        format!(
            "ProtrusionSet({:?}, {} primitives)",
            self.cfg.name,
            self.cfg.geometry.primitives.len()
        )
    }
}

/// The protrusion configurations of a `fabkit fixtures` output folder built from `design`
/// (`protrusions/index.json` and its pattern files): two per pattern (0 and 180 deg), in index
/// order. Raises GroundTruthError naming the file and the rule.
#[pyfunction]
pub fn read_protrusions(
    py: Python<'_>,
    fixtures_dir: std::path::PathBuf,
    design: &Design,
) -> PyResult<Vec<ProtrusionSet>> {
    sets_of(py, || read_fixtures(&fixtures_dir, &design.design.name))
}

/// The configurations `read` gives (off the GIL) as protrusion sets; its error as
/// GroundTruthError.
fn sets_of(
    py: Python<'_>,
    read: impl FnOnce() -> Result<
            fabkit_calibration::groundtruth::inputs::Fixtures,
            fabkit_calibration::groundtruth::inputs::InputError,
        > + Send,
) -> PyResult<Vec<ProtrusionSet>> {
    let f = crate::work(py, read)?.map_err(|e| err::<GroundTruthError>(&e))?;
    Ok(f.configurations
        .into_iter()
        .map(|c| ProtrusionSet { cfg: Arc::new(c) })
        .collect())
}

/// The captures of the pin dome of a `fabkit fixtures` output folder built from `design`
/// (points/capture_plan.csv, points/point_table.csv, the pin's shape in manifest.json): one
/// set per capture, its planned pins pressed in, named by its pins (`01_02_06_14_22`) as
/// `fabkit groundtruth --pin-captures` names its folders. Raises GroundTruthError naming the
/// file, the line and the rule.
#[pyfunction]
pub fn read_pin_captures(
    py: Python<'_>,
    fixtures_dir: std::path::PathBuf,
    design: &Design,
) -> PyResult<Vec<ProtrusionSet>> {
    sets_of(py, || {
        fabkit_calibration::groundtruth::pins::read_pin_captures(&fixtures_dir, &design.design.name)
    })
}

/// A sensor's photometric model as `fabkit calibrate photometric` wrote it
/// ([`read_photometric`]): images in the sensor's own appearance from `DepthRenderer.image(...,
/// photometric=model)`.
#[pyclass(module = "fabkit", frozen)]
pub struct PhotometricModel {
    model: Arc<fabkit_calibration::photometric::PhotometricModel>,
    source: String,
    /// sha256 of its photometric.json, for a dataset's manifest.
    sha256: String,
    /// The design, camera and extrinsics it was fitted with (photometric.json's record).
    fitted_with: fabkit_calibration::photometric::FittedWith,
}

#[pymethods]
impl PhotometricModel {
    /// The camera image's width, px.
    #[getter]
    fn width(&self) -> usize {
        self.model.width
    }
    /// The camera image's height, px.
    #[getter]
    fn height(&self) -> usize {
        self.model.height
    }
    /// 8 or 16: the bit depth of the captures it was fitted to, and of its images.
    #[getter]
    fn bit_depth(&self) -> u32 {
        if self.model.full_scale > 255.0 {
            16
        } else {
            8
        }
    }
    fn __repr__(&self) -> String {
        format!(
            "PhotometricModel({:?}, {} x {} px)",
            self.source, self.model.width, self.model.height
        )
    }
}

/// The photometric model in `dir`, the output folder of `fabkit calibrate photometric`
/// (photometric.json and appearance.npy). Raises GroundTruthError naming the file and what
/// does not fit: not JSON, another basis than this fabkit's, an appearance that is not
/// (H, W, 3) float32.
/// `DepthRenderer.image(..., photometric=model)` refuses it for another design, camera file
/// or extrinsics file than it was fitted with (photometric.json's record).
#[pyfunction]
pub fn read_photometric(py: Python<'_>, dir: std::path::PathBuf) -> PyResult<PhotometricModel> {
    let (model, sha256, fitted_with) = crate::work(py, || {
        fabkit_calibration::photometric::PhotometricModel::read(&dir)
    })?
    .map_err(GroundTruthError::new_err)?;
    Ok(PhotometricModel {
        model: Arc::new(model),
        source: dir.display().to_string(),
        sha256,
        fitted_with,
    })
}

/// Renders ground-truth depth of a design's skin seen through a calibrated camera.
///
/// `DepthRenderer(design, camera, T_cam_sensor)`: `camera` a Camera or a camera file path,
/// `T_cam_sensor` (4, 4) (sensor frame -> camera frame, mm; rotation block orthonormal). The
/// camera centre must be inside the sensor body. Arrays are (H, W) row-major, float32 as the
/// files `fabkit groundtruth` writes, NaN where the pixel's ray misses the skin.
#[pyclass(module = "fabkit", frozen)]
pub struct DepthRenderer {
    scene: Scene,
    /// The camera, its file (or `<arrays>`) and that file's sha256, for `write`'s manifest.
    camera: fabkit_calibration::CameraModel,
    camera_file: String,
    camera_sha256: Option<String>,
    /// T_cam_sensor, its extrinsics.json (or `<array>`) and that file's sha256.
    pose: nalgebra::Isometry3<f64>,
    extrinsics_file: String,
    extrinsics_sha256: Option<String>,
    /// The design as loaded: as named, its source, sha256 and preset.
    named: String,
    source: String,
    sha256: String,
    preset: Option<String>,
    reference_hits: SurfaceHits,
    reference: DepthFrame,
    /// The design, for its optics when an image is first asked for.
    design: fabkit_designs::Design,
    /// The camera's principal point (cx, cy), px: the vignetting's centre.
    principal_px: [f64; 2],
    /// The imaging of `image`, set up on its first call (the optics resolved, the exposure set
    /// on the reference).
    imaging: std::sync::OnceLock<Result<Imaging, String>>,
    /// The optical path the extrinsics.json's pose was solved through, as the manifest lists
    /// it; `None`: straight rays.
    optical_path: Option<serde_json::Value>,
}

/// An (H, W, 3) RGB image as a numpy array: uint16 at 16 bits, else uint8.
fn rgb_array(
    py: Python<'_>,
    img: Vec<[u16; 3]>,
    h: usize,
    w: usize,
    bits: u32,
) -> Bound<'_, PyAny> {
    let flat = img.into_iter().flatten();
    if bits == 16 {
        Array3::from_shape_vec((h, w, 3), flat.collect::<Vec<u16>>())
            .expect("h x w x 3")
            .into_pyarray(py)
            .into_any()
    } else {
        Array3::from_shape_vec((h, w, 3), flat.map(|c| c as u8).collect::<Vec<u8>>())
            .expect("h x w x 3")
            .into_pyarray(py)
            .into_any()
    }
}

fn f32_map(v: &[f64], h: usize, w: usize) -> Array2<f32> {
    Array2::from_shape_vec((h, w), v.iter().map(|x| *x as f32).collect()).expect("h x w")
}

/// A (H, W) bool numpy array.
type BoolMap<'py> = Bound<'py, numpy::PyArray2<bool>>;

fn bool_map(v: &[bool], h: usize, w: usize) -> Array2<bool> {
    Array2::from_shape_vec((h, w), v.to_vec()).expect("h x w")
}

/// The arrays of a frame: range_mm, zdepth_mm (H, W) float32, normals (H, W, 3) float32
/// (camera frame, out of the elastomer).
fn frame_dict<'py>(py: Python<'py>, f: &DepthFrame) -> PyResult<Bound<'py, PyDict>> {
    let (h, w) = (f.height, f.width);
    let d = PyDict::new(py);
    d.set_item("range_mm", f32_map(&f.range_mm, h, w).into_pyarray(py))?;
    d.set_item("zdepth_mm", f32_map(&f.zdepth_mm, h, w).into_pyarray(py))?;
    let n: Vec<f32> = f
        .normal_cam
        .iter()
        .flat_map(|n| n.map(|c| c as f32))
        .collect();
    d.set_item(
        "normals",
        Array3::from_shape_vec((h, w, 3), n)
            .expect("h x w x 3")
            .into_pyarray(py),
    )?;
    Ok(d)
}

impl DepthRenderer {
    /// Refuses a photometric model fitted with another design, camera file or extrinsics file
    /// than this renderer's (by sha256, as `fabkit groundtruth --photometric` does), or of
    /// another camera size; warns (UserWarning) where the renderer's camera or pose was given
    /// as values, whose match with the model's files cannot be checked.
    fn check_camera_of(&self, py: Python<'_>, model: &PhotometricModel) -> PyResult<()> {
        let fitted = &model.fitted_with;
        fitted
            .check("design", &self.sha256, &format!("design {}", self.named))
            .map_err(GroundTruthError::new_err)?;
        for (key, sha, file) in [
            ("camera", &self.camera_sha256, &self.camera_file),
            ("extrinsics", &self.extrinsics_sha256, &self.extrinsics_file),
        ] {
            match sha {
                Some(sha) => fitted
                    .check(key, sha, file)
                    .map_err(GroundTruthError::new_err)?,
                None if fitted.inputs.iter().any(|(k, _, _)| k == key) => {
                    let msg = std::ffi::CString::new(format!(
                        "photometric {}: this renderer's {key} was given as values ({file}), so fabkit cannot check that the model was fitted with it; pass the {key} file to check",
                        model.source
                    ))
                    .unwrap_or_default();
                    pyo3::PyErr::warn(
                        py,
                        &py.get_type::<pyo3::exceptions::PyUserWarning>(),
                        &msg,
                        1,
                    )?;
                }
                None => {}
            }
        }
        let (m, rays) = (&model.model, &self.scene.rays);
        if (m.width, m.height) != (rays.width, rays.height) {
            return Err(GroundTruthError::new_err(format!(
                "photometric: the model is of a {} x {} px camera, this renderer's is {} x {} px (the model was fitted to another camera)",
                m.width, m.height, rays.width, rays.height
            )));
        }
        Ok(())
    }

    /// The imaging of the design's optics, set up on first use (the optics resolved, the
    /// exposure set on the reference).
    fn physical_imaging(&self) -> Result<&Imaging, String> {
        self.imaging
            .get_or_init(|| {
                ImageSource::of_design(
                    &self.design,
                    self.principal_px,
                    &self.scene.rays,
                    &self.reference_hits,
                )
                .map_err(|e| e.to_string())
            })
            .as_ref()
            .map_err(Clone::clone)
    }

    /// The fixtures of `fixtures` for this design (the pin dome's captures with
    /// `pin_captures`, checked on this skin), each outside the camera.
    fn read_fixture_set(
        &self,
        py: Python<'_>,
        fixtures: &std::path::Path,
        pin_captures: bool,
    ) -> PyResult<Fixtures> {
        let name = self.design.name.clone();
        let fixture_set = crate::work(py, || {
            if pin_captures {
                fabkit_calibration::groundtruth::pins::read_pin_captures(fixtures, &name)
            } else {
                read_fixtures(fixtures, &name)
            }
        })?
        .map_err(|e| err::<GroundTruthError>(&e))?;
        if pin_captures {
            use fabkit_calibration::groundtruth::pins::{check_on_skin, read_pins};
            read_pins(fixtures)
                .and_then(|pins| check_on_skin(fixtures, &pins, &self.scene.surface))
                .map_err(|e| err::<GroundTruthError>(&e))?;
        }
        self.scene
            .check_outside(&fixture_set.configurations, "T_cam_sensor")
            .map_err(GroundTruthError::new_err)?;
        Ok(fixture_set)
    }

    /// What `write` renders each frame's image.png from: `photometric` (checked against this
    /// renderer), the design's optics with `images` alone, or nothing.
    fn image_source(
        &self,
        py: Python<'_>,
        photometric: Option<&PhotometricModel>,
        images: bool,
    ) -> PyResult<Option<ImageSource>> {
        if let Some(m) = photometric {
            self.check_camera_of(py, m)?;
        }
        Ok(match photometric {
            Some(m) => Some(ImageSource::Photometric(
                Box::new((*m.model).clone()),
                m.source.clone(),
                m.sha256.clone(),
            )),
            None if images => Some(ImageSource::Physical(Box::new(
                crate::work(py, || self.physical_imaging().cloned())?
                    .map_err(GroundTruthError::new_err)?,
            ))),
            None => None,
        })
    }

    /// Renders every frame of `fixture_set` into `out` (claimed by `claim`) with its
    /// manifest.json, as `fabkit groundtruth` does; `progress` after each frame. Returns the
    /// files written, manifest.json last.
    #[allow(clippy::too_many_arguments)]
    fn write_dataset(
        &self,
        py: Python<'_>,
        out: &std::path::Path,
        claim: fabkit_export::OutputClaim,
        fixture_set: &Fixtures,
        format: DataFormat,
        imaging: Option<&ImageSource>,
        command_line: &[String],
        progress: &Option<Py<PyAny>>,
    ) -> PyResult<Vec<String>> {
        let rays = &self.scene.rays;
        let name = &self.design.name;
        let frames = fixture_set.configurations.len() as u64 + 1;
        let provenance = dataset::provenance(name, &self.sha256);
        let written = crate::work(py, || -> Result<Vec<String>, String> {
            let staged = fabkit_export::StagedDir::new(out, claim).map_err(|e| e.to_string())?;
            let files = dataset::write(
                &staged,
                &FrameInputs {
                    rays,
                    reference_hits: &self.reference_hits,
                    base_z_mm: self.scene.surface.base_z_mm(),
                    fixtures: fixture_set,
                    format,
                    imaging,
                    provenance: &provenance,
                },
                &ManifestInputs {
                    fabkit_version: env!("CARGO_PKG_VERSION"),
                    command_line,
                    design_name: name,
                    design_source: &self.source,
                    design_sha256: &self.sha256,
                    flat_skin: self.design.body.flat_outline().is_some(),
                    camera: &self.camera,
                    camera_file: &self.camera_file,
                    camera_sha256: self.camera_sha256.as_deref(),
                    extrinsics_file: &self.extrinsics_file,
                    extrinsics_sha256: self.extrinsics_sha256.as_deref(),
                    t_cam_sensor: &self.pose,
                    camera_centre_mm: rays.origin_mm,
                    fixtures: fixture_set,
                    pixels_on_surface: self.reference_hits.valid_count(),
                    optical_path: self.optical_path.as_ref(),
                    imaging,
                },
                &|k| report_progress(progress, k as usize, frames as usize, "groundtruth"),
            )
            .map_err(|e| e.to_string())?;
            staged.commit().map_err(|e| e.to_string())?;
            let mut names: Vec<String> = files.into_iter().map(|(f, ..)| f).collect();
            names.push("manifest.json".into());
            Ok(names)
        })?
        .map_err(GroundTruthError::new_err)?;
        Ok(written)
    }
}

/// `write`'s `format`, checked with the options that go with it: `photometric` only with
/// `images`, `max_output_bytes` within its range.
fn checked_write_options(
    format: &str,
    images: bool,
    photometric: Option<&PhotometricModel>,
    max_output_bytes: u64,
) -> PyResult<DataFormat> {
    let format = match format {
        "npy" => DataFormat::Npy,
        "npz" => DataFormat::Npz,
        "png" => DataFormat::Png,
        other => {
            return Err(PyValueError::new_err(format!(
                "format = '{other}': must be 'npy', 'npz' or 'png'"
            )))
        }
    };
    if photometric.is_some() && !images {
        return Err(PyValueError::new_err(
            "photometric: given without images=True (the model renders each frame's image.png)",
        ));
    }
    if !(1..=dataset::MAX_OUTPUT_BYTES_LIMIT).contains(&max_output_bytes) {
        return Err(PyValueError::new_err(format!(
            "max_output_bytes = {max_output_bytes}: must be from 1 to {} (10^15)",
            dataset::MAX_OUTPUT_BYTES_LIMIT
        )));
    }
    Ok(format)
}

/// Refuses, before rendering, a dataset bounded over `max_output_bytes` (without `yes`) or
/// over the free space of `out`'s file system.
fn check_output_bound(
    out: &std::path::Path,
    rays: &fabkit_calibration::groundtruth::rays::PixelRays,
    fixture_set: &Fixtures,
    format: DataFormat,
    imaging: Option<&ImageSource>,
    max_output_bytes: u64,
    yes: bool,
) -> PyResult<()> {
    let n_cfg = fixture_set.configurations.len();
    let (n_files, bound) = dataset::output_bound(
        rays.width as u64,
        rays.height as u64,
        n_cfg as u64,
        fixture_set.patterns.len() as u64,
        format,
        imaging.map(ImageSource::bits),
    );
    if bound > max_output_bytes && !yes {
        return Err(GroundTruthError::new_err(format!(
            "{}: the ground truth would take up to {bound} bytes ({n_files} files), over max_output_bytes = {max_output_bytes}: refused before rendering (give yes=True to write it, or format='npz' or 'png')",
            out.display()
        )));
    }
    if let Some(free) = fabkit_export::free_bytes(out) {
        if bound > free {
            return Err(GroundTruthError::new_err(format!(
                "{}: the ground truth may take up to {bound} bytes ({n_files} files), more than the {free} bytes free on its file system: refused before rendering",
                out.display()
            )));
        }
    }
    Ok(())
}

/// The optical path an extrinsics.json holds (its layers, and the planes as the manifest lists
/// them), when the pose was solved through one.
type OpticalPathOf = Option<(
    fabkit_calibration::refraction::OpticalLayers,
    serde_json::Value,
)>;

/// T_cam_sensor from a (4, 4) array (`<array>`, no file) or the path of an extrinsics.json of
/// `fabkit calibrate extrinsics` (with its sha256 and the optical path it was solved through).
fn pose_of(
    py: Python<'_>,
    t: &Bound<'_, PyAny>,
) -> PyResult<(
    nalgebra::Isometry3<f64>,
    String,
    Option<String>,
    OpticalPathOf,
)> {
    if let Ok(path) = t.extract::<std::path::PathBuf>() {
        let (pose, sha) =
            crate::work(py, || read_extrinsics(&path))?.map_err(|e| err::<GroundTruthError>(&e))?;
        let optical = crate::work(py, || {
            fabkit_calibration::groundtruth::inputs::read_optical_path(&path)
        })?
        .map_err(|e| err::<GroundTruthError>(&e))?;
        return Ok((pose, path.display().to_string(), Some(sha), optical));
    }
    let t = crate::calibration::float64_array(t, "T_cam_sensor")?;
    if t.shape() != [4, 4] {
        return Err(PyValueError::new_err(format!(
            "T_cam_sensor: shape {} where (4, 4) is needed",
            crate::calibration::shape_text(t.shape())
        )));
    }
    let t = t.readonly();
    let t = t.as_array();
    let m: [[f64; 4]; 4] = std::array::from_fn(|r| std::array::from_fn(|c| t[[r, c]]));
    let pose = isometry_of(&m).map_err(|(field, value, rule)| {
        GroundTruthError::new_err(format!("{field} = {value}: {rule}"))
    })?;
    Ok((pose, "<array>".into(), None, None))
}

#[pymethods]
impl DepthRenderer {
    #[new]
    #[pyo3(signature = (design, camera, T_cam_sensor, *, max_pixels=DEFAULT_MAX_PIXELS))]
    #[allow(non_snake_case)]
    fn new(
        py: Python<'_>,
        design: &Design,
        camera: &Bound<'_, PyAny>,
        T_cam_sensor: &Bound<'_, PyAny>,
        max_pixels: u64,
    ) -> PyResult<DepthRenderer> {
        let camera = Camera::of(camera)?;
        let (pose, extrinsics_file, extrinsics_sha256, optical) = pose_of(py, T_cam_sensor)?;
        if !(1..=MAX_PIXELS_LIMIT).contains(&max_pixels) {
            return Err(PyValueError::new_err(format!(
                "max_pixels = {max_pixels}: must be from 1 to {MAX_PIXELS_LIMIT} (2048 x 2048, what the render's memory budget of {} GiB holds)",
                MEMORY_BUDGET_BYTES >> 30
            )));
        }
        let i = camera.model.intrinsics();
        let pixels = u64::from(i.image_width_px) * u64::from(i.image_height_px);
        if pixels > max_pixels {
            return Err(GroundTruthError::new_err(format!(
                "{}: the camera image is {} x {} = {pixels} pixels, over the ground-truth limit of {max_pixels} pixels (every per-pixel array of a frame is sized by it, refused before any is allocated; {})",
                camera.source,
                i.image_width_px,
                i.image_height_px,
                if max_pixels < MAX_PIXELS_LIMIT {
                    "raise max_pixels"
                } else {
                    "max_pixels is at its largest, what the render's memory budget holds"
                }
            )));
        }
        let camera_sha256 = std::path::Path::new(&camera.source)
            .is_file()
            .then(|| read_with_hash(std::path::Path::new(&camera.source)).ok())
            .flatten()
            .map(|(_, sha)| sha);
        let (named, source, sha256, preset) = (
            design.as_named(),
            design.source.clone(),
            design.sha256.clone(),
            design.preset.clone(),
        );
        let design = &design.design;
        let model = &camera.model;
        crate::work(py, || {
            // the rays bend where the pose was solved through an optical path, as `fabkit
            // groundtruth` bends them
            let scene = Scene::through(
                design,
                model,
                &pose,
                "T_cam_sensor",
                optical.as_ref().map(|(l, _)| l),
            )?;
            let hits = reference_hits(&scene.rays, &scene.surface);
            let needed = min_skin_pixels(pixels);
            if (hits.valid_count() as u64) < needed {
                return Err(format!(
                    "the camera sees the skin in {} of its {pixels} pixels, fewer than the {needed} ({}% of the image) ground truth needs (hint: check fx, fy, cx, cy = {}, {}, {}, {} px against the image size, the distortion model, and that T_cam_sensor points the camera at the skin)",
                    hits.valid_count(),
                    MIN_SKIN_FRACTION * 100.0,
                    fabkit_calibration::shown_f64(i.fx_px),
                    fabkit_calibration::shown_f64(i.fy_px),
                    fabkit_calibration::shown_f64(i.cx_px),
                    fabkit_calibration::shown_f64(i.cy_px),
                ));
            }
            let reference = DepthFrame::new(&scene.rays, &hits);
            Ok(DepthRenderer {
                scene,
                camera: *model,
                camera_file: camera.source.clone(),
                camera_sha256,
                pose,
                extrinsics_file,
                extrinsics_sha256,
                named,
                source,
                sha256,
                preset,
                reference_hits: hits,
                reference,
                design: design.clone(),
                principal_px: [i.cx_px, i.cy_px],
                imaging: std::sync::OnceLock::new(),
                optical_path: optical.map(|(_, v)| v),
            })
        })?
        .map_err(|e: String| GroundTruthError::new_err(e))
    }

    /// (height, width) of every map, px.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        (self.scene.rays.height, self.scene.rays.width)
    }

    /// The camera centre in the sensor frame, mm.
    #[getter]
    fn camera_centre_mm(&self) -> [f64; 3] {
        self.scene.rays.origin_mm
    }

    /// The reference (undeformed) skin: dict of `range_mm`, `zdepth_mm` (H, W) float32 mm and
    /// `normals` (H, W, 3) float32, as the ground truth's `reference/` folder.
    fn reference<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        frame_dict(py, &self.reference)
    }

    /// The skin indented by the protrusions of `protrusions` (a ProtrusionSet): as `reference`
    /// plus `delta_range_mm`, `delta_zdepth_mm` (indented minus reference, mm: negative where
    /// the skin is pushed towards the camera) and `contact` (H, W) bool (the surface seen is a
    /// protrusion), as a configuration folder of the ground truth. Raises GroundTruthError
    /// when the camera centre is inside a protrusion.
    fn indented<'py>(
        &self,
        py: Python<'py>,
        protrusions: &ProtrusionSet,
    ) -> PyResult<Bound<'py, PyDict>> {
        let cfg = &protrusions.cfg;
        self.scene
            .check_outside(std::slice::from_ref(cfg.as_ref()), "T_cam_sensor")
            .map_err(GroundTruthError::new_err)?;
        let frame = crate::work(py, || {
            let hits = indented_hits(
                &self.scene.rays,
                &self.reference_hits,
                &cfg.primitives,
                self.scene.surface.base_z_mm(),
            );
            DepthFrame::new(&self.scene.rays, &hits)
        })?;
        let (h, w) = (frame.height, frame.width);
        let d = frame_dict(py, &frame)?;
        let (dr, dz) = frame.delta(&self.reference);
        d.set_item("delta_range_mm", f32_map(&dr, h, w).into_pyarray(py))?;
        d.set_item("delta_zdepth_mm", f32_map(&dz, h, w).into_pyarray(py))?;
        d.set_item(
            "contact",
            bool_map(&frame.contact_mask(&self.reference), h, w).into_pyarray(py),
        )?;
        Ok(d)
    }

    /// Every configuration of `protrusions` (a list of ProtrusionSet) rendered with
    /// `indented`, in order; `progress(done, total, message)` after each.
    #[pyo3(signature = (protrusions, *, progress=None))]
    fn indented_all<'py>(
        &self,
        py: Python<'py>,
        protrusions: Vec<PyRef<'py, ProtrusionSet>>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let n = protrusions.len();
        let mut out = Vec::with_capacity(n);
        for (k, p) in protrusions.iter().enumerate() {
            out.push(self.indented(py, p)?);
            report_progress(&progress, k + 1, n, &p.cfg.name);
        }
        Ok(out)
    }

    /// The tactile image the camera sees, (H, W, 3) RGB, uint8 or uint16 by the design's
    /// `optics.camera.bit_depth`, as `fabkit groundtruth --images` writes `image.png`: the
    /// reference skin, or the skin indented by `protrusions` (a ProtrusionSet) with its shadows,
    /// under the design's lights (its `optics` section, or the lights of its housing, casing,
    /// shaft body or fingertip base), the markers moved with the skin, the camera's gain,
    /// vignetting and seeded noise. `frame` picks the frame's own noise: the CLI gives the
    /// reference 0 and configuration i of the fixtures folder i + 1. The exposure, when
    /// `optics.camera.gain` is not given, is set once on the reference and held. Raises
    /// GroundTruthError naming the parameter path of bad optics, or when the camera centre is
    /// inside a protrusion. With `photometric` (a PhotometricModel, [`read_photometric`]) the
    /// image is the sensor's own appearance from the fitted model instead, as `fabkit
    /// groundtruth --images --photometric DIR` writes it: its mean image, no noise (`frame` is
    /// not used), at the bit depth of the captures it was fitted to; a model of another camera
    /// size raises GroundTruthError.
    #[pyo3(signature = (protrusions=None, *, frame=0, photometric=None))]
    fn image<'py>(
        &self,
        py: Python<'py>,
        protrusions: Option<&ProtrusionSet>,
        frame: u64,
        photometric: Option<&PhotometricModel>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if let Some(p) = protrusions {
            self.scene
                .check_outside(std::slice::from_ref(p.cfg.as_ref()), "T_cam_sensor")
                .map_err(GroundTruthError::new_err)?;
        }
        let rays = &self.scene.rays;
        if let Some(m) = photometric {
            self.check_camera_of(py, m)?;
            let m = &m.model;
            let img = crate::work(py, || match protrusions {
                None => m.image(rays, &self.reference_hits, &self.reference_hits, None),
                Some(p) => {
                    let hits = indented_hits(
                        rays,
                        &self.reference_hits,
                        &p.cfg.primitives,
                        self.scene.surface.base_z_mm(),
                    );
                    m.image(rays, &self.reference_hits, &hits, Some(&p.cfg.primitives))
                }
            })?;
            let bits = if m.full_scale > 255.0 { 16 } else { 8 };
            return Ok(rgb_array(py, img, rays.height, rays.width, bits));
        }
        let img = crate::work(py, || -> Result<Vec<[u16; 3]>, String> {
            let imaging = self.physical_imaging()?;
            Ok(match protrusions {
                None => imaging.image(
                    rays,
                    &self.reference_hits,
                    &self.reference_hits,
                    None,
                    frame,
                ),
                Some(p) => {
                    let hits = indented_hits(
                        rays,
                        &self.reference_hits,
                        &p.cfg.primitives,
                        self.scene.surface.base_z_mm(),
                    );
                    imaging.image(
                        rays,
                        &self.reference_hits,
                        &hits,
                        Some(&p.cfg.primitives),
                        frame,
                    )
                }
            })
        })?
        .map_err(GroundTruthError::new_err)?;
        let (h, w) = (rays.height, rays.width);
        let bits = match self.imaging.get() {
            Some(Ok(im)) => im.optics.camera.bit_depth,
            _ => 8,
        };
        Ok(rgb_array(py, img, h, w, bits))
    }

    /// Writes the ground-truth dataset of the fixtures in `fixtures` (a `fabkit fixtures`
    /// output folder built from this design) to the folder `out`, exactly as `fabkit
    /// groundtruth` writes it: the same files, names, encodings and manifest.json, byte for
    /// byte for the same inputs and command line (`command_line`, default `sys.argv`, is
    /// recorded in the manifest). `pin_captures` renders the pin dome's captures instead of the
    /// protrusion patterns; `format` is `npy`, `npz` or `png`; `images` adds each frame's
    /// `image.png` from the design's optics, or from `photometric` (a PhotometricModel) when
    /// given. `out` is replaced as a whole only when it holds earlier ground truth of the same
    /// inputs (or of any inputs with `force`); anything else in it is refused. The output is
    /// bounded before anything is rendered: over `max_output_bytes` (bytes, default 1 GB) it is
    /// refused unless `yes`, and it is refused when larger than the free space. Files appear
    /// only when all are written. `progress(done, total, message)` after each frame. Returns
    /// the files written (relative paths, sorted; manifest.json last). Raises
    /// GroundTruthError naming the file and the rule, ValueError for a bad argument.
    #[pyo3(signature = (out, fixtures, *, pin_captures=false, format="npy", images=false,
                        photometric=None, force=false, max_output_bytes=DEFAULT_MAX_OUTPUT_BYTES,
                        yes=false, command_line=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn write(
        &self,
        py: Python<'_>,
        out: std::path::PathBuf,
        fixtures: std::path::PathBuf,
        pin_captures: bool,
        format: &str,
        images: bool,
        photometric: Option<&PhotometricModel>,
        force: bool,
        max_output_bytes: u64,
        yes: bool,
        command_line: Option<Vec<String>>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Vec<String>> {
        let format = checked_write_options(format, images, photometric, max_output_bytes)?;
        let command_line = match command_line {
            Some(c) => c,
            None => py.import("sys")?.getattr("argv")?.extract()?,
        };
        let claim = dataset::claim(
            &dataset::ClaimInputs {
                design: &self.named,
                preset: self.preset.as_deref(),
                camera_file: std::path::Path::new(&self.camera_file),
                extrinsics_file: std::path::Path::new(&self.extrinsics_file),
                fixtures_dir: &fixtures,
                pin_captures,
            },
            force,
        );
        fabkit_export::check_out_dir(&out, &claim).map_err(|e| err::<GroundTruthError>(&e))?;
        let fixture_set = self.read_fixture_set(py, &fixtures, pin_captures)?;
        let imaging = self.image_source(py, photometric, images)?;
        check_output_bound(
            &out,
            &self.scene.rays,
            &fixture_set,
            format,
            imaging.as_ref(),
            max_output_bytes,
            yes,
        )?;
        self.write_dataset(
            py,
            &out,
            claim,
            &fixture_set,
            format,
            imaging.as_ref(),
            &command_line,
            &progress,
        )
    }

    /// The half masks (left, right), (H, W) bool: pixels whose ray meets the reference
    /// surface at sensor-frame x < 0 (left) or x >= 0 (right), as left_mask.png and
    /// right_mask.png.
    fn masks<'py>(&self, py: Python<'py>) -> PyResult<(BoolMap<'py>, BoolMap<'py>)> {
        let (h, w) = (self.scene.rays.height, self.scene.rays.width);
        let (l, r) = half_masks(&self.scene.rays, &self.reference_hits);
        Ok((
            bool_map(&l, h, w).into_pyarray(py),
            bool_map(&r, h, w).into_pyarray(py),
        ))
    }
}

/// `fabkit.GROUNDTRUTH_FILES`: the names of a ground-truth dataset's files and the 16-bit
/// PNG encodings, as the writer (`fabkit groundtruth`, `DepthRenderer.write`) uses them.
fn groundtruth_files(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    use fabkit_calibration::groundtruth::dataset::{files, DELTA_PNG, DEPTH_PNG};
    let d = PyDict::new(py);
    for (k, v) in [
        ("manifest", files::MANIFEST),
        ("pairs", files::PAIRS),
        ("left_mask", files::LEFT_MASK),
        ("right_mask", files::RIGHT_MASK),
        ("reference_dir", files::REFERENCE_DIR),
        ("normals", files::NORMALS),
        ("npy_suffix", files::NPY_SUFFIX),
        ("png16_suffix", files::PNG16_SUFFIX),
        ("preview_suffix", files::PREVIEW_SUFFIX),
        ("arrays_npz", files::ARRAYS_NPZ),
        ("points", files::POINTS),
        ("contact_mask", files::CONTACT_MASK),
        ("image", files::IMAGE),
        (
            "press_json",
            fabkit_calibration::groundtruth::press::PRESS_JSON,
        ),
        (
            "press_dir",
            fabkit_calibration::groundtruth::press::PRESS_DIR,
        ),
    ] {
        d.set_item(k, v)?;
    }
    d.set_item("pairs_header", files::PAIRS_HEADER.to_vec())?;
    d.set_item("maps", files::MAPS.to_vec())?;
    d.set_item("delta_maps", files::DELTA_MAPS.to_vec())?;
    for (k, e) in [("png16_depth", DEPTH_PNG), ("png16_delta", DELTA_PNG)] {
        let enc = PyDict::new(py);
        enc.set_item("scale_mm_per_count", e.scale)?;
        enc.set_item("offset_counts", e.offset_counts)?;
        d.set_item(k, enc)?;
    }
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("GROUNDTRUTH_FILES", groundtruth_files(m.py())?)?;
    m.add_class::<ProtrusionSet>()?;
    m.add_class::<DepthRenderer>()?;
    m.add_function(wrap_pyfunction!(read_protrusions, m)?)?;
    m.add_class::<PhotometricModel>()?;
    m.add_function(wrap_pyfunction!(read_pin_captures, m)?)?;
    m.add_function(wrap_pyfunction!(read_photometric, m)?)?;
    Ok(())
}
