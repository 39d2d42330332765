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
use fabkit_calibration::photometric::seating::{seat_dome, DomeSeating, SEATING_PRIOR};
use fabkit_calibration::photometric::{
    capture_fault, image_fault, read_pins, rms_over_skin, shadow_map, Capture, ContactRegion,
    ImprintMap, LeaveOneOut, PhotometricModel, ShadowMap, ShadowRings, CONTACT_REACH_PX,
    DARKENING_NOISE_SIGMAS, GAIN_CLEARANCE_PX, GAIN_OUTLIER_SIGMAS,
};
use fabkit_export::raster::{npy_f32, png_rgb16_fast, png_rgb8_fast};
use fabkit_export::{OutputClaim, OutputCommand, StagedDir};
use serde_json::{json, Value};

use crate::args::{load_design, DataFileArgs};
use rayon::prelude::*;

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
    /// each named by the pins it holds (01_02_06_14_22.png: pins 1, 2, 6, 14 and 22), or an
    /// image.png in a folder so named (as `fabkit groundtruth --pin-captures --images` writes).
    #[arg(long, value_name = "CAPTURE.png", num_args = 2.., required = true)]
    images: Vec<PathBuf>,
    /// Output folder for photometric.json, appearance.npy and rerendered/: missing, empty, or
    /// an earlier fit of the same inputs as fabkit wrote it (replaced whole).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Replace an earlier fit in --out computed from other inputs.
    #[arg(long)]
    force: bool,
    /// The contact region the fit is judged in first: the skin within this distance of an
    /// imprint (its nearest pressed pixel), px, from 1 to 100.
    #[arg(long, value_name = "PX", default_value_t = CONTACT_REACH_PX)]
    contact_reach_px: f64,
    /// Keep the pin dome where the extrinsics put it in every capture: no per-capture seating
    /// (by default each capture's dome is moved by the small rigid motion its imprints show).
    #[arg(long)]
    no_seating: bool,
    #[command(flatten)]
    data_files: DataFileArgs,
}

/// One capture read and posed: its file, pin ids, image, the dome's seating and the surface
/// the seated pins make.
struct Posed {
    file: PathBuf,
    ids: Vec<String>,
    image: Vec<[f64; 3]>,
    seating: DomeSeating,
    hits: SurfaceHits,
    shadows: ShadowMap,
}

/// Rounds of seating: the model fitted, each capture's dome seated from its imprints, the
/// captures posed again; then the model fitted on the seated captures.
const SEATING_ROUNDS: usize = 2;

/// Largest `--contact-reach-px`: the distances are spread from every imprint's rim over a
/// disc of this radius.
const MAX_CONTACT_REACH_PX: f64 = 100.0;

/// One capture rendered from a model at its gain: the gain, the RMS over the skin, the
/// image and its fit within the contact region.
struct Rendered {
    gain: f64,
    rms_counts: f64,
    image: Vec<[f64; 3]>,
    contact: ContactRegion,
}

pub fn run(a: PhotometricArgs) -> Result<(), Box<dyn Error>> {
    let t0 = std::time::Instant::now();
    let reach = a.contact_reach_px;
    if !(1.0..=MAX_CONTACT_REACH_PX).contains(&reach) {
        return Err(format!(
            "--contact-reach-px = {reach}: must be a distance from 1 to {MAX_CONTACT_REACH_PX} px"
        )
        .into());
    }
    let claim = claim(&a);
    fabkit_export::check_out_dir(&a.out, &claim)?;
    let loaded = load_design(a.design.as_deref(), &a.data_files)?;
    let design = &loaded.design;
    let setup = Setup::read(&a, design)?;
    let listed = listed_pins(&a.images)?;
    let n = a.images.len();
    let progress = crate::progress::Progress::new(
        "calibrate photometric",
        &format!("reading and posing {n} captures"),
        n as u64,
    );
    let mut posed = pose_captures(&a, &setup, &listed, &|k| progress.set(k as u64, n as u64))?;
    {
        let all = captures_of(&posed);
        refuse_blank_frames(&a, &setup, &posed, &all)?;
    }
    let rounds = if a.no_seating { 0 } else { SEATING_ROUNDS };
    // the seating rounds render each capture themselves (`rendered`), so the fit does not
    let fit = |all: &[Capture]| {
        PhotometricModel::fit_unrendered(
            &setup.rays,
            &setup.reference,
            &setup.reference_image,
            all,
            setup.full_scale,
        )
    };
    for round in 1..=rounds {
        progress.stage(&format!(
            "fitting the model to {n} captures (seating round {round} of {rounds})"
        ));
        let all = captures_of(&posed);
        let model = fit(&all)?;
        // each capture's seating on its own: in parallel, collected in order
        let seatings: Vec<DomeSeating> = all
            .par_iter()
            .zip(&model.gains)
            .zip(&posed)
            .map(|((c, &g), p)| {
                let r = rendered(&setup, &model, c, g, reach);
                let pairs: Vec<([f64; 2], [f64; 2])> = r
                    .contact
                    .imprints
                    .iter()
                    .filter_map(|i| i.rendered_centroid_px.zip(i.real_centroid_px))
                    .collect();
                let moved = setup.pins.moved(&p.seating.isometry());
                let pins: Vec<([f64; 3], [f64; 3])> =
                    moved.rows.iter().map(|(_, t, a)| (*t, *a)).collect();
                let step = seat_dome(
                    &setup.rays,
                    &setup.reference,
                    &pairs,
                    &pins,
                    p.seating.pivot_mm,
                    &SEATING_PRIOR,
                );
                p.seating.then(&step)
            })
            .collect();
        drop(all);
        progress.stage(&format!("seating the pin dome of each of {n} captures"));
        let finished = std::sync::atomic::AtomicUsize::new(0);
        // each capture on its own: in parallel, the first error in the captures' order
        let again: Vec<Result<(), String>> = posed
            .par_iter_mut()
            .zip(seatings)
            .map(|(p, s)| {
                // the image moves to the posed capture, not copied
                let taken = (p.file.clone(), p.ids.clone(), std::mem::take(&mut p.image));
                *p = pose(&a, &setup, taken, s).map_err(|e| e.to_string())?;
                let k = finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress.set(k as u64, n as u64);
                Ok(())
            })
            .collect();
        again.into_iter().collect::<Result<Vec<()>, String>>()?;
    }
    progress.stage(&format!(
        "fitting the model to {n} {}captures",
        if rounds > 0 { "seated " } else { "" }
    ));
    let all = captures_of(&posed);
    // the fit on every capture and its leave-one-out share the checks, the gains, the
    // appearance's sorted values and the rows' terms
    let fits = LeaveOneOut::new(
        &setup.rays,
        &setup.reference,
        &setup.reference_image,
        &all,
        setup.full_scale,
    )?;
    let mut model = fits.all_unrendered()?;
    let fitted: Vec<Rendered> = all
        .par_iter()
        .zip(&model.gains)
        .map(|(c, &g)| rendered(&setup, &model, c, g, reach))
        .collect();
    // each capture's residual over its skin, as the fit reports it, from these renderings
    model.residual_rms = fitted.iter().map(|r| r.rms_counts).collect();
    progress.stage(&format!(
        "re-rendering each of {n} captures from the model fitted on the others"
    ));
    let loo = leave_one_out(&setup, &posed, &all, &fits, reach, &|k| {
        progress.set(k as u64, n as u64)
    })?;
    progress.stage(&format!("writing {}", a.out.display()));
    let staged = StagedDir::new(&a.out, claim)?;
    write_outputs(
        &staged,
        &a,
        &loaded,
        &setup,
        &posed,
        &model,
        [&fitted, &loo],
    )?;
    progress.finish();
    for w in staged.commit()? {
        eprintln!("warning: {w}");
    }
    let worst = |r: &[Rendered], f: fn(&Rendered) -> f64| {
        r.iter()
            .map(f)
            .filter(|x| x.is_finite())
            .fold(0.0f64, f64::max)
    };
    let offsets = |r: &Rendered| r.contact.median_offset_px.unwrap_or(f64::NAN);
    out!(
        "{}: photometric model from {} captures; within {reach} px of the imprints each capture re-rendered from the others within {:.2} counts RMS (fit {:.2}), median imprint centroid offset at most {:.2} px; over the whole skin within {:.2} (fit {:.2}) -> {} ({:.2} s)",
        design.name,
        posed.len(),
        worst(&loo, |r| r.contact.rms_counts),
        worst(&fitted, |r| r.contact.rms_counts),
        worst(&loo, offsets),
        worst(&loo, |r| r.rms_counts),
        worst(&fitted, |r| r.rms_counts),
        a.out.display(),
        t0.elapsed().as_secs_f64()
    );
    for ((p, f), l) in posed.iter().zip(&fitted).zip(&loo) {
        let median = l
            .contact
            .median_offset_px
            .map_or("none".to_string(), |x| format!("{x:.2} px"));
        let t = &p.seating;
        out!(
            "  {}: gain {:.4}; within {reach} px of its {} imprints {:.2} counts RMS (fit {:.2}), centroid offset {median} (median); whole skin {:.2} (fit {:.2}); dome seated {:.3} mm aside, turned {:.2} deg",
            p.file.display(),
            l.gain,
            l.contact.imprints.len(),
            l.contact.rms_counts,
            f.contact.rms_counts,
            l.rms_counts,
            f.rms_counts,
            fabkit_calibration::nalgebra::Vector3::from(t.translation_mm).norm(),
            fabkit_calibration::nalgebra::Vector3::from(t.rotation_deg).norm()
        );
    }
    Ok(())
}

/// `capture` rendered from `model` at `gain` ([`Rendered`]).
fn rendered(
    setup: &Setup,
    model: &PhotometricModel,
    capture: &Capture,
    gain: f64,
    reach_px: f64,
) -> Rendered {
    let (rays, reference) = (&setup.rays, &setup.reference);
    let image = model.render(rays, reference, capture.hits, capture.shadows, gain);
    let contact = model.contact_region(capture, reference, &image, gain, reach_px);
    Rendered {
        gain,
        rms_counts: rms_over_skin(&image, capture.image),
        image,
        contact,
    }
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
        if let Some(rule) = fabkit_calibration::capture_images::folder_given(file) {
            return Err(format!("--images = {name}: {rule}").into());
        }
        let ids = ids_from_file_name(file)
            .filter(|ids| !ids.is_empty())
            .ok_or_else(|| {
                format!("--images = {name}: the file name must list the capture's pins in ring order, e.g. 01_02_06_14_22.png (or image.png in a folder so named)")
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
    done: &(dyn Fn(usize) + Sync),
) -> Result<Vec<Posed>, Box<dyn Error>> {
    let finished = std::sync::atomic::AtomicUsize::new(0);
    // each capture on its own: in parallel, collected in order (the first error in the
    // images' order is the one reported)
    let posed: Vec<Result<Posed, String>> = a
        .images
        .par_iter()
        .zip(listed)
        .map(|(file, ids)| {
            let name = file.display().to_string();
            let ids: Vec<String> = ids.iter().map(u32::to_string).collect();
            setup.pins.primitives(&ids).map_err(|id| {
                format!(
                    "--images = {name}: pin {id} is not in {}",
                    point_table(a).display()
                )
            })?;
            let (image, scale) = read_rgb(file, "--images", setup.size, &setup.camera_name)
                .map_err(|e| e.to_string())?;
            if scale != setup.full_scale {
                return Err(format!(
                    "--images = {name}: {} bit, but --reference {} is {} bit; give the images at one bit depth",
                    if scale > 255.0 { 16 } else { 8 },
                    a.reference.display(),
                    if setup.full_scale > 255.0 { 16 } else { 8 }
                ));
            }
            let seating = DomeSeating::none(setup.pins.mean_tip_mm());
            let p = pose(a, setup, (file.clone(), ids, image), seating)
                .map_err(|e| e.to_string())?;
            done(finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
            Ok(p)
        })
        .collect();
    Ok(posed.into_iter().collect::<Result<Vec<_>, String>>()?)
}

/// The capture of `file` (its pins `ids`, its `image`) with its dome seated `seating`: the
/// pins moved, its surface and shadows cast.
fn pose(
    a: &PhotometricArgs,
    setup: &Setup,
    (file, ids, image): (PathBuf, Vec<String>, Vec<[f64; 3]>),
    seating: DomeSeating,
) -> Result<Posed, Box<dyn Error>> {
    let rays = &setup.rays;
    let name = file.display().to_string();
    let pins = setup.pins.moved(&seating.isometry());
    let prims = pins.primitives(&ids).map_err(|id| {
        format!(
            "--images = {name}: pin {id} is not in {}",
            point_table(a).display()
        )
    })?;
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
    Ok(Posed {
        file,
        ids,
        image,
        seating,
        hits,
        shadows,
    })
}

/// The captures as the model reads them.
fn captures_of(posed: &[Posed]) -> Vec<Capture<'_>> {
    posed
        .iter()
        .map(|p| Capture {
            image: &p.image,
            hits: &p.hits,
            shadows: &p.shadows,
        })
        .collect()
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
    // each capture checked on its own, in parallel; the first fault in the images' order
    let faults: Vec<_> = all
        .par_iter()
        .map(|c| capture_fault(reference, image, c, full_scale))
        .collect();
    if let Some((p, f)) = posed.iter().zip(faults).find_map(|(p, f)| Some((p, f?))) {
        return Err(format!("--images = {}: {f}", p.file.display()).into());
    }
    Ok(())
}

/// Each capture re-rendered from the model fitted on the others (`fits`), at its gain
/// against that model's appearance.
fn leave_one_out(
    setup: &Setup,
    posed: &[Posed],
    all: &[Capture],
    fits: &LeaveOneOut,
    reach_px: f64,
    done: &(dyn Fn(usize) + Sync),
) -> Result<Vec<Rendered>, Box<dyn Error>> {
    let reference = &setup.reference;
    let finished = std::sync::atomic::AtomicUsize::new(0);
    // the fits are independent: in parallel, collected in the captures' order
    let loo: Vec<Result<Rendered, String>> = (0..posed.len())
        .into_par_iter()
        .map(|k| {
            let m = fits
                .model(k)
                .map_err(|e| format!("leaving out {}: {e}", posed[k].file.display()))?;
            let gain = m.gain_of(&all[k], reference);
            let r = rendered(setup, &m, &all[k], gain, reach_px);
            done(finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
            Ok(r)
        })
        .collect();
    // the first capture's error, as the loop in order reported it
    Ok(loo.into_iter().collect::<Result<Vec<_>, String>>()?)
}

/// Writes appearance.npy, the re-rendered captures and photometric.json (which lists them)
/// into `staged`: each capture rendered from `model` and from the model fitted on the others.
fn write_outputs(
    staged: &StagedDir,
    a: &PhotometricArgs,
    loaded: &crate::args::Loaded,
    setup: &Setup,
    posed: &[Posed],
    model: &PhotometricModel,
    [fitted, loo]: [&[Rendered]; 2],
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
    // encoded in parallel, written in order
    let pngs: Vec<Result<Vec<u8>, String>> = loo
        .par_iter()
        .map(|r| rerendered_png(&r.image, w, h, setup.full_scale).map_err(|e| e.to_string()))
        .collect();
    for ((k, p), png) in posed.iter().enumerate().zip(pngs) {
        // `01_02_06/image.png` (a ground-truth capture's layout) by its folder's name
        let stem = fabkit_calibration::imprints::capture_name(&p.file)
            .unwrap_or_else(|| format!("capture_{k}"));
        let rel = format!("rerendered/{stem}.png");
        put(&rel, png?)?;
        captures.push(json!({
            "file": p.file.display().to_string(), "pins": p.ids,
            "contact_region": contact_json(setup, p, &fitted[k], &loo[k]),
            "seating": p.seating,
            "gain": model.gains[k], "leave_one_out_gain": loo[k].gain,
            "fit_rms_counts": model.residual_rms[k], "leave_one_out_rms_counts": loo[k].rms_counts,
            "rerendered": rel,
        }));
    }
    let report = report_json(a, loaded, setup, model, captures, files);
    let mut text = serde_json::to_vec_pretty(&report)?;
    text.push(b'\n');
    staged.write("photometric.json", &text)?;
    Ok(())
}

/// A number for the report: `null` when not finite.
fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// The fit of capture `p` within the contact region: the RMS of the fit (`fitted`) and of the
/// leave-one-out (`loo`), and per imprint (named by the pin whose tip lies nearest the mean of
/// its pressed surface points) its RMS and the centroids of the real and the leave-one-out
/// rendering's darkening.
fn contact_json(setup: &Setup, p: &Posed, fitted: &Rendered, loo: &Rendered) -> Value {
    let (rays, w, h) = (&setup.rays, setup.rays.width, setup.rays.height);
    let map = ImprintMap::of(&p.hits.contact, w, h, 0.0);
    let mut sums = vec![[0.0; 4]; map.centres_px.len()];
    for i in (0..w * h).filter(|&i| p.hits.contact[i] && p.hits.t_mm[i].is_finite()) {
        if let Some(j) = map.imprint_near(i, 0.0) {
            let s = &mut sums[j];
            for (q, x) in s.iter_mut().take(3).enumerate() {
                *x += rays.origin_mm[q] + p.hits.t_mm[i] * rays.dirs[i][q];
            }
            s[3] += 1.0;
        }
    }
    let pin_of = |s: &[f64; 4]| -> Option<&str> {
        let m: [f64; 3] = std::array::from_fn(|q| s[q] / s[3]);
        let d = |tip: &[f64; 3]| (0..3).map(|q| (tip[q] - m[q]).powi(2)).sum::<f64>();
        setup
            .pins
            .rows
            .iter()
            .filter(|(id, _, _)| p.ids.contains(id))
            .min_by(|a, b| d(&a.1).total_cmp(&d(&b.1)))
            .map(|(id, _, _)| id.as_str())
    };
    let px = |x: Option<[f64; 2]>| x.map_or(Value::Null, |x| json!(x));
    let imprints: Vec<Value> = loo
        .contact
        .imprints
        .iter()
        .zip(&fitted.contact.imprints)
        .zip(&sums)
        .map(|((l, f), s)| {
            json!({
                "pin": pin_of(s),
                "centre_px": l.centre_px,
                "pressed_pixels": l.pressed_pixels,
                "fit_rms_counts": num(f.rms_counts),
                "leave_one_out_rms_counts": num(l.rms_counts),
                "real_darkening_centroid_px": px(l.real_centroid_px),
                "rendered_darkening_centroid_px": px(l.rendered_centroid_px),
                "centroid_offset_px": l.offset_px.map_or(Value::Null, num),
            })
        })
        .collect();
    json!({
        "reach_px": loo.contact.reach_px,
        "pixels": loo.contact.pixels,
        "fit_rms_counts": num(fitted.contact.rms_counts),
        "leave_one_out_rms_counts": num(loo.contact.rms_counts),
        "median_centroid_offset_px": loo.contact.median_offset_px.map_or(Value::Null, num),
        "darkening_floor_counts": loo.contact.darkening_floor_counts,
        "imprints": imprints,
    })
}

/// A re-rendered capture as a PNG of the captures' bit depth (counts rounded; 0 where not
/// finite), deflated fast: thirty of them are written at the end of the command.
fn rerendered_png(
    img: &[[f64; 3]],
    w: usize,
    h: usize,
    full_scale: f64,
) -> Result<Vec<u8>, Box<dyn Error>> {
    let counts = |x: f64| if x.is_finite() { x.round() } else { 0.0 };
    Ok(if full_scale > 255.0 {
        let px: Vec<[u16; 3]> = img.iter().map(|q| q.map(|x| counts(x) as u16)).collect();
        png_rgb16_fast(w, h, &px, &[])?
    } else {
        let px: Vec<u8> = img
            .iter()
            .flat_map(|q| q.map(|x| counts(x) as u8))
            .collect();
        png_rgb8_fast(w, h, &px, &[])?
    })
}

/// What photometric.json's per-capture `seating` is.
fn seating_text(a: &PhotometricArgs) -> String {
    if a.no_seating {
        return "none (--no-seating): every capture's pin dome where the extrinsics put it".into();
    }
    let p = SEATING_PRIOR;
    format!(
        "per capture, the small rigid motion of the pin dome from where the extrinsics put it, X -> pivot_mm + R(rotation_deg) (X - pivot_mm) + translation_mm (sensor frame; rotation_deg a rotation vector, pivot_mm the mean of the dome's pin tips), found from the offsets between the centroids of each imprint's darkening in the capture and in the model's rendering ({SEATING_ROUNDS} rounds: fit, seat, pose again; the model then fitted on the seated captures): the maximum a posteriori motion under a zero-mean Gaussian prior of {} mm per translation component and {} deg per rotation component, centroids of {} px, each pin's move along its own axis held to {} mm (the dome's seat sets the pins' depths), bounded to {} mm and {} deg (bounded: true where it was scaled back); the extrinsics stay one per sensor (calibration/src/photometric/seating.rs)",
        p.translation_sigma_mm, p.rotation_sigma_deg, p.centroid_sigma_px, p.depth_sigma_mm, p.max_translation_mm, p.max_rotation_deg
    )
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
        "gain": format!("per capture, the least-squares ratio of the capture to the model's appearance (the fit's: to the reference image) over every channel of its skin further than {GAIN_CLEARANCE_PX} px from every imprint (its nearest pressed pixel) and unshadowed, lit and below full scale, values further than {GAIN_OUTLIER_SIGMAS} robust standard deviations from a first estimate left out; applied wherever the capture is rendered (fit RMS, leave-one-out RMS, rerendered/)"),
        "seating": seating_text(a),
        "contact_region": format!("per capture, the RMS of the fit and of the leave-one-out over the skin within reach_px = {} px of an imprint (8-connected pressed pixels of the ground truth; distance to its nearest pressed pixel), beside the whole-skin figures; per imprint, the distance between the centroids of the capture's darkening and of its leave-one-out rendering's (the appearance at the capture's gain minus the image, summed over the channels, each less the floor of {DARKENING_NOISE_SIGMAS} x the capture's noise beyond the reach and clipped at 0) over the pixels within the reach nearest it, and their median", a.contact_reach_px),
        "captures": captures,
        "files": files,
    })
}
