//! `fabkit calibrate photometric`: the sensor's photometric model fitted from pin captures
//! (fabkit-calibration `photometric`), with each capture re-rendered from the model fitted on
//! the others (leave-one-out).

use std::error::Error;
use std::path::{Path, PathBuf};

use fabkit_calibration::capture_images::read_rgb;
use fabkit_calibration::groundtruth::exact::ExactPrimitives;
use fabkit_calibration::groundtruth::inputs::{read_extrinsics, sha256_hex};
use fabkit_calibration::groundtruth::pins::Pins;
use fabkit_calibration::groundtruth::rays::PixelRays;
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
    let claim = claim(&a);
    fabkit_export::check_out_dir(&a.out, &claim)?;
    let loaded = load_design(a.design.as_deref(), &a.data_files)?;
    let design = &loaded.design;
    let setup = Setup::read(&a, design)?;
    let listed = listed_pins(&a.images)?;
    let posed = pose_captures(&a, &setup, &listed)?;
    let all: Vec<Capture> = posed
        .iter()
        .map(|p| Capture {
            image: &p.image,
            hits: &p.hits,
            shadows: &p.shadows,
        })
        .collect();
    refuse_blank_frames(&a, &setup, &posed, &all)?;
    let model = PhotometricModel::fit(
        &setup.rays,
        &setup.reference,
        &setup.reference_image,
        &all,
        setup.full_scale,
    )?;
    let loo = leave_one_out(&setup, &posed, &all)?;

    let staged = StagedDir::new(&a.out, claim)?;
    write_outputs(&staged, &a, &loaded, &setup, &posed, &model, &loo)?;
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

/// The point table of the pin dome in `--fixtures`.
fn point_table(a: &PhotometricArgs) -> PathBuf {
    a.fixtures.join("points").join("point_table.csv")
}

/// The claim on --out: the fit's inputs (camera, pose, pin dome, reference, captures, and the
/// design file when one is given).
fn claim(a: &PhotometricArgs) -> OutputClaim {
    let design_arg = a
        .design
        .as_deref()
        .unwrap_or(fabkit_designs::library::DEFAULT_DESIGN);
    let point_table = point_table(a);
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
    OutputClaim::of_inputs(
        OutputCommand::CalibratePhotometric,
        &format!("photometric model of design '{design_arg}'"),
        &inputs,
        a.force,
    )
}

/// What the fit is done in, read and checked: the camera and pose files, the pin dome, the
/// camera's rays onto the reference skin and the reference image.
struct Setup {
    camera_name: String,
    camera_sha: String,
    extrinsics_sha: String,
    pose_name: String,
    size: (u32, u32),
    pins: Pins,
    rays: PixelRays,
    base_z_mm: f64,
    reference: SurfaceHits,
    rings: ShadowRings,
    reference_image: Vec<[f64; 3]>,
    full_scale: f64,
}

impl Setup {
    /// Reads the camera, pose, pin dome and reference image of `a` for `design`, in the order
    /// their errors are reported.
    fn read(
        a: &PhotometricArgs,
        design: &fabkit_designs::schema::Design,
    ) -> Result<Setup, Box<dyn Error>> {
        let camera = a.cam.read()?;
        let i = camera.intrinsics();
        let size = (i.image_width_px, i.image_height_px);
        check_camera_size(&a.cam.camera, size)?;
        let camera_name = a.cam.camera.display().to_string();
        let (_, camera_sha) =
            fabkit_calibration::groundtruth::inputs::read_with_hash(&a.cam.camera)?;
        let (t_cam_sensor, extrinsics_sha) = read_extrinsics(&a.extrinsics)?;
        let pins = read_pins(&a.fixtures)?;
        // the pin dome of this design, as groundtruth --pin-captures checks it
        fabkit_calibration::groundtruth::pins::check_made_for(&a.fixtures, &design.name)?;
        let pose_name = a.extrinsics.display().to_string();
        // the rays bend where the pose was solved through an optical path, as groundtruth bends
        // them: the model's shading registers with the captures
        let optical_path =
            fabkit_calibration::groundtruth::inputs::read_optical_path(&a.extrinsics)?;
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
        let (reference_image, full_scale) =
            read_rgb(&a.reference, "--reference", size, &camera_name)?;
        Ok(Setup {
            camera_name,
            camera_sha,
            extrinsics_sha,
            pose_name,
            size,
            pins,
            rays,
            base_z_mm: surface.base_z_mm(),
            reference,
            rings,
            reference_image,
            full_scale,
        })
    }
}

/// Refuses a camera image over the pixels the fit's per-pixel arrays may hold.
fn check_camera_size(camera_file: &Path, size: (u32, u32)) -> Result<(), Box<dyn Error>> {
    // every per-pixel array of the fit is sized by the camera: bounded before any is allocated,
    // as groundtruth bounds its render (issue 95: 16384 x 16384 aborted at 3.9 GB)
    let limit = fabkit_calibration::groundtruth::budget::MAX_PIXELS_LIMIT;
    let pixels = u64::from(size.0) * u64::from(size.1);
    if pixels > limit {
        return Err(format!(
            "{}: the camera image is {} x {} = {pixels} pixels, over the limit of {limit} pixels (2048 x 2048) that the fit's per-pixel arrays hold in its memory budget (hint: calibrate the camera at a lower resolution or crop its image)",
            camera_file.display(),
            size.0,
            size.1
        )
        .into());
    }
    Ok(())
}

/// The pins of each capture from its file name, each capture given once: no file twice, no
/// two files of the same pins, no pin twice in one.
fn listed_pins(images: &[PathBuf]) -> Result<Vec<Vec<u32>>, Box<dyn Error>> {
    let mut seen: Vec<(&Path, Vec<u32>)> = Vec::new();
    let mut listed: Vec<Vec<u32>> = Vec::new();
    for file in images {
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
    Ok(listed)
}

/// Reads each capture image and poses its pins (`listed`) on the skin: its surface and
/// shadows.
fn pose_captures(
    a: &PhotometricArgs,
    setup: &Setup,
    listed: &[Vec<u32>],
) -> Result<Vec<Posed>, Box<dyn Error>> {
    let rays = &setup.rays;
    let mut posed = Vec::new();
    for (file, ids) in a.images.iter().zip(listed) {
        let name = file.display().to_string();
        let ids: Vec<String> = ids.iter().map(u32::to_string).collect();
        let prims = setup.pins.primitives(&ids).map_err(|id| {
            format!(
                "--images = {name}: pin {id} is not in {}",
                point_table(a).display()
            )
        })?;
        let (image, scale) = read_rgb(file, "--images", setup.size, &setup.camera_name)?;
        if scale != setup.full_scale {
            return Err(format!(
                "--images = {name}: {} bit, but --reference {} is {} bit; give the images at one bit depth",
                if scale > 255.0 { 16 } else { 8 },
                a.reference.display(),
                if setup.full_scale > 255.0 { 16 } else { 8 }
            )
            .into());
        }
        let prims = ExactPrimitives::new(&prims).map_err(|e| format!("--images = {name}: {e}"))?;
        if prims.contains(rays.origin_mm) {
            return Err(format!(
                "{}: the camera centre is inside a pin of {name}",
                setup.pose_name
            )
            .into());
        }
        let hits = indented_hits(rays, &setup.reference, &prims, setup.base_z_mm);
        let shadows = shadow_map(rays, &hits, &prims, &setup.rings);
        posed.push(Posed {
            file: file.clone(),
            ids,
            image,
            hits,
            shadows,
        });
    }
    Ok(posed)
}

/// Refuses, by file and before the fit, a frame the camera saw no imprint in.
fn refuse_blank_frames(
    a: &PhotometricArgs,
    setup: &Setup,
    posed: &[Posed],
    all: &[Capture],
) -> Result<(), Box<dyn Error>> {
    // a frame the camera saw no imprint in (a copy of the reference, an unpressed, dark or
    // white frame) fits nothing: refused by file before the fit (issue 95: it "fitted within
    // 0.00 counts" to an all-zero model)
    let (reference, image, full_scale) =
        (&setup.reference, &setup.reference_image, setup.full_scale);
    if let Some(f) = image_fault(reference, image, full_scale) {
        return Err(format!("--reference = {}: {f}", a.reference.display()).into());
    }
    for (p, c) in posed.iter().zip(all) {
        if let Some(f) = capture_fault(reference, image, c, full_scale) {
            return Err(format!("--images = {}: {f}", p.file.display()).into());
        }
    }
    Ok(())
}

/// Each capture re-rendered from the model fitted on the others: its RMS difference from the
/// capture and the image.
fn leave_one_out(
    setup: &Setup,
    posed: &[Posed],
    all: &[Capture],
) -> Result<Vec<(f64, Vec<[f64; 3]>)>, Box<dyn Error>> {
    let (rays, reference) = (&setup.rays, &setup.reference);
    let mut loo = Vec::new();
    for k in 0..posed.len() {
        let others: Vec<Capture> = (0..posed.len())
            .filter(|&j| j != k)
            .map(|j| all[j])
            .collect();
        let m = PhotometricModel::fit(
            rays,
            reference,
            &setup.reference_image,
            &others,
            setup.full_scale,
        )
        .map_err(|e| format!("leaving out {}: {e}", posed[k].file.display()))?;
        let gain = m.gain_of(&posed[k].image, &posed[k].hits);
        let again = m.render(rays, reference, &posed[k].hits, &posed[k].shadows, gain);
        loo.push((rms_over_skin(&again, &posed[k].image), again));
    }
    Ok(loo)
}

/// Writes appearance.npy, the re-rendered captures and photometric.json (which lists them)
/// into `staged`.
fn write_outputs(
    staged: &StagedDir,
    a: &PhotometricArgs,
    loaded: &crate::args::Loaded,
    setup: &Setup,
    posed: &[Posed],
    model: &PhotometricModel,
    loo: &[(f64, Vec<[f64; 3]>)],
) -> Result<(), Box<dyn Error>> {
    let (w, h) = (setup.rays.width, setup.rays.height);
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
        put(&rel, rerendered_png(&loo[k].1, w, h, setup.full_scale)?)?;
        captures.push(json!({
            "file": p.file.display().to_string(), "pins": p.ids, "gain": model.gains[k],
            "fit_rms_counts": model.residual_rms[k], "leave_one_out_rms_counts": loo[k].0,
            "rerendered": rel,
        }));
    }
    let report = report_json(a, loaded, setup, model, captures, files);
    let mut text = serde_json::to_vec_pretty(&report)?;
    text.push(b'\n');
    staged.write("photometric.json", &text)?;
    Ok(())
}

/// A re-rendered capture as a PNG of the captures' bit depth (counts rounded; 0 where not
/// finite).
fn rerendered_png(
    img: &[[f64; 3]],
    w: usize,
    h: usize,
    full_scale: f64,
) -> Result<Vec<u8>, Box<dyn Error>> {
    let counts = |x: f64| if x.is_finite() { x.round() } else { 0.0 };
    Ok(if full_scale > 255.0 {
        let px: Vec<[u16; 3]> = img.iter().map(|q| q.map(|x| counts(x) as u16)).collect();
        png_rgb16(w, h, &px, &[])?
    } else {
        let px: Vec<u8> = img
            .iter()
            .flat_map(|q| q.map(|x| counts(x) as u8))
            .collect();
        png_rgb8(w, h, &px, &[])?
    })
}

/// photometric.json: provenance, the model, the captures and the files written.
fn report_json(
    a: &PhotometricArgs,
    loaded: &crate::args::Loaded,
    setup: &Setup,
    model: &PhotometricModel,
    captures: Vec<Value>,
    files: Vec<Value>,
) -> Value {
    let (w, h) = (setup.rays.width, setup.rays.height);
    let design = &loaded.design;
    json!({
        "fabkit_version": env!("CARGO_PKG_VERSION"),
        "command_line": std::env::args().collect::<Vec<_>>(),
        "description": "Photometric model of the sensor: per channel I(x, n) = gain x R(x) x (1 + sum_km c_km P_m(x) f_k(n, x) + sum_l w_l G_l(x, n) - sum_j b_j S_j(x)); R: appearance.npy (H, W, 3 float32 counts, NaN off the skin), the median of the reference and the captures' unpressed pixels over their gains; f_k: the change of the surface normal from the reference normal in the local frame about the optical axis (a along the tangent away from the axis, r round it, c along the reference normal: 1 - cos of the tilt), the monomials of a and r to degree 3 and the indentation depth along the ray (mm); P_m: powers of the pixel's distance from the image centre over the half-diagonal; G_l: the change of candidate point light l's Lambertian irradiance (incidence cosine over squared distance; 0 where the protrusions block it) from the reference surface to the pressed one, over the sum of all candidates' irradiance of the reference, weighted by w_l (the last light_terms numbers of each coefficients list); S_j: the share of candidate light ring j's light the protrusions block at the pixel (shadows, also beside the imprints), weighted by b_j (calibration/src/photometric.rs)",
        "design": {"name": design.name, "source": loaded.source, "sha256": loaded.sha256},
        "camera": {"file": setup.camera_name, "sha256": setup.camera_sha, "image_width_px": w, "image_height_px": h},
        "extrinsics": {"file": setup.pose_name, "sha256": setup.extrinsics_sha},
        "fixtures": a.fixtures.display().to_string(),
        "model": model.model_json(),
        "captures": captures,
        "files": files,
    })
}
