//! The shaft body's rules (`shaft_body.*` paths, and the FDM bayonet's under `printers.`):
//! parts fit, walls print, the camera sees the tip; each reporting every violation.

use super::dimensions::{levels, radii, skin_layer, tip_bayonet, ShaftLevels, ShaftRadii};
use super::params::{ShaftBodyParams, CABLE_SLOT_MM};
use crate::error::ParamError;
use crate::parts::bayonet::Bayonet;
use crate::parts::context::{Context, Stack};

/// A printed fit's clearance: at least half the FDM nozzle, or the parts fuse or jam.
pub(crate) fn half_nozzle(
    path: &str,
    v: f64,
    fdm: &crate::schema::printers::PrinterProfile,
    errs: &mut Vec<ParamError>,
) {
    if !(v >= fdm.xy_resolution_mm / 2.0 && v.is_finite()) {
        errs.push(ParamError::new(
            path,
            v,
            format!(
                "must be at least half the nozzle (printers.fdm.xy_resolution_mm / 2 = {:.2} mm): a tighter printed fit fuses or jams",
                fdm.xy_resolution_mm / 2.0
            ),
        ));
    }
}

/// Rules on the shaft body: parts fit, walls print, the camera sees the tip.
pub fn check_params(
    ctx: &Context<'_>,
    sb: &ShaftBodyParams,
    stack: &Stack,
    errs: &mut Vec<ParamError>,
) {
    let before = errs.len();
    if let Some(fills) = sb.filling_gel.as_ref().and_then(|f| f.fills) {
        errs.push(ParamError::new(
            "shaft_body.filling_gel.fills",
            format!("{fills:?}").to_lowercase(),
            "the shaft body's gel always fills down to its lens window: remove fills",
        ));
    }
    // The mount checks its own numbers (robot_mount::check_params).
    crate::parts::check_above_zero("shaft_body.", sb, &["robot_mount"], errs);
    check_printer_and_angles(ctx, sb, stack, errs);
    if errs.len() > before || skin_layer(stack).is_none() {
        return;
    }
    let r = radii(ctx, sb, stack);
    let lv = levels(ctx, sb);
    let b = tip_bayonet(ctx, sb);
    check_fitting_and_shaft(ctx, sb, &r, &b, errs);
    check_base(ctx, sb, &r, errs);
    check_view(sb, &r, &lv, errs);
    if let Some(m) = &sb.robot_mount {
        crate::parts::robot_mount::check_params(ctx, sb, m, errs);
    }
}

/// The FDM bayonet's settings (`printers.fdm.bayonet`: 2 to 8 lugs, the ramp below 15 deg, the
/// clearance at least half the nozzle), the LED ring's LED count, `bayonet.lock_angle_deg` in
/// (0, 90) and `camera.view_angle_deg` in (0, 180), `fit_clearance_mm` at least half the nozzle,
/// and the skin's outermost layer printed (it carries the tip's fitting).
fn check_printer_and_angles(
    ctx: &Context<'_>,
    sb: &ShaftBodyParams,
    stack: &Stack,
    errs: &mut Vec<ParamError>,
) {
    let cam = &sb.camera;
    let fdm = &ctx.printers.fdm;
    let bp = &fdm.bayonet;
    if !(2..=8).contains(&bp.lug_count) {
        errs.push(ParamError::new(
            "printers.fdm.bayonet.lug_count",
            bp.lug_count,
            "must be 2 to 8",
        ));
    }
    if sb.led_ring.outer_diameter_mm > 0.0 && sb.led_ring.inner_diameter_mm > 0.0 {
        crate::parts::check_led_count(
            "shaft_body.led_ring.led_count",
            sb.led_ring.led_count,
            sb.led_ring.outer_diameter_mm,
            sb.led_ring.inner_diameter_mm,
            errs,
        );
    }
    if !(bp.ramp_deg >= 0.0 && bp.ramp_deg < 15.0) {
        errs.push(ParamError::new(
            "printers.fdm.bayonet.ramp_deg",
            bp.ramp_deg,
            "must be at least 0 and below 15 (steeper, the lug slips back out of its groove)",
        ));
    }
    half_nozzle(
        "printers.fdm.bayonet.clearance_mm",
        bp.clearance_mm,
        fdm,
        errs,
    );
    if !(sb.bayonet.lock_angle_deg > 0.0 && sb.bayonet.lock_angle_deg < 90.0) {
        errs.push(ParamError::new(
            "shaft_body.bayonet.lock_angle_deg",
            sb.bayonet.lock_angle_deg,
            "must be above 0 and below 90",
        ));
    }
    if !(cam.view_angle_deg > 0.0 && cam.view_angle_deg < 180.0) {
        errs.push(ParamError::new(
            "shaft_body.camera.view_angle_deg",
            cam.view_angle_deg,
            "must be above 0 and below 180",
        ));
    }
    half_nozzle(
        "shaft_body.fit_clearance_mm",
        sb.fit_clearance_mm,
        fdm,
        errs,
    );
    if skin_layer(stack).is_none() {
        errs.push(ParamError::new(
            format!("layers[{}].process", stack.layers.len().saturating_sub(1)),
            "not printed",
            "shaft_body: the tip's fitting is printed with the skin, so the outermost layer must be printed",
        ));
    }
}

/// Fits of the tip's fitting and the shaft's top, mm: the bayonet's grooves round the shaft,
/// the PolyJet walls of the skirt and the window's seat, the window on the shaft's top face,
/// the lip, the skirt's length, the grooves' floor over the LED seat, the LED ring and the
/// shaft's bore.
fn check_fitting_and_shaft(
    ctx: &Context<'_>,
    sb: &ShaftBodyParams,
    r: &ShaftRadii,
    b: &Bayonet,
    errs: &mut Vec<ParamError>,
) {
    let fdm = &ctx.printers.fdm;
    let poly = &ctx.printers.polyjet;
    let mut rule = |ok: bool, path: &str, v: f64, text: String| {
        if !ok {
            errs.push(ParamError::new(format!("shaft_body.{path}"), v, text));
        }
    };
    let groove_floor = r.shaft_outer_mm - b.lug_depth_mm - b.clearance_mm;
    // a groove narrower than its lug is left to the fit check, which names the interference
    let n = f64::from(b.lug_count);
    let lock = b.lock_angle_deg.to_radians() * r.shaft_outer_mm;
    rule(
        n * (lock + b.groove_width_mm + fdm.min_wall_mm) <= 2.0 * std::f64::consts::PI * r.shaft_outer_mm,
        "bayonet.lock_angle_deg",
        b.lock_angle_deg,
        format!(
            "{} grooves, each the lock's turn plus the groove's width, must fit round the shaft ({:.1} mm) with a {:.1} mm wall between them: fewer lugs, a narrower lug or a smaller turn",
            b.lug_count,
            2.0 * std::f64::consts::PI * r.shaft_outer_mm,
            fdm.min_wall_mm
        ),
    );
    rule(
        r.fitting_outer_mm - r.skirt_bore_mm >= poly.min_wall_mm,
        "shaft_diameter_mm",
        sb.shaft_diameter_mm,
        format!(
            "the tip's skirt round the shaft (outer diameter {:.2} mm, the skin's) must keep a {:.2} mm wall over the shaft and its clearance",
            2.0 * r.fitting_outer_mm,
            poly.min_wall_mm
        ),
    );
    rule(
        r.fitting_outer_mm - r.window_seat_mm >= poly.min_wall_mm,
        "lens_window.diameter_mm",
        sb.lens_window.diameter_mm,
        format!(
            "the window's seat must keep a {:.2} mm wall inside the fitting (outer diameter {:.2} mm)",
            poly.min_wall_mm,
            2.0 * r.fitting_outer_mm
        ),
    );
    rule(
        sb.lens_window.diameter_mm / 2.0 > r.led_seat_mm.max(r.shaft_bore_mm)
            && sb.lens_window.diameter_mm <= sb.shaft_diameter_mm + 1e-9,
        "lens_window.diameter_mm",
        sb.lens_window.diameter_mm,
        format!(
            "must rest on the shaft's top face: above the LED seat's diameter ({:.2} mm) and at most the shaft's ({:.2} mm)",
            2.0 * r.led_seat_mm.max(r.shaft_bore_mm),
            sb.shaft_diameter_mm
        ),
    );
    rule(
        r.lip_inner_mm > 0.0,
        "tip_fitting.lip_width_mm",
        sb.tip_fitting.lip_width_mm,
        "must be below the window's radius".into(),
    );
    rule(
        sb.tip_fitting.skirt_length_mm >= b.lug_height_mm + 2.0 * b.clearance_mm + fdm.min_wall_mm,
        "tip_fitting.skirt_length_mm",
        sb.tip_fitting.skirt_length_mm,
        format!(
            "must take the lug ({:.2} mm) under a {:.2} mm wall of groove above it, with the clearance",
            b.lug_height_mm, fdm.min_wall_mm
        ),
    );
    rule(
        groove_floor - r.led_seat_mm.max(r.shaft_bore_mm) >= fdm.min_wall_mm,
        "bayonet.lug_depth_mm",
        b.lug_depth_mm,
        format!(
            "the grooves' floor (radius {groove_floor:.2} mm) must keep a {:.2} mm wall over the LED seat and the bore (radius {:.2} mm)",
            fdm.min_wall_mm,
            r.led_seat_mm.max(r.shaft_bore_mm)
        ),
    );
    rule(
        r.led_seat_mm >= sb.led_ring.inner_diameter_mm / 2.0
            && sb.led_ring.inner_diameter_mm < sb.led_ring.outer_diameter_mm,
        "led_ring.inner_diameter_mm",
        sb.led_ring.inner_diameter_mm,
        "must be below the ring's outer diameter".into(),
    );
    rule(
        r.shaft_bore_mm >= r.lens_hole_mm,
        "wall_thickness_mm",
        sb.wall_thickness_mm,
        format!(
            "the shaft's bore (diameter {:.2} mm) must pass the lens and the LED ring's wires beside it (hole {:.2} mm)",
            2.0 * r.shaft_bore_mm,
            2.0 * r.lens_hole_mm
        ),
    );
    rule(
        r.shaft_bore_mm <= r.led_seat_mm,
        "wall_thickness_mm",
        sb.wall_thickness_mm,
        format!(
            "the bore (diameter {:.2} mm) must leave a ledge under the LED ring's seat ({:.2} mm)",
            2.0 * r.shaft_bore_mm,
            2.0 * r.led_seat_mm
        ),
    );
}

/// The base under the shaft, mm: the camera board's pocket inside an FDM wall, the base at
/// least the shaft's diameter, the board's mounting pilots between the lens's hole and the
/// pocket's side and under the ceiling, and the cable slot in the camera's bay.
fn check_base(ctx: &Context<'_>, sb: &ShaftBodyParams, r: &ShaftRadii, errs: &mut Vec<ParamError>) {
    let cam = &sb.camera;
    let fdm = &ctx.printers.fdm;
    let mut rule = |ok: bool, path: &str, v: f64, text: String| {
        if !ok {
            errs.push(ParamError::new(format!("shaft_body.{path}"), v, text));
        }
    };
    let corner = r.board_pocket_half_mm * std::f64::consts::SQRT_2;
    rule(
        r.base_outer_mm - corner >= fdm.min_wall_mm,
        "base.outer_diameter_mm",
        sb.base.outer_diameter_mm,
        format!(
            "must hold the board's pocket ({:.2} mm square, corners at radius {corner:.2} mm) inside a {:.2} mm wall",
            2.0 * r.board_pocket_half_mm,
            fdm.min_wall_mm
        ),
    );
    rule(
        r.base_outer_mm >= r.shaft_outer_mm,
        "base.outer_diameter_mm",
        sb.base.outer_diameter_mm,
        format!(
            "must be at least the shaft's diameter ({:.2} mm)",
            sb.shaft_diameter_mm
        ),
    );
    let half_spacing = cam.mount_hole_spacing_mm / 2.0;
    rule(
        half_spacing + cam.mount_pilot_diameter_mm / 2.0 + fdm.min_wall_mm <= r.board_pocket_half_mm
            && half_spacing - cam.mount_pilot_diameter_mm / 2.0 - fdm.min_wall_mm >= r.lens_hole_mm,
        "camera.mount_hole_spacing_mm",
        cam.mount_hole_spacing_mm,
        format!(
            "the pilots must lie between the lens's hole (radius {:.2} mm) and the pocket's side ({:.2} mm from the axis) with a {:.2} mm wall",
            r.lens_hole_mm, r.board_pocket_half_mm, fdm.min_wall_mm
        ),
    );
    // the pilots go up into the ceiling; outside the shaft the ceiling is all there is
    let pilot_r = half_spacing * std::f64::consts::SQRT_2 + cam.mount_pilot_diameter_mm / 2.0;
    let above = if pilot_r > r.shaft_bore_mm - fdm.min_wall_mm {
        sb.base.ceiling_thickness_mm
    } else {
        f64::INFINITY
    };
    rule(
        cam.mount_pilot_depth_mm + fdm.min_wall_mm <= above,
        "camera.mount_pilot_depth_mm",
        cam.mount_pilot_depth_mm,
        format!(
            "must leave a {:.2} mm wall under the base's top (ceiling {:.2} mm thick)",
            fdm.min_wall_mm, sb.base.ceiling_thickness_mm
        ),
    );
    rule(
        CABLE_SLOT_MM[1] + fdm.min_wall_mm <= cam.bay_height_mm + sb.base.ceiling_thickness_mm,
        "camera.bay_height_mm",
        cam.bay_height_mm,
        format!("must take the {:.1} mm cable slot", CABLE_SLOT_MM[1]),
    );
}

/// The camera's view: the lens's front at least 1 mm under the LED ring, and the view cone
/// (`camera.view_angle_deg`) covering the lip's opening at the base plane.
fn check_view(sb: &ShaftBodyParams, r: &ShaftRadii, lv: &ShaftLevels, errs: &mut Vec<ParamError>) {
    let cam = &sb.camera;
    let mut rule = |ok: bool, path: &str, v: f64, text: String| {
        if !ok {
            errs.push(ParamError::new(format!("shaft_body.{path}"), v, text));
        }
    };
    rule(
        lv.lens_z_mm < lv.led_pcb_z_mm - 1.0,
        "camera.lens_height_mm",
        cam.lens_height_mm,
        format!(
            "the lens's front (z {:.2} mm) must stay at least 1 mm under the LED ring (z {:.2} mm): lengthen the shaft",
            lv.lens_z_mm, lv.led_pcb_z_mm
        ),
    );
    let half = (cam.view_angle_deg / 2.0).to_radians();
    let cone = (lv.skin_base_z_mm - lv.lens_z_mm) * half.tan();
    rule(
        cone >= r.lip_inner_mm,
        "shaft_length_mm",
        sb.shaft_length_mm,
        format!(
            "the camera's view cone ({:.0} deg) covers only {cone:.2} mm of the tip's opening (radius {:.2} mm) at the base plane: lengthen the shaft or take a wider lens",
            cam.view_angle_deg, r.lip_inner_mm
        ),
    );
}
