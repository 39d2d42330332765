//! The argument groups and helpers the commands share: where a design and its data files come
//! from, the mesh outputs of `export` and `fixtures`, the camera of the calibration and ground
//! truth commands. Below every command module: they import it, it imports none of them.

use clap::ValueEnum;
use fabkit_calibration::DistortionModelHint;
use fabkit_designs::input_files::DataFileRules;
use fabkit_designs::timings;
use fabkit_designs::{library, ChordTolerance, DesignError};
use fabkit_export::{ExportOptions, Formats};
use std::error::Error;
use std::path::{Path, PathBuf};

/// The mesh output options of `fabkit export` and `fabkit fixtures`: what is written, for which
/// printers, how finely, and the bound on the work.
#[derive(clap::Args, Debug)]
pub(crate) struct MeshOutputArgs {
    /// Output formats, comma separated: stl, 3mf, step (exact B-rep through the CadQuery twin;
    /// needs scripts/setup-cadquery or FABKIT_CADQUERY_PYTHON).
    #[arg(long, value_delimiter = ',', default_value = "stl,3mf")]
    pub format: Vec<Format>,
    #[command(flatten)]
    pub printer: crate::printers::PrinterArgs,
    /// Largest distance between the exported meshes and the exact solids, mm (seams included).
    #[arg(long, default_value_t = ChordTolerance::DEFAULT_MM)]
    pub chord_tolerance_mm: f64,
    /// Also write the CSG tree of every part (fabkit-csg/1 JSON) to this file, for the
    /// manifold3d replays (tests/oracles/replay_csg.py, export/python/twins).
    #[arg(long)]
    pub csg: Option<PathBuf>,
    /// Refuse an output estimated (before building) at more triangles than this (about 1 KB of
    /// memory each; 1 to 100000000).
    #[arg(long, value_name = "N", default_value_t = fabkit_designs::estimate::DEFAULT_MAX_TRIANGLES,
          value_parser = fabkit_designs::estimate::parse_max_triangles, allow_negative_numbers = true)]
    pub max_triangles: u64,
}

impl MeshOutputArgs {
    /// The chord tolerance, checked (`--chord-tolerance-mm` names the error).
    pub fn tolerance(&self) -> Result<ChordTolerance, Box<dyn Error>> {
        tolerance(self.chord_tolerance_mm)
    }

    /// Reads the design (`design`, or the default library design), applies `preset` and then
    /// the printer overrides.
    pub fn load(
        &self,
        design: Option<&str>,
        preset: Option<&str>,
        data: &DataFileArgs,
    ) -> Result<Loaded, Box<dyn Error>> {
        let t = timings::stage("read the design");
        let mut loaded = load_design(design, data)?;
        if let Some(p) = preset {
            loaded.apply_preset(p)?;
        }
        drop(t);
        crate::printers::apply(&self.printer, &mut loaded.design.printers)?;
        Ok(loaded)
    }

    /// The export options of this run: formats, provenance (command line, design, version).
    pub fn options(&self, loaded: &Loaded, tol: ChordTolerance) -> ExportOptions {
        let format = &self.format;
        let mut opts = ExportOptions::for_design(
            Formats {
                stl: format.contains(&Format::Stl),
                threemf: format.contains(&Format::ThreeMf),
                step: format.contains(&Format::Step),
                mjcf: format.contains(&Format::Mjcf),
                urdf: format.contains(&Format::Urdf),
                usd: format.contains(&Format::Usd),
            },
            std::env::args().collect(),
            &loaded.source,
            &loaded.sha256,
            tol.mm(),
            loaded.design.printers.clone(),
        );
        if opts.formats.mjcf || opts.formats.urdf || opts.formats.usd {
            opts.sim = fabkit_calibration::nominal::sim_scene(&loaded.design, tol);
        }
        opts
    }

    /// Refuses a `--csg` path that may not be written, before anything is built.
    pub fn check_csg(&self) -> Result<(), Box<dyn Error>> {
        self.csg.as_deref().map_or(Ok(()), check_csg_path)
    }

    /// Writes the CSG tree of `kit` to `--csg`, if given.
    pub fn write_csg(&self, kit: &fabkit_designs::Kit) -> Result<(), Box<dyn Error>> {
        self.csg
            .as_deref()
            .map_or(Ok(()), |path| write_csg(kit, path))
    }
}

/// Which data files (a pattern's `csv_file`) a design file may read.
#[derive(clap::Args, Debug, Clone, Default)]
pub(crate) struct DataFileArgs {
    /// Also read data files (a marker pattern's csv_file) from this folder and its subfolders;
    /// by default only the design file's own folder is read. May be given more than once.
    #[arg(long, value_name = "DIR", value_parser = parse_allow_data_dir)]
    pub allow_data_dir: Vec<PathBuf>,
    /// Largest data file, bytes (1 to 67108864).
    #[arg(long, value_name = "BYTES", default_value_t = fabkit_designs::input_files::DEFAULT_MAX_DATA_FILE_BYTES, value_parser = parse_max_data_file_bytes,
        allow_negative_numbers = true)]
    pub max_data_file_bytes: u64,
}

impl DataFileArgs {
    pub(crate) fn rules(&self) -> DataFileRules {
        DataFileRules {
            allowed_dirs: self.allow_data_dir.clone(),
            max_bytes: self.max_data_file_bytes,
        }
    }
}

fn parse_allow_data_dir(s: &str) -> Result<PathBuf, String> {
    DataFileRules::allow_dir(Path::new(s))
}

fn parse_max_data_file_bytes(s: &str) -> Result<u64, String> {
    DataFileRules::parse_max_bytes(s)
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
pub(crate) enum Format {
    Stl,
    #[value(name = "3mf")]
    ThreeMf,
    /// STEP through the CadQuery twin (export/python/twins).
    Step,
    /// The assembled sensor for MuJoCo: sim/<design>.xml (MJCF) and sim/meshes/*.stl, with its
    /// mass, inertia, camera and lights.
    Mjcf,
    /// The assembled sensor as a URDF (PyBullet, ROS): sim/<design>.urdf, sim/meshes/*.stl and
    /// the camera's file, with its mass, inertia and camera frame.
    Urdf,
    /// The assembled sensor as a USD layer (Isaac Sim, Isaac Lab): sim/<design>.usda with
    /// UsdPhysics mass, the meshes, the camera, the LEDs.
    Usd,
}

/// The simulators' camera of a calibration: the intrinsics of `camera_file` as a pinhole (fy
/// and the image size; a principal point off the centre or a lens distortion is named in the
/// note, as MJCF's and USD's cameras cannot carry them) where `extrinsics_file` (the
/// `extrinsics.json` of `fabkit calibrate extrinsics`) puts it; the camera file itself goes
/// beside the models.
///
/// # Errors
/// Unreadable files, by option; an extrinsics file solved for another design than `design`
/// (its `optical_path_from`), by option, with both names; a camera file of another image size
/// than the one the extrinsics were solved with (its `provenance.camera_file`, when that file
/// is where the calibration read it).
pub(crate) fn calibrated_sim_camera(
    design: &str,
    camera_file: &Path,
    extrinsics_file: &Path,
) -> Result<fabkit_export::sim::SimCamera, Box<dyn Error>> {
    let model = fabkit_calibration::camera_file::read_camera_file(camera_file)
        .map_err(|e| format!("--camera {}: {e}", camera_file.display()))?;
    let (t_cam_sensor, _) =
        fabkit_calibration::groundtruth::inputs::read_extrinsics(extrinsics_file)
            .map_err(|e| format!("--extrinsics {}: {e}", extrinsics_file.display()))?;
    // `design rtac0, the point table's (...)` or `design 'rtac0'` (calibrate nominal)
    let text = std::fs::read_to_string(extrinsics_file)
        .map_err(|e| format!("--extrinsics {}: {e}", extrinsics_file.display()))?;
    let solved_for = serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| v["optical_path_from"].as_str().map(str::to_owned))
        .and_then(|from| {
            let rest = from.strip_prefix("design ")?;
            let name: String = rest
                .trim_start_matches('\'')
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == '-')
                .collect();
            Some(name)
        });
    if let Some(other) = solved_for.filter(|n| !n.is_empty() && n != design) {
        return Err(format!(
            "--extrinsics {}: solved for design '{other}', not '{design}': its pose is of another sensor",
            extrinsics_file.display()
        )
        .into());
    }
    let i = model.intrinsics();
    // the camera the pose was solved with, when its file is where the calibration read it
    let solved_with = serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| v["provenance"]["camera_file"].as_str().map(PathBuf::from))
        .and_then(|p| {
            let m = fabkit_calibration::camera_file::read_camera_file(&p).ok()?;
            Some((p, m))
        });
    if let Some((p, m)) = solved_with {
        let (a, b) = (m.intrinsics(), i);
        if (a.image_width_px, a.image_height_px) != (b.image_width_px, b.image_height_px) {
            return Err(format!(
                "--camera {}: {} x {} px, but {} was solved with {} ({} x {} px): give that camera's file",
                camera_file.display(),
                b.image_width_px,
                b.image_height_px,
                extrinsics_file.display(),
                p.display(),
                a.image_width_px,
                a.image_height_px
            )
            .into());
        }
    }
    let (w, h) = (f64::from(i.image_width_px), f64::from(i.image_height_px));
    let mut left_out = Vec::new();
    let (dx, dy) = (i.cx_px - (w - 1.0) / 2.0, i.cy_px - (h - 1.0) / 2.0);
    if dx.abs() > 1e-9 || dy.abs() > 1e-9 {
        left_out.push(format!(
            "its principal point {dx:+.2}, {dy:+.2} px off the image's centre"
        ));
    }
    if (i.fx_px - i.fy_px).abs() > 1e-9 * i.fy_px {
        left_out.push(format!(
            "fx {:.2} px (fy {:.2} px is used)",
            i.fx_px, i.fy_px
        ));
    }
    if i.distortion.coefficients().iter().any(|c| *c != 0.0)
        || matches!(
            i.distortion,
            fabkit_calibration::camera::Distortion::Fisheye(_)
        )
    {
        left_out.push(format!("its {} lens model", i.distortion.name()));
    }
    let what = format!(
        "the calibrated camera: {} placed by {}, as a pinhole of fy {:.2} px on {} x {} px{}",
        camera_file.display(),
        extrinsics_file.display(),
        i.fy_px,
        i.image_width_px,
        i.image_height_px,
        if left_out.is_empty() {
            String::new()
        } else {
            format!(
                "; the MJCF and USD cameras leave out {} (camera.yaml beside them has it)",
                left_out.join(", ")
            )
        }
    );
    let file = std::fs::read(camera_file)
        .map_err(|e| format!("--camera {}: {e}", camera_file.display()))?;
    Ok(fabkit_export::sim::SimCamera {
        t_sensor_cam: t_cam_sensor.inverse(),
        width_px: i.image_width_px,
        height_px: i.image_height_px,
        fy_px: i.fy_px,
        what,
        file: Some(file),
    })
}

/// A design and where it came from.
pub(crate) type Loaded = library::LoadedDesign;

pub(crate) fn load_design(arg: Option<&str>, data: &DataFileArgs) -> Result<Loaded, DesignError> {
    let arg = arg.unwrap_or(library::DEFAULT_DESIGN);
    let loaded = library::load_source_with(arg, Path::new(""), &data.rules())?;
    // a value valid in its unit but likely typed in another (issue 102)
    for w in loaded.unit_warnings() {
        eprintln!("warning: {w}");
    }
    Ok(loaded)
}

/// The first bytes of every CSG file fabkit writes (`serde_json` orders the keys).
const CSG_HEADER: &[u8] = b"{\"format\":\"fabkit-csg/1\"";

/// Checks that `--csg PATH` may be written: missing, or a regular file that is an earlier
/// fabkit CSG file. A user's own file (a design, anything else) and a symbolic link are refused.
pub(crate) fn check_csg_path(path: &Path) -> Result<(), Box<dyn Error>> {
    use std::io::Read as _;
    let refuse = |why: &str| -> Box<dyn Error> {
        format!(
            "--csg {}: {why}; refusing to overwrite it (hint: name a new file)",
            path.display()
        )
        .into()
    };
    let md = match std::fs::symlink_metadata(path) {
        Ok(md) => md,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(format!("--csg {}: {e}", path.display()).into()),
    };
    if md.file_type().is_symlink() {
        return Err(refuse("is a symbolic link"));
    }
    if !md.is_file() {
        return Err(refuse("exists and is not a regular file"));
    }
    let mut head = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(CSG_HEADER.len() as u64).read_to_end(&mut head))
        .map_err(|e| format!("--csg {}: {e}", path.display()))?;
    if head != CSG_HEADER {
        return Err(refuse("exists and is not a CSG file fabkit wrote"));
    }
    Ok(())
}

/// Writes the CSG tree of every part of `kit` (fabkit-csg/1 JSON) to `path` (checked by
/// [`check_csg_path`]) through a temporary sibling and a rename.
pub(crate) fn write_csg(kit: &fabkit_designs::Kit, path: &Path) -> Result<(), Box<dyn Error>> {
    check_csg_path(path)?;
    let parts: Vec<(&str, &fabkit_designs::Solid)> = kit
        .parts
        .iter()
        .map(|p| (p.name.as_str(), &p.solid))
        .collect();
    let json = serde_json::to_vec(&fabkit_designs::geometry::csg_json(&parts))?;
    debug_assert!(json.starts_with(CSG_HEADER));
    let name = path
        .file_name()
        .ok_or_else(|| format!("--csg {}: names no file", path.display()))?;
    let tmp = path.with_file_name(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let r = std::fs::write(&tmp, &json).and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = r {
        let _ = std::fs::remove_file(&tmp);
        return Err(format!("writing {}: {e}", path.display()).into());
    }
    Ok(())
}

/// Prints the written parts, a line each: name, print technology, volume and file.
pub(crate) fn print_parts(parts: &[fabkit_export::ManifestPart]) {
    for p in parts {
        out!(
            "  {:34} {:4} {:>10.1} mm3  {}",
            p.name,
            p.print_technology.to_string(),
            p.volume_mm3,
            p.file.as_deref().unwrap_or("(3MF only)")
        );
    }
}

pub(crate) fn tolerance(mm: f64) -> Result<ChordTolerance, Box<dyn Error>> {
    ChordTolerance::new(mm).map_err(|e| format!("--chord-tolerance-mm: {e}").into())
}

/// `--camera-model`: the distortion model names of ROS and OpenCV.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum CameraModelArg {
    /// Kannala-Brandt, k1..k4 (cv2.fisheye).
    #[value(name = "fisheye")]
    Fisheye,
    /// k1, k2, p1, p2[, k3] (cv2.calibrateCamera).
    #[value(name = "plumb_bob")]
    PlumbBob,
    /// k1, k2, p1, p2, k3..k6 (cv2.calibrateCamera with CALIB_RATIONAL_MODEL).
    #[value(name = "rational_polynomial")]
    RationalPolynomial,
}

impl From<CameraModelArg> for DistortionModelHint {
    fn from(a: CameraModelArg) -> DistortionModelHint {
        match a {
            CameraModelArg::Fisheye => DistortionModelHint::Fisheye,
            CameraModelArg::PlumbBob => DistortionModelHint::PlumbBob,
            CameraModelArg::RationalPolynomial => DistortionModelHint::RationalPolynomial,
        }
    }
}

/// The camera options of every command that reads a camera file.
#[derive(clap::Args, Debug)]
pub struct CameraArgs {
    /// Camera file: OpenCV FileStorage YAML or XML, ROS camera_info YAML or fabkit JSON.
    #[arg(long, value_name = "CAM")]
    pub camera: PathBuf,
    /// Distortion model of a camera file that does not name one (e.g. the 4 coefficients of
    /// cv2.fisheye.calibrate)
    #[arg(long, value_enum, value_name = "MODEL")]
    pub camera_model: Option<CameraModelArg>,
}

impl CameraArgs {
    /// The camera of `--camera` (with `--camera-model` for a file that names none).
    /// Says on stdout which of the file's keys were read (`camera: K (intrinsics), D
    /// (distortion) read from cam.yaml`): a file in another tool's spelling is read, and the
    /// reader sees what was taken from it.
    pub fn read(
        &self,
    ) -> Result<fabkit_calibration::CameraModel, fabkit_calibration::CameraFileError> {
        let read = fabkit_calibration::camera_file::read_camera_file_keys(
            &self.camera,
            self.camera_model.map(Into::into),
        )?;
        out!(
            "camera: {} read from {}",
            read.keys_read,
            self.camera.display()
        );
        Ok(read.camera)
    }
}
