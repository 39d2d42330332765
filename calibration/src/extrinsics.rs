//! `fabkit calibrate extrinsics` as a library call: read the camera file, the point table and the
//! observations (or find them in capture images, [`crate::capture_images`]), solve T_cam_sensor (SQPnP, then Levenberg-Marquardt on the reprojection error,
//! inside RANSAC), and render the output files `extrinsics.json`, `extrinsics.yaml` and, given a
//! capture image, `overlay.png`; from images also `observations.csv` and `overlays/*.png` (the caller writes them: `fabkit calibrate extrinsics` stages them
//! in one output folder, moved into place whole).
//!
//! Source: R-Tac0 paper, Sec. IV-A, Eq. (1) and Fig. 5 (pins inserted through a dome at known
//! coordinates, their pixels recorded, the pose solved by PnP).

use std::path::{Path, PathBuf};

use crate::camera::CameraModel;
use crate::camera_file::{read_camera_file_as, CameraFileError, DistortionModelHint};
use crate::capture_images::{observe_images, CaptureImages, ImageError, ImageObservations};
use crate::overlay::{read_png_rgb8_sized, render_overlay, OverlayError};
use crate::pnp::{solve_pnp_through, PnpError, PnpOptions, PnpSolution, RansacOptions};
use crate::refine::{
    refine_intrinsics_keeping, solution_at, RefineError, RefineParameters, Refinement,
    RefinementReport,
};
use crate::refraction::{refine_plane, Imaging, OpticalLayers, PlanePrior};
use crate::report::{CaptureReport, ExtrinsicsReport, PlaneFitReport, Provenance};
use crate::tables::{
    check_inside_image, pair, read_capture_plan, read_captures, read_observations,
    read_point_table, CapturePlan, Observations, Pairs, PointTable, PointsFrom, TableError,
};
use nalgebra::{Vector2, Vector3};

/// Inputs of one extrinsics calibration.
#[derive(Debug, Clone)]
pub struct ExtrinsicsJob {
    /// Camera file (OpenCV FileStorage YAML or XML, ROS camera_info YAML or fabkit JSON).
    pub camera: PathBuf,
    /// Distortion model of a camera file that names none ([`DistortionModelHint`]); `None`:
    /// inferred from the coefficient count.
    pub camera_model: Option<DistortionModelHint>,
    /// Point table (fixtures table or `id,x_mm,y_mm,z_mm`), sensor frame, mm.
    pub points: PathBuf,
    pub points_from: PointsFrom,
    /// Observation files, or capture images to find them in.
    pub observations: Observed,
    /// Capture plan (`capture,id,ring`) that the observation files (or capture images) follow,
    /// one per capture in capture order; each file's ids are checked against its capture.
    pub capture_plan: Option<PathBuf>,
    /// Capture image for the overlay.
    pub image: Option<PathBuf>,
    /// `None`: no outlier rejection.
    pub ransac: Option<RansacOptions>,
    /// Refine the intrinsics jointly with the pose ([`crate::refine`]) over the inliers of the
    /// pose solve, and write the refined camera file in the form read; `None`: the camera
    /// file's intrinsics are used as they are.
    pub refine_intrinsics: Option<RefineParameters>,
    /// Refine the filling gel's free surface of `optical_path` (its height and the gel's
    /// index, under the priors [`crate::refraction::GEL_SURFACE_HEIGHT_SD_MM`] and
    /// [`crate::refraction::SILICONE_INDEX_SD`]) with the pose over the inliers, before any
    /// intrinsics refinement, which then sees the refined surface.
    pub refine_optical_path: bool,
    /// The optical path between the lens and the pins (a design's
    /// `fabkit_designs::optics::optical_path`): rays bend at each plane and curved face
    /// ([`crate::refraction`]);
    /// `None`: straight rays from the lens.
    pub optical_path: Option<fabkit_designs::optics::OpticalPath>,
    /// Where `optical_path` comes from, in words (`--design rtac0`, or the point table's
    /// design); recorded in the report.
    pub optical_path_from: Option<String>,
    /// Recorded in the report's provenance.
    pub command_line: String,
}

/// Where the pixels of the pins come from.
#[derive(Debug, Clone)]
pub enum Observed {
    /// Observation files `id,u_px,v_px`.
    Files(Vec<PathBuf>),
    /// Capture images and the reference image ([`crate::capture_images`]).
    Images(CaptureImages),
}

/// Why an extrinsics calibration failed.
#[derive(Debug, thiserror::Error)]
pub enum ExtrinsicsError {
    #[error(transparent)]
    Camera(#[from] CameraFileError),
    #[error(transparent)]
    Table(#[from] TableError),
    #[error("{context}: {source}")]
    Pnp {
        context: String,
        #[source]
        source: PnpError,
    },
    #[error(transparent)]
    Overlay(#[from] OverlayError),
    #[error(transparent)]
    Image(#[from] ImageError),
    #[error(transparent)]
    Refine(#[from] RefineError),
    #[error("cannot serialise the report as YAML: {0}")]
    Yaml(String),
    #[error("the design's optical path: {0}")]
    OpticalPath(String),
}

/// The result of one extrinsics calibration: the report and the files of its output folder.
#[derive(Debug, Clone)]
pub struct ExtrinsicsOutput {
    pub report: ExtrinsicsReport,
    /// (file name, bytes), in this order: `extrinsics.json`, `extrinsics.yaml` (the pose as
    /// OpenCV matrices), `transform.yaml` (the pose as a ROS `TransformStamped`), given a capture
    /// image `overlay.png`, `residuals.png` (a histogram of the reprojection errors), with
    /// `--refine-intrinsics` the refined camera file, and from capture images
    /// `observations.csv`, its sidecar `observations.json` (what the columns mean) and
    /// `overlays/<capture>.png`.
    pub files: Vec<(String, Vec<u8>)>,
    /// From capture images: what was found.
    pub found: Option<FoundInImages>,
}

/// What the detector found in the capture images.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FoundInImages {
    pub captures: usize,
    /// Captures left out (reported in the warnings with why).
    pub captures_left_out: usize,
    /// Spots found but taken for no pin (a speck, an edge), in the captures kept.
    pub spots_discarded: usize,
    /// Planned pins without a spot in the captures kept.
    pub pins_missing: usize,
    /// Rows of `observations.csv` (a pin in several captures once per capture).
    pub detections: usize,
}

/// Runs the calibration; returns the report and the output files. Reads only the job's input
/// files and writes nothing.
///
/// # Errors
/// [`ExtrinsicsError`]: unreadable or invalid inputs (file:line and field; every bad row of a
/// table), observations outside the camera file's image (every such row), unmatched ids, fewer
/// than 4 usable points, pixels outside the lens's field, degenerate layouts, points behind the
/// camera at the solved pose, too few RANSAC inliers, a capture image of the wrong size; from
/// images, also the errors of [`observe_images`] (an unreadable image, file names without ids,
/// a plan of another length).
pub fn calibrate_extrinsics(job: &ExtrinsicsJob) -> Result<ExtrinsicsOutput, ExtrinsicsError> {
    let camera = read_camera_file_as(&job.camera, job.camera_model)?;
    let layers = job
        .optical_path
        .as_ref()
        .map(OpticalLayers::from_optical_path)
        .transpose()
        .map_err(|e| ExtrinsicsError::OpticalPath(e.to_string()))?;

    let table = read_point_table(&job.points, job.points_from)?;
    let plan = job
        .capture_plan
        .as_deref()
        .map(read_capture_plan)
        .transpose()?;
    let (obs_paths, from_images) =
        observation_sources(job, &camera, layers.as_ref(), &table, plan.as_ref())?;
    let (obs, unobserved_ids) = match (&from_images, &plan) {
        (Some(found), _) => (found.observations.clone(), found.unobserved_ids.clone()),
        (None, Some(plan)) => read_captures(&obs_paths, plan)?,
        (None, None) => (read_observations(&obs_paths)?, Vec::new()),
    };
    let i = camera.intrinsics();
    check_inside_image(
        &obs,
        i.image_width_px,
        i.image_height_px,
        &job.camera.display().to_string(),
    )?;
    let pairs = pair(&table, &obs)?;
    let opts = PnpOptions {
        ransac: job.ransac,
        ..Default::default()
    };
    let sol = solve_pnp_through(
        &Imaging::new(&camera, layers.as_ref()),
        &pairs.points_mm,
        &pairs.pixels_px,
        &opts,
    )
    .map_err(|source| {
        let mut e = pnp_error(source, &obs, &table, &obs_paths);
        // found in images: why captures were left out or pins missed says why so few pairs
        if let (ExtrinsicsError::Pnp { context, .. }, Some(found)) = (&mut e, &from_images) {
            for n in &found.notes {
                context.push_str("\n  ");
                context.push_str(n);
            }
        }
        e
    })?;
    let mut layers = layers;
    // pins left out: the models that might explain them compared first (crate::models)
    let mut compared = if job.refine_optical_path {
        None
    } else {
        crate::models::compare_if_rejected(
            &camera,
            layers.as_ref(),
            job.optical_path.as_ref(),
            &pairs.points_mm,
            &pairs.pixels_px,
            &sol,
        )
    };
    let (sol, path_fit) = fit_optical_path(job, &camera, &mut layers, &pairs, sol, &mut compared)?;
    let (camera, sol, refinement) = match &job.refine_intrinsics {
        None => (camera, sol, None),
        Some(which) => {
            let r = refine_camera(&camera, layers.as_ref(), &pairs, sol, &opts, which)?;
            (r.0, r.1, Some(r.2))
        }
    };
    let provenance = provenance(job, &obs_paths, unobserved_ids);
    let mut report = ExtrinsicsReport::new(
        &Imaging::new(&camera, layers.as_ref()),
        &pairs,
        &sol,
        provenance,
    );
    report.optical_path = job.optical_path.clone();
    report.optical_path_from = job.optical_path.as_ref().and(job.optical_path_from.clone());
    report.optical_path_fit = path_fit;
    if let Some(c) = compared {
        report.warnings.extend(c.warning);
        report.model_comparison = Some(c.report);
    }
    if let Some(found) = &from_images {
        report.warnings.extend(found.notes.iter().cloned());
        report.captures = found.outcomes.iter().map(CaptureReport::from).collect();
    }
    let refined_file = refinement
        .as_ref()
        .map(|r| refined_camera(job, r, &mut report));
    let files = output_files(
        job,
        &Imaging::new(&camera, layers.as_ref()),
        &report,
        refined_file,
        from_images.as_ref(),
        &table,
        &sol,
    )?;
    let found = from_images
        .as_ref()
        .map(|f| found_in_images(f, obs_paths.len()));
    Ok(ExtrinsicsOutput {
        report,
        files,
        found,
    })
}

/// The files the observations come from (observation files, or the capture images), and from
/// capture images what [`observe_images`] found in them.
fn observation_sources<'j>(
    job: &'j ExtrinsicsJob,
    camera: &CameraModel,
    layers: Option<&OpticalLayers>,
    table: &PointTable,
    plan: Option<&CapturePlan>,
) -> Result<(Vec<&'j Path>, Option<ImageObservations>), ExtrinsicsError> {
    Ok(match &job.observations {
        Observed::Files(f) => (f.iter().map(PathBuf::as_path).collect(), None),
        Observed::Images(i) => {
            let camera_file = job.camera.display().to_string();
            let found =
                observe_images(&Imaging::new(camera, layers), &camera_file, table, plan, i)?;
            (
                i.captures.iter().map(PathBuf::as_path).collect(),
                Some(found),
            )
        }
    })
}

/// The pose solve's error with its context: the observation a point error is about, else the
/// point table and the observation files.
fn pnp_error(
    source: PnpError,
    obs: &Observations,
    table: &PointTable,
    obs_paths: &[&Path],
) -> ExtrinsicsError {
    let at = |index: usize| {
        let (id, _, origin) = &obs.rows[index];
        format!("id {id} ({origin})")
    };
    let context = match &source {
        PnpError::NonFinite { index, .. }
        | PnpError::Unprojectable { index, .. }
        | PnpError::BehindCamera { index } => at(*index),
        _ => format!(
            "{} with {}",
            table.file,
            obs_paths
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    ExtrinsicsError::Pnp { context, source }
}

/// The pairs the solution `s` keeps (its inliers), for the refinements over them: points
/// (sensor frame, mm) and pixels (px).
fn inliers_of(pairs: &Pairs, s: &PnpSolution) -> (Vec<Vector3<f64>>, Vec<Vector2<f64>>) {
    pairs
        .points_mm
        .iter()
        .zip(&pairs.pixels_px)
        .zip(&s.inliers)
        .filter(|(_, &inlier)| inlier)
        .map(|((p, q), _)| (*p, *q))
        .unzip()
}

/// The optical path's part of the solve: the gel surface's fit the model comparison took
/// (`compared`), or with `--refine-optical-path` the filling gel's free surface refined with
/// the pose over the inliers of `sol`; `layers` then become the fitted ones. Returns the
/// solution at the fitted path and its report (`sol` and `None` when neither applies).
///
/// # Errors
/// [`ExtrinsicsError::OpticalPath`]: `--refine-optical-path` without an optical path or a
/// filling gel's plane in it, or a surface the pins do not determine.
fn fit_optical_path(
    job: &ExtrinsicsJob,
    camera: &CameraModel,
    layers: &mut Option<OpticalLayers>,
    pairs: &Pairs,
    sol: PnpSolution,
    compared: &mut Option<crate::models::Compared>,
) -> Result<(PnpSolution, Option<PlaneFitReport>), ExtrinsicsError> {
    // the design's filling gel surface, and its prior, when the optical path has one
    let gel = job.optical_path.as_ref().and_then(crate::models::gel_prior);
    if let Some((fit, every)) = compared.as_mut().and_then(|c| c.taken.take()) {
        let what = gel.as_ref().map_or("", |g| g.1.as_str());
        let report = PlaneFitReport::new(&fit, what);
        *layers = Some(fit.layers);
        return Ok((every, Some(report)));
    }
    if !job.refine_optical_path {
        return Ok((sol, None));
    }
    let (path, l) = match (&job.optical_path, &*layers) {
        (Some(p), Some(l)) => (p, l),
        _ => {
            return Err(ExtrinsicsError::OpticalPath(
                "--refine-optical-path needs the design's optical path (--design)".into(),
            ))
        }
    };
    let Some(plane) = path
        .planes
        .iter()
        .position(|p| p.what.starts_with("housing.filling_gel"))
    else {
        return Err(ExtrinsicsError::OpticalPath(format!(
            "--refine-optical-path refines a filling gel's free surface; the design's planes are: {}",
            if path.planes.is_empty() {
                "none".to_string()
            } else {
                path.planes
                    .iter()
                    .map(|p| p.what.as_str())
                    .collect::<Vec<_>>()
                    .join("; ")
            }
        )));
    };
    let prior = PlanePrior {
        plane,
        height_sd_mm: crate::refraction::GEL_SURFACE_HEIGHT_SD_MM,
        index_sd: crate::refraction::SILICONE_INDEX_SD,
    };
    let (pts, px) = inliers_of(pairs, &sol);
    let fit = refine_plane(camera, l, prior, &pts, &px, &sol.t_cam_sensor).ok_or_else(|| {
        ExtrinsicsError::OpticalPath(
            "--refine-optical-path: the gel's surface and the pose are not determined by these pins (a point does not project, or the normal matrix is singular)".into(),
        )
    })?;
    let refined = solution_at(
        &Imaging::new(camera, Some(&fit.layers)),
        &pairs.points_mm,
        &pairs.pixels_px,
        &sol,
        fit.t_cam_sensor,
    );
    *layers = Some(fit.layers.clone());
    let report = PlaneFitReport::new(&fit, &path.planes[plane].what);
    Ok((refined, Some(report)))
}

/// `--refine-intrinsics`: the intrinsics refined over the inliers of `sol`, then the pose
/// solved again through the refined camera: pairs the camera file's model put out may come
/// back in; refined again (from the file's values) over the larger set, while it grows (at
/// most 4 rounds). Returns the refined camera, the solution at it and the refinement.
///
/// # Errors
/// [`ExtrinsicsError::Refine`] from the first refinement.
fn refine_camera(
    camera: &CameraModel,
    layers: Option<&OpticalLayers>,
    pairs: &Pairs,
    sol: PnpSolution,
    opts: &PnpOptions,
    which: &RefineParameters,
) -> Result<(CameraModel, PnpSolution, Refinement), ExtrinsicsError> {
    let count = |s: &crate::PnpSolution| s.inliers.iter().filter(|&&b| b).count();
    let (pts, px) = inliers_of(pairs, &sol);
    let l = layers;
    // every pin that projects at the camera file's intrinsics keeps projecting
    let all = &pairs.points_mm;
    let mut r = refine_intrinsics_keeping(camera, l, &pts, &px, &sol.t_cam_sensor, which, all)?;
    let mut kept = sol;
    for _ in 1..4 {
        let Ok(again) = solve_pnp_through(
            &Imaging::new(&r.camera, layers),
            &pairs.points_mm,
            &pairs.pixels_px,
            opts,
        ) else {
            break;
        };
        if count(&again) <= count(&kept) {
            break;
        }
        let (pts, px) = inliers_of(pairs, &again);
        match refine_intrinsics_keeping(camera, l, &pts, &px, &again.t_cam_sensor, which, all) {
            Ok(r2) => {
                r = r2;
                kept = again;
            }
            Err(_) => break,
        }
    }
    let sol = solution_at(
        &Imaging::new(&r.camera, layers),
        &pairs.points_mm,
        &pairs.pixels_px,
        &kept,
        r.t_cam_sensor,
    );
    Ok((r.camera, sol, r))
}

/// The report's provenance: this fabkit, the command line and the input files (`obs_paths`
/// the observation files or capture images), and the planned pins never observed.
fn provenance(job: &ExtrinsicsJob, obs_paths: &[&Path], unobserved_ids: Vec<String>) -> Provenance {
    let fixtures = crate::read_text(&job.points)
        .map(|t| t.contains("tip_x_mm"))
        .unwrap_or(false);
    Provenance {
        fabkit_version: env!("CARGO_PKG_VERSION").into(),
        command_line: job.command_line.clone(),
        camera_file: job.camera.display().to_string(),
        points_file: job.points.display().to_string(),
        points_from: match (fixtures, job.points_from) {
            (false, _) => "xyz".into(),
            (true, PointsFrom::Tip) => "tip".into(),
            (true, PointsFrom::Contact) => "contact".into(),
        },
        observation_files: obs_paths.iter().map(|p| p.display().to_string()).collect(),
        capture_plan: job.capture_plan.as_ref().map(|p| p.display().to_string()),
        unobserved_ids,
        reference_image: match &job.observations {
            Observed::Images(i) => Some(i.reference.display().to_string()),
            Observed::Files(_) => None,
        },
    }
}

/// The refined camera file (name, bytes) in the form the camera file was read, its
/// refinement set in `report`.
fn refined_camera(
    job: &ExtrinsicsJob,
    r: &Refinement,
    report: &mut ExtrinsicsReport,
) -> (String, Vec<u8>) {
    let text = crate::read_text(&job.camera).unwrap_or_default();
    let (name, format) = crate::refine::refined_camera_file(&text);
    report.set_refinement(RefinementReport::new(r, name));
    (
        name.to_string(),
        crate::write_camera(r.camera.intrinsics(), format).into_bytes(),
    )
}

/// The output folder's files ([`ExtrinsicsOutput::files`]) from the finished `report`, seen
/// through `imaging` (the refined camera and path) at the solution `sol`.
///
/// # Errors
/// [`ExtrinsicsError`]: the report's YAML, a capture image of the wrong size, an overlay
/// that does not encode.
fn output_files(
    job: &ExtrinsicsJob,
    imaging: &Imaging<'_>,
    report: &ExtrinsicsReport,
    refined_file: Option<(String, Vec<u8>)>,
    from_images: Option<&ImageObservations>,
    table: &PointTable,
    sol: &PnpSolution,
) -> Result<Vec<(String, Vec<u8>)>, ExtrinsicsError> {
    let json = report.to_json();
    let yaml = report.to_yaml().map_err(ExtrinsicsError::Yaml)?;
    let overlay = match &job.image {
        Some(p) => {
            let i = imaging.camera.intrinsics();
            let img = read_png_rgb8_sized(p, (i.image_width_px, i.image_height_px))?;
            Some(render_overlay(img, report)?)
        }
        None => None,
    };
    let mut files = vec![
        ("extrinsics.json".to_string(), json.into_bytes()),
        ("extrinsics.yaml".to_string(), yaml.into_bytes()),
        (
            "transform.yaml".to_string(),
            crate::report::transform_stamped_yaml(
                &report.t_cam_sensor,
                &report.provenance.fabkit_version,
            )
            .into_bytes(),
        ),
    ];
    if let Some(o) = overlay {
        files.push(("overlay.png".into(), o));
    }
    files.push((
        "residuals.png".into(),
        crate::overlay::render_residual_histogram(report)?,
    ));
    files.extend(refined_file);
    if let Some(found) = from_images {
        files.push(("observations.csv".into(), found.csv.clone().into_bytes()));
        let sidecar = serde_json::json!({
            "file": "observations.csv",
            "columns": ["capture", "id", "u_px", "v_px", "score"],
            "notes": crate::capture_images::OBSERVATIONS_NOTES,
        });
        files.push((
            "observations.json".into(),
            format!("{sidecar:#}\n").into_bytes(),
        ));
        files.extend(found.overlays(imaging, table, &sol.t_cam_sensor)?);
    }
    Ok(files)
}

/// What the detector found in `captures` capture images ([`FoundInImages`]).
fn found_in_images(f: &ImageObservations, captures: usize) -> FoundInImages {
    FoundInImages {
        captures,
        captures_left_out: f.outcomes.iter().filter(|o| o.left_out.is_some()).count(),
        spots_discarded: f.outcomes.iter().map(|o| o.discarded.len()).sum(),
        pins_missing: f.outcomes.iter().map(|o| o.missing.len()).sum(),
        detections: f.csv.lines().filter(|l| !l.starts_with('#')).count() - 1,
    }
}
