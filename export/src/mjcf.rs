//! The assembled sensor for MuJoCo (issue 103): `sim/<design>.xml`, an MJCF model of one rigid
//! body, and `sim/meshes/<member>.stl`, the meshes of `assembly.3mf` (the same written meshes).
//!
//! - Units: MJCF's metres and kilograms, converted here once from the kit's mm and g (meshes
//!   scaled by 0.001); angles in degrees (MJCF's default; a camera's `fovy` is always degrees).
//! - The body (named after the design, its frame the sensor frame, docs/conventions.md) carries
//!   the sensor's mass, centre of mass and full inertia tensor ([`crate::mass::SensorMass`],
//!   `compiler inertiafromgeom="false"`: the geoms add nothing). It has no joint: a child of the
//!   world it is fixed; attach it to a robot's link (MJCF `attach`/`include`).
//! - Each member is a visual mesh geom (group 1, no contacts) coloured by what it is; the skin
//!   (the outermost cast layer or the printed skin: [`skin_member`]) is also a collision geom
//!   (group 3; MuJoCo collides with a mesh's convex hull), and each printed housing member
//!   collides as a cylinder or a box round it ([`housing_shapes`]).
//! - The `contact_surface` site sits at the top of the skin's box, on its axis.
//! - The camera, when the design places one ([`SimCamera`]): MJCF cameras are pinholes looking
//!   along their -z with y up; the camera frame here is OpenCV's (x right, y down, z forward),
//!   turned about x by 180 deg. `fovy` is the pinhole's vertical view, 2 atan(h / 2 / fy).
//! - The design's lights as spot lights (position, direction, cone half-angle, colour).

use fabkit_designs::assembly::MemberKind;
use fabkit_designs::geometry::Mesh;
use nalgebra::Isometry3;
use std::fmt::Write as _;

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

/// The MJCF model of `design`'s assembled sensor: `members` (the manifest's, in assembly
/// order, their meshes in `meshes/<name>.stl`), its `mass` and `scene`. `header` names the
/// fabkit version and the design, for the comment.
pub fn model(
    design: &str,
    header: &str,
    members: &[ManifestMember],
    mass: &SensorMass,
    scene: &SimScene,
) -> String {
    const MM: f64 = 1e-3;
    let mut x = String::new();
    let _ = writeln!(x, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
    for line in intro(header, "one rigid body", members, mass, scene) {
        let _ = writeln!(x, "<!-- {} -->", escape(&line));
    }
    let _ = writeln!(x, "<mujoco model=\"{}\">", escape(design));
    let _ = writeln!(
        x,
        "  <compiler meshdir=\"meshes\" inertiafromgeom=\"false\"/>"
    );
    let _ = writeln!(x, "  <asset>");
    for m in members {
        let _ = writeln!(
            x,
            "    <mesh name=\"{0}\" file=\"{0}.stl\" scale=\"0.001 0.001 0.001\"/>",
            escape(&m.name)
        );
    }
    let _ = writeln!(x, "  </asset>");
    let _ = writeln!(x, "  <worldbody>");
    let _ = writeln!(x, "    <body name=\"{}\">", escape(design));
    // g mm^2 = 1e-9 kg m^2
    let i = mass.inertia_g_mm2;
    let _ = writeln!(
        x,
        "      <inertial pos=\"{}\" mass=\"{}\" fullinertia=\"{} {} {} {} {} {}\"/>",
        vec3(mass.centre_of_mass_mm, MM),
        num(mass.mass_g * 1e-3),
        num(i[0][0] * 1e-9),
        num(i[1][1] * 1e-9),
        num(i[2][2] * 1e-9),
        num(i[0][1] * 1e-9),
        num(i[0][2] * 1e-9),
        num(i[1][2] * 1e-9),
    );
    for m in members {
        let _ = writeln!(
            x,
            "      <geom name=\"{0}\" type=\"mesh\" mesh=\"{0}\" group=\"1\" contype=\"0\" conaffinity=\"0\" rgba=\"{1}\"/>",
            escape(&m.name),
            rgba(m)
        );
    }
    if let Some(s) = skin_member(members) {
        let m = &members[s];
        let _ = writeln!(
            x,
            "      <geom name=\"contact_surface_collision\" type=\"mesh\" mesh=\"{}\" group=\"3\" rgba=\"1 0.5 0 0.2\"/>",
            escape(&m.name)
        );
        for (h, shape) in housing_shapes(members) {
            let (kind, size, c) = match shape {
                HousingShape::Cylinder(r, height, c) => (
                    "cylinder",
                    format!("{} {}", num(r * MM), num(height / 2.0 * MM)),
                    c,
                ),
                HousingShape::Box(half, c) => ("box", vec3(half, MM), c),
            };
            let _ = writeln!(
                x,
                "      <geom name=\"{}_collision\" type=\"{kind}\" size=\"{size}\" pos=\"{}\" group=\"3\" rgba=\"0.5 0.5 1 0.2\"/>",
                escape(&h.name),
                vec3(c, MM)
            );
        }
        let b = m.bbox_mm;
        let top = [
            (b.min[0] + b.max[0]) / 2.0,
            (b.min[1] + b.max[1]) / 2.0,
            b.max[2],
        ];
        let _ = writeln!(
            x,
            "      <site name=\"contact_surface\" pos=\"{}\" size=\"0.0005\"/>",
            vec3(top, MM)
        );
    }
    if let Some(c) = &scene.camera {
        let r = c.t_sensor_cam.rotation.to_rotation_matrix();
        let (ex, ey) = (r.matrix().column(0), r.matrix().column(1));
        let fovy = 2.0 * (f64::from(c.height_px) / 2.0 / c.fy_px).atan().to_degrees();
        let _ = writeln!(x, "      <!-- {} -->", escape(&c.what));
        let _ = writeln!(
            x,
            "      <camera name=\"camera\" pos=\"{}\" xyaxes=\"{} {} {} {} {} {}\" fovy=\"{}\" resolution=\"{} {}\"/>",
            vec3(c.t_sensor_cam.translation.vector.into(), MM),
            num(ex[0]),
            num(ex[1]),
            num(ex[2]),
            num(-ey[0]),
            num(-ey[1]),
            num(-ey[2]),
            num(fovy),
            c.width_px,
            c.height_px
        );
    }
    for (k, l) in scene.lights.iter().enumerate() {
        let n = (l.direction.iter().map(|v| v * v).sum::<f64>()).sqrt();
        let _ = writeln!(
            x,
            "      <light name=\"led_{}\" pos=\"{}\" dir=\"{}\" cutoff=\"{}\" diffuse=\"{}\" directional=\"false\"/>",
            k + 1,
            vec3(l.position_mm, MM),
            vec3(l.direction, 1.0 / n),
            num(l.cone_half_angle_deg),
            vec3(l.colour_rgb, 1.0)
        );
    }
    let _ = writeln!(x, "    </body>");
    let _ = writeln!(x, "  </worldbody>");
    let _ = writeln!(x, "</mujoco>");
    x
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
            model(design, &header, members, mass, scene).into_bytes(),
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
