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

use std::fmt::Write as _;

use crate::manifest::ManifestMember;
use crate::mass::SensorMass;
use crate::sim::{
    escape, housing_shapes, intro, num, rgba, skin_member, vec3, HousingShape, SimScene,
};

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
