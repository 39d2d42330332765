//! From capture photos to pin observations (R-Tac0 Sec. IV-A, Fig. 5): each capture image is
//! compared with one reference image of the unloaded skin ([`crate::imprints::detect`] inside
//! [`crate::imprints::reference_mask`]), each capture's spots get the ids of the pins planned
//! for it ([`crate::imprints::assign_ids`]: the capture plan's row, or the ids the file name
//! lists in ring order), and the result is the observations the solve uses, the
//! `observations.csv` table (capture, id, u_px, v_px, score) and an overlay per capture.
//! `observations.csv` starts with its header row; what its columns mean ([`OBSERVATIONS_NOTES`])
//! is in the sidecar `observations.json` written beside it.
//!
//! Images: PNG or JPEG, 8- or 16-bit, grey or RGB (converted to grey, 0..255 grey levels), of
//! the camera file's size (checked from the header, before any pixel is decoded).

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Vector2, Vector3};
use rayon::prelude::*;

use crate::imprints::{
    assign_ids_through, detect, ids_from_file_name, reference_mask, CaptureOutcome, CaptureSpots,
    DetectParams, GrayImage, Observation,
};
use crate::overlay::{OverlayError, Rgb8};
use crate::tables::{CapturePlan, Observations, PointTable};

/// Capture images and the reference image they are compared with.
#[derive(Debug, Clone)]
pub struct CaptureImages {
    /// One image per capture: in the capture plan's order, or named by the ids they hold in
    /// ring order (`01_02_06_14_22.png`).
    pub captures: Vec<PathBuf>,
    /// The unloaded skin, same camera and lighting.
    pub reference: PathBuf,
}

/// LED reflections in the reference are masked with this margin, px.
pub const REFLECTION_MARGIN_PX: usize = 4;

/// A capture or reference image that cannot be used; `option` is the command-line option that
/// gave the file (`--images`, `--reference`).
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("{option} = {file}: cannot read: {source}")]
    Io {
        option: &'static str,
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{option} = {file}: {rule}")]
    Folder {
        option: &'static str,
        file: String,
        rule: String,
    },
    #[error("{option} = {file}: not a readable PNG or JPEG image: {message}")]
    Decode {
        option: &'static str,
        file: String,
        message: String,
    },
    #[error("{option} = {file}: the image is {width} x {height} px but the camera file {camera} says {camera_width} x {camera_height} px; they must match")]
    Size {
        option: &'static str,
        file: String,
        width: u32,
        height: u32,
        camera: String,
        camera_width: u32,
        camera_height: u32,
    },
    #[error("--images = {file}: {rule}")]
    Ids { file: String, rule: String },
    #[error("--images: {images} images but the capture plan {plan} has {captures} captures; give one image per capture, in capture order")]
    Count {
        images: usize,
        plan: String,
        captures: usize,
    },
    #[error("--images = {file}: given twice")]
    Twice { file: String },
    /// A capture that lists a pin more than once.
    #[error("--images = {file}: pin {id} listed {times} times; a capture presses each pin once")]
    RepeatedPin { file: String, id: u32, times: usize },
}

/// Whether a JPEG's bytes hold an end-of-image marker (FF D9) after its first start-of-scan
/// (FF DA): a file cut short has none, and the decoder fills what is missing in grey. Inside
/// the scan data an FF byte is followed by 00 (or a restart marker), so FF D9 there is the
/// end (ITU-T T.81, B.1.1.2 and F.1.2.3).
fn jpeg_is_complete(bytes: &[u8]) -> bool {
    let Some(sos) = bytes.windows(2).position(|w| w == [0xFF, 0xDA]) else {
        return false;
    };
    bytes[sos..].windows(2).any(|w| w == [0xFF, 0xD9])
}

/// Decodes `path` (PNG or JPEG), checking its size against the camera's (`expect_px`, from
/// the camera file `camera`) before decoding.
/// What to say when `path`, given as an image, is a folder (`None`: it is not one): give the
/// images in it, as the shell's `DIR/*.png` lists them.
pub fn folder_given(path: &Path) -> Option<String> {
    path.is_dir().then(|| {
        format!(
            "is a folder, not an image: give the capture images themselves (as {}/*.png, which the shell expands in name order)",
            path.display().to_string().trim_end_matches('/')
        )
    })
}

fn decode_checked(
    path: &Path,
    option: &'static str,
    expect_px: (u32, u32),
    camera: &str,
) -> Result<image::DynamicImage, ImageError> {
    let file = path.display().to_string();
    if let Some(rule) = folder_given(path) {
        return Err(ImageError::Folder { option, file, rule });
    }
    let bytes = crate::read_binary(path).map_err(|source| ImageError::Io {
        option,
        file: file.clone(),
        source,
    })?;
    let decode = |message: String| ImageError::Decode {
        option,
        file: file.clone(),
        message,
    };
    let reader = || {
        image::ImageReader::new(Cursor::new(&bytes[..]))
            .with_guessed_format()
            .map_err(|e| decode(e.to_string()))
    };
    match reader()?.format() {
        Some(image::ImageFormat::Jpeg) if !jpeg_is_complete(&bytes) => {
            return Err(decode(
                "the JPEG is incomplete (no end-of-image marker after its scan data: the file was cut short)".into(),
            ))
        }
        Some(image::ImageFormat::Png | image::ImageFormat::Jpeg) => {}
        Some(f) => return Err(decode(format!("{f:?} images are not read"))),
        None => return Err(decode("the content is neither PNG nor JPEG".into())),
    }
    let (width, height) = reader()?
        .into_dimensions()
        .map_err(|e| decode(e.to_string()))?;
    if (width, height) != expect_px {
        return Err(ImageError::Size {
            option,
            file,
            width,
            height,
            camera: camera.into(),
            camera_width: expect_px.0,
            camera_height: expect_px.1,
        });
    }
    reader()?.decode().map_err(|e| match e {
        // the decoder's memory limit, in words (issue 95: "Memory limit exceeded")
        image::ImageError::Limits(_) => {
            let bytes = reader()
                .ok()
                .and_then(|r| r.into_decoder().ok())
                .map(|d| image::ImageDecoder::total_bytes(&d));
            decode(format!(
                "{width} x {height} pixels{} decode to more than the {} MiB an image may take in memory (hint: calibrate the camera at a lower resolution or crop its images)",
                bytes.map_or(String::new(), |b| format!(" ({} MiB decoded)", b.div_ceil(1 << 20))),
                IMAGE_MEMORY_LIMIT_BYTES >> 20
            ))
        }
        e => decode(e.to_string()),
    })
}

/// The image decoder's memory limit (the `image` crate's default allocation limit), bytes.
pub const IMAGE_MEMORY_LIMIT_BYTES: u64 = 512 << 20;

/// Reads `path` (PNG or JPEG, any depth, grey or colour) as grey levels 0..255, checking its
/// size against the camera's (`expect_px`, from the camera file `camera`) before decoding.
///
/// # Errors
/// [`ImageError`] naming `option` and the file.
pub fn read_gray(
    path: &Path,
    option: &'static str,
    expect_px: (u32, u32),
    camera: &str,
) -> Result<GrayImage, ImageError> {
    let img = decode_checked(path, option, expect_px, camera)?;
    // 16 bits per grey level: 8-bit images come back as g * 257, exactly g after the division
    let luma = img.into_luma16();
    Ok(GrayImage {
        width: luma.width() as usize,
        height: luma.height() as usize,
        data: luma.as_raw().iter().map(|&g| g as f32 / 257.0).collect(),
    })
}

/// Reads `path` (PNG or JPEG, grey or colour) as RGB counts at its own bit depth, row-major,
/// with its full scale (255 for 8-bit images, 65535 for 16-bit; a grey image gives three
/// equal channels), checking its size against the camera's as [`read_gray`] does: the
/// intensities the photometric model is fitted to.
///
/// # Errors
/// [`ImageError`] naming `option` and the file.
pub fn read_rgb(
    path: &Path,
    option: &'static str,
    expect_px: (u32, u32),
    camera: &str,
) -> Result<(Vec<[f64; 3]>, f64), ImageError> {
    let img = decode_checked(path, option, expect_px, camera)?;
    let sixteen = matches!(
        img.color(),
        image::ColorType::L16
            | image::ColorType::La16
            | image::ColorType::Rgb16
            | image::ColorType::Rgba16
    );
    Ok(if sixteen {
        let rgb = img.into_rgb16();
        (rgb.pixels().map(|p| p.0.map(f64::from)).collect(), 65535.0)
    } else {
        let rgb = img.into_rgb8();
        (rgb.pixels().map(|p| p.0.map(f64::from)).collect(), 255.0)
    })
}

/// One capture after detection.
#[derive(Debug, Clone)]
struct Capture {
    image: GrayImage,
    spots: CaptureSpots,
    /// (spot index, id) of the assigned spots; empty for a capture left out.
    ids: Vec<(usize, u32)>,
}

/// What `observations.csv` holds: the `notes` of its sidecar `observations.json`.
pub const OBSERVATIONS_NOTES: &str = "fabkit pin-imprint observations: pixel of each pin's imprint (sub-pixel centroid; (0, 0) the centre of the top-left pixel, docs/conventions.md); score: the imprint's peak over the noise sigma";

/// The captures' observations.
#[derive(Debug, Clone)]
pub struct ImageObservations {
    /// One row per pin id (a pin seen in several captures, the pole pin, combined by
    /// [`crate::tables::combine_observations`]), first-seen
    /// order; ids spelled as in the point table.
    pub observations: Observations,
    /// Planned pins with no observation (in a capture left out, or not in the table), plan
    /// order.
    pub unobserved_ids: Vec<String>,
    /// `observations.csv`: capture, id, u_px, v_px, score, one row per detection.
    pub csv: String,
    /// A line per capture left out, or kept with a spot discarded or a pin missing (why, and
    /// the pixels of the spots).
    pub notes: Vec<String>,
    /// Per capture, in input order: the spots found, kept (with ids), discarded (with why),
    /// the pins missing, or why it is left out.
    pub outcomes: Vec<CaptureOutcome>,
    captures: Vec<Capture>,
}

fn csv_cell(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.into()
    }
}

/// Finds the pins in every capture of `input` and gives them their ids: from `plan` (one image
/// per capture, in order) or, without a plan, from each image's file name. `camera_file` names
/// the camera file in size errors.
///
/// # Errors
/// [`ImageError`]: an unreadable image or one of another size than the camera's, an image
/// given twice, a file name that lists no ids (without a plan), a plan id that is not a
/// number, a plan with another number of captures.
pub fn observe_images(
    imaging: &crate::refraction::Imaging<'_>,
    camera_file: &str,
    table: &PointTable,
    plan: Option<&CapturePlan>,
    input: &CaptureImages,
) -> Result<ImageObservations, ImageError> {
    let camera = imaging.camera;
    let intr = camera.intrinsics();
    let size = (intr.image_width_px, intr.image_height_px);
    if let Some((dir, rule)) = input
        .captures
        .iter()
        .find_map(|p| folder_given(p).map(|r| (p, r)))
    {
        return Err(ImageError::Ids {
            file: dir.display().to_string(),
            rule,
        });
    }
    for (k, p) in input.captures.iter().enumerate() {
        if input.captures[..k].contains(p) {
            return Err(ImageError::Twice {
                file: p.display().to_string(),
            });
        }
    }
    let planned = planned_ids(plan, input)?;
    for (p, ids) in input.captures.iter().zip(&planned) {
        if let Some((id, times)) = crate::imprints::repeated_pin(ids) {
            return Err(ImageError::RepeatedPin {
                file: p.display().to_string(),
                id,
                times,
            });
        }
    }
    let reference = read_gray(&input.reference, "--reference", size, camera_file)?;
    let mut captures = detect_captures(&reference, input, &planned, size, camera_file)?;
    // the table's ids by number
    let by_number: BTreeMap<u32, (&String, Vector3<f64>)> = table
        .rows
        .iter()
        .filter_map(|(id, p, _)| id.parse::<u32>().ok().map(|n| (n, (id, *p))))
        .collect();
    let points: BTreeMap<u32, Vector3<f64>> =
        by_number.iter().map(|(n, (_, p))| (*n, *p)).collect();
    let spots: Vec<CaptureSpots> = captures.iter().map(|c| c.spots.clone()).collect();
    let assignment = assign_ids_through(imaging, &points, &spots);
    let (csv, rows) = merge_observations(&assignment.observations, &mut captures, &by_number);
    let mut unobserved_ids: Vec<String> = Vec::new();
    for n in planned.iter().flatten() {
        let id = by_number
            .get(n)
            .map_or_else(|| n.to_string(), |(id, _)| (*id).clone());
        if !rows.iter().any(|r| r.0 == id) && !unobserved_ids.contains(&id) {
            unobserved_ids.push(id);
        }
    }
    Ok(ImageObservations {
        observations: Observations { rows },
        unobserved_ids,
        csv,
        notes: assignment.notes(),
        outcomes: assignment.captures,
        captures,
    })
}

/// The pin ids of each capture of `input`: its row of `plan` (ids parsed as pin numbers), or
/// without a plan the ids its file name lists ([`ids_from_file_name`]).
///
/// # Errors
/// [`ImageError::Count`] for a plan of another number of captures, [`ImageError::Ids`] for a
/// plan id that is not a number or a file name that lists no ids.
fn planned_ids(
    plan: Option<&CapturePlan>,
    input: &CaptureImages,
) -> Result<Vec<Vec<u32>>, ImageError> {
    Ok(match plan {
        Some(plan) => {
            if plan.captures.len() != input.captures.len() {
                return Err(ImageError::Count {
                    images: input.captures.len(),
                    plan: plan.file.clone(),
                    captures: plan.captures.len(),
                });
            }
            plan.captures
                .iter()
                .zip(&input.captures)
                .map(|(ids, p)| {
                    ids.iter()
                        .map(|id| {
                            id.parse::<u32>().map_err(|_| ImageError::Ids {
                                file: p.display().to_string(),
                                rule: format!(
                                    "its pins in the capture plan {} include id '{id}', not a pin number",
                                    plan.file
                                ),
                            })
                        })
                        .collect()
                })
                .collect::<Result<_, _>>()?
        }
        None => input
            .captures
            .iter()
            .map(|p| {
                ids_from_file_name(p).ok_or_else(|| ImageError::Ids {
                    file: p.display().to_string(),
                    rule: "the file name does not list the capture's pin ids in ring order (as 01_02_06_14_22.png for pins 1, 2, 6, 14 and 22, or image.png in a folder so named); name the images so, or give --capture-plan".into(),
                })
            })
            .collect::<Result<_, _>>()?,
    })
}

/// Each capture of `input` read (of the camera's `size`, px) and its spots detected against
/// `reference` inside the reference's mask, with its `planned` ids; read and detected in
/// parallel.
///
/// # Errors
/// The first [`ImageError`] in capture order.
fn detect_captures(
    reference: &GrayImage,
    input: &CaptureImages,
    planned: &[Vec<u32>],
    size: (u32, u32),
    camera_file: &str,
) -> Result<Vec<Capture>, ImageError> {
    let mask = reference_mask(reference, 255.0, REFLECTION_MARGIN_PX);
    let params = DetectParams::default();
    // read and detect in parallel; the first error in capture order is reported
    let captures: Vec<Result<Capture, ImageError>> = input
        .captures
        .par_iter()
        .zip(planned.par_iter())
        .map(|(p, ids)| {
            let image = read_gray(p, "--images", size, camera_file)?;
            let spots = detect(reference, &image, Some(&mask), &params)
                .expect("sizes checked against the camera's");
            Ok(Capture {
                image,
                spots: CaptureSpots {
                    name: p.display().to_string(),
                    planned_ids: ids.clone(),
                    spots,
                },
                ids: Vec::new(),
            })
        })
        .collect();
    captures.into_iter().collect()
}

/// The assigned `observations` as `observations.csv` (one row per detection) and as
/// observation rows (id spelled as in the table's `by_number`, pixel, origin), one per pin in
/// first-seen order, a pin seen in several captures combined
/// ([`crate::tables::combine_observations`]); each capture's assigned spots noted in its
/// `ids`.
fn merge_observations(
    observations: &[Observation],
    captures: &mut [Capture],
    by_number: &BTreeMap<u32, (&String, Vector3<f64>)>,
) -> (String, Vec<(String, Vector2<f64>, String)>) {
    let mut csv = String::from("capture,id,u_px,v_px,score\n");
    // id -> (sum of pixels, count, captures), first-seen order
    let mut merged: Vec<(String, Vec<Vector2<f64>>, Vec<String>)> = Vec::new();
    for o in observations {
        csv.push_str(&format!(
            "{},{},{:.4},{:.4},{:.2}\n",
            csv_cell(&o.capture),
            o.id,
            o.u_px,
            o.v_px,
            o.score
        ));
        let c = captures
            .iter_mut()
            .find(|c| c.spots.name == o.capture)
            .expect("an observation's capture is one of the captures");
        if let Some(j) = c
            .spots
            .spots
            .iter()
            .position(|s| s.u_px == o.u_px && s.v_px == o.v_px)
        {
            c.ids.push((j, o.id));
        }
        let id = by_number[&o.id].0.clone();
        let uv = Vector2::new(o.u_px, o.v_px);
        match merged.iter_mut().find(|m| m.0 == id) {
            Some(m) => {
                m.1.push(uv);
                m.2.push(o.capture.clone());
            }
            None => merged.push((id, vec![uv], vec![o.capture.clone()])),
        }
    }
    let rows = merged
        .into_iter()
        .map(|(id, px, caps)| {
            let origin = format!("detected in {}", caps.join(" + "));
            (id, crate::tables::combine_observations(&px), origin)
        })
        .collect();
    (csv, rows)
}

impl ImageObservations {
    /// An overlay per capture, `overlays/<file stem>.png` (a stem used twice gets `-2`, `-3`,
    /// ...): the capture with each assigned spot circled in green and labelled with its id,
    /// the spots of a capture left out circled in magenta and labelled `?`, and each planned
    /// pin's point of the table projected at `t_cam_sensor` as a red cross.
    ///
    /// # Errors
    /// [`OverlayError::Encode`].
    pub fn overlays(
        &self,
        camera: &crate::refraction::Imaging<'_>,
        table: &PointTable,
        t_cam_sensor: &Isometry3<f64>,
    ) -> Result<Vec<(String, Vec<u8>)>, OverlayError> {
        const GREEN: [u8; 3] = [0, 220, 0];
        const RED: [u8; 3] = [255, 40, 40];
        const YELLOW: [u8; 3] = [255, 220, 0];
        const MAGENTA: [u8; 3] = [255, 0, 255];
        let mut names: Vec<String> = Vec::new();
        let mut out = Vec::new();
        let r = *t_cam_sensor.rotation.to_rotation_matrix().matrix();
        let t = t_cam_sensor.translation.vector;
        for c in &self.captures {
            // `01_02_06/image.png` (a ground-truth capture's layout) by its folder's name
            let stem = crate::imprints::capture_name(Path::new(&c.spots.name))
                .unwrap_or_else(|| "capture".into());
            let mut name = stem.clone();
            let mut k = 1;
            while names.contains(&name) {
                k += 1;
                name = format!("{stem}-{k}");
            }
            names.push(name.clone());
            let mut img = Rgb8 {
                width: c.image.width as u32,
                height: c.image.height as u32,
                data: c
                    .image
                    .data
                    .iter()
                    .flat_map(|&g| [g.round().clamp(0.0, 255.0) as u8; 3])
                    .collect(),
            };
            for id in &c.spots.planned_ids {
                let Some((_, p, _)) = table
                    .rows
                    .iter()
                    .find(|r| r.0.parse::<u32>().ok() == Some(*id))
                else {
                    continue;
                };
                if let Some(q) = camera.project(&r, &t, p) {
                    img.line(q.x - 3.0, q.y, q.x + 3.0, q.y, RED);
                    img.line(q.x, q.y - 3.0, q.x, q.y + 3.0, RED);
                }
            }
            for (j, s) in c.spots.spots.iter().enumerate() {
                let r = (s.area_px as f64 / std::f64::consts::PI).sqrt() + 2.0;
                let (colour, label) = match c.ids.iter().find(|(k, _)| *k == j) {
                    Some((_, id)) => (GREEN, id.to_string()),
                    None => (MAGENTA, "?".to_string()),
                };
                img.circle(s.u_px, s.v_px, r, colour);
                img.text(
                    s.u_px + r + 2.0,
                    s.v_px - 5.0,
                    &label,
                    2,
                    if colour == GREEN { YELLOW } else { MAGENTA },
                );
            }
            out.push((format!("overlays/{name}.png"), img.to_png()?));
        }
        Ok(out)
    }
}
