//! The ground-truth dataset's files (`fabkit groundtruth`): per frame the float32 maps as NPY
//! or in one NPZ, their 16-bit PNGs (micrometres) and colour-mapped previews, the normals, the
//! PLY points, the contact mask and the rendered image, each with its manifest entry; and the
//! bound on the output's files and bytes, computed before anything is rendered. Defined here
//! once for the CLI and Python (R-Tac0 Sec. IV-B, Fig. 6, Eq. (2)-(3)).

use fabkit_export::raster::{
    normals_rgb, npy_f32, npz as npz_file, ply_points, png_gray16, png_gray8, png_rgb16, png_rgb8,
    preview_rgb, with_colour_bar, PlyPoint, Png16Encoding,
};
use fabkit_export::{ExportError, OutputClaim, OutputCommand, StagedDir};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use super::budget::frames_at_once;
use super::exact::ExactPrimitives;
use super::inputs::{pairs_csv, sha256_hex, Configuration, Fixtures, PAIRS_NOTES};
use super::rays::PixelRays;
use super::shading::Imaging;
use super::{half_masks, indented_hits};
use super::{DepthFrame, SurfaceHits};
use crate::photometric::PhotometricModel;

pub use super::files;

/// How the ground-truth arrays are written (`--format`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataFormat {
    /// float32 `.npy` per map and `points.ply` (numpy.load, Open3D).
    Npy,
    /// The float32 maps of each frame in one compressed `arrays.npz` (numpy.load); no PLY.
    Npz,
    /// 16-bit PNGs (micrometres), previews and masks only.
    Png,
}

/// 16-bit PNG encoding of depth and range: micrometres (`value_mm = count * 0.001`).
pub const DEPTH_PNG: Png16Encoding = Png16Encoding {
    scale: 0.001,
    offset_counts: 0,
};
/// 16-bit PNG encoding of the differences: micrometres offset by 32768 counts.
pub const DELTA_PNG: Png16Encoding = Png16Encoding {
    scale: 0.001,
    offset_counts: 32768,
};

/// Files of one rendered frame: (relative path, bytes, manifest entry).
pub type Files = Vec<(String, Vec<u8>, Value)>;

fn f32s(v: &[f64]) -> Vec<f32> {
    v.iter().map(|x| *x as f32).collect()
}

/// The least and greatest finite value of `v`, if it has one.
pub fn finite_range(v: &[f64]) -> Option<(f64, f64)> {
    let (lo, hi) = v
        .iter()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        });
    (lo <= hi).then_some((lo, hi))
}

/// The float32 maps of a frame bound for its `arrays.npz`: (name, NPY bytes, description).
type NpzArrays = Vec<(String, Vec<u8>, Value)>;

/// A float32 map as a `.npy` file (`npy`), an entry of the frame's `arrays.npz` (`npz`) or
/// nothing (`png`).
#[allow(clippy::too_many_arguments)]
fn array_file(
    files: &mut Files,
    npz: &mut NpzArrays,
    format: DataFormat,
    dir: &str,
    name: &str,
    shape: &[usize],
    data: &[f32],
    meta: Value,
) {
    match format {
        DataFormat::Npy => {
            let file = format!("{dir}/{name}{}", files::NPY_SUFFIX);
            let mut e = meta;
            e["file"] = json!(file);
            files.push((file, npy_f32(shape, data), e));
        }
        DataFormat::Npz => npz.push((name.to_string(), npy_f32(shape, data), meta)),
        DataFormat::Png => {}
    }
}

/// A scalar map as float32 mm ([`array_file`]), 16-bit PNG (um) and preview PNG.
#[allow(clippy::too_many_arguments)]
fn scalar_files(
    files: &mut Files,
    npz: &mut NpzArrays,
    format: DataFormat,
    dir: &str,
    name: &str,
    what: &str,
    values: &[f64],
    (w, h): (usize, usize),
    enc: Png16Encoding,
    preview: (f64, f64),
) -> Result<(), ExportError> {
    let stem = files::stem(name);
    array_file(
        files,
        npz,
        format,
        dir,
        name,
        &[h, w],
        &f32s(values),
        json!({"quantity": what, "units": "mm", "dtype": "float32", "shape": [h, w], "missing": "NaN"}),
    );
    let (counts, clipped) = enc.encode(values);
    let png = format!("{dir}/{stem}{}", files::PNG16_SUFFIX);
    let text = format!(
        "{what}; value_mm = (count - {}) * {}; count 0 = no value",
        enc.offset_counts, enc.scale
    );
    files.push((
        png.clone(),
        png_gray16(w, h, &counts, &[("Description", &text)])?,
        json!({"file": png, "quantity": what, "units": "um", "dtype": "uint16", "shape": [h, w],
               "value_mm": format!("(count - {}) * {}", enc.offset_counts, enc.scale), "scale_mm_per_count": enc.scale,
               "offset_counts": enc.offset_counts, "missing": 0, "clipped_pixels": clipped}),
    ));
    let pv = format!("{dir}/{stem}{}", files::PREVIEW_SUFFIX);
    let (w2, rgb) = with_colour_bar(
        w,
        h,
        &preview_rgb(values, preview.0, preview.1),
        preview.0,
        preview.1,
    );
    files.push((
        pv.clone(),
        png_rgb8(w2, h, &rgb, &[])?,
        json!({"file": pv, "quantity": format!("preview of {name}"), "colour_map": "turbo (d3, colorous)", "range_mm": [preview.0, preview.1], "missing": "black",
               "colour_bar": {"columns_px": [w, w2], "top_mm": preview.1, "bottom_mm": preview.0}}),
    ));
    Ok(())
}

/// Every file of a rendered frame (and of its difference to the reference, for a
/// configuration), in folder `dir`, maps previewed over `preview` (mm).
///
/// # Errors
/// [`ExportError`] of a PNG or NPZ encoder.
pub fn frame_files(
    dir: &str,
    f: &DepthFrame,
    reference: Option<&DepthFrame>,
    preview: (f64, f64),
    provenance: &str,
    format: DataFormat,
) -> Result<Files, ExportError> {
    let (w, h) = (f.width, f.height);
    let mut files = Files::new();
    let mut npz = NpzArrays::new();
    scalar_files(
        &mut files,
        &mut npz,
        format,
        dir,
        files::MAPS[0],
        "range: distance along the pixel's ray from the camera centre to the elastomer surface",
        &f.range_mm,
        (w, h),
        DEPTH_PNG,
        preview,
    )?;
    scalar_files(
        &mut files,
        &mut npz,
        format,
        dir,
        files::MAPS[1],
        "z-depth: z of the surface point in the camera frame",
        &f.zdepth_mm,
        (w, h),
        DEPTH_PNG,
        preview,
    )?;
    let normals: Vec<f32> = f
        .normal_cam
        .iter()
        .flat_map(|n| n.map(|c| c as f32))
        .collect();
    array_file(
        &mut files,
        &mut npz,
        format,
        dir,
        files::NORMALS,
        &[h, w, 3],
        &normals,
        json!({"quantity": "unit normal of the elastomer surface, pointing out of the elastomer, camera frame", "units": "1", "dtype": "float32", "shape": [h, w, 3], "missing": "NaN"}),
    );
    let np = format!("{dir}/{}{}", files::NORMALS, files::PREVIEW_SUFFIX);
    files.push((np.clone(), png_rgb8(w, h, &normals_rgb(&f.normal_cam), &[])?, json!({"file": np, "quantity": "preview of the unit normals: rgb = (n + 1) / 2", "missing": "black"})));
    if format == DataFormat::Npy {
        ply_file(&mut files, dir, f, provenance);
    }
    if let Some(r) = reference {
        let (dr, dz) = f.delta(r);
        let lo = finite_range(&dr)
            .map(|x| x.0)
            .unwrap_or(0.0)
            .min(finite_range(&dz).map(|x| x.0).unwrap_or(0.0));
        let pr = (if lo < 0.0 { lo } else { -0.001 }, 0.0);
        scalar_files(&mut files, &mut npz, format, dir, files::DELTA_MAPS[0], "differential range: indented minus reference (negative where the skin is pushed towards the camera)", &dr, (w, h), DELTA_PNG, pr)?;
        scalar_files(
            &mut files,
            &mut npz,
            format,
            dir,
            files::DELTA_MAPS[1],
            "differential z-depth: indented minus reference",
            &dz,
            (w, h),
            DELTA_PNG,
            pr,
        )?;
        let mask: Vec<u8> = f
            .contact_mask(r)
            .iter()
            .map(|&c| if c { 255 } else { 0 })
            .collect();
        let cm = format!("{dir}/{}", files::CONTACT_MASK);
        files.push((cm.clone(), png_gray8(w, h, &mask, &[])?, json!({"file": cm, "quantity": "contact mask: 255 where a protrusion pushes the skin in (the surface seen is a protrusion), else 0", "dtype": "uint8", "shape": [h, w]})));
    }
    if format == DataFormat::Npz {
        let file = format!("{dir}/{}", files::ARRAYS_NPZ);
        let bytes = npz_file(
            &npz.iter()
                .map(|(n, b, _)| (n.as_str(), b.as_slice()))
                .collect::<Vec<_>>(),
        )?;
        let arrays: serde_json::Map<String, Value> =
            npz.into_iter().map(|(n, _, m)| (n, m)).collect();
        files.push((
            file.clone(),
            bytes,
            json!({"file": file, "quantity": "the float32 maps of this frame (numpy.load: a mapping from name to array)", "arrays": arrays}),
        ));
    }
    Ok(files)
}

/// What the rendered images leave out, in the manifest and the guide.
pub const IMAGES_NOT_MODELLED: &str = "refraction through the clear layers between the camera and the reflective surface (rays are straight from the camera centre); light scattered inside the elastomer; light reflected from one part of the skin onto another; the skin's deformation around a protrusion (the indented surface is the skin minus the protrusion solids); the dimples in the depth maps (the images show them, the depth is of the skin without them); penumbrae (each LED is a point: shadows have hard edges); the markers' own relief and their parallax (a marker is albedo on the reference surface at its normal's foot); fluorescence under UV LEDs (UV light is drawn as violet); lens blur, motion blur and rolling shutter";

/// Where the images of `--images` come from.
pub enum ImageSource {
    /// The design's optics through the physical image model.
    Physical(Box<Imaging>),
    /// The sensor's photometric model (`--photometric DIR`), with the folder and the sha256
    /// of its photometric.json.
    Photometric(Box<PhotometricModel>, String, String),
}

impl ImageSource {
    /// The design's optics through the physical image model ([`Imaging::new`]: the exposure
    /// set on the reference image, the vignetting centred on the principal point
    /// `principal_px`).
    ///
    /// # Errors
    /// The design's optics do not resolve (the error names the parameter path).
    pub fn of_design(
        design: &fabkit_designs::Design,
        principal_px: [f64; 2],
        rays: &PixelRays,
        reference_hits: &SurfaceHits,
    ) -> Result<Imaging, fabkit_designs::DesignError> {
        let optics = fabkit_designs::optics::of_design(design, Default::default())?;
        Ok(Imaging::new(optics, principal_px, rays, reference_hits))
    }

    /// Bits per channel of the images: the design's camera's, or the model's captures'.
    pub fn bits(&self) -> u32 {
        match self {
            ImageSource::Physical(im) => im.optics.camera.bit_depth,
            ImageSource::Photometric(m, ..) => {
                if m.full_scale > 255.0 {
                    16
                } else {
                    8
                }
            }
        }
    }
}

/// The rendered image of a frame (`--images`): `dir/image.png`, RGB at the source's bit
/// depth, on the depth maps' pixel grid; from the design's optics its noise is that of frame
/// `frame` of the set, from a photometric model it is the model's noise-free image.
///
/// # Errors
/// [`ExportError`] of the PNG encoder.
#[allow(clippy::too_many_arguments)]
pub fn image_file(
    dir: &str,
    src: &ImageSource,
    rays: &PixelRays,
    reference: &SurfaceHits,
    hits: &SurfaceHits,
    protrusions: Option<&ExactPrimitives>,
    frame: u64,
) -> Result<(String, Vec<u8>, Value), ExportError> {
    let (w, h) = (rays.width, rays.height);
    let bits = src.bits();
    let full = ((1u32 << bits) - 1) as u16;
    let (img, text) = match src {
        ImageSource::Physical(im) => (
            im.image(rays, reference, hits, protrusions, frame),
            format!(
                "fabkit rendered tactile image, frame {frame}: RGB, {bits} bit; the skin lit by the design's lights, exposure gain {}",
                im.gain
            ),
        ),
        ImageSource::Photometric(m, folder, _) => (
            m.image(rays, reference, hits, protrusions),
            format!("fabkit rendered tactile image: RGB, {bits} bit; the sensor's photometric model from {folder}"),
        ),
    };
    let saturated = img.iter().filter(|p| p.contains(&full)).count();
    let file = format!("{dir}/{}", files::IMAGE);
    let meta = [("Description", text.as_str())];
    let bytes = if bits == 16 {
        png_rgb16(w, h, &img, &meta)?
    } else {
        let rgb: Vec<u8> = img.iter().flat_map(|p| p.map(|c| c as u8)).collect();
        png_rgb8(w, h, &rgb, &meta)?
    };
    Ok((
        file.clone(),
        bytes,
        json!({"file": file, "quantity": "the tactile image the camera sees: the surface of this frame under the design's lights, with its shadows, the camera's gain, vignetting and noise (see images in the manifest)",
               "dtype": if bits == 16 { "uint16" } else { "uint8" }, "shape": [h, w, 3], "channels": "RGB",
               "bit_depth": bits, "noise_frame": frame, "saturated_pixels": saturated}),
    ))
}

/// The surface points of a frame with their normals as binary PLY.
fn ply_file(files: &mut Files, dir: &str, f: &DepthFrame, provenance: &str) {
    let w = f.width;
    let pts: Vec<PlyPoint> = (0..w * f.height)
        .filter(|&p| f.range_mm[p].is_finite())
        .map(|p| PlyPoint {
            xyz: f.point_cam_mm[p].map(|c| c as f32),
            normal: f.normal_cam[p].map(|c| c as f32),
            u: (p % w) as u16,
            v: (p / w) as u16,
            contact: f.contact[p] as u8,
        })
        .collect();
    let ply = format!("{dir}/{}", files::POINTS);
    let comments = vec![
        "frame: camera (x right, y down, z forward; docs/conventions.md), mm".to_string(),
        "properties: point, unit normal out of the elastomer, pixel (u column, v row), contact (1 on a protrusion)".to_string(),
        provenance.to_string(),
    ];
    files.push((ply.clone(), ply_points(&pts, &comments), json!({"file": ply, "quantity": "surface points with normals, one per pixel that sees the surface", "frame": "camera", "units": "mm", "points": pts.len()})));
}

/// A bound on the size of a PNG of `raw` pixel bytes in `rows` rows: the filter byte of each
/// row, deflate's stored-block worst case (5 bytes per 16 KiB) and the chunks around it.
fn png_bound(raw: u64, rows: u64) -> u64 {
    let filtered = raw + rows;
    filtered + filtered / 16_384 * 5 + 1024
}

/// Files and bytes of the output, (files, bytes): the files exactly, the bytes as an upper
/// bound (float arrays and PLY at their exact sizes, PNG and NPZ at deflate's worst case, the
/// manifest and pairs.csv generously), for a `w` x `h` camera, `n_cfg` configurations and
/// `n_patterns` patterns, with an RGB image of `image_bits` bits per channel per frame
/// (`--images`).
pub fn output_bound(
    w: u64,
    h: u64,
    n_cfg: u64,
    n_patterns: u64,
    format: DataFormat,
    image_bits: Option<u32>,
) -> (u64, u64) {
    let px = w * h;
    let frame = |delta: bool| -> (u64, u64) {
        let (mut files, mut bytes, mut arrays) = (0u64, 0u64, Vec::new());
        if let Some(bits) = image_bits {
            files += 1;
            bytes += png_bound(3 * px * u64::from(bits.div_ceil(8)), h);
        }
        let maps = if delta { 4 } else { 2 };
        for _ in 0..maps {
            arrays.push(4 * px + 128);
            files += 2;
            bytes += png_bound(2 * px, h) + png_bound(3 * px, h);
        }
        arrays.push(12 * px + 128);
        files += 1;
        bytes += png_bound(3 * px, h);
        if delta {
            files += 1;
            bytes += png_bound(px, h);
        }
        match format {
            DataFormat::Npy => {
                files += arrays.len() as u64 + 1;
                bytes += arrays.iter().sum::<u64>() + 33 * px + 4096;
            }
            DataFormat::Npz => {
                files += 1;
                bytes += arrays.iter().map(|a| a + a / 16_384 * 5 + 256).sum::<u64>() + 1024;
            }
            DataFormat::Png => {}
        }
        (files, bytes)
    };
    let (rf, rb) = frame(false);
    let (cf, cb) = frame(true);
    // two half masks, pairs.csv and the manifest
    let files = rf + n_cfg * cf + 4;
    let pairs = 128 * (n_patterns * n_patterns + 1);
    let bytes = rb + n_cfg * cb + 2 * png_bound(px, h) + pairs + 65_536 + 4096 * files;
    (files, bytes)
}

/// Written files: (relative path, sha256, bytes).
pub type Written = Vec<(String, String, usize)>;

/// An error of the sink the dataset's files are written to (or of their encoding).
pub type SinkError = Box<dyn std::error::Error + Send + Sync>;

/// Where a dataset's files go: called with each file's relative `/`-separated path and bytes,
/// from any thread.
pub type Sink<'a> = dyn Fn(&str, &[u8]) -> Result<(), SinkError> + Sync + 'a;

/// What a dataset's frames are rendered from: the camera's rays and the reference surface
/// they see, the body's base plane, the configurations, the array format, the image source
/// (`--images`) and the provenance line of the PLY files.
#[derive(Clone, Copy)]
pub struct FrameInputs<'a> {
    pub rays: &'a PixelRays,
    pub reference_hits: &'a SurfaceHits,
    pub base_z_mm: f64,
    pub fixtures: &'a Fixtures,
    pub format: DataFormat,
    pub imaging: Option<&'a ImageSource>,
    pub provenance: &'a str,
}

/// The manifest entries of a rendered dataset and its files.
#[derive(Debug)]
pub struct Rendered {
    /// The reference frame's files.
    pub reference: Vec<Value>,
    /// One entry per configuration, in the fixtures' order, with its files.
    pub configurations: Vec<Value>,
    /// The half masks and (for protrusion patterns) pairs.csv.
    pub masks_and_pairs: Vec<Value>,
    /// Every file written: (relative path, sha256, bytes), sorted by path.
    pub files: Written,
}

/// Renders every frame of a dataset (the reference, then the configurations in parallel, as
/// many at a time as the memory budget holds, [`super::budget::frames_at_once`]), hands each
/// file to `write` (relative `/`-separated path, bytes) as it is made, and calls `progress`
/// with the number of frames done. The half masks and, for protrusion patterns, pairs.csv
/// come last. The files and entries do not depend on the thread count.
///
/// # Errors
/// The first error of `write` or of an encoder.
pub fn render_frames(
    inputs: &FrameInputs<'_>,
    write: &Sink<'_>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, SinkError> {
    let FrameInputs {
        rays,
        reference_hits: ref_hits,
        fixtures,
        format,
        imaging,
        provenance,
        ..
    } = *inputs;
    let (w, h) = (rays.width, rays.height);
    let pin_captures = fixtures.configurations.iter().any(|c| !c.pins.is_empty());
    let reference = DepthFrame::new(rays, ref_hits);
    let preview = preview_range(&reference);
    let mut all: Vec<(String, String, usize)> = Vec::new();
    let mut ref_entries = put_files(
        write,
        frame_files(
            files::REFERENCE_DIR,
            &reference,
            None,
            preview,
            provenance,
            format,
        )?,
        &mut all,
    )?;
    if let Some(im) = imaging {
        ref_entries.extend(put_files(
            write,
            vec![image_file(
                files::REFERENCE_DIR,
                im,
                rays,
                ref_hits,
                ref_hits,
                None,
                0,
            )?],
            &mut all,
        )?);
    }
    progress(1);

    // Configurations in parallel, as many at a time as the memory budget holds; each writes
    // its own folder. Entries are kept in index order.
    let at_once = frames_at_once(w as u64 * h as u64, rayon::current_num_threads() as u64);
    let frames = ConfigurationFrames {
        inputs,
        write,
        progress,
        reference: &reference,
        preview,
        done: AtomicUsize::new(0),
    };
    let indexed: Vec<(usize, &Configuration)> =
        fixtures.configurations.iter().enumerate().collect();
    let rendered: Vec<Result<(Value, Written), String>> = indexed
        .chunks(at_once)
        .flat_map(|chunk| {
            chunk
                .par_iter()
                .copied()
                .map(|(k, cfg)| frames.render(k, cfg))
                .collect::<Vec<_>>()
        })
        .collect();
    let mut cfg_entries = Vec::new();
    for r in rendered {
        let (e, list) = r?;
        cfg_entries.push(e);
        all.extend(list);
    }

    let extra = masks_and_pairs(rays, ref_hits, fixtures, pin_captures)?;
    let extra_entries = put_files(write, extra, &mut all)?;
    all.sort();
    Ok(Rendered {
        reference: ref_entries,
        configurations: cfg_entries,
        masks_and_pairs: extra_entries,
        files: all,
    })
}

/// The range of the previews' colour map, mm: the least and greatest finite value of the
/// reference frame's range and z-depth maps ((0, 1) when it has none).
fn preview_range(reference: &DepthFrame) -> (f64, f64) {
    let preview = finite_range(&reference.range_mm)
        .into_iter()
        .chain(finite_range(&reference.zdepth_mm))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (lo, hi)| {
            (a.min(lo), b.max(hi))
        });
    if preview.0 <= preview.1 {
        preview
    } else {
        (0.0, 1.0)
    }
}

/// Hands each of `files` to `write` and adds it to `all` (path, sha256, bytes); returns their
/// manifest entries with their sha256.
///
/// # Errors
/// The first error of `write`.
fn put_files(
    write: &Sink<'_>,
    files: Files,
    all: &mut Vec<(String, String, usize)>,
) -> Result<Vec<Value>, SinkError> {
    let mut entries = Vec::new();
    for (rel, bytes, mut e) in files {
        write(&rel, &bytes)?;
        let sha = sha256_hex(&bytes);
        e["sha256"] = json!(sha);
        all.push((rel, sha, bytes.len()));
        entries.push(e);
    }
    Ok(entries)
}

/// What every configuration's frame is rendered with ([`render_frames`]): the inputs, the
/// sink, the progress callback, the reference frame, the previews' range, and the count of
/// frames done.
struct ConfigurationFrames<'a> {
    inputs: &'a FrameInputs<'a>,
    write: &'a Sink<'a>,
    progress: &'a (dyn Fn(u64) + Sync),
    reference: &'a DepthFrame,
    preview: (f64, f64),
    done: AtomicUsize,
}

impl ConfigurationFrames<'_> {
    /// Renders configuration `cfg` (index `k`): its depth files, then its image, each handed
    /// to the sink; returns its manifest entry and its files, and reports the frames done.
    ///
    /// # Errors
    /// The first error of the sink or of an encoder, as text.
    fn render(&self, k: usize, cfg: &Configuration) -> Result<(Value, Written), String> {
        let FrameInputs {
            rays,
            reference_hits: ref_hits,
            format,
            imaging,
            provenance,
            ..
        } = *self.inputs;
        let (w, h) = (rays.width, rays.height);
        let (reference, write) = (self.reference, self.write);
        let hits = indented_hits(rays, ref_hits, &cfg.primitives, self.inputs.base_z_mm);
        let frame = DepthFrame::new(rays, &hits);
        let files = frame_files(
            &cfg.name,
            &frame,
            Some(reference),
            self.preview,
            provenance,
            format,
        )
        .map_err(|e| e.to_string())?;
        let mut entries = Vec::new();
        let mut list = Vec::new();
        let mut put = |files: Files| -> Result<(), String> {
            for (rel, bytes, mut e) in files {
                write(&rel, &bytes).map_err(|e| e.to_string())?;
                let sha = sha256_hex(&bytes);
                e["sha256"] = json!(sha);
                list.push((rel, sha, bytes.len()));
                entries.push(e);
            }
            Ok(())
        };
        put(files)?;
        // The image after the depth files are written: its buffers take the place of theirs
        // in the frame's memory budget.
        if let Some(im) = imaging {
            let f = image_file(
                &cfg.name,
                im,
                rays,
                ref_hits,
                &hits,
                Some(&cfg.primitives),
                k as u64 + 1,
            )
            .map_err(|e| e.to_string())?;
            put(vec![f])?;
        }
        let contact = (0..w * h)
            .filter(|&p| frame.contact[p] && reference.range_mm[p].is_finite())
            .count();
        let (dr, _) = frame.delta(reference);
        let deepest = finite_range(&dr).map(|x| -x.0).unwrap_or(0.0).max(0.0);
        let k = self.done.fetch_add(1, Ordering::Relaxed) + 2;
        (self.progress)(k as u64);
        Ok((configuration_entry(cfg, contact, deepest, entries), list))
    }
}

/// The manifest entry of configuration `cfg`: its name, pattern or pins, fixture description,
/// `contact` pixels, `deepest` range decrease (mm) and its files' `entries`.
fn configuration_entry(
    cfg: &Configuration,
    contact: usize,
    deepest: f64,
    entries: Vec<Value>,
) -> Value {
    let mut entry = json!({
        "name": cfg.name, "dir": cfg.name, "pattern": cfg.pattern, "orientation_deg": cfg.orientation_deg,
        "pattern_side": if cfg.orientation_deg == 0 { "+x (right_mask.png)" } else { "-x (left_mask.png)" },
        "fixture_description": {"file": cfg.description_file, "sha256": cfg.description_sha256},
        "primitives": cfg.geometry.primitives.len(),
        "contact_pixels": contact, "max_range_decrease_mm": deepest,
        "files": entries,
    });
    if !cfg.pins.is_empty() {
        let e = entry.as_object_mut().expect("an object");
        for k in ["pattern", "orientation_deg", "pattern_side"] {
            e.remove(k);
        }
        e.insert("pins".into(), json!(cfg.pins));
    }
    entry
}

/// The half masks (`left_mask.png`, `right_mask.png`) and, unless the frames are pin captures,
/// pairs.csv, with their manifest entries.
///
/// # Errors
/// An encoder's.
fn masks_and_pairs(
    rays: &PixelRays,
    ref_hits: &SurfaceHits,
    fixtures: &Fixtures,
    pin_captures: bool,
) -> Result<Files, SinkError> {
    let (w, h) = (rays.width, rays.height);
    let (left, right) = half_masks(rays, ref_hits);
    let mut extra: Files = Vec::new();
    for (name, m, side) in [
        (files::LEFT_MASK, &left, "x < 0 (the -x half)"),
        (files::RIGHT_MASK, &right, "x >= 0 (the +x half)"),
    ] {
        let px: Vec<u8> = m.iter().map(|&b| if b { 255 } else { 0 }).collect();
        let count = m.iter().filter(|&&b| b).count();
        extra.push((name.into(), png_gray8(w, h, &px, &[])?, json!({"file": name, "quantity": format!("pixels whose ray meets the reference surface at sensor-frame {side}: 255, else 0"), "pixels": count})));
    }
    let n_pairs = fixtures.patterns.len() * fixtures.patterns.len();
    if !pin_captures {
        extra.push((
            files::PAIRS.into(),
            pairs_csv(&fixtures.patterns).into_bytes(),
            json!({"file": files::PAIRS, "pairs": n_pairs, "notes": PAIRS_NOTES}),
        ));
    }
    Ok(extra)
}

/// What a dataset's manifest.json says besides its files: the version and command line that
/// wrote it, the design, the camera and its file, the pose and its file, the fixtures, and the
/// image source (`--images`).
#[derive(Clone, Copy)]
pub struct ManifestInputs<'a> {
    pub fabkit_version: &'a str,
    pub command_line: &'a [String],
    pub design_name: &'a str,
    pub design_source: &'a str,
    pub design_sha256: &'a str,
    /// The design's skin is flat (semi-plates rather than semi-domes).
    pub flat_skin: bool,
    pub camera: &'a crate::CameraModel,
    pub camera_file: &'a str,
    /// The camera file's sha256; `None` for a camera that is not from a file (null).
    pub camera_sha256: Option<&'a str>,
    pub extrinsics_file: &'a str,
    /// The extrinsics file's sha256; `None` for a pose that is not from a file (null).
    pub extrinsics_sha256: Option<&'a str>,
    pub t_cam_sensor: &'a nalgebra::Isometry3<f64>,
    /// The camera centre in the sensor frame, mm.
    pub camera_centre_mm: [f64; 3],
    pub fixtures: &'a Fixtures,
    /// Pixels whose ray meets the reference skin.
    pub pixels_on_surface: usize,
    pub imaging: Option<&'a ImageSource>,
    /// The optical path the rays were bent along ([`super::inputs::read_optical_path`]'s
    /// summary); `None`: straight rays.
    pub optical_path: Option<&'a Value>,
}

/// The dataset's manifest.json ([`render_frames`] made `rendered`): what it is, its inputs,
/// its conventions (frames, units, the 16-bit PNG encodings, what is missing and what is not
/// modelled), every frame's files with their quantities, and the image model.
pub fn manifest(inputs: &ManifestInputs<'_>, rendered: &Rendered) -> Value {
    let ManifestInputs {
        fixtures, imaging, ..
    } = *inputs;
    let pin_captures = fixtures.configurations.iter().any(|c| !c.pins.is_empty());
    let (fixture_kind, surface_text) = if pin_captures {
        ("pin-dome", "outer skin surface (body profile at offset 0) from the pole to the base plane; indented: the skin minus the solids of the capture's pins (hemispherical tip, 45 deg cone, shaft)")
    } else if inputs.flat_skin {
        ("semi-plate", "the flat skin's contact face over its outline (its edges continued below the base plane bound the body); indented: the skin minus the protrusion solids")
    } else {
        ("semi-dome", "outer skin surface (body profile at offset 0) from the pole to the base plane; indented: the skin minus the protrusion solids")
    };
    let (ref_entries, cfg_entries, extra_entries, all) = (
        &rendered.reference,
        &rendered.configurations,
        &rendered.masks_and_pairs,
        &rendered.files,
    );
    let i = inputs.camera.intrinsics();
    let (w, h) = (i.image_width_px, i.image_height_px);
    let m = inputs.t_cam_sensor.to_homogeneous();
    let c = inputs.camera_centre_mm;
    let mut manifest = json!({
        "fabkit_version": inputs.fabkit_version,
        "command_line": inputs.command_line,
        "description": if pin_captures {
            "Ground-truth depth of the sensor surface, reference (undeformed) and indented by the pins of each capture of the pin dome (R-Tac0 Sec. IV-A, Fig. 5; the capture plan of points/capture_plan.csv): complete depth = reference + delta. Exact per-pixel rays of the camera model; surfaces in closed form.".to_string()
        } else {
            format!("Ground-truth depth of the sensor surface, reference (undeformed) and indented by each protrusion {} configuration (R-Tac0 Sec. IV-B, Fig. 6, Eq. (2)-(3)): complete depth = reference + delta. Exact per-pixel rays of the camera model; surfaces in closed form.", fixture_kind)
        },
        "design": {"name": inputs.design_name, "source": inputs.design_source, "sha256": inputs.design_sha256},
        "camera": {"file": inputs.camera_file, "sha256": inputs.camera_sha256, "distortion_model": i.distortion.name(),
                   "fx_px": i.fx_px, "fy_px": i.fy_px, "cx_px": i.cx_px, "cy_px": i.cy_px, "distortion_coefficients": i.distortion.coefficients(),
                   "image_width_px": w, "image_height_px": h},
        "extrinsics": {"file": inputs.extrinsics_file, "sha256": inputs.extrinsics_sha256,
                       "T_cam_sensor": (0..4).map(|r| (0..4).map(|c| m[(r, c)]).collect::<Vec<_>>()).collect::<Vec<_>>(),
                       "camera_centre_in_sensor_mm": c},
        "fixtures": if pin_captures {
            json!({"dir": fixtures.dir.display().to_string(), "capture_plan_sha256": fixtures.index_sha256, "pin_captures": fixtures.configurations.len()})
        } else {
            json!({"dir": fixtures.dir.display().to_string(), "index_sha256": fixtures.index_sha256, "patterns": fixtures.patterns})
        },
        "conventions": {
            "pixels": "(u, v) = (column, row); (0, 0) is the centre of the top-left pixel; arrays are (H, W) row-major",
            "camera_frame": "x right, y down, z forward (docs/conventions.md)",
            "sensor_frame": "docs/conventions.md; split plane x = 0",
            "range_mm": "distance along the pixel's ray from the camera centre to the surface, mm",
            "zdepth_mm": "z of the surface point in the camera frame, mm (= range * bearing z)",
            "delta": "indented minus reference, mm (negative where the skin is pushed towards the camera, 0 elsewhere)",
            "surface": surface_text,
            "missing": "a pixel whose ray misses the skin (or does not unproject) is NaN in float files, 0 in integer files, and in no mask",
            "png16": {"depth": {"scale_mm_per_count": DEPTH_PNG.scale, "offset_counts": DEPTH_PNG.offset_counts},
                      "delta": {"scale_mm_per_count": DELTA_PNG.scale, "offset_counts": DELTA_PNG.offset_counts},
                      "value_mm": "(count - offset_counts) * scale_mm_per_count; count 0 = no value (also values that do not fit, counted as clipped_pixels)"},
            "not_modelled": "refraction in the elastomer and the core; the skin's deformation around a protrusion (the indented surface is the skin minus the protrusion solids)",
        },
        "image": {"width_px": w, "height_px": h, "pixels_on_surface": inputs.pixels_on_surface},
        "reference": {"dir": files::REFERENCE_DIR, "files": ref_entries},
        "configurations": cfg_entries,
        "masks_and_pairs": extra_entries,
        "files": all.iter().map(|(f, s, b)| json!({"file": f, "sha256": s, "bytes": b})).collect::<Vec<_>>(),
    });
    if let Some(path) = inputs.optical_path {
        manifest["optical_path"] = path.clone();
        let c = &mut manifest["conventions"];
        c["range_mm"] = json!("distance from the camera centre to the surface point, mm (the pixel's ray is bent by Snell's law at each plane and curved face of optical_path, so the hit is not on the straight bearing)");
        c["zdepth_mm"] = json!("z of the surface point in the camera frame, mm");
        c["not_modelled"] = json!("refraction at faces that are not planes or spheres on cylinders (a half-ellipsoidal core); the clear layers' faces moving under a protrusion (they bend the rays where the design puts them); the skin's deformation around a protrusion (the indented surface is the skin minus the protrusion solids)");
    }
    if let Some(ImageSource::Photometric(_, dir, sha)) = imaging {
        manifest["images"] = json!({
            "file": "image.png in reference/ and in each configuration's folder",
            "model": "the sensor's photometric model (fabkit calibrate photometric): per channel the appearance of every pixel times one plus its fitted response to the surface's tilt and indentation (calibration/src/photometric.rs); the model's mean image, no noise",
            "photometric": {"dir": dir, "photometric_json_sha256": sha},
            "not_modelled": "lights at a few azimuths (the spatial term and the shadows' light rings are round the optical axis); refraction; the skin's deformation around a protrusion",
        });
    }
    if let Some(ImageSource::Physical(im)) = imaging {
        manifest["images"] = json!({
            "file": "image.png in reference/ and in each configuration's folder",
            "model": "each light a point emitter with a cosine beam inside its cone, inverse-square fall-off and the incidence cosine; the surface Lambertian (albedo_rgb) plus a normalised Blinn-Phong lobe (specular, roughness); a light is shadowed where the segment to it enters a protrusion; then gain, vignetting 1 - v (r / r_corner)^2 about the principal point, photon noise (Gaussian with the Poisson variance of the signal's electrons) and read noise, clipped and quantised (calibration/src/groundtruth/shading.rs)",
            "lights": im.optics.lights.iter().zip(&im.optics.light_sources).map(|(l, src)| {
                let mut v = serde_json::to_value(l).unwrap_or(Value::Null);
                v["source"] = json!(src);
                v
            }).collect::<Vec<_>>(),
            "surface": im.optics.surface,
            "dimples": {
                "patterns": im.optics.dimple_sources.iter().map(|(src, n)| json!({"source": src, "count": n})).collect::<Vec<_>>(),
                "drawn_as": "solids in the surface the camera sees: the recessed features of the outer skin surface, each a cylinder with a hemispherical end standing towards the camera, which shade and cast shadows (ShadowTac Sec. III-A); moved with the skin as the markers are",
            },
            "markers": {
                "albedo_rgb": im.optics.marker_albedo_rgb,
                "patterns": im.optics.marker_sources.iter().map(|(src, n)| json!({"source": src, "count": n})).collect::<Vec<_>>(),
                "drawn_as": "albedo on the skin's reference surface: the points within the feature's radius of the marker's centre, moved along its normal onto the reference surface; raised features only (pins, painted ends, ink-filled protrusions)",
                "motion": "normal displacement only: a marker a protrusion pushes in moves along its normal to the protrusion's surface, keeping its size; the skin's stretch along the surface is not modelled",
            },
            "camera": im.optics.camera,
            "gain": im.gain,
            "exposure": if im.auto_exposed { "set on the reference image (its 99th-percentile pixel at 0.8 of full scale; optics.camera.gain not given) and held for every frame" } else { "optics.camera.gain, every frame" },
            "noise": "seeded (optics.camera.seed): each frame draws its own noise (noise_frame: 0 for the reference, i + 1 for configuration i); the same seed gives the same bytes",
            "not_modelled": IMAGES_NOT_MODELLED,
        });
        if inputs.optical_path.is_some() {
            manifest["images"]["not_modelled"] = json!(IMAGES_NOT_MODELLED.replacen(
                IMAGES_REFRACTION,
                IMAGES_REFRACTION_THROUGH_PATH,
                1
            ));
        }
        if let Some(k) = im.optics.surface.darkness_per_mm {
            manifest["images"]["darkness_mapping"] = json!(format!(
                "optics.surface.darkness_per_mm = {k}: a pressed point returns what its unpressed point returned times 1 - {k} x its sink along that point's normal (mm), at least 0; no protrusion casts a shadow on the skin (its light is scattered within its translucent layer; DTact, Lin et al., ICRA 2023; calibration/src/groundtruth/shading.rs)"
            ));
        }
    }
    manifest
}

/// The first clause of [`IMAGES_NOT_MODELLED`], for straight rays.
const IMAGES_REFRACTION: &str = "refraction through the clear layers between the camera and the reflective surface (rays are straight from the camera centre)";
/// ... and in its place when the camera's rays are bent at the optical path's planes.
const IMAGES_REFRACTION_THROUGH_PATH: &str = "refraction of the light (the camera's rays bend at the planes and curved faces of optical_path; the LEDs' rays to the skin are straight, without Fresnel losses at them)";

/// Default bound on a dataset's bytes, refused above it unless asked for (`--max-output-bytes`,
/// `max_output_bytes=`): 1 GB.
pub const DEFAULT_MAX_OUTPUT_BYTES: u64 = 1_000_000_000;
/// Largest bound on a dataset's bytes: 1 PB.
pub const MAX_OUTPUT_BYTES_LIMIT: u64 = 1_000_000_000_000_000;

/// The provenance line of the dataset's PLY files: fabkit's version, the design's name and
/// the sha256 of its text.
pub fn provenance(design_name: &str, design_sha256: &str) -> String {
    format!(
        "fabkit {} groundtruth, design {design_name} (sha256 {design_sha256})",
        env!("CARGO_PKG_VERSION")
    )
}

/// What a dataset is rendered from, for its claim on the output folder
/// ([`claim`]).
pub struct ClaimInputs<'a> {
    /// The design as named: a library design's name or a design file's path.
    pub design: &'a str,
    pub preset: Option<&'a str>,
    pub camera_file: &'a Path,
    pub extrinsics_file: &'a Path,
    pub fixtures_dir: &'a Path,
    pub pin_captures: bool,
}

/// The dataset's claim on its output folder: ground truth of the design (by name, or its
/// file's content), the camera file, the extrinsics and the fixtures folder (its marker lists
/// the SHA-256 of every file in it; its protrusion index, or its point table, capture plan and
/// manifest, count when there is no marker). `force` replaces earlier ground truth of other
/// inputs.
pub fn claim(inputs: &ClaimInputs<'_>, force: bool) -> OutputClaim {
    let design_file = Path::new(inputs.design);
    let fixtures_marker = inputs.fixtures_dir.join(fabkit_export::OUTPUT_MARKER);
    let points = inputs.fixtures_dir.join("points");
    let fixture_files = if inputs.pin_captures {
        vec![
            points.join("point_table.csv"),
            points.join("capture_plan.csv"),
            inputs.fixtures_dir.join("manifest.json"),
        ]
    } else {
        vec![inputs.fixtures_dir.join("protrusions").join("index.json")]
    };
    let mut files: Vec<&Path> = vec![inputs.camera_file, inputs.extrinsics_file, &fixtures_marker];
    files.extend(fixture_files.iter().map(PathBuf::as_path));
    if design_file.is_file() {
        files.push(design_file);
    }
    let what = match inputs.preset {
        Some(p) => format!("ground truth of design '{}' preset '{p}'", inputs.design),
        None => format!("ground truth of design '{}'", inputs.design),
    };
    OutputClaim::of_inputs(OutputCommand::Groundtruth, &what, &files, force)
}

/// Renders the dataset into `staged` ([`render_frames`], `progress` with the frames done) and
/// writes its manifest.json ([`manifest`]) last; the caller commits the folder. Returns every
/// file written but the manifest: (relative path, sha256, bytes), sorted by path.
///
/// # Errors
/// The first error of an encoder or of writing a file.
pub fn write(
    staged: &StagedDir,
    frames: &FrameInputs<'_>,
    manifest_inputs: &ManifestInputs<'_>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Written, SinkError> {
    let rendered = render_frames(
        frames,
        &|rel, bytes| staged.write(rel, bytes).map_err(Into::into),
        progress,
    )?;
    let manifest = manifest(manifest_inputs, &rendered);
    let mut text = serde_json::to_vec_pretty(&manifest)?;
    text.push(b'\n');
    staged.write(files::MANIFEST, &text)?;
    Ok(rendered.files)
}
