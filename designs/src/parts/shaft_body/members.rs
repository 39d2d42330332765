//! What the shaft body adds to the assembled sensor beside its printed parts: the bought and
//! cut members (lens window, LED ring, camera board and lens) and the bought-items list.

use super::dimensions::levels;
use super::params::ShaftBodyParams;
use crate::error::{DesignError, GeometryContext};
use crate::geometry::{cuboid, cylinder, ChordTolerance, Solid};
use crate::parts::context::Context;
use crate::parts::{axial_cylinder, ExactShape, Member, MemberKind};

/// The bought and cut members of the assembled sensor: the lens window, the LED ring, the
/// camera board and its lens, in the sensor frame.
///
/// # Errors
/// [`DesignError::Geometry`] if the kernel fails.
pub fn members(
    ctx: &Context<'_>,
    sb: &ShaftBodyParams,
    tol: ChordTolerance,
) -> Result<Vec<Member>, DesignError> {
    let lv = levels(ctx, sb);
    let disc = |name: &str, r: f64, z0: f64, z1: f64| -> Result<(Solid, ExactShape), DesignError> {
        axial_cylinder(r, z0, z1, tol).part(name)
    };
    let member = |name: &str,
                  description: String,
                  (solid, exact): (Solid, ExactShape),
                  fix: &[&str]| Member {
        name: name.into(),
        kind: MemberKind::Bought,
        description,
        solid,
        fix: fix.iter().map(|f| format!("shaft_body.{f}")).collect(),
        nested_by_stack: false,
        features: Default::default(),
        exact: Some(exact),
        material: None,
    };
    let l = &sb.led_ring;
    let (ro, ri) = (l.outer_diameter_mm / 2.0, l.inner_diameter_mm / 2.0);
    let z0 = lv.led_pcb_z_mm;
    let z1 = lv.shaft_top_z_mm;
    let ring = cylinder(z1 - z0, ro, tol)
        .and_then(|o| {
            let i = cylinder(z1 - z0 + 2.0, ri, tol)?.translate([0.0, 0.0, -1.0]);
            o.difference(&i)
        })
        .map(|s| s.translate([0.0, 0.0, z0]))
        .part("led_ring_envelope")?;
    let bw = sb.camera.board_width_mm / 2.0;
    let board_min = [-bw, -bw, lv.bottom_z_mm];
    let board_max = [bw, bw, lv.ceiling_z_mm];
    Ok(vec![
        member(
            "lens_window_envelope",
            format!(
                "Lens window (laser-cut acrylic, {:.1} mm)",
                sb.lens_window.thickness_mm
            ),
            disc(
                "lens_window_envelope",
                sb.lens_window.diameter_mm / 2.0,
                lv.shaft_top_z_mm,
                lv.lip_z_mm,
            )?,
            &["lens_window.diameter_mm", "lens_window.thickness_mm"],
        ),
        member(
            "led_ring_envelope",
            format!(
                "LED ring PCB (bought), {} LEDs, with the LEDs' height",
                l.led_count
            ),
            (
                ring,
                ExactShape::Ring {
                    outer_radius_mm: ro,
                    inner_radius_mm: ri,
                    z0_mm: z0,
                    z1_mm: z1,
                },
            ),
            &["led_ring.seat_diameter_mm", "led_ring.outer_diameter_mm"],
        ),
        member(
            "camera_board_envelope",
            format!(
                "Camera board with its components (bought): {}",
                sb.camera.module
            ),
            (
                cuboid(board_min, board_max).part("camera_board_envelope")?,
                ExactShape::Box {
                    min_mm: board_min,
                    max_mm: board_max,
                },
            ),
            &["camera.board_width_mm", "camera.bay_height_mm"],
        ),
        member(
            "camera_lens_envelope",
            format!(
                "Camera lens (bought): f = {:.1} mm, {:.0} deg",
                sb.camera.focal_length_mm, sb.camera.view_angle_deg
            ),
            disc(
                "camera_lens_envelope",
                sb.camera.lens_diameter_mm / 2.0,
                lv.ceiling_z_mm,
                lv.lens_z_mm,
            )?,
            &["camera.lens_diameter_mm", "camera.lens_height_mm"],
        ),
    ])
}

/// The bought items of the shaft body: the camera with its lens and screws, the LED ring, the
/// lens window (cut), the microcontroller.
pub fn bought_items(sb: &ShaftBodyParams) -> Vec<String> {
    let cam = &sb.camera;
    let screw = crate::parts::fasteners::metric_from_pilot(cam.mount_pilot_diameter_mm)
        .map(|d| format!(" M{d}"))
        .unwrap_or_default();
    vec![
        format!(
            "Camera: {} on a {:.1} mm square board, lens f = {:.1} mm, {:.0} deg view, fixed up against the base's ceiling with 4 self-tapping screws{screw} ({:.1} mm pilots, {:.1} mm square pattern, {:.1} mm deep)",
            cam.module,
            cam.board_width_mm,
            cam.focal_length_mm,
            cam.view_angle_deg,
            cam.mount_pilot_diameter_mm,
            cam.mount_hole_spacing_mm,
            cam.mount_pilot_depth_mm
        ),
        format!(
            "LED ring PCB: {} LEDs, outer diameter {:.1} mm, inner diameter {:.1} mm, {:.1} mm thick, LEDs up to {:.1} mm high (Pestell et al. Sec. III-A)",
            sb.led_ring.led_count,
            sb.led_ring.outer_diameter_mm,
            sb.led_ring.inner_diameter_mm,
            sb.led_ring.thickness_mm,
            sb.led_ring.led_height_mm
        ),
        format!(
            "Lens window: laser-cut clear acrylic (cut/lens_window.dxf), diameter {:.1} mm, {:.1} mm thick (Pestell et al. Sec. III-A)",
            sb.lens_window.diameter_mm, sb.lens_window.thickness_mm
        ),
        "Microcontroller: Arduino Nano (8-bit, 16 MHz) on the outside of the body, wired to the camera over SPI (Pestell et al. Sec. III-A2)".into(),
    ]
}
