//! `fabkit calibrate photometric`: the sensor's photometric model fitted from pin captures
//! (fabkit-calibration `photometric`), with each capture re-rendered from the model fitted on
//! the others (leave-one-out).

use std::error::Error;
use std::path::{Path, PathBuf};

use fabkit_calibration::capture_images::read_rgb;
use fabkit_calibration::groundtruth::exact::ExactPrimitives;
use fabkit_calibration::groundtruth::inputs::{read_extrinsics, sha256_hex};
use fabkit_calibration::groundtruth::{indented_hits, reference_hits, Scene, SurfaceHits};
use fabkit_calibration::imprints::ids_from_file_name;
use fabkit_calibration::photometric::{
    capture_fault, image_fault, read_pins, rms_over_skin, shadow_map, Capture, PhotometricModel,
    ShadowMap, ShadowRings,
};
use fabkit_export::raster::{npy_f32, png_rgb16, png_rgb8};
use fabkit_export::{OutputClaim, OutputCommand, StagedDir};
use serde_json::{json, Value};

use crate::args::{load_design, DataFileArgs};

#[derive(clap::Args, Debug)]
pub struct PhotometricArgs {
    /// A design YAML file or the name of a library design (default: rtac0): its skin is the
    /// surface the pins press.
    design: Option<String>,
    #[command(flatten)]
    cam: crate::args::CameraArgs,
    /// extrinsics.json of `fabkit calibrate extrinsics` (T_cam_sensor) for these captures.
    #[arg(long, value_name = "extrinsics.json")]
    extrinsics: PathBuf,
    /// Output folder of `fabkit fixtures` with the pin dome: its point table (tips and axes)
    /// and the pin's shape (manifest.json).
    #[arg(long, value_name = "FIXTURES_DIR")]
    fixtures: PathBuf,
    /// Reference image of the unloaded skin (same camera, lighting and exposure).
    #[arg(long, value_name = "REF.png")]
    reference: PathBuf,
    /// Capture images (PNG or JPEG, the camera's size, all of one bit depth), at least two,
    /// each named by the pins it holds (01_02_06_14_22.png: pins 1, 2, 6, 14 and 22).
    #[arg(long, value_name = "CAPTURE.png", num_args = 2.., required = true)]
    images: Vec<PathBuf>,
    /// Output folder for photometric.json, appearance.npy and rerendered/: missing, empty, or
    /// an earlier fit of the same inputs as fabkit wrote it (replaced whole).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Replace an earlier fit in --out computed from other inputs.
    #[arg(long)]
    force: bool,
    #[command(flatten)]
    data_files: DataFileArgs,
}

/// One capture read and posed: its file, pin ids, image and surface.
struct Posed {
    file: PathBuf,
    ids: Vec<String>,
    image: Vec<[f64; 3]>,
    hits: SurfaceHits,
    shadows: ShadowMap,
}

pub fn run(a: PhotometricArgs) -> Result<(), Box<dyn Error>> {
    let t0 = std::time::Instant::now();
    let design_arg = a
        .design
        .as_deref()
        .unwrap_or(fabkit_designs::library::DEFAULT_DESIGN);
    let point_table = a.fixtures.join("points").join("point_table.csv");
    let fixtures_manifest = a.fixtures.join("manifest.json");
    let mut inputs: Vec<&Path> = vec![
        &a.cam.camera,
        &a.extrinsics,
        &point_table,
        &fixtures_manifest,
        &a.reference,
    ];
    inputs.extend(a.images.iter().map(PathBuf::as_path));
    let design_file = Path::new(design_arg);
    if design_file.is_file() {
        inputs.push(design_file);
    }
    let claim = OutputClaim::of_inputs(
        OutputCommand::CalibratePhotometric,
        &format!("photometric model of design '{design_arg}'"),
        &inputs,
        a.force,
    );
    fabkit_export::check_out_dir(&a.out, &claim)?;
    let loaded = load_design(a.design.as_deref(), &a.data_files)?;
    let design = &loaded.design;
    let camera = a.cam.read()?;
    let i = camera.intrinsics();
    let size = (i.image_width_px, i.image_height_px);
    // every per-pixel array of the fit is sized by the camera: bounded before any is allocated,
    // as groundtruth bounds its render (issue 95: 16384 x 16384 aborted at 3.9 GB)
    let limit = fabkit_calibration::groundtruth::budget::MAX_PIXELS_LIMIT;
    let pixels = u64::from(size.0) * u64::from(size.1);
    if pixels > limit {
        return Err(format!(
            "{}: the camera image is {} x {} = {pixels} pixels, over the limit of {limit} pixels (2048 x 2048) that the fit's per-pixel arrays hold in its memory budget (hint: calibrate the camera at a lower resolution or crop its image)",
            a.cam.camera.display(),
            size.0,
            size.1
        )
        .into());
    }
    let camera_name = a.cam.camera.display().to_string();
    let (_, camera_sha) = fabkit_calibration::groundtruth::inputs::read_with_hash(&a.cam.camera)?;
    let (t_cam_sensor, extrinsics_sha) = read_extrinsics(&a.extrinsics)?;
    let pins = read_pins(&a.fixtures)?;
    // the pin dome of this design, as groundtruth --pin-captures checks it
    fabkit_calibration::groundtruth::pins::check_made_for(&a.fixtures, &design.name)?;
    let pose_name = a.extrinsics.display().to_string();
    // the rays bend where the pose was solved through an optical path, as groundtruth bends
    // them: the model's shading registers with the captures
    let optical_path = fabkit_calibration::groundtruth::inputs::read_optical_path(&a.extrinsics)?;
    let Scene { surface, rays } = Scene::through(
        design,
        &camera,
        &t_cam_sensor,
        &pose_name,
        optical_path.as_ref().map(|(l, _)| l),
    )?;
    // and of its skin, whatever the design's name (issue 95: R-Tac0's dome fitted to R15.3)
    fabkit_calibration::groundtruth::pins::check_on_skin(&a.fixtures, &pins, &surface)?;
    let reference = reference_hits(&rays, &surface);
    let rings = ShadowRings::of(&rays, &reference);
    let (reference_image, full_scale) = read_rgb(&a.reference, "--reference", size, &camera_name)?;
    let mut posed = Vec::new();
    // each capture once: no file twice, no two files of the same pins, no pin twice in one
    let mut seen: Vec<(&Path, Vec<u32>)> = Vec::new();
    let mut listed: Vec<Vec<u32>> = Vec::new();
    for file in &a.images {
        let name = file.display().to_string();
        let ids = ids_from_file_name(file)
            .filter(|ids| !ids.is_empty())
            .ok_or_else(|| {
                format!("--images = {name}: the file name must list the capture's pins in ring order, e.g. 01_02_06_14_22.png")
            })?;
        if let Some((id, times)) = fabkit_calibration::imprints::repeated_pin(&ids) {
            return Err(format!(
                "--images = {name}: pin {id} listed {times} times; a capture presses each pin once"
            )
            .into());
        }
        let mut sorted = ids.clone();
        sorted.sort_unstable();
        let same = |p: &Path| {
            p == file.as_path()
                || matches!(
                    (std::fs::canonicalize(p), std::fs::canonicalize(file)),
                    (Ok(a), Ok(b)) if a == b
                )
        };
        if let Some((first, _)) = seen.iter().find(|(p, s)| same(p) || *s == sorted) {
            return Err(format!(
                "--images = {name}: given twice (as {}, the same pins); give each capture once",
                first.display()
            )
            .into());
        }
        seen.push((file.as_path(), sorted));
        listed.push(ids);
    }
    for (file, ids) in a.images.iter().zip(&listed) {
        let name = file.display().to_string();
        let ids: Vec<String> = ids.iter().map(u32::to_string).collect();
        let prims = pins.primitives(&ids).map_err(|id| {
            format!(
                "--images = {name}: pin {id} is not in {}",
                point_table.display()
            )
        })?;
        let (image, scale) = read_rgb(file, "--images", size, &camera_name)?;
        if scale != full_scale {
            return Err(format!(
                "--images = {name}: {} bit, but --reference {} is {} bit; give the images at one bit depth",
                if scale > 255.0 { 16 } else { 8 },
                a.reference.display(),
                if full_scale > 255.0 { 16 } else { 8 }
            )
            .into());
        }
        let prims = ExactPrimitives::new(&prims).map_err(|e| format!("--images = {name}: {e}"))?;
        if prims.contains(rays.origin_mm) {
            return Err(format!("{pose_name}: the camera centre is inside a pin of {name}").into());
        }
        let hits = indented_hits(&rays, &reference, &prims, surface.base_z_mm());
        let shadows = shadow_map(&rays, &hits, &prims, &rings);
        posed.push(Posed {
            file: file.clone(),
            ids,
            image,
            hits,
            shadows,
        });
    }
    let all: Vec<Capture> = posed
        .iter()
        .map(|p| Capture {
            image: &p.image,
            hits: &p.hits,
            shadows: &p.shadows,
        })
        .collect();
    // a frame the camera saw no imprint in (a copy of the reference, an unpressed, dark or
    // white frame) fits nothing: refused by file before the fit (issue 95: it "fitted within
    // 0.00 counts" to an all-zero model)
    if let Some(f) = image_fault(&reference, &reference_image, full_scale) {
        return Err(format!("--reference = {}: {f}", a.reference.display()).into());
    }
    for (p, c) in posed.iter().zip(&all) {
        if let Some(f) = capture_fault(&reference, &reference_image, c, full_scale) {
            return Err(format!("--images = {}: {f}", p.file.display()).into());
        }
    }
    let model = PhotometricModel::fit(&rays, &reference, &reference_image, &all, full_scale)?;
    // Each capture from the model fitted on the others.
    let mut loo = Vec::new();
    for k in 0..posed.len() {
        let others: Vec<Capture> = (0..posed.len())
            .filter(|&j| j != k)
            .map(|j| all[j])
            .collect();
        let m = PhotometricModel::fit(&rays, &reference, &reference_image, &others, full_scale)
            .map_err(|e| format!("leaving out {}: {e}", posed[k].file.display()))?;
        let gain = m.gain_of(&posed[k].image, &posed[k].hits);
        let again = m.render(&rays, &reference, &posed[k].hits, &posed[k].shadows, gain);
        loo.push((rms_over_skin(&again, &posed[k].image), again));
    }

    let staged = StagedDir::new(&a.out, claim)?;
    let (w, h) = (rays.width, rays.height);
    let mut files: Vec<Value> = Vec::new();
    let mut put = |rel: &str, bytes: Vec<u8>| -> Result<(), Box<dyn Error>> {
        staged.write(rel, &bytes)?;
        files.push(json!({"file": rel, "sha256": sha256_hex(&bytes), "bytes": bytes.len()}));
        Ok(())
    };
    let appearance: Vec<f32> = model
        .reference
        .iter()
        .flat_map(|p| p.map(|x| x as f32))
        .collect();
    put("appearance.npy", npy_f32(&[h, w, 3], &appearance))?;
    let mut captures = Vec::new();
    for (k, p) in posed.iter().enumerate() {
        let stem = p
            .file
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_else(|| format!("capture_{k}"));
        let rel = format!("rerendered/{stem}.png");
        let img = &loo[k].1;
        let counts = |x: f64| if x.is_finite() { x.round() } else { 0.0 };
        let bytes = if full_scale > 255.0 {
            let px: Vec<[u16; 3]> = img.iter().map(|q| q.map(|x| counts(x) as u16)).collect();
            png_rgb16(w, h, &px, &[])?
        } else {
            let px: Vec<u8> = img
                .iter()
                .flat_map(|q| q.map(|x| counts(x) as u8))
                .collect();
            png_rgb8(w, h, &px, &[])?
        };
        put(&rel, bytes)?;
        captures.push(json!({
            "file": p.file.display().to_string(), "pins": p.ids, "gain": model.gains[k],
            "fit_rms_counts": model.residual_rms[k], "leave_one_out_rms_counts": loo[k].0,
            "rerendered": rel,
        }));
    }
    let report = json!({
        "fabkit_version": env!("CARGO_PKG_VERSION"),
        "command_line": std::env::args().collect::<Vec<_>>(),
        "description": "Photometric model of the sensor: per channel I(x, n) = gain x R(x) x (1 + sum_km c_km P_m(x) f_k(n, x) + sum_l w_l G_l(x, n) - sum_j b_j S_j(x)); R: appearance.npy (H, W, 3 float32 counts, NaN off the skin), the median of the reference and the captures' unpressed pixels over their gains; f_k: the change of the surface normal from the reference normal in the local frame about the optical axis (a along the tangent away from the axis, r round it, c along the reference normal: 1 - cos of the tilt), the monomials of a and r to degree 3 and the indentation depth along the ray (mm); P_m: powers of the pixel's distance from the image centre over the half-diagonal; G_l: the change of candidate point light l's Lambertian irradiance (incidence cosine over squared distance; 0 where the protrusions block it) from the reference surface to the pressed one, over the sum of all candidates' irradiance of the reference, weighted by w_l (the last light_terms numbers of each coefficients list); S_j: the share of candidate light ring j's light the protrusions block at the pixel (shadows, also beside the imprints), weighted by b_j (calibration/src/photometric.rs)",
        "design": {"name": design.name, "source": loaded.source, "sha256": loaded.sha256},
        "camera": {"file": camera_name, "sha256": camera_sha, "image_width_px": w, "image_height_px": h},
        "extrinsics": {"file": pose_name, "sha256": extrinsics_sha},
        "fixtures": a.fixtures.display().to_string(),
        "model": model.model_json(),
        "captures": captures,
        "files": files,
    });
    let mut text = serde_json::to_vec_pretty(&report)?;
    text.push(b'\n');
    staged.write("photometric.json", &text)?;
    for w in staged.commit()? {
        eprintln!("warning: {w}");
    }
    let worst = loo.iter().map(|l| l.0).fold(0.0f64, f64::max);
    out!(
        "{}: photometric model from {} captures, fit within {:.2} counts RMS, each capture re-rendered from the others within {:.2} -> {} ({:.2} s)",
        design.name,
        posed.len(),
        model.residual_rms.iter().copied().fold(0.0f64, f64::max),
        worst,
        a.out.display(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
