//! The shaft body's dimensions, derived from its parameters: the levels ([`ShaftLevels`]) and
//! radii ([`ShaftRadii`]) of the body and the tip's fitting, the tip's bayonet, the camera
//! board's mounting holes, and the twin parameters that state them all.

use super::params::{ShaftBodyParams, CABLE_SLOT_MM, LED_WIRE_ROOM_MM, OVERLAP_MM};
use crate::parts::bayonet::Bayonet;
use crate::parts::context::{Context, Stack};
use crate::schema::shared::LayerProcess;
use serde::Serialize;
use serde_json::json;

/// Levels of the shaft body and the tip's fitting, sensor frame, mm (top to bottom).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShaftLevels {
    /// The base plane: the skin's bottom, the fitting's top.
    pub skin_base_z_mm: f64,
    /// Underside of the lip, the window's top face.
    pub lip_z_mm: f64,
    /// The shaft's top face, the window's bottom face.
    pub shaft_top_z_mm: f64,
    /// Bottom of the fitting's skirt.
    pub fitting_bottom_z_mm: f64,
    /// Bottom of the LED ring PCB (the seat's floor).
    pub led_pcb_z_mm: f64,
    /// Top of the base, bottom of the shaft.
    pub base_top_z_mm: f64,
    /// The base's ceiling over the board's pocket: the board's top face.
    pub ceiling_z_mm: f64,
    /// The lens's front.
    pub lens_z_mm: f64,
    /// The sensor's bottom: the base's bottom face.
    pub bottom_z_mm: f64,
    /// From the bottom to the skin's pole, mm.
    pub envelope_height_mm: f64,
}

/// The skin's layer that carries the fitting: the outermost layer, printed.
pub(super) fn skin_layer(stack: &Stack) -> Option<&crate::parts::context::ResolvedLayer> {
    stack
        .layers
        .last()
        .filter(|l| l.process == LayerProcess::Printed)
}

/// The shaft body's levels (see [`ShaftLevels`]).
pub fn levels(ctx: &Context<'_>, sb: &ShaftBodyParams) -> ShaftLevels {
    let zb = ctx.body.base_z_mm();
    let lip = zb - sb.tip_fitting.lip_thickness_mm;
    let top = lip - sb.lens_window.thickness_mm;
    let base_top = top - sb.shaft_length_mm;
    let ceiling = base_top - sb.base.ceiling_thickness_mm;
    let bottom = ceiling - sb.camera.bay_height_mm;
    ShaftLevels {
        skin_base_z_mm: zb,
        lip_z_mm: lip,
        shaft_top_z_mm: top,
        fitting_bottom_z_mm: top - sb.tip_fitting.skirt_length_mm,
        led_pcb_z_mm: top - sb.led_ring.led_height_mm - sb.led_ring.thickness_mm,
        base_top_z_mm: base_top,
        ceiling_z_mm: ceiling,
        lens_z_mm: ceiling + sb.camera.lens_height_mm,
        bottom_z_mm: bottom,
        envelope_height_mm: ctx.body.pole_z_mm(0.0) - bottom,
    }
}

/// The resolved radii, mm.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShaftRadii {
    /// The fitting's outside: the skin's outer radius at the base plane.
    pub fitting_outer_mm: f64,
    /// The lip's opening.
    pub lip_inner_mm: f64,
    /// The window's seat in the fitting.
    pub window_seat_mm: f64,
    /// The skirt's bore over the shaft.
    pub skirt_bore_mm: f64,
    pub shaft_outer_mm: f64,
    pub shaft_bore_mm: f64,
    /// The LED ring's seat in the shaft's top.
    pub led_seat_mm: f64,
    /// The lens's hole through the base's ceiling, with [`LED_WIRE_ROOM_MM`] beside the lens.
    pub lens_hole_mm: f64,
    pub base_outer_mm: f64,
    /// Half the side of the board's square pocket.
    pub board_pocket_half_mm: f64,
}

/// The radii of the fitting and the body.
pub fn radii(ctx: &Context<'_>, sb: &ShaftBodyParams, stack: &Stack) -> ShaftRadii {
    let c = sb.fit_clearance_mm;
    let outer = skin_layer(stack).map_or(0.0, |l| l.outer_offset_mm);
    let rw = sb.lens_window.diameter_mm / 2.0;
    let rs = sb.shaft_diameter_mm / 2.0;
    ShaftRadii {
        fitting_outer_mm: ctx.body.rim_radius_mm(outer),
        lip_inner_mm: rw - sb.tip_fitting.lip_width_mm,
        window_seat_mm: rw + c,
        skirt_bore_mm: rs + ctx.printers.fdm.bayonet.clearance_mm,
        shaft_outer_mm: rs,
        shaft_bore_mm: rs - sb.wall_thickness_mm,
        led_seat_mm: sb
            .led_ring
            .seat_diameter_mm
            .map_or(sb.led_ring.outer_diameter_mm / 2.0 + c, |d| d / 2.0),
        lens_hole_mm: sb.camera.lens_diameter_mm / 2.0 + c + LED_WIRE_ROOM_MM,
        base_outer_mm: sb.base.outer_diameter_mm / 2.0,
        board_pocket_half_mm: sb.camera.board_width_mm / 2.0 + c,
    }
}

/// The tip-to-shaft bayonet, locked.
pub fn tip_bayonet(ctx: &Context<'_>, sb: &ShaftBodyParams) -> Bayonet {
    let lv = levels(ctx, sb);
    Bayonet {
        spigot_radius_mm: sb.shaft_diameter_mm / 2.0,
        outward: false,
        clockwise: false,
        // the first lug on +x, locked
        first_lug_deg: 0.0,
        // lugs flush with the skirt's bottom
        lug_z_mm: lv.fitting_bottom_z_mm + sb.bayonet.lug_height_mm / 2.0,
        spigot_end_z_mm: lv.shaft_top_z_mm,
        ..Bayonet::sized(&ctx.printers.fdm.bayonet, &sb.bayonet)
    }
}

/// The twin parameters of the fitting and the body: levels, radii, the bayonet, the pilots.
pub fn twin_params(ctx: &Context<'_>, sb: &ShaftBodyParams, stack: &Stack) -> serde_json::Value {
    let b = tip_bayonet(ctx, sb);
    json!({
        "levels": levels(ctx, sb),
        "radii": radii(ctx, sb, stack),
        "bayonet": b,
        "lug_azimuths_deg": b.lug_azimuths_deg(),
        "mount_holes_xy_mm": mount_holes(sb),
        "cable_slot_mm": CABLE_SLOT_MM,
        "overlap_mm": OVERLAP_MM,
        "shaft_body": sb,
        "mount": sb
            .robot_mount
            .as_ref()
            .map(|m| crate::parts::robot_mount::twin_params(ctx, sb, m)),
    })
}

pub(super) fn mount_holes(sb: &ShaftBodyParams) -> Vec<[f64; 2]> {
    let h = sb.camera.mount_hole_spacing_mm / 2.0;
    vec![[h, h], [-h, h], [-h, -h], [h, -h]]
}
