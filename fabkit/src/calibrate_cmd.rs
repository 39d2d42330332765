//! `fabkit calibrate ...`: argument parsing and dispatch over fabkit-calibration.

use std::error::Error;
use std::path::PathBuf;

use fabkit_calibration::capture_images::CaptureImages;
use fabkit_calibration::refine::RefineParameters;
use fabkit_calibration::{
    calibrate_extrinsics, ExtrinsicsJob, ExtrinsicsReport, FoundInImages, Observed, PointsFrom,
    RansacOptions,
};
use fabkit_export::{OutputClaim, OutputCommand, StagedDir};

use crate::args::CameraArgs;

#[derive(clap::Subcommand, Debug)]
pub enum CalibrateCommand {
    /// Solve the camera pose (T_cam_sensor) from pin-dome observations.
    Extrinsics(ExtrinsicsArgs),
    /// Fit the sensor's photometric model (how its images respond to the skin's normal) from
    /// pin captures whose pose is solved.
    Photometric(crate::photometric_cmd::PhotometricArgs),
    /// Calibrate a flat sensor's camera from one press of its calibration board (or a grid
    /// plate pressed over several captures): the bumps' imprints found against the reference,
    /// each given its grid id, the camera model (the distortion, its centre and the plane's
    /// pose; the focal length held, as one plane seen square on shows it only over the
    /// plane's distance) and the map from pixels to the skin's plane.
    Board(BoardArgs),
    /// Write the camera the design places, before anything is calibrated: a camera file
    /// (camera.yaml, an ideal equidistant fisheye of the lens's view angle across the image's
    /// short side, centred) and its pose (extrinsics.json, extrinsics.yaml, transform.yaml:
    /// the lens's front on the sensor's axis, looking along +z, with the design's optical
    /// path). Inputs for `fabkit groundtruth --pin-captures --images` (synthetic pin captures)
    /// and a first ground truth; a real camera's file and `calibrate extrinsics` replace them
    Nominal(NominalArgs),
}

#[derive(clap::Args, Debug)]
pub struct NominalArgs {
    /// A design YAML file or the name of a library design (default: rtac0)
    pub design: Option<String>,
    /// Apply one of the design's presets
    #[arg(long)]
    pub preset: Option<String>,
    /// The image's width, px (2 to 16384)
    #[arg(long, value_name = "PX", default_value_t = 640)]
    pub width_px: u32,
    /// The image's height, px (2 to 16384)
    #[arg(long, value_name = "PX", default_value_t = 480)]
    pub height_px: u32,
    /// The lens's full view angle, degrees, in (0, 360), across the image's short side.
    /// Default: the design's (`housing.camera.view_angle_deg`); required for a design that
    /// gives none
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub view_angle_deg: Option<f64>,
    /// Output folder for camera.yaml, extrinsics.json, extrinsics.yaml and transform.yaml.
    /// Replaced as a whole if it holds an earlier nominal camera of the same design as fabkit
    /// wrote it; refused if it holds anything else
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Replace an earlier nominal camera in --out of another design or size
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub(crate) data_files: crate::args::DataFileArgs,
}

#[derive(clap::Args, Debug)]
pub struct BoardArgs {
    /// The board's point table: points/board_table.csv of `fabkit fixtures`, or a CSV with
    /// id,x_mm,y_mm,z_mm (sensor frame, mm) on one plane of constant z, filling a grid of one
    /// pitch along x and y
    #[arg(long, value_name = "BOARD_TABLE.csv")]
    pub points: PathBuf,
    /// Which columns of a fixtures point table give the plane: the skin's face where the
    /// board's floor meets it (contact), or the bumps' tips (tip)
    #[arg(long, value_enum, default_value = "contact")]
    pub points_from: PointsFromArg,
    /// Reference image of the skin with no contact (PNG or JPEG)
    #[arg(long, value_name = "REF.png")]
    pub reference: PathBuf,
    /// The board pressed in, in one capture or over several (each pressing some of its bumps or
    /// pins, like a grid plate's): same camera, lighting and size as --reference. The
    /// imprints of all captures form one lattice; a bump seen in several is solved at the
    /// mean of its pixels
    #[arg(long, visible_alias = "images", value_name = "PRESS.png", num_args = 1.., required = true)]
    pub image: Vec<PathBuf>,
    /// Which ids each capture presses (points/capture_plan.csv of `fabkit fixtures`), one
    /// --image per capture in the plan's order: a spot at a place its capture does not press
    /// is left out, and a planned id without a spot is reported missing
    #[arg(long, value_name = "PLAN.csv")]
    pub capture_plan: Option<PathBuf>,
    /// The plane's distance from the lens's centre of projection, in air (each solid layer's
    /// thickness over its refractive index), mm: the focal length is held at this times the
    /// scale the press shows. Default: from the design's flat housing (--design, or the design
    /// the point table was made for), the lens taken at the shell plate's underside
    #[arg(long, value_name = "MM")]
    pub plane_distance_mm: Option<f64>,
    /// The sensor's design (a YAML file or a library name), for --plane-distance-mm
    #[arg(long, value_name = "DESIGN")]
    pub design: Option<String>,
    /// The board's grid turned in the image, degrees: 0, 90, 180 or 270 (the camera mounted
    /// turned about its optical axis). The ids are placed as if the image's u ran along the
    /// sensor's +x turned by this from u towards v (clockwise as the image is shown): at 90,
    /// +x runs down the image and +y to its left, and a 7 x 9 board shows 9 tall and 7 wide.
    /// The board's grid looks the same under a half turn, so the turn cannot be seen in the
    /// capture: it is given
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub board_turn: f64,
    /// Output folder for extrinsics.json, extrinsics.yaml (OpenCV), transform.yaml (ROS
    /// TransformStamped), camera.yaml (OpenCV), camera_info.yaml (ROS), camera.json, observations.csv, pixel_to_plane_mm.npy and overlay.png: missing,
    /// empty, or an earlier calibration of the same inputs as fabkit wrote it
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Replace an earlier board calibration in --out computed from other inputs
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub(crate) data_files: crate::args::DataFileArgs,
}

/// Which point of the fixtures point table the pins touch.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum PointsFromArg {
    /// The tip columns (tip_x_mm, ...).
    Tip,
    /// The contact columns (contact_x_mm, ...).
    Contact,
}

#[derive(clap::Args, Debug)]
pub struct ExtrinsicsArgs {
    #[command(flatten)]
    pub cam: CameraArgs,
    /// Point table: the one `fabkit fixtures` writes, or a CSV with id,x_mm,y_mm,z_mm (sensor frame, mm).
    #[arg(long, value_name = "POINTS.csv")]
    pub points: PathBuf,
    /// Columns of a fixtures point table to use.
    #[arg(long, value_enum, default_value = "tip")]
    pub points_from: PointsFromArg,
    /// Pixel observations, CSV id,u_px,v_px; several files (one per capture) may be given.
    #[arg(long, value_name = "OBS.csv", num_args = 1.., required_unless_present = "images", conflicts_with = "images")]
    pub observations: Vec<PathBuf>,
    /// Capture images (PNG or JPEG, 8- or 16-bit, grey or RGB, the camera's size), one per
    /// capture: the pins' imprints are found against --reference, written to observations.csv
    /// with an overlay per capture (overlays/), and the pose solved from them. Pin ids come from
    /// --capture-plan (images in capture order) or from the file names, which list the
    /// capture's pins in ring order (01_02_06_14_22.png: pins 1, 2, 6, 14 and 22), or from
    /// the folder of an image.png (01_02_06_14_22/image.png, as `fabkit groundtruth
    /// --pin-captures --images` writes a capture).
    #[arg(long, value_name = "CAPTURE.png", num_args = 1.., requires = "reference")]
    pub images: Vec<PathBuf>,
    /// Reference image of the unloaded skin (same camera and lighting as --images).
    #[arg(long, value_name = "REF.png", requires = "images")]
    pub reference: Option<PathBuf>,
    /// Capture plan (points/capture_plan.csv of `fabkit fixtures`): the observation files (or
    /// capture images) are one per capture, in capture order, and each may hold only that
    /// capture's pins.
    #[arg(long, value_name = "PLAN.csv")]
    pub capture_plan: Option<PathBuf>,
    /// Output folder for extrinsics.json, extrinsics.yaml (OpenCV), transform.yaml (ROS
    /// TransformStamped), residuals.png (overlay.png; from images
    /// observations.csv and overlays/): missing, empty, or an earlier calibration of the same
    /// inputs as fabkit wrote it (replaced whole; never a folder of the user's own files or
    /// another command's output).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Replace an earlier calibration in --out computed from other inputs (other captures,
    /// observations, camera file or point table); without it that result is kept and this run
    /// refused. Another command's output (an export, fixtures, ground truth) is never replaced.
    #[arg(long)]
    pub force: bool,
    /// Capture image (PNG) for an overlay of observed and reprojected points.
    #[arg(long, value_name = "IMG.png")]
    pub image: Option<PathBuf>,
    /// RANSAC inlier threshold on the reprojection error, px. Default: from the data
    /// (sqrt(2 ln(n / 0.002)) robust standard deviations of the reprojection error by least
    /// median of squares, 4.4 for 30 pins, at least 3 px, at most a tenth of the pixels'
    /// spread), so that a camera file that follows the lens only roughly towards the edge of
    /// its field still gives a pose.
    #[arg(long)]
    pub ransac_threshold_px: Option<f64>,
    /// Use every observation (no outlier rejection).
    #[arg(long)]
    pub no_ransac: bool,
    /// Refine the intrinsics with the pose, by Levenberg-Marquardt on the reprojection error,
    /// and write the refined camera file (camera_refined.yaml or .json, the form read). Alone:
    /// every parameter the captures constrain (the others, such as the focal length seen from
    /// near the dome's axis, are held at the camera file's values and the report says why);
    /// or a list, e.g. cx,cy,k1,k2 (names: fx fy cx cy and the model's k1 k2 [p1 p2] k3 ...),
    /// refused if the captures do not constrain it.
    #[arg(long, value_name = "PARAMS", num_args = 0..=1, default_missing_value = "")]
    pub refine_intrinsics: Option<String>,
    /// Ignored: RANSAC draws its samples on a fixed schedule, so the pose depends on the data
    /// only (the same captures in any order, the same pose). Accepted so that command lines
    /// that give it still run.
    #[arg(long, value_name = "SEED")]
    pub seed: Option<u64>,
    /// The sensor's design (a YAML file or a library name): the rays from the lens bend by
    /// Snell's law at its interfaces (the filling gel's free surface, a window's or a plate's
    /// faces, a spherical core's faces), with the refractive indices of the materials table;
    /// the report lists them (`optical_path`).
    /// Without it, the design the point table was made for (its sidecar point_table.json,
    /// as `fabkit fixtures` writes it) gives the optical path, when that design reads as it
    /// did then (the same sha256) and none of its presets moves an interface.
    #[arg(long, value_name = "DESIGN")]
    pub design: Option<String>,
    /// Straight rays from the lens: no optical path, not even the point table's design's (a
    /// camera that looks at the skin through air only).
    #[arg(long, conflicts_with_all = ["design", "refine_optical_path"])]
    pub straight_rays: bool,
    /// Refine the height of the design's filling gel surface and the gel's index with the
    /// pose, under priors of 0.5 mm and 0.01 about the design's and the materials table's
    /// values; the report gives both with their standard deviations (`optical_path_fit`).
    /// With --design or the point table's design.
    #[arg(long)]
    pub refine_optical_path: bool,
    /// Apply one of the design's presets (with --design).
    #[arg(long, value_name = "NAME", requires = "design")]
    pub preset: Option<String>,
    #[command(flatten)]
    pub(crate) data_files: crate::args::DataFileArgs,
}

pub fn run(cmd: CalibrateCommand) -> Result<(), Box<dyn Error>> {
    match cmd {
        CalibrateCommand::Extrinsics(a) => extrinsics(a),
        CalibrateCommand::Photometric(a) => crate::photometric_cmd::run(a),
        CalibrateCommand::Board(a) => board(a),
        CalibrateCommand::Nominal(a) => nominal(a),
    }
}

fn nominal(a: NominalArgs) -> Result<(), Box<dyn Error>> {
    use fabkit_calibration::nominal::{nominal_camera, nominal_files};
    let mut loaded = crate::args::load_design(a.design.as_deref(), &a.data_files)?;
    if let Some(p) = &a.preset {
        loaded.apply_preset(p)?;
    }
    let n = nominal_camera(&loaded.design, a.width_px, a.height_px, a.view_angle_deg)?;
    let command_line = std::env::args().collect::<Vec<_>>().join(" ");
    let files = nominal_files(&n, &command_line)?;
    let claim = OutputClaim {
        command: OutputCommand::CalibrateNominal,
        job: format!(
            "the nominal camera of design '{}', {} x {} px, view {} deg",
            n.design, a.width_px, a.height_px, n.view_angle_deg
        ),
        force: a.force,
        inputs: Vec::new(),
    };
    let staged = StagedDir::new(&a.out, claim)?;
    for (name, bytes) in &files {
        staged.write(name, bytes)?;
    }
    let warnings = staged.commit()?;
    let i = &n.intrinsics;
    println!(
        "camera: {} x {} px, equidistant fisheye f = {:.2} px (view {:.1} deg across {} px, from {}), principal point ({:.1}, {:.1}) px",
        i.image_width_px,
        i.image_height_px,
        i.fx_px,
        n.view_angle_deg,
        i.image_width_px.min(i.image_height_px),
        n.view_angle_from,
        i.cx_px,
        i.cy_px
    );
    println!(
        "pose: the lens's front at z = {:.3} mm on the sensor's axis, looking along +z ({})",
        n.lens.front_z_mm, n.lens.what
    );
    println!(
        "optical path: {}",
        if n.optical_path.planes.is_empty() {
            "straight rays (no interface in front of the lens)".to_string()
        } else {
            plane_names(&n.optical_path).join("; ")
        }
    );
    println!(
        "nominal, not calibrated: a real camera's file and `fabkit calibrate extrinsics` replace these"
    );
    println!("wrote {}", a.out.display());
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}

fn board(a: BoardArgs) -> Result<(), Box<dyn Error>> {
    use fabkit_calibration::board::{
        board_claim, calibrate_board, plane_distance_of_design, BoardJob, BoardTurn,
    };
    let board_turn = BoardTurn::from_deg(a.board_turn)?;
    let (plane_distance_mm, plane_distance_from) = match (a.plane_distance_mm, &a.design) {
        (Some(d), _) => (d, "--plane-distance-mm".to_string()),
        (None, given) => {
            let arg = match given {
                Some(d) => d.clone(),
                None => provenance_design(&a.points).map(|(_, arg, _)| arg).ok_or_else(|| {
                    format!(
                        "--plane-distance-mm: not given, and no design to take it from: give it, or --design (the point table {} names none)",
                        a.points.display()
                    )
                })?,
            };
            let loaded = crate::args::load_design(Some(&arg), &a.data_files)?;
            let materials = fabkit_designs::materials::MaterialsTable::embedded()?;
            plane_distance_of_design(&loaded.design, &materials).ok_or_else(|| {
                format!(
                    "--plane-distance-mm: not given, and the design {arg} has no flat_housing to take it from: give it"
                )
            })?
        }
    };
    let job = BoardJob {
        points: a.points,
        points_from: match a.points_from {
            PointsFromArg::Tip => PointsFrom::Tip,
            PointsFromArg::Contact => PointsFrom::Contact,
        },
        reference: a.reference,
        images: a.image,
        capture_plan: a.capture_plan,
        plane_distance_mm,
        plane_distance_from,
        board_turn,
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
    };
    let staged = StagedDir::new(&a.out, board_claim(&job, a.force))?;
    let out = calibrate_board(&job)?;
    for (name, bytes) in &out.files {
        staged.write(name, bytes)?;
    }
    let warnings = staged.commit()?;
    let r = &out.report;
    println!(
        "board: {} of {} bumps found ({} spots; {} missing, {} taken for no bump)",
        r.found,
        r.grid.rows * r.grid.columns,
        r.spots,
        r.missing_ids.len(),
        r.extra_spots.len()
    );
    if r.board_turn_deg != 0 {
        println!(
            "board turned {} deg in the image: the sensor's +x along the image's {}",
            r.board_turn_deg,
            board_turn.axes_in_image().0
        );
    }
    for n in &r.notes {
        println!("note: {n}");
    }
    if r.captures.len() > 1 {
        for c in &r.captures {
            let missing = if c.missing_planned_ids.is_empty() {
                String::new()
            } else {
                format!(
                    "; planned but not found: {}",
                    c.missing_planned_ids.join(" ")
                )
            };
            println!(
                "  capture {} ({}): {} bumps found, {} spot(s) left out{missing}",
                c.capture,
                c.image,
                c.found.len(),
                c.extra.len()
            );
        }
    }
    println!(
        "camera: RMS reprojection error {:.3} px, worst {:.3} px (id {}); plane {:.3} mm away ({})",
        r.rms_reprojection_error_px,
        r.worst_px,
        r.worst_id,
        r.plane_distance_mm,
        r.plane_distance_from
    );
    for p in &r.parameters {
        match (&p.held, p.std) {
            (None, Some(sd)) => println!("  {} = {:.6} +- {:.6}", p.name, p.value, sd),
            (Some(why), _) => println!("  {} = {:.6} held: {why}", p.name, p.value),
            (None, None) => println!("  {} = {:.6}", p.name, p.value),
        }
    }
    if let (Some(s), Some(n)) = (r.mm_per_px_at_centre, r.mm_per_px_neighbours) {
        println!(
            "scale at the centre bump {} ({:.1}, {:.1}) px: {s:.5} mm per px ({n:.5} from its four neighbours' distances)",
            r.centre_bump_id, r.centre_bump_px[0], r.centre_bump_px[1]
        );
    }
    print_tf(&r.t_cam_sensor);
    println!("wrote {}", a.out.display());
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}

fn extrinsics(a: ExtrinsicsArgs) -> Result<(), Box<dyn Error>> {
    check_options(&a)?;
    let claim = claim(&a);
    let (optical_path, optical_path_from) = optical_path(&a)?;
    if a.refine_optical_path && optical_path.is_none() {
        return Err(
            "--refine-optical-path: there is no optical path to refine (give --design; the point table names no design whose camera looks through an interface)"
                .into(),
        );
    }
    let out_dir = a.out.clone();
    let camera_file = a.cam.camera.clone();
    let camera_model = a.cam.camera_model.map(Into::into);
    let job = job(a, optical_path, optical_path_from);
    // The output folder is checked (and its temporary sibling made) before the solve; nothing
    // appears under --out unless every file is written.
    let staged = StagedDir::new(&out_dir, claim)?;
    let out = calibrate_extrinsics(&job)?;
    for (name, bytes) in &out.files {
        staged.write(name, bytes)?;
    }
    let warnings = staged.commit()?;
    if let Some(f) = out.found {
        print_found(&f);
    }
    // which keys of the camera file were read (`K`, `cameraMatrix`, ...); the solve read it
    if let Ok(read) =
        fabkit_calibration::camera_file::read_camera_file_keys(&camera_file, camera_model)
    {
        println!(
            "camera: {} read from {}",
            read.keys_read,
            camera_file.display()
        );
    }
    let r = out.report;
    print_report(&r);
    print_tf(&r.t_cam_sensor);
    println!("wrote {}", out_dir.display());
    for w in r.warnings.iter().chain(&warnings) {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// Notes an ignored --seed and refuses a --ransac-threshold-px that is not a finite positive
/// number.
fn check_options(a: &ExtrinsicsArgs) -> Result<(), Box<dyn Error>> {
    if let Some(seed) = a.seed {
        eprintln!(
            "note: --seed {seed} has no effect: RANSAC samples on a fixed schedule, so the pose depends on the data only"
        );
    }
    if let Some(t) = a.ransac_threshold_px {
        if !(t.is_finite() && t > 0.0) {
            return Err(format!("--ransac-threshold-px = {t}: must be finite and > 0").into());
        }
    }
    Ok(())
}

/// The claim on --out: the job of the output is its inputs (what it was computed from), not
/// the solver's options.
fn claim(a: &ExtrinsicsArgs) -> OutputClaim {
    let captures = a.images.len().max(a.observations.len());
    let inputs: Vec<&std::path::Path> = [&a.cam.camera, &a.points]
        .into_iter()
        .chain(&a.observations)
        .chain(&a.images)
        .chain(&a.reference)
        .chain(&a.capture_plan)
        .map(PathBuf::as_path)
        .collect();
    OutputClaim::of_inputs(
        OutputCommand::CalibrateExtrinsics,
        &format!(
            "extrinsics from {captures} {}",
            if a.images.is_empty() {
                "observation files"
            } else {
                "captures"
            }
        ),
        &inputs,
        a.force,
    )
}

/// The optical path the rays bend through and where it comes from in words: none with
/// --straight-rays, that of --design (and --preset), or that of the point table's design.
fn optical_path(
    a: &ExtrinsicsArgs,
) -> Result<(Option<fabkit_designs::optics::OpticalPath>, Option<String>), Box<dyn Error>> {
    Ok(match (&a.design, a.straight_rays) {
        (_, true) => (None, None),
        (Some(d), false) => {
            let mut loaded = crate::args::load_design(Some(d), &a.data_files)?;
            if let Some(p) = &a.preset {
                loaded.apply_preset(p)?;
            }
            let path = fabkit_designs::optics::optical_path_of_design(
                &loaded.design,
                fabkit_designs::ChordTolerance::new(fabkit_designs::ChordTolerance::DEFAULT_MM)?,
            )?;
            let from = match &a.preset {
                Some(p) => format!("--design {d} --preset {p}"),
                None => format!("--design {d}"),
            };
            (Some(path), Some(from))
        }
        (None, false) => match table_design(&a.points, &a.data_files) {
            TableDesign::Unknown => (None, None),
            TableDesign::Unusable(why) => {
                eprintln!("note: {why}; the rays are straight from the lens");
                (None, None)
            }
            TableDesign::Path { path, from } => {
                eprintln!(
                    "note: the rays bend at the interfaces of {from}: {} (--straight-rays for straight rays)",
                    plane_names(&path).join("; ")
                );
                (Some(path), Some(from))
            }
        },
    })
}

/// The calibration job of the arguments `a` through `optical_path`.
fn job(
    a: ExtrinsicsArgs,
    optical_path: Option<fabkit_designs::optics::OpticalPath>,
    optical_path_from: Option<String>,
) -> ExtrinsicsJob {
    ExtrinsicsJob {
        optical_path,
        optical_path_from,
        refine_optical_path: a.refine_optical_path,
        camera: a.cam.camera,
        camera_model: a.cam.camera_model.map(Into::into),
        points: a.points,
        points_from: match a.points_from {
            PointsFromArg::Tip => PointsFrom::Tip,
            PointsFromArg::Contact => PointsFrom::Contact,
        },
        observations: match a.reference {
            Some(reference) => Observed::Images(CaptureImages {
                captures: a.images,
                reference,
            }),
            None => Observed::Files(a.observations),
        },
        capture_plan: a.capture_plan,
        image: a.image,
        refine_intrinsics: match a.refine_intrinsics.as_deref() {
            None => None,
            Some("") => Some(RefineParameters::Constrained),
            Some(list) => Some(RefineParameters::Only(
                list.split(',').map(|s| s.trim().to_string()).collect(),
            )),
        },
        ransac: (!a.no_ransac).then_some(RansacOptions {
            threshold_px: a.ransac_threshold_px,
            ..Default::default()
        }),
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
    }
}

/// Prints the pose as ROS publishes it (transform.yaml holds the same as a TransformStamped).
fn print_tf(t_cam_sensor: &[[f64; 4]; 4]) {
    println!(
        "ROS (transform.yaml): {}",
        fabkit_calibration::report::static_transform_publisher(t_cam_sensor)
    );
}

/// Prints the pins found in the capture images and what was left out.
fn print_found(f: &FoundInImages) {
    println!(
        "imprints: {} pins found in {} of {} captures (observations.csv; overlays/){}",
        f.detections,
        f.captures - f.captures_left_out,
        f.captures,
        if f.captures_left_out + f.spots_discarded + f.pins_missing > 0 {
            let n = |k: usize, one: &str, many: &str| {
                format!("{k} {}", if k == 1 { one } else { many })
            };
            format!(
                "; {} left out, {} discarded, {} missing: named below",
                n(f.captures_left_out, "capture", "captures"),
                n(f.spots_discarded, "spot", "spots"),
                n(f.pins_missing, "pin", "pins")
            )
        } else {
            String::new()
        }
    );
}

/// Prints the solved pose: the reprojection errors, outliers and models compared, the pose,
/// refined intrinsics and the pose's uncertainty.
fn print_report(r: &ExtrinsicsReport) {
    let c = r.residuals.camera_centre_in_sensor_mm;
    println!(
        "extrinsics: {} of {} points, RMS reprojection error {:.3} px, worst {:.3} px (id {})",
        r.residuals.inliers,
        r.residuals.observations,
        r.rms_reprojection_error_px,
        r.residuals.worst_px,
        r.residuals.worst_id
    );
    if !r.residuals.outlier_ids.is_empty() {
        println!(
            "outliers rejected: {}{}",
            r.residuals.outlier_ids.join(", "),
            r.residuals
                .ransac_threshold_px
                .map_or_else(String::new, |t| format!(" (beyond {t:.2} px)"))
        );
    }
    if let Some(c) = &r.model_comparison {
        println!(
            "models compared before rejecting: {}; {}",
            c.models
                .iter()
                .map(|m| format!(
                    "{} BIC {:.1} (RMS {:.2} px, worst {:.2} px)",
                    m.model, m.bic, m.rms_px, m.worst_px
                ))
                .collect::<Vec<_>>()
                .join(", "),
            if c.chosen == "RANSAC" {
                "the rejection stands".to_string()
            } else {
                format!("{}: every pin kept", c.chosen)
            }
        );
    }
    println!(
        "RMS by polar angle: {}",
        r.residuals
            .by_polar_angle
            .iter()
            .map(|b| match b.projected {
                0 => format!("{} none projects ({} pins)", b.angles(), b.points),
                _ => format!("{} {:.2} px ({} pins)", b.angles(), b.rms_px, b.points),
            })
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!(
        "rvec = [{:.6}, {:.6}, {:.6}] rad, tvec_mm = [{:.4}, {:.4}, {:.4}], camera centre in sensor frame = [{:.4}, {:.4}, {:.4}] mm",
        r.rvec[0], r.rvec[1], r.rvec[2], r.tvec_mm[0], r.tvec_mm[1], r.tvec_mm[2], c[0], c[1], c[2]
    );
    if let Some(ir) = &r.intrinsics_refinement {
        println!(
            "intrinsics: RMS reprojection error {:.3} px with the camera file's, {:.3} px refined (condition number {:.0}); {}",
            ir.rms_before_px, ir.rms_after_px, ir.condition_number, ir.camera_file
        );
        for p in &ir.parameters {
            match (&p.held, p.std) {
                (None, Some(sd)) => println!(
                    "  {} = {:.6} +- {:.6} (camera file {:.6})",
                    p.name, p.value, sd, p.initial
                ),
                (Some(why), _) => println!("  {} = {:.6} held: {why}", p.name, p.value),
                (None, None) => println!("  {} = {:.6}", p.name, p.value),
            }
        }
    }
    if let Some(u) = &r.pose_uncertainty {
        let [rx, ry, rz] = u.rotation_std_deg_per_px;
        let [tx, ty, tz] = u.translation_std_mm_per_px;
        println!(
            "pose standard deviation per px of pixel noise: rotation [{rx:.3}, {ry:.3}, {rz:.3}] deg, translation [{tx:.4}, {ty:.4}, {tz:.4}] mm"
        );
    }
}

/// The design a point table was made for, as its sidecar (`point_table.json`, as `fabkit
/// fixtures` writes it) names it in its provenance (`fabkit V, design NAME (SOURCE, sha256 H)`).
enum TableDesign {
    /// No sidecar, no provenance, or a design with no interface: straight rays.
    Unknown,
    /// A design whose optical path cannot be taken for the table's: why, in words.
    Unusable(String),
    /// The design's optical path, and where it comes from in words.
    Path {
        path: fabkit_designs::optics::OpticalPath,
        from: String,
    },
}

/// The names of the planes and curved faces of `path` without their parameter paths.
fn plane_names(path: &fabkit_designs::optics::OpticalPath) -> Vec<&str> {
    let what = path
        .planes
        .iter()
        .map(|p| p.what.as_str())
        .chain(path.shells.iter().map(|s| s.what.as_str()));
    what.map(|w| w.split_once(": ").map_or(w, |(_, w)| w))
        .collect()
}

/// The design the point table's sidecar names ([`fabkit_calibration::board::point_table_design`]).
fn provenance_design(points: &std::path::Path) -> Option<(String, String, String)> {
    fabkit_calibration::board::point_table_design(points)
}

/// [`TableDesign`] of the point table `points`. The design is used only when it reads as it
/// did when the table was written (the same sha256) and its presets, which the provenance does
/// not record, leave its optical path as it is.
fn table_design(points: &std::path::Path, data: &crate::args::DataFileArgs) -> TableDesign {
    let side = points.with_extension("json");
    let Some((name, arg, sha)) = provenance_design(points) else {
        return TableDesign::Unknown;
    };
    let (name, arg, sha) = (name.as_str(), arg.as_str(), sha.as_str());
    let Ok(tol) = fabkit_designs::ChordTolerance::new(fabkit_designs::ChordTolerance::DEFAULT_MM)
    else {
        return TableDesign::Unknown;
    };
    let loaded = match crate::args::load_design(Some(arg), data) {
        Ok(l) => l,
        Err(e) => {
            return TableDesign::Unusable(format!(
                "the point table is of design {name} ({}), which does not load ({e}): give --design for its optical path",
                side.display()
            ))
        }
    };
    let Ok(path) = fabkit_designs::optics::optical_path_of_design(&loaded.design, tol) else {
        return TableDesign::Unknown;
    };
    if path.planes.is_empty() && path.shells.is_empty() {
        return TableDesign::Unknown;
    }
    let planes = plane_names(&path).join("; ");
    if loaded.sha256 != sha {
        return TableDesign::Unusable(format!(
            "the point table is of design {name}, whose camera looks through {planes}, but {arg} no longer reads as it did when the table was written (sha256 {sha} in {}): give --design {arg} for its optical path",
            side.display()
        ));
    }
    for preset in loaded.design.presets.keys() {
        let mut variant = loaded.clone();
        let moved = match variant.apply_preset(preset) {
            Ok(()) => fabkit_designs::optics::optical_path_of_design(&variant.design, tol)
                .map_or(true, |p| p != path),
            Err(_) => true,
        };
        if moved {
            return TableDesign::Unusable(format!(
                "the point table is of design {name}, whose camera looks through {planes}, and its preset {preset} moves them (the table does not say which preset it was made with): give --design {arg} [--preset {preset}] for its optical path"
            ));
        }
    }
    TableDesign::Path {
        path,
        from: format!("design {name}, the point table's ({})", side.display()),
    }
}
