//! `fabkit groundtruth`: argument parsing, dispatch over fabkit-calibration (rendering; the
//! dataset's files and bounds in `groundtruth::dataset`) and fabkit-export (the atomic output
//! folder), progress.

use fabkit_calibration::groundtruth::budget::{
    min_skin_pixels, render_memory, DEFAULT_MAX_PIXELS, FIXED_BYTES_PER_PIXEL,
    FRAME_BYTES_PER_PIXEL, MAX_PIXELS_LIMIT, MEMORY_BUDGET_BYTES, MIN_SKIN_FRACTION,
};
use std::error::Error;
use std::path::{Path, PathBuf};

use fabkit_calibration::groundtruth::dataset::{
    self, output_bound, FrameInputs, ImageSource, ManifestInputs, DEFAULT_MAX_OUTPUT_BYTES,
    MAX_OUTPUT_BYTES_LIMIT,
};
use fabkit_calibration::groundtruth::inputs::{
    read_extrinsics, read_fixtures, read_with_hash, Fixtures,
};
use fabkit_calibration::groundtruth::pins::read_pin_captures;
use fabkit_calibration::groundtruth::press::{self, Press, PressInputError, PressJob};
use fabkit_calibration::groundtruth::rays::PixelRays;
use fabkit_calibration::groundtruth::shading::Imaging;
use fabkit_calibration::groundtruth::surface::ReferenceSurface;
use fabkit_calibration::groundtruth::{reference_hits, Scene, SurfaceHits};
use fabkit_calibration::photometric::PhotometricModel;
use fabkit_calibration::refraction::OpticalLayers;
use fabkit_export::{OutputClaim, StagedDir};

use crate::args::{load_design, DataFileArgs};

#[derive(clap::Args, Debug)]
pub struct GroundTruthArgs {
    /// A design YAML file or the name of a library design (default: rtac0); the fixtures must
    /// have been built from it.
    design: Option<String>,
    #[command(flatten)]
    cam: crate::args::CameraArgs,
    /// extrinsics.json of `fabkit calibrate extrinsics` (T_cam_sensor).
    #[arg(long, value_name = "extrinsics.json")]
    extrinsics: PathBuf,
    /// Output folder of `fabkit fixtures` (reads protrusions/index.json and the pattern files;
    /// with --pin-captures the pin dome's points/ and manifest.json). Not with --press-image.
    #[arg(
        long,
        value_name = "FIXTURES_DIR",
        required_unless_present = "press_image",
        conflicts_with = "press_image"
    )]
    fixtures: Option<PathBuf>,
    /// Render the pin dome's captures instead of the protrusion patterns: one frame per capture
    /// of points/capture_plan.csv with its pins pressed in (tips and axes from
    /// points/point_table.csv, the pin's tip, cone and shaft from manifest.json), each folder
    /// named by its pins (`01_02_06_14_22`) as `fabkit calibrate images` and `calibrate
    /// photometric` read a capture's file name. With --images: synthetic pin captures.
    #[arg(long, conflicts_with = "press_image")]
    pin_captures: bool,
    /// Render a real press instead of fixtures: a capture of a sphere (--sphere-radius-mm)
    /// pressed into the design's flat skin, taken by the calibrated camera (PNG or JPEG of its
    /// size). The sphere's centre over the contact face and its depth are fitted against
    /// --press-reference and printed with their standard deviations; one frame, `press/`, is
    /// rendered with the sphere placed there, beside a copy of the capture (`capture.png`),
    /// and the fit is written to press.json.
    #[arg(long, value_name = "IMAGE", requires_all = ["press_reference", "sphere_radius_mm"])]
    press_image: Option<PathBuf>,
    /// With --press-image: the same camera's capture of the unpressed skin, under the same
    /// lighting (copied to `reference/capture.png`).
    #[arg(long, value_name = "IMAGE", requires = "press_image")]
    press_reference: Option<PathBuf>,
    /// With --press-image: the pressed sphere's radius, mm (above 0, at most 1000).
    #[arg(long, value_name = "MM", requires = "press_image", value_parser = parse_radius_mm,
          allow_negative_numbers = true)]
    sphere_radius_mm: Option<f64>,
    /// Output folder. Replaced as a whole if it holds earlier ground truth of the same inputs
    /// (design, camera, extrinsics, fixtures; or the press's captures and sphere radius) as
    /// fabkit wrote it; refused if it holds anything else.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Replace earlier ground truth in --out computed from other inputs; without it that
    /// output is kept and this run refused. Another command's output (an export, fixtures, a
    /// calibration) is never replaced.
    #[arg(long)]
    force: bool,
    /// Apply one of the design's presets.
    #[arg(long)]
    preset: Option<String>,
    /// Largest camera image, pixels (width x height; 1 to 4194304, what the render's memory
    /// budget of 2 GiB holds): every per-pixel array of a frame (rays, hits, depth maps, the
    /// files of a frame) is sized by it.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_PIXELS,
          value_parser = parse_max_pixels, allow_negative_numbers = true)]
    max_pixels: u64,
    /// What the arrays are written as: `npy` (one float32 .npy per map, and points.ply), `npz`
    /// (the maps of a frame in one compressed arrays.npz, no PLY) or `png` (the 16-bit PNGs
    /// and previews only). The 16-bit PNGs, previews and masks are written in every format.
    #[arg(long, value_enum, default_value_t = DataFormat::Npy)]
    format: DataFormat,
    /// Refuse, before rendering, output estimated at more than this many bytes (an upper bound
    /// printed first; 1 to 10^15) unless --yes is given.
    #[arg(long, value_name = "BYTES", default_value_t = DEFAULT_MAX_OUTPUT_BYTES,
          value_parser = parse_max_output_bytes, allow_negative_numbers = true)]
    max_output_bytes: u64,
    /// Write output estimated above --max-output-bytes (never more than the free space of the
    /// output's file system).
    #[arg(long)]
    yes: bool,
    /// Also render the tactile image the camera sees of every frame (`image.png` beside the
    /// depth maps, RGB at the design's `optics.camera.bit_depth`): the design's lights, skin
    /// reflectance and camera response (its `optics` section, or the lights of its housing),
    /// shadows cast by the protrusions, seeded camera noise.
    #[arg(long)]
    images: bool,
    /// With --images: render them in the sensor's own appearance, from the photometric model
    /// `fabkit calibrate photometric` wrote to DIR (photometric.json, appearance.npy; same
    /// camera size), instead of the design's optics. The model's mean image: no noise.
    #[arg(long, value_name = "DIR", requires = "images")]
    photometric: Option<PathBuf>,
    #[command(flatten)]
    data_files: DataFileArgs,
}

/// How the ground-truth arrays are written (`--format`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataFormat {
    /// float32 `.npy` per map and `points.ply` (numpy.load, Open3D).
    Npy,
    /// The float32 maps of each frame in one compressed `arrays.npz` (numpy.load); no PLY.
    Npz,
    /// 16-bit PNGs (micrometres), previews and masks only.
    Png,
}

impl From<DataFormat> for dataset::DataFormat {
    fn from(f: DataFormat) -> Self {
        match f {
            DataFormat::Npy => dataset::DataFormat::Npy,
            DataFormat::Npz => dataset::DataFormat::Npz,
            DataFormat::Png => dataset::DataFormat::Png,
        }
    }
}

fn parse_max_output_bytes(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(n) if (1..=MAX_OUTPUT_BYTES_LIMIT).contains(&n) => Ok(n),
        _ => Err(format!(
            "must be a whole number of bytes from 1 to {MAX_OUTPUT_BYTES_LIMIT} (10^15)"
        )),
    }
}

fn parse_radius_mm(s: &str) -> Result<f64, String> {
    let max = fabkit_designs::values::MAX_LENGTH_MM;
    match s.trim().parse::<f64>() {
        Ok(r) if r > 0.0 && r <= max => Ok(r),
        _ => Err(format!(
            "must be a finite length above 0 mm, at most {max} mm (the sphere's radius)"
        )),
    }
}

fn parse_max_pixels(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(n) if (1..=MAX_PIXELS_LIMIT).contains(&n) => Ok(n),
        _ => Err(format!(
            "must be a whole number of pixels from 1 to {MAX_PIXELS_LIMIT} (2048 x 2048, what the \
             render's memory budget of {} GiB holds)",
            MEMORY_BUDGET_BYTES >> 30
        )),
    }
}

/// The photometric model `fabkit calibrate photometric` wrote to `dir`, for a `w` x `h`
/// camera, and the sha256 of its photometric.json.
///
/// # Errors
/// Naming `--photometric`, the file and what does not fit: another basis than this fabkit's,
/// coefficients of another length, an appearance of another size than the camera's.
fn load_photometric(
    dir: &Path,
    w: usize,
    h: usize,
    fitted_for: [(&str, &str, &Path); 3],
) -> Result<(PhotometricModel, String), Box<dyn Error>> {
    let (model, sha, fitted) =
        PhotometricModel::read(dir).map_err(|e| format!("--photometric {e}"))?;
    // A model is of one sensor, camera and pose: those it was fitted with, by their files'
    // sha256 as photometric.json records them.
    for (key, sha, file) in fitted_for {
        fitted
            .check(key, sha, &file.display().to_string())
            .map_err(|e| format!("--photometric {e}"))?;
    }
    if (model.width, model.height) != (w, h) {
        return Err(format!(
            "--photometric {}: shape [{}, {}, 3], the camera's images need [{h}, {w}, 3] (the model was fitted to another camera)",
            dir.join("appearance.npy").display(),
            model.height,
            model.width
        )
        .into());
    }
    Ok((model, sha))
}

/// `n` bytes for people: `1.2 GB`, `340 MB`, `12 kB`.
fn shown_bytes(n: u64) -> String {
    let x = n as f64;
    if x >= 1e9 {
        format!("{:.1} GB", x / 1e9)
    } else if x >= 1e6 {
        format!("{:.0} MB", x / 1e6)
    } else {
        format!("{:.0} kB", (x / 1e3).ceil())
    }
}

/// Checks that the camera sees the skin in at least [`MIN_SKIN_FRACTION`] of its pixels.
/// `seen` pixels see it; `file` and `text` are the camera file's name and text (its form names
/// the fields in the error), `pose` the extrinsics file.
///
/// # Errors
/// Naming the camera file, the pixels seen, the rule, and the camera file's fields as it names
/// them (`camera_matrix` of an OpenCV or ROS file, `fx_px`... of a fabkit JSON file) with
/// their values in scientific notation where long.
pub fn check_skin_seen(
    seen: usize,
    camera: &fabkit_calibration::CameraModel,
    file: &str,
    text: &str,
    pose: &str,
) -> Result<(), String> {
    let i = camera.intrinsics();
    let pixels = u64::from(i.image_width_px) * u64::from(i.image_height_px);
    let needed = min_skin_pixels(pixels);
    if seen as u64 >= needed {
        return Ok(());
    }
    let v = fabkit_calibration::shown_f64;
    let fields = match fabkit_calibration::refine::refined_camera_file(text).1 {
        fabkit_calibration::CameraFileFormat::Json => format!(
            "fx_px = {}, fy_px = {}, cx_px = {}, cy_px = {}",
            v(i.fx_px),
            v(i.fy_px),
            v(i.cx_px),
            v(i.cy_px)
        ),
        _ => format!(
            "camera_matrix: fx = {}, fy = {}, cx = {}, cy = {}",
            v(i.fx_px),
            v(i.fy_px),
            v(i.cx_px),
            v(i.cy_px)
        ),
    };
    Err(format!(
        "{file}: {fields} px, image {} x {} px: the camera sees the skin in {seen} of its {pixels} pixels, \
         fewer than the {needed} ({}% of the image) ground truth needs (hint: check the focal \
         lengths and the principal point against the image size, the distortion model, and that \
         {pose} (T_cam_sensor) points the camera at the skin)",
        i.image_width_px,
        i.image_height_px,
        MIN_SKIN_FRACTION * 100.0
    ))
}

/// The press of --press-image: (capture, reference, sphere radius mm); `None` without it.
fn press_of(args: &GroundTruthArgs) -> Option<(&Path, &Path, f64)> {
    match (
        &args.press_image,
        &args.press_reference,
        args.sphere_radius_mm,
    ) {
        (Some(image), Some(reference), Some(r)) => Some((image, reference, r)),
        _ => None,
    }
}

/// --fixtures, which every mode but --press-image needs.
fn fixtures_dir(args: &GroundTruthArgs) -> Result<&Path, String> {
    args.fixtures.as_deref().ok_or_else(|| {
        "--fixtures: required (the output folder of `fabkit fixtures`), unless --press-image, --press-reference and --sphere-radius-mm give a real press".to_string()
    })
}

/// The claim on --out ([`dataset::claim`], or [`press::claim`] with --press-image).
fn claim(args: &GroundTruthArgs) -> Result<OutputClaim, String> {
    let design = args
        .design
        .as_deref()
        .unwrap_or(fabkit_designs::library::DEFAULT_DESIGN);
    if let Some((capture, reference, radius_mm)) = press_of(args) {
        return Ok(press::claim(
            &press::PressClaimInputs {
                design,
                preset: args.preset.as_deref(),
                camera_file: &args.cam.camera,
                extrinsics_file: &args.extrinsics,
                capture,
                reference,
                radius_mm,
            },
            args.force,
        ));
    }
    Ok(dataset::claim(
        &dataset::ClaimInputs {
            design,
            preset: args.preset.as_deref(),
            camera_file: &args.cam.camera,
            extrinsics_file: &args.extrinsics,
            fixtures_dir: fixtures_dir(args)?,
            pin_captures: args.pin_captures,
        },
        args.force,
    ))
}

pub fn run(args: GroundTruthArgs) -> Result<(), Box<dyn Error>> {
    let t0 = std::time::Instant::now();
    // The output folder is checked before anything is read or rendered, as `fabkit export`
    // checks it.
    let claim = claim(&args)?;
    fabkit_export::check_out_dir(&args.out, &claim)?;
    let mut loaded = load_design(args.design.as_deref(), &args.data_files)?;
    if let Some(p) = &args.preset {
        loaded.apply_preset(p)?;
    }
    let design = &loaded.design;
    let inputs = Inputs::read(&args, design)?;
    // The optics (or the photometric model) are checked before the output is bounded or
    // anything is written.
    let looks = Looks::read(&args, &loaded, &inputs)?;
    // The output is bounded before anything is rendered or written.
    check_output_bound(&args, &inputs, looks.image_bits())?;
    // A camera that sees (almost) none of the skin is refused before anything is written.
    let ref_hits = reference_hits(&inputs.rays, &inputs.surface);
    check_skin_seen(
        ref_hits.valid_count(),
        &inputs.camera,
        &args.cam.camera.display().to_string(),
        &String::from_utf8_lossy(&inputs.camera_bytes),
        &inputs.pose_name,
    )?;
    let n_cfg = inputs.fixtures.configurations.len();
    let frames = n_cfg as u64 + 1;
    let bar = crate::progress::Progress::new(
        "groundtruth",
        &format!("rendering {frames} frames of {}", design.name),
        frames,
    );
    let imaging = looks.image_source(&inputs, &ref_hits);
    let staged = StagedDir::new(&args.out, claim)?;
    let all = write_dataset(
        &staged,
        &args,
        &loaded,
        &inputs,
        &ref_hits,
        imaging.as_ref(),
        &|k| bar.set(k, frames),
    )?;
    bar.finish();
    for w in staged.commit()? {
        eprintln!("warning: {w}");
    }
    if let Some(p) = &inputs.press {
        print_press(p);
    }
    out!(
        "{}: reference + {}, {} of {} pixels on the surface -> {} ({} files, {:.2} s)",
        design.name,
        rendered_what(&args, &inputs.fixtures),
        ref_hits.valid_count(),
        inputs.rays.width * inputs.rays.height,
        args.out.display(),
        all.len() + 1,
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Prints the fitted press: the sphere's centre over the contact face and its depth with
/// their standard deviations, the depth's spread over the core, the gain.
fn print_press(p: &Press) {
    let f = &p.fit;
    out!(
        "press: a {} mm sphere at ({:.3} +- {:.3}, {:.3} +- {:.3}) mm over the contact face z = {} mm, {:.3} +- {:.3} mm deep ({:.3} mm spread over the fitted core; gain {:.1} grey levels per mm, {} core pixels, residual RMS {:.2} grey levels)",
        fabkit_calibration::shown_f64(p.radius_mm),
        f.centre_mm[0],
        f.centre_std_mm[0],
        f.centre_mm[1],
        f.centre_std_mm[1],
        fabkit_calibration::shown_f64(p.plane_z_mm),
        f.depth_mm,
        f.depth_std_mm,
        f.depth_spread_mm,
        f.gain_grey_per_mm,
        f.core_pixels,
        f.residual_rms_grey
    );
}

/// What was rendered besides the reference, in words: the press, the pin captures, or the
/// configurations and stitched pairs of the protrusion patterns.
fn rendered_what(args: &GroundTruthArgs, fixtures: &Fixtures) -> String {
    let n_cfg = fixtures.configurations.len();
    let n_pairs = fixtures.patterns.len() * fixtures.patterns.len();
    if let Some((_, _, r)) = press_of(args) {
        format!(
            "the press of a {} mm sphere",
            fabkit_calibration::shown_f64(r)
        )
    } else if args.pin_captures {
        format!("{n_cfg} pin captures")
    } else {
        format!(
            "{n_cfg} configurations ({} patterns x 2 orientations), {n_pairs} stitched pairs",
            fixtures.patterns.len()
        )
    }
}

/// Refuses a camera image over --max-pixels, before any per-pixel buffer is allocated.
fn check_pixels(
    args: &GroundTruthArgs,
    camera: &fabkit_calibration::CameraModel,
) -> Result<(), Box<dyn Error>> {
    let (cw, ch) = (
        camera.intrinsics().image_width_px,
        camera.intrinsics().image_height_px,
    );
    let pixels = u64::from(cw) * u64::from(ch);
    // The memory of every per-pixel buffer is bounded before any is allocated.
    if pixels > args.max_pixels {
        let remedy = if args.max_pixels < MAX_PIXELS_LIMIT {
            format!("raise the limit with --max-pixels, up to {MAX_PIXELS_LIMIT}")
        } else {
            format!(
                "--max-pixels is at its largest value, what the render's memory budget of {} GiB \
                 holds (about {} bytes a pixel)",
                MEMORY_BUDGET_BYTES >> 30,
                FIXED_BYTES_PER_PIXEL + FRAME_BYTES_PER_PIXEL
            )
        };
        return Err(format!(
            "{}: the camera image is {cw} x {ch} = {pixels} pixels, over the ground-truth limit of \
             {} pixels (image_width x image_height against --max-pixels; the render would need \
             about {} of memory, every per-pixel array of a frame being sized by it; {remedy}; \
             hint: calibrate the camera at a lower resolution or crop its image)",
            args.cam.camera.display(),
            args.max_pixels,
            shown_bytes(render_memory(pixels, 1)),
        )
        .into());
    }
    Ok(())
}

/// The render's inputs besides the design, read and checked: the camera and pose files, the
/// fixtures (or the fitted press as one configuration), and the camera's rays onto the
/// reference skin.
struct Inputs {
    camera: fabkit_calibration::CameraModel,
    camera_bytes: Vec<u8>,
    camera_sha: String,
    t_cam_sensor: fabkit_calibration::nalgebra::Isometry3<f64>,
    extrinsics_sha: String,
    fixtures: Fixtures,
    pose_name: String,
    optical_path: Option<(OpticalLayers, serde_json::Value)>,
    surface: ReferenceSurface,
    rays: PixelRays,
    /// The press fitted with --press-image.
    press: Option<Press>,
}

impl Inputs {
    /// Reads the camera, pose and fixtures of `args` for `design` and sets the scene, in the
    /// order their errors are reported; the fixtures must lie outside the camera.
    fn read(
        args: &GroundTruthArgs,
        design: &fabkit_designs::schema::Design,
    ) -> Result<Inputs, Box<dyn Error>> {
        let camera = args.cam.read()?;
        check_pixels(args, &camera)?;
        let (camera_bytes, camera_sha) = read_with_hash(&args.cam.camera)?;
        let (t_cam_sensor, extrinsics_sha) = read_extrinsics(&args.extrinsics)?;
        let pose_name = args.extrinsics.display().to_string();
        // the rays bend where the pose was solved through an optical path (`calibrate
        // extrinsics --design`): the depth maps register with the captures that calibration
        // saw
        let optical_path =
            fabkit_calibration::groundtruth::inputs::read_optical_path(&args.extrinsics)?;
        let (fixtures, press) = match press_of(args) {
            Some((capture, reference, radius_mm)) => {
                // the press is fitted along straight rays
                if optical_path.is_some() {
                    return Err(PressInputError::OpticalPath {
                        option: "--extrinsics",
                        file: pose_name,
                    }
                    .into());
                }
                let press = press::fit_press(&PressJob {
                    design,
                    camera: &camera,
                    camera_file: &args.cam.camera.display().to_string(),
                    t_cam_sensor: &t_cam_sensor,
                    capture,
                    capture_option: "--press-image",
                    reference,
                    reference_option: "--press-reference",
                    radius_mm,
                    radius_option: "--sphere-radius-mm",
                })?;
                (press.fixtures()?, Some(press))
            }
            None if args.pin_captures => {
                (read_pin_captures(fixtures_dir(args)?, &design.name)?, None)
            }
            None => (read_fixtures(fixtures_dir(args)?, &design.name)?, None),
        };
        let scene = Scene::through(
            design,
            &camera,
            &t_cam_sensor,
            &pose_name,
            optical_path.as_ref().map(|(l, _)| l),
        )?;
        if args.pin_captures {
            // the pin dome of this design's skin, whatever its name
            let dir = fixtures_dir(args)?;
            let pins = fabkit_calibration::groundtruth::pins::read_pins(dir)?;
            fabkit_calibration::groundtruth::pins::check_on_skin(dir, &pins, &scene.surface)?;
        }
        scene.check_outside(&fixtures.configurations, &pose_name)?;
        let Scene { surface, rays } = scene;
        Ok(Inputs {
            camera,
            camera_bytes,
            camera_sha,
            t_cam_sensor,
            extrinsics_sha,
            fixtures,
            pose_name,
            optical_path,
            surface,
            rays,
            press,
        })
    }
}

/// What the frames' images are rendered from, if any: the photometric model of
/// --photometric (with its sha256 and folder), or the design's optics with --images alone.
struct Looks<'a> {
    photometric: Option<((PhotometricModel, String), &'a Path)>,
    optics: Option<fabkit_designs::optics::ResolvedOptics>,
}

impl<'a> Looks<'a> {
    /// Reads --photometric (checked against the design, camera and pose files it must have
    /// been fitted with) or, with --images alone, the design's optics.
    fn read(
        args: &'a GroundTruthArgs,
        loaded: &crate::args::Loaded,
        inputs: &Inputs,
    ) -> Result<Looks<'a>, Box<dyn Error>> {
        let photometric = match &args.photometric {
            Some(dir) => Some((
                load_photometric(
                    dir,
                    inputs.rays.width,
                    inputs.rays.height,
                    [
                        (
                            "design",
                            loaded.sha256.as_str(),
                            Path::new(
                                args.design
                                    .as_deref()
                                    .unwrap_or(fabkit_designs::library::DEFAULT_DESIGN),
                            ),
                        ),
                        ("camera", inputs.camera_sha.as_str(), &args.cam.camera),
                        (
                            "extrinsics",
                            inputs.extrinsics_sha.as_str(),
                            &args.extrinsics,
                        ),
                    ],
                )?,
                dir.as_path(),
            )),
            None => None,
        };
        let optics = if args.images && photometric.is_none() {
            Some(fabkit_designs::optics::of_design(
                &loaded.design,
                fabkit_designs::ChordTolerance::new(fabkit_designs::ChordTolerance::DEFAULT_MM)?,
            )?)
        } else {
            None
        };
        Ok(Looks {
            photometric,
            optics,
        })
    }

    /// The bit depth of the frames' images (None: no images).
    fn image_bits(&self) -> Option<u32> {
        match &self.photometric {
            Some(((m, _), _)) => Some(if m.full_scale > 255.0 { 16 } else { 8 }),
            None => self.optics.as_ref().map(|o| o.camera.bit_depth),
        }
    }

    /// The source of the frames' images, the physical one shading from the reference skin
    /// `ref_hits`.
    fn image_source(self, inputs: &Inputs, ref_hits: &SurfaceHits) -> Option<ImageSource> {
        match self.photometric {
            Some(((m, sha), dir)) => Some(ImageSource::Photometric(
                Box::new(m),
                dir.display().to_string(),
                sha,
            )),
            None => self.optics.map(|o| {
                let i = inputs.camera.intrinsics();
                ImageSource::Physical(Box::new(Imaging::new(
                    o,
                    [i.cx_px, i.cy_px],
                    &inputs.rays,
                    ref_hits,
                )))
            }),
        }
    }
}

/// The `--format` names.
fn format_name(f: DataFormat) -> &'static str {
    match f {
        DataFormat::Npy => "npy",
        DataFormat::Npz => "npz",
        DataFormat::Png => "png",
    }
}

/// Prints the bound on the output and refuses it, before rendering, over --max-output-bytes
/// (without --yes) or the free space of the output's file system.
fn check_output_bound(
    args: &GroundTruthArgs,
    inputs: &Inputs,
    image_bits: Option<u32>,
) -> Result<(), Box<dyn Error>> {
    let (w, h) = (inputs.rays.width, inputs.rays.height);
    let n_cfg = inputs.fixtures.configurations.len();
    let bound_of = |f: DataFormat| match &inputs.press {
        Some(p) => press::output_bound(w as u64, h as u64, f.into(), image_bits, p),
        None => output_bound(
            w as u64,
            h as u64,
            n_cfg as u64,
            inputs.fixtures.patterns.len() as u64,
            f.into(),
            image_bits,
        ),
    };
    let (n_files, bound) = bound_of(args.format);
    let frames = match inputs.press {
        Some(_) => "the press".to_string(),
        None => format!("{n_cfg} configurations"),
    };
    eprintln!(
        "groundtruth: reference + {frames} of {w} x {h} pixels -> {} files, at most {} (--format {})",
        n_files,
        shown_bytes(bound),
        format_name(args.format)
    );
    let alternatives = [DataFormat::Npz, DataFormat::Png]
        .into_iter()
        .filter(|f| *f != args.format)
        .map(|f| {
            let (_, b) = bound_of(f);
            format!("--format {} (at most {})", format_name(f), shown_bytes(b))
        })
        .collect::<Vec<_>>()
        .join(" or ");
    if bound > args.max_output_bytes && !args.yes {
        return Err(format!(
            "--out {}: the ground truth would take up to {} ({bound} bytes, {n_files} files), over --max-output-bytes {} ({}): refusing before rendering (hint: give --yes to write it, use {alternatives}, or build fewer protrusion patterns)",
            args.out.display(),
            shown_bytes(bound),
            args.max_output_bytes,
            shown_bytes(args.max_output_bytes)
        )
        .into());
    }
    if let Some(free) = fabkit_export::free_bytes(&args.out) {
        if bound > free {
            return Err(format!(
                "--out {}: the ground truth may take up to {} ({bound} bytes, {n_files} files), more than the {} ({free} bytes) free on its file system: refusing before rendering (hint: use {alternatives}, free space, or write elsewhere)",
                args.out.display(),
                shown_bytes(bound),
                shown_bytes(free)
            )
            .into());
        }
    }
    Ok(())
}

/// Renders every frame into `staged` and writes its manifest.json; `progress(k)` after each
/// frame. Returns the files written.
fn write_dataset(
    staged: &StagedDir,
    args: &GroundTruthArgs,
    loaded: &crate::args::Loaded,
    inputs: &Inputs,
    ref_hits: &SurfaceHits,
    imaging: Option<&ImageSource>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<dataset::Written, Box<dyn Error>> {
    let design = &loaded.design;
    let provenance = dataset::provenance(&design.name, &loaded.sha256);
    let frames = FrameInputs {
        rays: &inputs.rays,
        reference_hits: ref_hits,
        base_z_mm: inputs.surface.base_z_mm(),
        fixtures: &inputs.fixtures,
        format: args.format.into(),
        imaging,
        provenance: &provenance,
    };
    let command_line = std::env::args().collect::<Vec<_>>();
    let manifest = ManifestInputs {
        fabkit_version: env!("CARGO_PKG_VERSION"),
        command_line: &command_line,
        design_name: &design.name,
        design_source: &loaded.source,
        design_sha256: &loaded.sha256,
        flat_skin: design.body.flat_outline().is_some(),
        camera: &inputs.camera,
        camera_file: &args.cam.camera.display().to_string(),
        camera_sha256: Some(&inputs.camera_sha),
        extrinsics_file: &args.extrinsics.display().to_string(),
        extrinsics_sha256: Some(&inputs.extrinsics_sha),
        t_cam_sensor: &inputs.t_cam_sensor,
        camera_centre_mm: inputs.rays.origin_mm,
        fixtures: &inputs.fixtures,
        pixels_on_surface: ref_hits.valid_count(),
        optical_path: inputs.optical_path.as_ref().map(|(_, v)| v),
        imaging,
    };
    match &inputs.press {
        Some(p) => press::write(staged, &frames, &manifest, p, progress),
        None => dataset::write(staged, &frames, &manifest, progress),
    }
    .map_err(|e| -> Box<dyn Error> { e })
}
