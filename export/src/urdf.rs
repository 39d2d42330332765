//! The assembled sensor as a URDF (issue 103): `sim/<design>.urdf`, for PyBullet (TACTO), ROS
//! and the tools that read URDF, beside the meshes and camera file of [`crate::sim::files`].
//!
//! - One link named after the design, its frame the sensor frame (docs/conventions.md), in
//!   metres and kilograms: its inertial is the sensor's mass, centre of mass and inertia tensor
//!   ([`crate::mass::SensorMass`]; URDF's `ixy` is the tensor's entry, minus the product
//!   integral, as fabkit's), each member a visual mesh with its colour, the skin
//!   ([`crate::sim::skin_member`]) a collision mesh and each printed housing member a collision
//!   cylinder or box ([`crate::sim::housing_shapes`]).
//! - `camera_optical_frame`: a link fixed to the sensor's at the camera's pose, in ROS's optical
//!   frame convention (REP 103: z forward, x right, y down, which is OpenCV's camera frame and
//!   fabkit's), when the design places a camera; its intrinsics are `camera.yaml` beside the
//!   file (the true model, a fisheye for the nominal camera), which URDF has no element for.
//! - `contact_surface`: a link fixed on the skin's top, on its axis.
//! - Frame-only links carry a zero-mass inertial: without one PyBullet gives a link 1 kg and a
//!   unit inertia (its URDF importer's default), which would add a kilogram per frame.
//! - A fixed joint's `rpy` is roll, pitch, yaw about the fixed x, y, z axes: R = Rz Ry Rx.

use std::fmt::Write as _;

use crate::manifest::ManifestMember;
use crate::mass::SensorMass;
use crate::sim::{escape, num, rgba, skin_member, vec3, HousingShape, SimScene};

/// The URDF of `design`'s assembled sensor (see the module docs); `header` for the comment.
pub fn model(
    design: &str,
    header: &str,
    members: &[ManifestMember],
    mass: &SensorMass,
    scene: &SimScene,
) -> String {
    const MM: f64 = 1e-3;
    let d = escape(design);
    let mut x = String::new();
    let _ = writeln!(x, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
    for line in crate::sim::intro(header, "one link", members, mass, scene) {
        let _ = writeln!(x, "<!-- {} -->", escape(&line));
    }
    let _ = writeln!(x, "<robot name=\"{d}\">");
    let _ = writeln!(x, "  <link name=\"{d}\">");
    let i = mass.inertia_g_mm2;
    let _ = writeln!(x, "    <inertial>");
    let _ = writeln!(
        x,
        "      <origin xyz=\"{}\" rpy=\"0 0 0\"/>",
        vec3(mass.centre_of_mass_mm, MM)
    );
    let _ = writeln!(x, "      <mass value=\"{}\"/>", num(mass.mass_g * 1e-3));
    // g mm^2 = 1e-9 kg m^2
    let _ = writeln!(
        x,
        "      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>",
        num(i[0][0] * 1e-9),
        num(i[0][1] * 1e-9),
        num(i[0][2] * 1e-9),
        num(i[1][1] * 1e-9),
        num(i[1][2] * 1e-9),
        num(i[2][2] * 1e-9),
    );
    let _ = writeln!(x, "    </inertial>");
    let mesh = |name: &str| {
        format!(
            "<geometry><mesh filename=\"meshes/{}.stl\" scale=\"0.001 0.001 0.001\"/></geometry>",
            escape(name)
        )
    };
    for m in members {
        let _ = writeln!(
            x,
            "    <visual name=\"{0}\"><origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>{1}<material name=\"{0}\"><color rgba=\"{2}\"/></material></visual>",
            escape(&m.name),
            mesh(&m.name),
            rgba(m)
        );
    }
    let skin = skin_member(members);
    if let Some(s) = skin {
        let _ = writeln!(
            x,
            "    <collision name=\"contact_surface\"><origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>{}</collision>",
            mesh(&members[s].name)
        );
    }
    for (h, shape) in crate::sim::housing_shapes(members) {
        let (geometry, c) = match shape {
            HousingShape::Cylinder(r, height, c) => (
                format!(
                    "<cylinder radius=\"{}\" length=\"{}\"/>",
                    num(r * MM),
                    num(height * MM)
                ),
                c,
            ),
            HousingShape::Box(half, c) => (format!("<box size=\"{}\"/>", vec3(half, 2.0 * MM)), c),
        };
        let _ = writeln!(
            x,
            "    <collision name=\"{}\"><origin xyz=\"{}\" rpy=\"0 0 0\"/><geometry>{geometry}</geometry></collision>",
            escape(&h.name),
            vec3(c, MM)
        );
    }
    let _ = writeln!(x, "  </link>");
    let fixed = |x: &mut String, name: &str, xyz: String, rpy: [f64; 3], comment: Option<&str>| {
        if let Some(c) = comment {
            let _ = writeln!(x, "  <!-- {} -->", escape(c));
        }
        let _ = writeln!(
            x,
            "  <link name=\"{name}\"><inertial><mass value=\"0\"/><inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>"
        );
        let _ = writeln!(
            x,
            "  <joint name=\"{name}_joint\" type=\"fixed\"><parent link=\"{d}\"/><child link=\"{name}\"/><origin xyz=\"{xyz}\" rpy=\"{}\"/></joint>",
            vec3(rpy, 1.0)
        );
    };
    if let Some(c) = &scene.camera {
        let (roll, pitch, yaw) = c.t_sensor_cam.rotation.euler_angles();
        fixed(
            &mut x,
            "camera_optical_frame",
            vec3(c.t_sensor_cam.translation.vector.into(), MM),
            [roll, pitch, yaw],
            Some(&format!(
                "{}; its intrinsics: camera.yaml beside this file",
                c.what
            )),
        );
    }
    if let Some(s) = skin {
        let b = members[s].bbox_mm;
        let top = [
            (b.min[0] + b.max[0]) / 2.0,
            (b.min[1] + b.max[1]) / 2.0,
            b.max[2],
        ];
        fixed(&mut x, "contact_surface", vec3(top, MM), [0.0; 3], None);
    }
    let _ = writeln!(x, "</robot>");
    x
}
