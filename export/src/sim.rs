//! What the simulator files share (issue 103): the folder `sim/`, the camera and lights they
//! carry ([`SimScene`]), which member is the skin ([`skin_member`]) and which simple shapes the
//! housing collides as ([`housing_shapes`]), the files' opening comment and number format, and
//! [`files`], which writes `sim/`: the meshes and camera file, then the MJCF
//! ([`crate::mjcf`]), URDF ([`crate::urdf`]) and USD ([`crate::usd`]) models.

use fabkit_designs::assembly::MemberKind;
use fabkit_designs::geometry::Mesh;
use nalgebra::Isometry3;

use crate::manifest::ManifestMember;
use crate::mass::SensorMass;

/// The folder of the simulator files.
pub const SIM_DIR: &str = "sim";

/// The camera an MJCF model carries: a pinhole.
#[derive(Debug, Clone, PartialEq)]
pub struct SimCamera {
    /// The camera frame (OpenCV: x right, y down, z forward) in the sensor frame, mm:
    /// `T_sensor_cam`, the inverse of a calibration's `T_cam_sensor`.
    pub t_sensor_cam: Isometry3<f64>,
    /// Image size, px.
    pub width_px: u32,
    pub height_px: u32,
    /// Focal length along y, px: `fovy` = 2 atan(height / 2 / fy_px).
    pub fy_px: f64,
    /// What the camera is and what the pinhole leaves out, for the file's comment.
    pub what: String,
    /// The camera's own file (OpenCV YAML, its true model), written beside the models as
    /// `sim/camera.yaml`; `None`: none.
    pub file: Option<Vec<u8>>,
}

/// A light an MJCF model carries: a spot light.
#[derive(Debug, Clone, PartialEq)]
pub struct SimLight {
    /// Sensor frame, mm.
    pub position_mm: [f64; 3],
    /// The beam's axis, sensor frame (normalised here).
    pub direction: [f64; 3],
    pub cone_half_angle_deg: f64,
    pub colour_rgb: [f64; 3],
}

/// What a simulator file carries besides the kit: the camera and the lights the design (or a
/// calibration) places.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimScene {
    pub camera: Option<SimCamera>,
    pub lights: Vec<SimLight>,
    /// Notes for the file's comment (where the camera comes from, what is left out).
    pub notes: Vec<String>,
}

/// The member whose mesh is the skin's contact surface: among the cast members (the filling
/// gel aside) and a printed skin (named `skin`), the one whose box reaches highest, the first
/// of equals.
pub fn skin_member(members: &[ManifestMember]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, m) in members.iter().enumerate() {
        let skin = (m.kind == MemberKind::Cast && m.name != "filling_gel")
            || (m.kind == MemberKind::Printed && m.name == "skin");
        if skin && best.is_none_or(|b| m.bbox_mm.max[2] > members[b].bbox_mm.max[2]) {
            best = Some(i);
        }
    }
    best
}

/// A simple collision shape standing in for a housing member: a cylinder on the sensor's axis
/// when the member's box is centred on it and square in x and y (within 1 um), else its box.
/// Centre and sizes in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HousingShape {
    /// Radius, height, centre.
    Cylinder(f64, f64, [f64; 3]),
    /// Half extents, centre.
    Box([f64; 3], [f64; 3]),
}

/// The housing members (printed, not the skin) with their collision shapes, in assembly order.
pub fn housing_shapes(members: &[ManifestMember]) -> Vec<(&ManifestMember, HousingShape)> {
    let skin = skin_member(members);
    members
        .iter()
        .enumerate()
        .filter(|(i, m)| m.kind == MemberKind::Printed && Some(*i) != skin)
        .map(|(_, m)| {
            let (lo, hi) = (m.bbox_mm.min, m.bbox_mm.max);
            let c: [f64; 3] = std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0);
            let half: [f64; 3] = std::array::from_fn(|k| (hi[k] - lo[k]) / 2.0);
            let round = c[0].abs() < 1e-3 && c[1].abs() < 1e-3 && (half[0] - half[1]).abs() < 1e-3;
            let shape = if round {
                HousingShape::Cylinder(half[0], 2.0 * half[2], c)
            } else {
                HousingShape::Box(half, c)
            };
            (m, shape)
        })
        .collect()
}

/// The lines every simulator file opens with, in words (unescaped): `header` (version and
/// design), the body (`what`: "one rigid body", "one link") with its frame, units and mass, and
/// the scene's notes.
pub(crate) fn intro(
    header: &str,
    what: &str,
    members: &[ManifestMember],
    mass: &SensorMass,
    scene: &SimScene,
) -> Vec<String> {
    let mut lines = vec![
        header.to_string(),
        format!(
            "the assembled sensor as {what} in its sensor frame (docs/conventions.md); metres, kilograms; its mass {:.3} g from {} of {} members ({})",
            mass.mass_g,
            mass.counted.len(),
            members.len(),
            mass.assumptions.join("; ")
        ),
    ];
    lines.extend(scene.notes.iter().cloned());
    lines
}

/// `rgba` of a member: black for a black material, clear for the core and the filling gel,
/// translucent for a cast layer, grey for a printed part, green for a bought board.
pub(crate) fn rgba(m: &ManifestMember) -> &'static str {
    let material = m.material.as_deref().unwrap_or("");
    if material.contains("black") {
        "0.08 0.08 0.08 1"
    } else if m.name.starts_with("core") || m.name == "filling_gel" || material == "pmma" {
        "0.85 0.92 1 0.3"
    } else {
        match m.kind {
            MemberKind::Cast => "0.92 0.9 0.85 0.7",
            MemberKind::Printed => "0.6 0.6 0.6 1",
            MemberKind::Bought => "0.2 0.45 0.25 1",
        }
    }
}

/// A number in metres (from mm) or any unit, written to 12 significant digits.
pub(crate) fn num(v: f64) -> String {
    if v == 0.0 {
        // -0 too
        return "0".into();
    }
    let s = format!("{v:.12e}");
    // 1.000000000000e-3 -> 1e-3 (shorter, the same value)
    match s.split_once('e') {
        Some((m, e)) => {
            let m = m.trim_end_matches('0').trim_end_matches('.');
            if e == "0" {
                m.to_string()
            } else {
                format!("{m}e{e}")
            }
        }
        None => s,
    }
}

pub(crate) fn vec3(v: [f64; 3], scale: f64) -> String {
    format!(
        "{} {} {}",
        num(v[0] * scale),
        num(v[1] * scale),
        num(v[2] * scale)
    )
}

pub(crate) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace("--", "- -")
}

/// The simulator files: `sim/meshes/<member>.stl` (binary STL of each member's written mesh,
/// mm), `sim/camera.yaml` when the camera has a file, then `sim/<design>.xml` (MJCF, with
/// `mjcf`), `sim/<design>.urdf` (with `urdf`) and `sim/<design>.usda` (with `usd`), as
/// (relative path, bytes).
///
/// # Errors
/// As the STL writer's.
pub(crate) fn files(
    design: &str,
    opts: &crate::ExportOptions,
    members: &[ManifestMember],
    meshes: &[Mesh],
    mass: &SensorMass,
) -> Result<Vec<(String, Vec<u8>)>, crate::ExportError> {
    let scene = &opts.sim;
    let mut out = Vec::new();
    for (m, mesh) in members.iter().zip(meshes) {
        let head = crate::stl::header(&opts.fabkit_version, design, &m.name, &opts.design_sha256);
        out.push((
            format!("{SIM_DIR}/meshes/{}.stl", m.name),
            crate::stl::encode(&m.name, mesh, &head)?,
        ));
    }
    if let Some(bytes) = scene.camera.as_ref().and_then(|c| c.file.clone()) {
        out.push((format!("{SIM_DIR}/camera.yaml"), bytes));
    }
    let header = format!(
        "fabkit {}: design {} ({}, sha256:{})",
        opts.fabkit_version, design, opts.design_source, opts.design_sha256
    );
    if opts.formats.mjcf {
        out.push((
            format!("{SIM_DIR}/{design}.xml"),
            crate::mjcf::model(design, &header, members, mass, scene).into_bytes(),
        ));
    }
    if opts.formats.urdf {
        out.push((
            format!("{SIM_DIR}/{design}.urdf"),
            crate::urdf::model(design, &header, members, mass, scene).into_bytes(),
        ));
    }
    if opts.formats.usd {
        out.push((
            format!("{SIM_DIR}/{design}.usda"),
            crate::usd::layer(design, &header, members, meshes, mass, scene).into_bytes(),
        ));
    }
    Ok(out)
}
