//! Ground truth of a real press of a known indenter (`fabkit groundtruth --press-image`): a
//! sphere of known radius pressed into a flat skin, found in one capture against its
//! reference through the calibrated camera ([`crate::press::fit_sphere_press`]), and rendered
//! as one frame of the ground-truth dataset (the depth maps, normals and contact mask of
//! [`super::dataset::frame_files`]) beside a copy of the capture.
//!
//! The sphere is placed where the fit puts it: its centre over (x, y) = `centre_mm` of the
//! skin's contact face (sensor frame, the face of the design's flat body), its lowest point
//! `depth_mm` below the face, towards the camera. Two surfaces are rendered. The indenter's
//! (`press/`, as for a fixture's protrusions): the skin minus the sphere, flat outside the
//! sphere's intersection with the face, of radius `sqrt(2 R d - d^2)` (its contact mask).
//! The skin's (`press/skin/`): the skin as the sphere deforms it
//! ([`super::press_skin::PressedSkin`]: an elastic layer bonded to its base at the fitted
//! depth): the sphere's shape where it touches (its contact mask) and the smooth sink round
//! it. The rendered image (`--images`) is the face the camera sees (under an opaque coat, its
//! inner face) as the sphere deforms it. On the real 9DTact ball press (1.715 mm of a 4 mm
//! ball on 2.8 mm of gel) the capture's darkening ends at 64 to 67 px from the centre (5.6
//! grey levels inside, 0.2 outside), where the geometric mask's edge is (63.6 to 67.2 px):
//! the bonded layer's elastic contact is as wide (press.json: elastic). The rays are the
//! camera's straight rays (a board press's camera takes the refraction of the flat layers up
//! in its distortion, which so holds for points on the face; the sphere's points below it are
//! seen along the same rays).
//!
//! Layout: `reference/` and `press/` as the frames of [`super::dataset`] (the reference
//! frame, the pressed one with its differences and contact mask; `press/skin/` the deformed
//! skin's maps, differences and contact mask), each with a byte-for-byte
//! copy of its real capture (`capture.png` or `capture.jpg`), the half masks, `press.json`
//! (the fit, its uncertainty and the sphere placed) and `manifest.json`.

use std::path::{Path, PathBuf};

use fabkit_designs::primitives::{Geometry, Primitive};
use fabkit_export::raster::png_gray8;
use fabkit_export::{OutputClaim, OutputCommand, StagedDir};
use nalgebra::{Isometry3, Point3};
use serde_json::{json, Value};

use super::dataset::{
    self, files, finite_range, frame_files, image_file, manifest, FrameInputs, ManifestInputs,
    Rendered, SinkError, Written,
};
use super::exact::ExactPrimitives;
use super::inputs::{sha256_hex, Configuration, Fixtures, InputError};
use super::press_skin::{Face, PressedSkin, SkinModel};
use super::{half_masks, indented_hits, DepthFrame};
use crate::capture_images::{read_gray, ImageError};
use crate::elastic::ContactError;
use crate::press::{fit_sphere_press, PressError, PressFit, PressOptions};
use crate::CameraModel;

/// The pressed frame's folder.
pub const PRESS_DIR: &str = "press";
/// The deformed skin's frame, inside the pressed frame's folder.
pub const SKIN_DIR: &str = "skin";
/// The fit and the sphere placed, at the top of the dataset.
pub const PRESS_JSON: &str = "press.json";
/// The stem of a frame's copy of its real capture: `capture.png` or `capture.jpg`.
pub const CAPTURE_STEM: &str = "capture";

/// Why a press cannot be fitted or rendered; each names the option and its file or value.
#[derive(Debug, thiserror::Error)]
pub enum PressInputError {
    /// A capture that cannot be read or is of another size than the camera's.
    #[error(transparent)]
    Image(#[from] ImageError),
    #[error(
        "{option} = {file} (against {reference_option} = {reference}): {source} (hint: {hint})"
    )]
    Fit {
        option: &'static str,
        file: String,
        reference_option: &'static str,
        reference: String,
        #[source]
        source: Box<PressError>,
        hint: &'static str,
    },
    #[error("{option} = {value}: must be a finite length above 0 mm, at most {max} mm (the sphere's radius)")]
    Radius {
        option: &'static str,
        value: f64,
        max: f64,
    },
    #[error("design {design}: body.profile = {profile}: {option} needs a flat skin (a sphere pressed into a plane's contact face)")]
    NotFlat {
        option: &'static str,
        design: String,
        profile: String,
    },
    #[error("the embedded materials table: {0}")]
    Materials(String),
    #[error("{option} = {file}: the skin's elastic contact at the fitted depth: {source}")]
    Elastic {
        option: &'static str,
        file: String,
        #[source]
        source: ContactError,
    },
    #[error("{option} = {file}: the pose was solved through an optical path (optical_path.planes), but the press is fitted along straight rays (hint: give the extrinsics.json of `fabkit calibrate board`, whose camera takes the flat layers' refraction up in its distortion)")]
    OpticalPath { option: &'static str, file: String },
}

/// What a press is fitted from: the design (its flat contact face is the skin's plane), the
/// calibrated camera and its pose, the capture and its reference (grey or colour PNG or JPEG
/// of the camera's size), the sphere's radius, and the options that give each (for errors).
pub struct PressJob<'a> {
    pub design: &'a fabkit_designs::Design,
    pub camera: &'a CameraModel,
    /// The camera file, as named in errors.
    pub camera_file: &'a str,
    /// Sensor frame -> camera frame, mm.
    pub t_cam_sensor: &'a Isometry3<f64>,
    pub capture: &'a Path,
    pub capture_option: &'static str,
    pub reference: &'a Path,
    pub reference_option: &'static str,
    pub radius_mm: f64,
    pub radius_option: &'static str,
}

/// A real capture as given: its path, bytes, sha256 and the extension of its format (`png`,
/// `jpg`).
#[derive(Debug, Clone)]
pub struct CaptureFile {
    pub file: PathBuf,
    pub bytes: Vec<u8>,
    pub sha256: String,
    pub extension: &'static str,
}

impl CaptureFile {
    /// The path of its copy in the frame folder `dir`: `dir/capture.<ext>`.
    pub fn copy_path(&self, dir: &str) -> String {
        format!("{dir}/{CAPTURE_STEM}.{}", self.extension)
    }
}

/// A fitted press: the fit, the sphere's radius, the skin's plane (sensor frame z, mm) and the
/// captures it came from.
#[derive(Debug, Clone)]
pub struct Press {
    pub fit: PressFit,
    /// The skin as the sphere deforms it (the elastic contact at the fitted depth).
    pub skin: PressedSkin,
    pub radius_mm: f64,
    pub plane_z_mm: f64,
    pub capture: CaptureFile,
    pub reference: CaptureFile,
}

impl Press {
    /// The sphere's centre, sensor frame, mm: over the fitted centre, its lowest point
    /// `depth_mm` below the plane.
    pub fn sphere_centre_mm(&self) -> [f64; 3] {
        let [x, y] = self.fit.centre_mm;
        [x, y, self.plane_z_mm - self.fit.depth_mm + self.radius_mm]
    }

    /// The sphere's lowest point (the deepest point of the indentation), sensor frame, mm.
    pub fn lowest_point_mm(&self) -> [f64; 3] {
        let [x, y] = self.fit.centre_mm;
        [x, y, self.plane_z_mm - self.fit.depth_mm]
    }

    /// The radius of the sphere's intersection with the plane, `sqrt(2 R d - d^2)`, mm (the
    /// contact mask's radius on the face).
    pub fn contact_radius_mm(&self) -> f64 {
        let (r, d) = (self.radius_mm, self.fit.depth_mm.min(self.radius_mm));
        (2.0 * r * d - d * d).max(0.0).sqrt()
    }

    /// press.json's `elastic`: the skin model, its grid, the elastic contact's radius beside
    /// the geometric one, and how far the skin sinks round the contact.
    pub fn elastic_json(&self) -> Value {
        let k = &self.skin;
        let [cx, cy] = k.centre_mm;
        // the skin's sink just outside the contact and its largest outside it
        let outside: Vec<f64> = (0..k.grid.n * k.grid.n)
            .filter(|&c| !k.in_contact[c])
            .map(|c| k.surface_mm[c])
            .collect();
        let rim = k.contact_radius_mm + 0.5;
        let (rim_surface, _) = k.sample(Face::Surface, cx + rim, cy);
        let (rim_seen, _) = k.sample(Face::Seen, cx + rim, cy);
        let (centre_seen, _) = k.sample(Face::Seen, cx, cy);
        json!({
            "model": "the skin's layers as one elastic layer bonded to a rigid base at the base plane, pressed by the rigid, frictionless sphere to the fitted depth (calibration/src/elastic.rs: a bonded layer's influence, Polonsky and Keer's conjugate gradient; calibration/src/groundtruth/press_skin.rs)",
            "thickness_mm": k.model.thickness_mm,
            "poisson": k.model.poisson,
            "seen_face": k.model.seen,
            "seen_depth_mm": k.model.seen_depth_mm,
            "grid": {"cells": k.grid.n, "cell_mm": k.grid.cell_mm, "centre_mm": k.centre_mm},
            "contact_radius_mm": k.contact_radius_mm,
            "geometric_contact_radius_mm": self.contact_radius_mm(),
            "sink_mm": {
                "what": "displacement into the skin, mm",
                "surface_0.5_mm_past_the_contact": rim_surface,
                "seen_face_0.5_mm_past_the_contact": rim_seen,
                "seen_face_at_the_centre": centre_seen,
                "surface_largest_outside_the_contact": outside.iter().cloned().fold(0.0, f64::max),
            },
            "assumptions": [
                "one material through the skin's layers (a coat stiffer than the gel spreads the dent wider)",
                "Poisson's ratio 0.5: silicone rubbers are incompressible to within 1e-3; for a given depth the shape does not depend on the modulus",
                "the base (the window a flat housing seats, or the plate the skin is cast on) rigid",
                "small strains and no friction (a deep press of a small ball widens the contact somewhat)"
            ],
        })
    }

    /// The sphere as the caster's solid.
    pub fn primitives(&self) -> Vec<Primitive> {
        vec![Primitive::Sphere {
            centre_mm: self.sphere_centre_mm(),
            radius_mm: self.radius_mm,
        }]
    }

    /// The press as the one configuration of a dataset (`press`), its description file the
    /// capture.
    ///
    /// # Errors
    /// [`InputError::Primitive`] when the sphere is not usable (a depth that is not finite).
    pub fn fixtures(&self) -> Result<Fixtures, InputError> {
        let primitives = self.primitives();
        let exact = ExactPrimitives::new(&primitives).map_err(|source| InputError::Primitive {
            file: self.capture.file.display().to_string(),
            orientation_deg: 0,
            source,
        })?;
        let dir = self
            .capture
            .file
            .parent()
            .map_or_else(PathBuf::new, Path::to_path_buf);
        Ok(Fixtures {
            dir,
            index_sha256: self.capture.sha256.clone(),
            patterns: Vec::new(),
            configurations: vec![Configuration {
                pattern: PRESS_DIR.into(),
                orientation_deg: 0,
                name: PRESS_DIR.into(),
                description_file: self.capture.file.display().to_string(),
                description_sha256: self.capture.sha256.clone(),
                geometry: Geometry {
                    frame: "sensor".into(),
                    primitives,
                },
                primitives: exact,
                pins: Vec::new(),
            }],
        })
    }
}

/// The format of an image's bytes as a file extension: `png`, `jpg`, or `None` for neither.
fn image_extension(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some("png")
    } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
        Some("jpg")
    } else {
        None
    }
}

/// Reads the capture of `option` (checked against the camera's size) as grey levels, with its
/// bytes.
fn read_capture(
    path: &Path,
    option: &'static str,
    camera: &CameraModel,
    camera_file: &str,
) -> Result<(crate::imprints::GrayImage, CaptureFile), ImageError> {
    let i = camera.intrinsics();
    let gray = read_gray(
        path,
        option,
        (i.image_width_px, i.image_height_px),
        camera_file,
    )?;
    let file = path.display().to_string();
    let bytes = crate::read_binary(path).map_err(|source| ImageError::Io {
        option,
        file: file.clone(),
        source,
    })?;
    let extension = image_extension(&bytes).ok_or_else(|| ImageError::Decode {
        option,
        file,
        message: "the content is neither PNG nor JPEG (it changed while it was read)".into(),
    })?;
    Ok((
        gray,
        CaptureFile {
            file: path.to_path_buf(),
            sha256: sha256_hex(&bytes),
            bytes,
            extension,
        },
    ))
}

/// Fits the press of `job`: the sphere of `radius_mm` in the capture against its reference,
/// the skin's plane the design's flat contact face (`body.pole_z_mm(0)`, sensor frame).
///
/// # Errors
/// [`PressInputError`] naming the option and its file or value: a radius that is not finite
/// and above 0 (at most the design's largest length), a design whose skin is not flat, a
/// capture that cannot be read or is of another size than the camera's, no contact (the
/// reference given as the press), a darkening too small or not a sphere's dome.
pub fn fit_press(job: &PressJob<'_>) -> Result<Press, PressInputError> {
    let max = fabkit_designs::values::MAX_LENGTH_MM;
    if !(job.radius_mm > 0.0 && job.radius_mm <= max) {
        return Err(PressInputError::Radius {
            option: job.radius_option,
            value: job.radius_mm,
            max,
        });
    }
    if job.design.body.flat_outline().is_none() {
        return Err(PressInputError::NotFlat {
            option: job.capture_option,
            design: job.design.name.clone(),
            profile: job.design.body.kind().to_string(),
        });
    }
    let plane_z_mm = job.design.body.pole_z_mm(0.0);
    let (capture, capture_file) =
        read_capture(job.capture, job.capture_option, job.camera, job.camera_file)?;
    let (reference, reference_file) = read_capture(
        job.reference,
        job.reference_option,
        job.camera,
        job.camera_file,
    )?;
    let fit = fit_sphere_press(
        &reference,
        &capture,
        job.camera,
        job.t_cam_sensor,
        plane_z_mm,
        &PressOptions::sphere(job.radius_mm),
    )
    .map_err(|source| PressInputError::Fit {
        option: job.capture_option,
        file: job.capture.display().to_string(),
        reference_option: job.reference_option,
        reference: job.reference.display().to_string(),
        hint: match source {
            PressError::NoContact { .. } => "give a capture with the sphere pressed in, not the reference; same camera, lighting and exposure as the reference",
            PressError::TooFewPixels(_) => "the contact's core is a few pixels: press deeper, or check that the camera and extrinsics are this sensor's",
            PressError::NotADome(_) => "check that the indenter is a sphere and that the reference is this sensor's unpressed skin under the same lighting",
            PressError::Size(..) => "give the capture and its reference at the camera's size",
        },
        source: Box::new(source),
    })?;
    let materials = fabkit_designs::materials::MaterialsTable::embedded()
        .map_err(|e| PressInputError::Materials(e.to_string()))?;
    let model = SkinModel::of(job.design, &materials).ok_or_else(|| PressInputError::NotFlat {
        option: job.capture_option,
        design: job.design.name.clone(),
        profile: job.design.body.kind().to_string(),
    })?;
    let skin = PressedSkin::solve(&model, job.radius_mm, fit.centre_mm, fit.depth_mm).map_err(
        |source| PressInputError::Elastic {
            option: job.capture_option,
            file: job.capture.display().to_string(),
            source,
        },
    )?;
    Ok(Press {
        fit,
        skin,
        radius_mm: job.radius_mm,
        plane_z_mm,
        capture: capture_file,
        reference: reference_file,
    })
}

/// What a press's ground truth is rendered from, for its claim on the output folder
/// ([`claim`]).
pub struct PressClaimInputs<'a> {
    /// The design as named: a library design's name or a design file's path.
    pub design: &'a str,
    pub preset: Option<&'a str>,
    pub camera_file: &'a Path,
    pub extrinsics_file: &'a Path,
    pub capture: &'a Path,
    pub reference: &'a Path,
    pub radius_mm: f64,
}

/// The press's claim on its output folder: ground truth of a sphere's press (its radius) on the
/// design, from the camera file, the extrinsics, the capture and its reference (and the
/// design's file); `force` replaces earlier ground truth of other inputs.
pub fn claim(inputs: &PressClaimInputs<'_>, force: bool) -> OutputClaim {
    let design_file = Path::new(inputs.design);
    let mut files: Vec<&Path> = vec![
        inputs.camera_file,
        inputs.extrinsics_file,
        inputs.capture,
        inputs.reference,
    ];
    if design_file.is_file() {
        files.push(design_file);
    }
    let preset = inputs
        .preset
        .map_or(String::new(), |p| format!(" preset '{p}'"));
    let what = format!(
        "ground truth of a {} mm sphere's press on design '{}'{preset}",
        crate::shown_f64(inputs.radius_mm),
        inputs.design
    );
    OutputClaim::of_inputs(OutputCommand::Groundtruth, &what, &files, force)
}

/// Files and bytes of a press's output, (files, bytes), an upper bound as
/// [`dataset::output_bound`]'s for one configuration, with the copies of the captures and
/// press.json in place of pairs.csv.
pub fn output_bound(
    w: u64,
    h: u64,
    format: dataset::DataFormat,
    image_bits: Option<u32>,
    press: &Press,
) -> (u64, u64) {
    let (files, bytes) = dataset::output_bound(w, h, 1, 0, format, image_bits);
    let copies = (press.capture.bytes.len() + press.reference.bytes.len()) as u64;
    (files + 2, bytes + copies + 65_536 + 2 * 4096)
}

/// The previews' range: the reference frame's finite range and z-depth ((0, 1) when none).
fn preview_range(reference: &DepthFrame) -> (f64, f64) {
    let (lo, hi) = [
        finite_range(&reference.range_mm),
        finite_range(&reference.zdepth_mm),
    ]
    .into_iter()
    .flatten()
    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (lo, hi)| {
        (a.min(lo), b.max(hi))
    });
    if lo <= hi {
        (lo, hi)
    } else {
        (0.0, 1.0)
    }
}

/// Hands each of `files` to `staged`, adding it to `all`; returns their manifest entries with
/// their sha256.
fn put(
    staged: &StagedDir,
    files: dataset::Files,
    all: &mut Written,
) -> Result<Vec<Value>, SinkError> {
    let mut entries = Vec::new();
    for (rel, bytes, mut e) in files {
        staged.write(&rel, &bytes)?;
        let sha = sha256_hex(&bytes);
        e["sha256"] = json!(sha);
        all.push((rel, sha, bytes.len()));
        entries.push(e);
    }
    Ok(entries)
}

/// The copy of a real capture in the frame folder `dir`, with its manifest entry.
fn capture_copy(dir: &str, c: &CaptureFile, what: &str) -> (String, Vec<u8>, Value) {
    let rel = c.copy_path(dir);
    let entry = json!({"file": rel, "quantity": format!("the real {what}, copied byte for byte"),
                       "from": c.file.display().to_string()});
    (rel, c.bytes.clone(), entry)
}

/// press.json: the fit (its fields at the top: `centre_mm`, `depth_mm`, their standard
/// deviations, `depth_spread_mm`, `gain_grey_per_mm`, ...), the sphere placed, and the files
/// it came from.
pub fn press_json(press: &Press, m: &ManifestInputs<'_>) -> Value {
    let mut v = serde_json::to_value(&press.fit).unwrap_or_else(|_| json!({}));
    let lowest = press.lowest_point_mm();
    let lowest_px = m
        .camera
        .project(&(m.t_cam_sensor * Point3::new(lowest[0], lowest[1], lowest[2])).coords)
        .map(|p| vec![p.x, p.y]);
    let extra = json!({
        "fabkit_version": m.fabkit_version,
        "command_line": m.command_line,
        "description": "A sphere of known radius pressed into the flat skin, found in one capture against its reference through the calibrated camera (fit_sphere_press, calibration/src/press.rs): the darkening near the axis is a paraboloid whose apex is the sphere's centre over the plane and whose curvature, with the known radius, gives the response's gain and so the depth",
        "frame": "sensor (docs/conventions.md): x, y over the skin's contact face, z out of the skin; mm",
        "indenter": {"shape": "sphere", "radius_mm": press.radius_mm},
        "plane_z_mm": press.plane_z_mm,
        "plane": "the design's flat contact face (body.pole_z_mm), the skin's plane the fit maps pixels onto",
        "uncertainty": "centre_std_mm and depth_std_mm are the fit's, from its residuals (the pixels' noise); depth_spread_mm is how far the depth moves when the core is taken above 0.5 or 0.75 of the apex instead of 0.6 (a response not linear in depth); the camera's calibration error is in neither",
        "sphere": {
            "centre_mm": press.sphere_centre_mm(),
            "lowest_point_mm": lowest,
            "lowest_point_px": lowest_px,
            "contact_radius_mm": press.contact_radius_mm(),
            "placed": "centre over centre_mm, lowest point depth_mm below the contact face; the rendered contact is the sphere's intersection with the face, of radius contact_radius_mm = sqrt(2 R d - d^2)",
        },
        "elastic": press.elastic_json(),
        "capture": {"file": press.capture.file.display().to_string(), "sha256": press.capture.sha256, "copy": press.capture.copy_path(PRESS_DIR)},
        "reference": {"file": press.reference.file.display().to_string(), "sha256": press.reference.sha256, "copy": press.reference.copy_path(files::REFERENCE_DIR)},
        "camera": {"file": m.camera_file, "sha256": m.camera_sha256},
        "extrinsics": {"file": m.extrinsics_file, "sha256": m.extrinsics_sha256},
        "design": {"name": m.design_name, "source": m.design_source, "sha256": m.design_sha256},
    });
    if let (Some(o), Value::Object(e)) = (v.as_object_mut(), extra) {
        o.extend(e);
    }
    v
}

/// Renders the press's dataset into `staged`: the reference frame and the pressed one (the
/// sphere of `frames.fixtures`' one configuration, [`Press::fixtures`]) with their files
/// ([`frame_files`], and [`image_file`] with `--images`), a copy of each real capture in its
/// frame's folder, the half masks, [`PRESS_JSON`] ([`press_json`]) and last the manifest
/// ([`dataset::manifest`], its `fixtures` replaced by `press`). `progress(k)` after each
/// frame. Returns every file written but the manifest, sorted by path.
///
/// # Errors
/// The first error of an encoder or of writing a file.
pub fn write(
    staged: &StagedDir,
    frames: &FrameInputs<'_>,
    manifest_inputs: &ManifestInputs<'_>,
    press: &Press,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Written, SinkError> {
    let FrameInputs {
        rays,
        reference_hits: ref_hits,
        base_z_mm,
        fixtures,
        format,
        imaging,
        provenance,
    } = *frames;
    let cfg = fixtures
        .configurations
        .first()
        .ok_or("the press's fixtures hold no configuration")?;
    let (w, h) = (rays.width, rays.height);
    let mut all = Written::new();

    let reference = DepthFrame::new(rays, ref_hits);
    let preview = preview_range(&reference);
    let mut ref_files = frame_files(
        files::REFERENCE_DIR,
        &reference,
        None,
        preview,
        provenance,
        format,
    )?;
    if let Some(im) = imaging {
        ref_files.push(image_file(
            files::REFERENCE_DIR,
            im,
            rays,
            ref_hits,
            ref_hits,
            None,
            0,
        )?);
    }
    ref_files.push(capture_copy(
        files::REFERENCE_DIR,
        &press.reference,
        "reference capture (the unpressed skin)",
    ));
    let ref_entries = put(staged, ref_files, &mut all)?;
    progress(1);

    let hits = indented_hits(rays, ref_hits, &cfg.primitives, base_z_mm);
    let frame = DepthFrame::new(rays, &hits);
    let mut press_files = frame_files(
        &cfg.name,
        &frame,
        Some(&reference),
        preview,
        provenance,
        format,
    )?;
    if let Some(im) = imaging {
        // the image from the face the camera sees, as the sphere deforms it
        let seen_hits = press
            .skin
            .hits(Face::Seen, rays, ref_hits, press.plane_z_mm);
        press_files.push(image_file(
            &cfg.name,
            im,
            rays,
            ref_hits,
            &seen_hits,
            Some(&cfg.primitives),
            1,
        )?);
    }
    press_files.push(capture_copy(
        &cfg.name,
        &press.capture,
        "capture of the press",
    ));
    let press_entries = put(staged, press_files, &mut all)?;
    // the skin as the sphere deforms it
    let plane = press.plane_z_mm;
    let skin_hits = press.skin.hits(Face::Surface, rays, ref_hits, plane);
    let skin_frame = DepthFrame::new(rays, &skin_hits);
    let skin_dir = format!("{}/{SKIN_DIR}", cfg.name);
    let skin_files = frame_files(
        &skin_dir,
        &skin_frame,
        Some(&reference),
        preview,
        provenance,
        format,
    )?;
    let skin_entries = put(staged, skin_files, &mut all)?;
    let skin_contact = skin_frame.contact_mask(&reference);
    let (skin_dr, skin_dz) = skin_frame.delta(&reference);
    let contact = frame.contact_mask(&reference);
    let (dr, dz) = frame.delta(&reference);
    let deepest = |d: &[f64]| finite_range(d).map_or(0.0, |x| (-x.0).max(0.0));
    let entry = json!({
        "name": cfg.name, "dir": cfg.name,
        "indenter": {"shape": "sphere", "radius_mm": press.radius_mm, "centre_mm": press.sphere_centre_mm()},
        "fit": PRESS_JSON,
        "contact_pixels": contact.iter().filter(|&&c| c).count(),
        "max_range_decrease_mm": deepest(&dr),
        "max_zdepth_decrease_mm": deepest(&dz),
        "files": press_entries,
        "skin": {
            "dir": skin_dir,
            "surface": "the skin's outer surface as the sphere deforms it (press.json: elastic)",
            "contact_pixels": skin_contact.iter().filter(|&&c| c).count(),
            "max_range_decrease_mm": deepest(&skin_dr),
            "max_zdepth_decrease_mm": deepest(&skin_dz),
            "files": skin_entries,
        },
    });
    progress(2);

    let (left, right) = half_masks(rays, ref_hits);
    let mut masks: dataset::Files = Vec::new();
    for (name, m, side) in [
        (files::LEFT_MASK, &left, "x < 0 (the -x half)"),
        (files::RIGHT_MASK, &right, "x >= 0 (the +x half)"),
    ] {
        let px: Vec<u8> = m.iter().map(|&b| if b { 255 } else { 0 }).collect();
        let count = m.iter().filter(|&&b| b).count();
        masks.push((name.into(), png_gray8(w, h, &px, &[])?, json!({"file": name, "quantity": format!("pixels whose ray meets the reference surface at sensor-frame {side}: 255, else 0"), "pixels": count})));
    }
    let mut fit = press_json(press, manifest_inputs);
    let mut text = serde_json::to_vec_pretty(&fit)?;
    text.push(b'\n');
    masks.push((
        PRESS_JSON.into(),
        text,
        json!({"file": PRESS_JSON, "quantity": "the press's fit: the sphere's centre over the contact face and its depth, with their standard deviations, and the sphere placed"}),
    ));
    let extra_entries = put(staged, masks, &mut all)?;
    all.sort();

    let rendered = Rendered {
        reference: ref_entries,
        configurations: vec![entry],
        masks_and_pairs: extra_entries,
        files: all,
    };
    let mut m = manifest(manifest_inputs, &rendered);
    m["description"] = json!("Ground-truth depth of the sensor surface, reference (undeformed) and indented by a sphere of known radius where a real press of it was found in a capture (press.json; calibration/src/groundtruth/press.rs): complete depth = reference + delta. Exact per-pixel rays of the camera model; surfaces in closed form.");
    if let Some(o) = m.as_object_mut() {
        o.remove("fixtures");
        if let Some(f) = fit.as_object_mut() {
            f.retain(|k, _| {
                [
                    "indenter",
                    "centre_mm",
                    "centre_std_mm",
                    "depth_mm",
                    "depth_std_mm",
                    "depth_spread_mm",
                    "sphere",
                    "capture",
                    "reference",
                ]
                .contains(&k.as_str())
            });
            f.insert("file".into(), json!(PRESS_JSON));
        }
        o.insert("press".into(), fit);
    }
    m["conventions"]["surface"] = json!("the flat skin's contact face over its outline (its edges continued below the base plane bound the body); press/: the indenter's surface, the skin minus the fitted sphere (its contact mask the sphere's intersection with the face); press/skin/: the skin's outer surface as the sphere deforms it, an elastic layer bonded to its base (press.json: elastic; its contact mask where the sphere touches it); press/image.png (with --images): rendered from the face the camera sees, deformed");
    m["conventions"]["not_modelled"] = json!("the skin's layers as one material, small strains and no friction (press.json: elastic.assumptions); refraction at the flat layers for points off the contact face (the camera's straight rays, whose distortion holds for points on the face)");
    let mut text = serde_json::to_vec_pretty(&m)?;
    text.push(b'\n');
    staged.write(files::MANIFEST, &text)?;
    Ok(rendered.files)
}
