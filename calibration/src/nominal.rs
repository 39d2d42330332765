//! The camera a design places, before anything is calibrated: a camera file and a pose
//! (`T_cam_sensor`) from the design's lens ([`fabkit_designs::optics::Lens`]: where its front
//! is on the sensor's axis and, when the design gives it, its view angle) and the optical path
//! in front of it. With them, `fabkit groundtruth --pin-captures --images` renders the pin
//! dome's captures as this camera would take them, so the calibration path runs before a
//! sensor is built, and a first ground truth can be rendered before the camera is calibrated.
//!
//! The model (all of it ASSUMPTIONS, stated in the files' notes):
//! - the lens is an ideal equidistant fisheye (Kannala-Brandt with k1..k4 = 0: a ray `theta`
//!   off the axis lands `f theta` from the principal point; Kannala & Brandt, IEEE TPAMI 28(8),
//!   2006, Sec. 2, the model of `cv2.fisheye`), the principal point at the image's centre, square
//!   pixels;
//! - its view angle spans the image's short side (`f = (min(w, h) / 2) / (view / 2)`), so the
//!   whole cone the fixtures keep their pins in ([`fabkit_designs::optics::Lens`]) is in the
//!   picture. A real lens quotes its view angle across its sensor's diagonal or width, and its
//!   distortion is not ideal: a real camera's file replaces this one;
//! - the camera's centre of projection is the lens's front on the sensor's axis, looking along
//!   +z, its x and y along the sensor's (the camera frame of `docs/conventions.md`: x right,
//!   y down, z forward); a real camera sits where its assembly put it, which is what
//!   `fabkit calibrate extrinsics` measures.

use fabkit_designs::optics::{Lens, OpticalPath};
use fabkit_designs::Design;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use serde::Serialize;

use crate::camera::{Distortion, Intrinsics};
use crate::camera_file::{write_camera, CameraFileFormat};

/// The largest camera image side, px (a camera file's rule).
pub const MAX_SIDE_PX: u32 = 16384;

/// Why a design's nominal camera cannot be written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NominalError {
    #[error("design '{0}' places no camera (no section family gives a lens): there is no nominal camera to write")]
    NoLens(String),
    #[error("design '{design}' gives no view angle for its lens ({what}): give --view-angle-deg")]
    NoViewAngle { design: String, what: String },
    #[error("{option} = {value}: {rule}")]
    Option {
        option: &'static str,
        value: String,
        rule: &'static str,
    },
    #[error("{0}")]
    Design(String),
}

/// A design's nominal camera: its intrinsics, its pose and what it looks through.
#[derive(Debug, Clone, PartialEq)]
pub struct NominalCamera {
    /// The design's name.
    pub design: String,
    /// The ideal equidistant fisheye (module docs), px.
    pub intrinsics: Intrinsics,
    /// Sensor frame to camera frame, mm.
    pub t_cam_sensor: Isometry3<f64>,
    /// The full view angle used, degrees, and where it comes from.
    pub view_angle_deg: f64,
    pub view_angle_from: String,
    /// The lens the design places.
    pub lens: Lens,
    /// The flat interfaces between the lens and the skin.
    pub optical_path: OpticalPath,
}

/// The nominal camera of `design`, its image `width_px` x `height_px`, its view angle the
/// design's unless `view_angle_deg` is given (full angle, degrees, in (0, 360): a fisheye may
/// see past 180 deg).
///
/// # Errors
/// [`NominalError::Option`] for a size outside 2 to [`MAX_SIDE_PX`] px or a view angle outside
/// (0, 360); [`NominalError::NoLens`] for a design that places no camera,
/// [`NominalError::NoViewAngle`] when neither the design nor `view_angle_deg` gives the angle;
/// [`NominalError::Design`] with the design's validation errors.
pub fn nominal_camera(
    design: &Design,
    width_px: u32,
    height_px: u32,
    view_angle_deg: Option<f64>,
) -> Result<NominalCamera, NominalError> {
    for (option, v) in [("--width-px", width_px), ("--height-px", height_px)] {
        if !(2..=MAX_SIDE_PX).contains(&v) {
            return Err(NominalError::Option {
                option,
                value: v.to_string(),
                rule: "must be 2 to 16384 px",
            });
        }
    }
    if let Some(v) = view_angle_deg {
        if !(v > 0.0 && v < 360.0) {
            return Err(NominalError::Option {
                option: "--view-angle-deg",
                value: v.to_string(),
                rule: "must be above 0 and under 360 deg (the lens's full view angle)",
            });
        }
    }
    let tol = fabkit_designs::ChordTolerance::default();
    let (lens, optical_path) = fabkit_designs::optics::camera_view_of_design(design, tol)
        .map_err(|e| NominalError::Design(e.to_string()))?
        .ok_or_else(|| NominalError::NoLens(design.name.clone()))?;
    let (view, from) = match (view_angle_deg, lens.view_angle_deg) {
        (Some(v), _) => (v, "--view-angle-deg".to_string()),
        (None, Some(v)) => (v, "the design".to_string()),
        (None, None) => {
            return Err(NominalError::NoViewAngle {
                design: design.name.clone(),
                what: lens.what.clone(),
            })
        }
    };
    let f = f64::from(width_px.min(height_px)) / 2.0 / (view / 2.0).to_radians();
    let intrinsics = Intrinsics {
        image_width_px: width_px,
        image_height_px: height_px,
        fx_px: f,
        fy_px: f,
        cx_px: (f64::from(width_px) - 1.0) / 2.0,
        cy_px: (f64::from(height_px) - 1.0) / 2.0,
        distortion: Distortion::Fisheye([0.0; 4]),
    };
    let t_cam_sensor = Isometry3::from_parts(
        Translation3::new(0.0, 0.0, -lens.front_z_mm),
        UnitQuaternion::identity(),
    );
    Ok(NominalCamera {
        design: design.name.clone(),
        intrinsics,
        t_cam_sensor,
        view_angle_deg: view,
        view_angle_from: from,
        lens,
        optical_path,
    })
}

/// What the nominal pose's files hold (`extrinsics.json`, `extrinsics.yaml`): the fields of
/// `fabkit calibrate extrinsics`' report that `fabkit groundtruth` reads (`T_cam_sensor`,
/// `rvec`, `tvec_mm`, `optical_path`), and what they are.
#[derive(Debug, Clone, Serialize)]
struct NominalPoseFile<'a> {
    description: String,
    fabkit_version: &'static str,
    command_line: &'a str,
    assumptions: Vec<&'static str>,
    lens: &'a Lens,
    view_angle_deg: f64,
    view_angle_from: &'a str,
    optical_path: &'a OpticalPath,
    optical_path_from: String,
    rvec: [f64; 3],
    tvec_mm: [f64; 3],
    #[serde(rename = "T_cam_sensor")]
    t_cam_sensor: [[f64; 4]; 4],
}

/// The assumptions of the nominal camera (module docs), as the files state them.
pub const ASSUMPTIONS: &[&str] = &[
    "an ideal equidistant fisheye (Kannala-Brandt, k1..k4 = 0), principal point at the image centre, square pixels",
    "the view angle spans the image's short side, so the whole view the pin dome is planned for is in the picture (a real lens quotes it across its sensor's diagonal or width)",
    "the centre of projection at the lens's front on the sensor's axis, looking along +z, camera x and y along the sensor's",
    "a real camera's file and `fabkit calibrate extrinsics` replace these",
];

/// The nominal camera's files: `camera.yaml` (OpenCV FileStorage, `fisheye`),
/// `extrinsics.json` and `extrinsics.yaml` (the pose as `fabkit calibrate extrinsics` writes
/// it, with the optical path, the lens and the assumptions; no residuals: nothing was
/// measured) and `transform.yaml` (the pose as a ROS 2 `TransformStamped`).
///
/// # Errors
/// The YAML serialiser's message.
pub fn nominal_files(
    n: &NominalCamera,
    command_line: &str,
) -> Result<Vec<(String, Vec<u8>)>, String> {
    let m = n.t_cam_sensor.to_homogeneous();
    let mut t = [[0.0; 4]; 4];
    for (r, row) in t.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = m[(r, c)];
        }
    }
    let rv = n.t_cam_sensor.rotation.scaled_axis();
    let tv = n.t_cam_sensor.translation.vector;
    let pose = NominalPoseFile {
        description: format!(
            "the camera design '{}' places, not a calibration: T_cam_sensor maps sensor-frame points (mm) to the camera frame (x right, y down, z forward), x_cam = R(rvec) x_sensor + tvec_mm",
            n.design
        ),
        fabkit_version: env!("CARGO_PKG_VERSION"),
        command_line,
        assumptions: ASSUMPTIONS.to_vec(),
        lens: &n.lens,
        view_angle_deg: n.view_angle_deg,
        view_angle_from: &n.view_angle_from,
        optical_path: &n.optical_path,
        optical_path_from: format!("design '{}'", n.design),
        rvec: [rv[0], rv[1], rv[2]],
        tvec_mm: [tv[0], tv[1], tv[2]],
        t_cam_sensor: t,
    };
    let mut json = serde_json::to_string_pretty(&pose).map_err(|e| e.to_string())?;
    json.push('\n');
    let yaml = crate::report::opencv_yaml(&pose, crate::report::POSE_MATRICES)?;
    Ok(vec![
        (
            "camera.yaml".into(),
            write_camera(&n.intrinsics, CameraFileFormat::OpenCvYaml).into_bytes(),
        ),
        ("extrinsics.json".into(), json.into_bytes()),
        ("extrinsics.yaml".into(), yaml.into_bytes()),
        (
            "transform.yaml".into(),
            crate::report::transform_stamped_yaml(&t, env!("CARGO_PKG_VERSION")).into_bytes(),
        ),
    ])
}

/// The camera and lights of `design`'s simulator files: its nominal camera (`fabkit calibrate
/// nominal`'s, 640 x 480) as a pinhole of the same focal length, and its lights; what is
/// missing is said in the notes.
pub fn sim_scene(
    design: &fabkit_designs::Design,
    tol: fabkit_designs::geometry::ChordTolerance,
) -> fabkit_export::sim::SimScene {
    use fabkit_export::sim::{SimCamera, SimLight, SimScene};
    let mut scene = SimScene::default();
    match nominal_camera(design, 640, 480, None) {
        Ok(n) => {
            let i = &n.intrinsics;
            let fovy = 2.0
                * (f64::from(i.image_height_px) / 2.0 / i.fy_px)
                    .atan()
                    .to_degrees();
            scene.camera = Some(SimCamera {
                t_sensor_cam: n.t_cam_sensor.inverse(),
                width_px: i.image_width_px,
                height_px: i.image_height_px,
                fy_px: i.fy_px,
                what: format!(
                    "the design's nominal camera (`fabkit calibrate nominal`: the lens's front on the sensor's axis looking +z, its {:.1} deg view across the image's {} px side as an ideal fisheye, f = {:.2} px) as a pinhole of the same focal length: MuJoCo renders pinholes, so it sees {:.1} deg across that side, not the fisheye's {:.1}; a calibrated camera's pose and pinhole intrinsics replace it",
                    n.view_angle_deg,
                    i.image_height_px.min(i.image_width_px),
                    i.fy_px,
                    fovy,
                    n.view_angle_deg
                ),
                file: nominal_files(&n, "fabkit export")
                    .ok()
                    .and_then(|f| f.into_iter().find(|(name, _)| name == "camera.yaml"))
                    .map(|(_, bytes)| bytes),
            });
        }
        Err(e) => scene.notes.push(format!("no camera: {e}")),
    }
    match fabkit_designs::optics::of_design(design, tol) {
        Ok(o) => {
            scene.lights = o
                .lights
                .iter()
                .map(|l| SimLight {
                    position_mm: l.position_mm,
                    direction: l.direction,
                    cone_half_angle_deg: l.cone_half_angle_deg,
                    colour_rgb: l.colour_rgb,
                })
                .collect()
        }
        Err(e) => scene.notes.push(format!("no lights: {e}")),
    }
    scene
}
