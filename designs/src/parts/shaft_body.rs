//! The shaft body of a TacTip-style sensor (Pestell et al. Sec. III-A, Fig. 1): a printed
//! tip (the skin) on a rigid fitting that locks onto a round shaft by a bayonet, the shaft
//! housing the LED ring and the camera (`shaft_body` in a design).
//!
//! From the top down, in the sensor frame (mm):
//!
//! - The skin, down to the base plane `z_b`, and under it the tip's fitting, printed with the
//!   skin in the fitting's rigid material (Vero White) as a further volume of the same
//!   multi-material object. The fitting is a ring of the skin's outer diameter: at its top an
//!   inward lip over the lens window's rim, under the lip the window's seat, then the skirt
//!   that goes over the shaft's top, with the bayonet's lugs reaching in from its bottom.
//! - The lens window: an acrylic disc (laser-cut) between the lip and the shaft's top face.
//!   The clear gel fills the skin above it, round the pins (Sec. III-A: "the space between the
//!   inside of the skin and an inserted acrylic lens is manually filled with a clear silicone
//!   gel"); the lip keeps it in the tip when the tip is off the body.
//! - The body (ABS, Sec. III-A): the shaft, `shaft_length_mm` from its top face down to the
//!   base, with the bayonet's grooves round its top, the LED ring PCB's seat in its top (LEDs
//!   up, under the window) and a bore for the light and the view; under the shaft the base,
//!   with a pocket open at the bottom into which the camera board is screwed up against the
//!   ceiling, its lens up through the ceiling into the shaft's bore, and a slot for the cable.
//!
//! The camera's view cone must cover the lip's opening; the fraction of the skin's inner
//! surface it sees (through the lip, the LED ring and the shaft's bore, the pins' shadows
//! ignored) is stated in the manifest ([`view_fraction`]).

use super::{axial_cylinder, ExactShape, Member, MemberKind};
use super::{Part, PrintTechnology};
use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::Polyline2;
use crate::geometry::{cuboid, cylinder, revolve, ChordTolerance, GeometryError, Solid};
use crate::materials::CastReport;
use crate::optics::elements::{ring_of_lights, FlatInterface, Lens, Light};
use crate::parts::bayonet::Bayonet;
pub use crate::parts::bayonet::BayonetLugs;
use crate::parts::context::Context;
use crate::parts::context::Stack;
use crate::parts::cut_part::{CutPart, Operation, Outline};
use crate::parts::family::envelope;
use crate::parts::family::{
    named, AssemblyInput, AssemblyStep, Built, Family, FamilyInput, FillingPour, InnerCavity,
    FILLING_GEL,
};
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::{ProcedureAction, ProcedureStep};
use crate::schema::shared::{FillingGel, LayerProcess};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The shaft body and the tip's fitting (see the module docs). Lengths in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShaftBodyParams {
    /// Material key of the body (printed FDM), e.g. `abs`.
    pub material: String,
    /// Outer diameter of the shaft, mm (Sec. III-A: about 23 mm).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub shaft_diameter_mm: f64,
    /// From the shaft's top face (under the lens window) down to the base, mm (Sec. III-A:
    /// about 38 mm, chosen for the lens's focal length and view angle).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub shaft_length_mm: f64,
    /// Wall of the shaft round its bore, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wall_thickness_mm: f64,
    /// Radial clearance round seated parts (window, LED ring, lens, camera board), mm, at
    /// least half the FDM nozzle.
    pub fit_clearance_mm: f64,
    pub tip_fitting: TipFitting,
    pub bayonet: BayonetLugs,
    pub lens_window: LensWindow,
    pub led_ring: LedRing,
    pub camera: ShaftCamera,
    pub base: ShaftBase,
    /// The clear gel between the skin and the lens window; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filling_gel: Option<FillingGel>,
    /// The mount that holds the body on a robot by a bayonet; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot_mount: Option<crate::parts::robot_mount::RobotMount>,
}

/// The tip's rigid fitting, printed with the skin (Sec. III-A: "a rigid bayonet fitting (Vero
/// White). Both elements are printed as a single part").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TipFitting {
    /// Material key, a PolyJet material printed with the skin (`vero_white`).
    pub material: String,
    /// How far the skirt reaches down over the shaft, below the window, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub skirt_length_mm: f64,
    /// How far the lip reaches in over the window's rim, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lip_width_mm: f64,
    /// Thickness of the lip, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lip_thickness_mm: f64,
}

/// The acrylic lens window (Sec. III-A: "an inserted acrylic lens"), laser-cut.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LensWindow {
    /// Diameter of the acrylic disc, mm: it rests on the shaft's top face, so above the LED
    /// ring's seat (and the shaft's bore) and at most `shaft_diameter_mm`; its seat in the
    /// tip's fitting (this plus `fit_clearance_mm` on each side) must keep the PolyJet minimum
    /// wall inside the fitting.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub diameter_mm: f64,
    /// Thickness of the disc along the axis (the acrylic sheet it is cut from), mm, > 0: from
    /// the shaft's top face up to the underside of the fitting's lip.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
}

/// The LED ring PCB (Sec. III-A: "a PCB ring of six LEDs"), seated in the shaft's top.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LedRing {
    /// Outer diameter of the ring PCB, mm, > 0; its seat in the shaft's top is this plus
    /// `fit_clearance_mm` on each side unless `seat_diameter_mm` is given.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Diameter of the PCB's bore, mm: below the outer diameter and at most the seat's. The
    /// camera looks through it (the manifest's view fraction counts the rays it passes).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inner_diameter_mm: f64,
    /// Thickness of the PCB along the axis, mm, > 0: it sits on the seat's floor, the tops of
    /// its LEDs (`led_height_mm` over it) flush with the shaft's top face.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// LEDs on the ring, for the bought-items list and the assembly (Pestell et al. Sec.
    /// III-A: six); no part's shape depends on it.
    pub led_count: u32,
    /// Height of the LEDs over the PCB, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub led_height_mm: f64,
    /// Diameter of the seat in the shaft's top, mm; the PCB's plus the fit clearance on each
    /// side when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub seat_diameter_mm: Option<f64>,
}

/// The camera board in the base, its lens up the shaft (Sec. III-A2: an ADNS-3080 on a
/// breakout board with an adjustable lens, focal length 4.2 mm, view angle 86 deg).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShaftCamera {
    /// Module name, for the fabrication sheet.
    pub module: String,
    /// Side of the square board, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub board_width_mm: f64,
    /// Height of the pocket under the base's ceiling: the board and what hangs under it, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bay_height_mm: f64,
    /// Diameter of the lens holder, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lens_diameter_mm: f64,
    /// Height of the lens's front over the board's top face, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lens_height_mm: f64,
    /// Focal length of the lens, mm, > 0 (Pestell et al. Sec. III-A2: 4.2 mm); stated in the
    /// bought-items list and the manifest's camera view. No shape or rule uses it: the view
    /// is checked with `view_angle_deg`.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub focal_length_mm: f64,
    /// Full view angle of the lens, degrees, in (0, 180).
    #[schemars(extend("exclusiveMinimum" = 0, "exclusiveMaximum" = 180))]
    pub view_angle_deg: f64,
    /// Square pattern of the board's mounting holes, centre to centre, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub mount_hole_spacing_mm: f64,
    /// Pilot for the self-tapping mounting screws, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub mount_pilot_diameter_mm: f64,
    /// Depth of the pilots up into the ceiling, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub mount_pilot_depth_mm: f64,
}

/// The base under the shaft that holds the camera board.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShaftBase {
    /// Outer diameter of the base, mm: at least `shaft_diameter_mm`, and the board's square
    /// pocket must keep the FDM minimum wall inside it at its corners. With a `robot_mount`,
    /// the mount's cup takes it and its lugs stand out of it.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Thickness of the ceiling over the board's pocket, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub ceiling_thickness_mm: f64,
}

/// The camera's cable slot through the base's wall at its bottom, on +y: width x height, mm.
/// ASSUMPTION: the breakout's cable or pin header wires fit 10 x 4 mm (measure yours).
pub const CABLE_SLOT_MM: [f64; 2] = [10.0, 4.0];

/// How far a solid reaches into the one it is united with or cut from, so that no two faces
/// of a boolean coincide, mm.
pub const OVERLAP_MM: f64 = 0.01;

/// Room beside the lens in the ceiling's hole for the LED ring's wires, which run down the
/// shaft's bore into the camera's pocket and out through the cable slot, mm (ASSUMPTION: two
/// 26 AWG wires).
pub const LED_WIRE_ROOM_MM: f64 = 1.0;

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
fn skin_layer(stack: &Stack) -> Option<&crate::parts::context::ResolvedLayer> {
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

/// The fitting's profile of revolution (r, z), closed, counter-clockwise.
fn fitting_profile(r: &ShaftRadii, lv: &ShaftLevels) -> Polyline2 {
    Polyline2 {
        points: vec![
            [r.skirt_bore_mm, lv.fitting_bottom_z_mm],
            [r.fitting_outer_mm, lv.fitting_bottom_z_mm],
            [r.fitting_outer_mm, lv.skin_base_z_mm],
            [r.lip_inner_mm, lv.skin_base_z_mm],
            [r.lip_inner_mm, lv.lip_z_mm],
            [r.window_seat_mm, lv.lip_z_mm],
            [r.window_seat_mm, lv.shaft_top_z_mm],
            [r.skirt_bore_mm, lv.shaft_top_z_mm],
        ],
    }
}

/// The tip's fitting in the sensor frame: the ring of revolution and the lugs (locked).
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn tip_fitting_solid(
    sb: &ShaftBodyParams,
    input: FamilyInput<'_>,
) -> Result<Solid, GeometryError> {
    let FamilyInput { ctx, stack, tol } = input;
    let r = radii(ctx, sb, stack);
    let lv = levels(ctx, sb);
    let ring = Solid::from_mesh(&revolve(&fitting_profile(&r, &lv), tol)?)?;
    let lugs = tip_bayonet(ctx, sb).lugs(r.skirt_bore_mm + OVERLAP_MM, tol)?;
    ring.union(&lugs)
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

fn mount_holes(sb: &ShaftBodyParams) -> Vec<[f64; 2]> {
    let h = sb.camera.mount_hole_spacing_mm / 2.0;
    vec![[h, h], [-h, h], [-h, -h], [h, -h]]
}

/// The body (see the module docs), printed standing on its base.
///
/// # Errors
/// [`DesignError::Geometry`] naming the part if the kernel fails.
pub fn build_body(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> Result<Part, DesignError> {
    let FamilyInput { ctx, stack, tol } = input;
    let r = radii(ctx, sb, stack);
    let lv = levels(ctx, sb);
    let g = |x: Result<Solid, GeometryError>| x.part("shaft_body");
    let cyl =
        |r: f64, z0: f64, z1: f64| cylinder(z1 - z0, r, tol).map(|s| s.translate([0.0, 0.0, z0]));
    let e = OVERLAP_MM;
    let outer = g(
        cyl(r.base_outer_mm, lv.bottom_z_mm, lv.base_top_z_mm).and_then(|b| {
            b.union(&cyl(
                r.shaft_outer_mm,
                lv.base_top_z_mm - e,
                lv.shaft_top_z_mm,
            )?)
        }),
    )?;
    let p = r.board_pocket_half_mm;
    let (sw, sh) = (CABLE_SLOT_MM[0] / 2.0, CABLE_SLOT_MM[1]);
    let cam = &sb.camera;
    let mut cuts = vec![
        g(cyl(r.led_seat_mm, lv.led_pcb_z_mm, lv.shaft_top_z_mm + 1.0))?,
        g(cyl(r.shaft_bore_mm, lv.base_top_z_mm, lv.led_pcb_z_mm + e))?,
        g(cyl(
            r.lens_hole_mm,
            lv.ceiling_z_mm - e,
            lv.base_top_z_mm + e,
        ))?,
        g(cuboid(
            [-p, -p, lv.bottom_z_mm - 1.0],
            [p, p, lv.ceiling_z_mm],
        ))?,
        g(cuboid(
            [-sw, 0.0, lv.bottom_z_mm - 1.0],
            [sw, r.base_outer_mm + 1.0, lv.bottom_z_mm + sh],
        ))?,
        g(tip_bayonet(ctx, sb).grooves(tol))?,
    ];
    for [x, y] in mount_holes(sb) {
        cuts.push(g(cyl(
            cam.mount_pilot_diameter_mm / 2.0,
            lv.ceiling_z_mm - e,
            lv.ceiling_z_mm + cam.mount_pilot_depth_mm,
        )
        .map(|s| s.translate([x, y, 0.0])))?);
    }
    // the lugs that lock the base into the robot's mount
    let outer = match &sb.robot_mount {
        Some(m) => g(outer.union(&g(crate::parts::robot_mount::base_lugs(ctx, sb, m, tol))?))?,
        None => outer,
    };
    let body = g(outer.difference(&g(Solid::union_all(&cuts))?))?;
    let (placed, pose) = place_posed(&body, &crate::geometry::Affine::identity());
    let fdm_tech = PrintTechnology::Fdm;
    Ok(Part {
        name: "shaft_body".into(),
        role: "shaft_body".into(),
        description: format!(
            "Body: {:.1} mm shaft, {:.1} mm long, with the bayonet for the tip, the LED ring's seat and the camera's pocket (Pestell et al. Sec. III-A)",
            sb.shaft_diameter_mm, sb.shaft_length_mm
        ),
        material: sb.material.clone(),
        print_technology: fdm_tech,
        solid: placed,
        params: with_pose(twin_params(ctx, sb, stack), &pose),
        group: None,
    })
}

/// Fraction of the skin's inner surface the camera sees, in [0, 1]: area-weighted over the
/// inner surface above the base plane, a point counting when it lies inside the lens's view
/// cone and its ray from the lens passes the lip's opening, the LED ring's bore and the
/// shaft's bore (the pins' shadows and the gel's refraction ignored).
pub fn view_fraction(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> f64 {
    let FamilyInput { ctx, stack, tol } = input;
    let Some(skin) = skin_layer(stack) else {
        return 0.0;
    };
    let r = radii(ctx, sb, stack);
    let lv = levels(ctx, sb);
    let first = stack
        .layers
        .first()
        .map_or(skin.inner_offset_mm, |l| l.inner_offset_mm);
    let curve = ctx.body.offset_polyline(first, 0.0, tol);
    let zl = lv.lens_z_mm;
    let tan_half = (sb.camera.view_angle_deg / 2.0).to_radians().tan();
    // apertures: (z of the top of the narrowing, radius)
    let apertures = [
        (lv.skin_base_z_mm, r.lip_inner_mm),
        (
            lv.led_pcb_z_mm + sb.led_ring.thickness_mm,
            sb.led_ring.inner_diameter_mm / 2.0,
        ),
        (lv.led_pcb_z_mm, r.shaft_bore_mm),
    ];
    let seen = |p: [f64; 2]| {
        let dz = p[1] - zl;
        dz > 0.0
            && p[0] <= dz * tan_half
            && apertures
                .iter()
                .all(|&(z, ra)| z >= p[1] || p[0] * (z - zl) / dz <= ra)
    };
    let (mut total, mut visible) = (0.0, 0.0);
    for w in curve.points.windows(2) {
        let (a, b) = (w[0], w[1]);
        if a[1] < lv.skin_base_z_mm - 1e-9 || b[1] < lv.skin_base_z_mm - 1e-9 {
            continue;
        }
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        let n = 16;
        for k in 0..n {
            let t = (k as f64 + 0.5) / n as f64;
            let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            let da = 2.0 * std::f64::consts::PI * p[0] * len / n as f64;
            total += da;
            if seen(p) {
                visible += da;
            }
        }
    }
    if total > 0.0 {
        visible / total
    } else {
        0.0
    }
}

/// The filling gel's solid, sensor frame: `cavity`, the innermost layer's inside above the
/// base plane round the pins and their tips (`layers::inner_cavity`), and the lip's opening
/// down to the window.
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn filling_gel_solid(
    sb: &ShaftBodyParams,
    input: FamilyInput<'_>,
    cavity: Solid,
) -> Result<Solid, GeometryError> {
    let FamilyInput { ctx, stack, tol } = input;
    let r = radii(ctx, sb, stack);
    let lv = levels(ctx, sb);
    let lip = cylinder(lv.skin_base_z_mm - lv.lip_z_mm + 0.01, r.lip_inner_mm, tol)?.translate([
        0.0,
        0.0,
        lv.lip_z_mm,
    ]);
    cavity.union(&lip)
}

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
    let screw = super::fasteners::metric_from_pilot(cam.mount_pilot_diameter_mm)
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

/// The shaft-body family (`shaft_body`, with its `robot_mount`): the body, the tip's fitting
/// with the printed skin, the bayonet, the camera and the LED ring (Pestell et al. Sec. III-A).
pub struct ShaftBodyFamily;

impl Family for ShaftBodyFamily {
    type Params = ShaftBodyParams;
    const PATH: &'static str = "shaft_body";
    const SENSOR_PARTS: &'static [(&'static str, &'static [&'static str])] = &[
        (
            "tip_fitting",
            &["shaft_body.bayonet.lug_width_mm", "shaft_body.tip_fitting"],
        ),
        (
            "shaft_body",
            &["shaft_body.bayonet.groove_width_mm", "shaft_body"],
        ),
        (
            "robot_mount",
            &[
                "shaft_body.robot_mount.bayonet.groove_width_mm",
                "shaft_body.robot_mount",
            ],
        ),
    ];

    fn flat_interfaces(
        sb: &ShaftBodyParams,
        ctx: &Context<'_>,
        _stack: &Stack,
    ) -> Vec<FlatInterface> {
        // the acrylic lens window's faces (Pestell et al. Sec. III-A: "an inserted acrylic
        // lens"), the filling gel over it when there is one, else the air of the tip's inside
        let lv = levels(ctx, sb);
        let (above, what) = match &sb.filling_gel {
            Some(g) => (g.material.clone(), "under the filling gel"),
            None => (
                crate::optics::elements::AIR.to_string(),
                "under the tip's air",
            ),
        };
        vec![
            FlatInterface {
                z_mm: lv.shaft_top_z_mm,
                // the window is acrylic (Sec. III-A): the materials table's `pmma`
                above: "pmma".into(),
                what: "shaft_body.lens_window: the acrylic window's bottom face".into(),
            },
            FlatInterface {
                z_mm: lv.lip_z_mm,
                above,
                what: format!("shaft_body.lens_window: the window's top face, {what}"),
            },
        ]
    }

    fn lens(sb: &ShaftBodyParams, ctx: &Context<'_>, _stack: &Stack) -> Option<Lens> {
        Some(Lens {
            front_z_mm: levels(ctx, sb).lens_z_mm,
            view_angle_deg: Some(sb.camera.view_angle_deg),
            what: "shaft_body.camera.lens_height_mm: the lens's front over the board's top".into(),
        })
    }

    fn lights(sb: &ShaftBodyParams, ctx: &Context<'_>, _stack: &Stack) -> Vec<Light> {
        // the LEDs' tops at the shaft's top face, under the window, at the ring's mid-width,
        // facing the skin (Pestell et al. Sec. III-A: "a PCB ring of six LEDs"; white and the
        // first on +x, not given)
        let l = &sb.led_ring;
        ring_of_lights(
            l.led_count,
            (l.outer_diameter_mm + l.inner_diameter_mm) / 4.0,
            levels(ctx, sb).shaft_top_z_mm,
            0.0,
            Some([0.0, 0.0, 1.0]),
            |_| [1.0, 1.0, 1.0],
        )
    }

    fn estimated_triangles(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> f64 {
        let FamilyInput { ctx, stack, tol } = input;
        // the body's and the fitting's cylinders, seats and bayonet bands: about 30 and 27
        // circles of their outer radius
        let r = radii(ctx, sb, stack);
        30.0 * tol.circle_segments(r.base_outer_mm) as f64
            + 27.0 * tol.circle_segments(r.fitting_outer_mm) as f64
    }

    fn cut_parts(sb: &ShaftBodyParams) -> Vec<CutPart> {
        let w = &sb.lens_window;
        vec![CutPart {
            name: "lens_window".into(),
            description: format!(
                "Lens window: clear acrylic, {:.1} mm thick, diameter {:.1} mm (Pestell et al. \
                 Sec. III-A: the acrylic lens the gel is filled against)",
                w.thickness_mm, w.diameter_mm
            ),
            material: "pmma".into(),
            thickness_mm: w.thickness_mm,
            outlines: vec![(Operation::Cut, Outline::centred_circle(w.diameter_mm / 2.0))],
            kerf_mm: 0.0,
            quantity: 1,
            nominal_rings_mm: None,
        }]
    }

    fn check(sb: &ShaftBodyParams, ctx: &Context<'_>, stack: &Stack, errs: &mut Vec<ParamError>) {
        check_params(ctx, sb, stack, errs);
    }

    fn build(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> Result<Built, DesignError> {
        let FamilyInput { ctx, tol, .. } = input;
        let mut parts = vec![build_body(sb, input)?];
        if let Some(m) = &sb.robot_mount {
            parts.push(crate::parts::robot_mount::build_mount(ctx, sb, m, tol)?);
        }
        let lv = levels(ctx, sb);
        let camera_view = json!({
            "tip_inner_surface_fraction_seen": view_fraction(sb, input),
            "lens_z_mm": lv.lens_z_mm,
            "view_angle_deg": sb.camera.view_angle_deg,
            "focal_length_mm": sb.camera.focal_length_mm,
            "rule": "area fraction of the skin's inner surface above the base plane inside the lens's view cone whose ray passes the lip's opening, the LED ring's bore and the shaft's bore (the pins' shadows and the gel's refraction ignored)",
        });
        Ok(Built {
            parts,
            summary: vec![
                ("shaft_levels", json!(&lv)),
                envelope(ctx, sb.base.outer_diameter_mm, lv.envelope_height_mm),
                ("camera_view", camera_view),
            ],
        })
    }

    fn members(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> Result<Vec<Member>, DesignError> {
        members(input.ctx, sb, input.tol)
    }

    fn bought_items(sb: &ShaftBodyParams) -> Vec<String> {
        let mut v = bought_items(sb);
        if let Some(m) = &sb.robot_mount {
            v.extend(crate::parts::robot_mount::bought_items(m));
        }
        v
    }

    fn filling_pour<'p>(
        sb: &'p ShaftBodyParams,
        input: FamilyInput<'_>,
        cavity: InnerCavity<'_>,
    ) -> Result<Option<FillingPour<'p>>, DesignError> {
        // The clear gel between the skin and the lens window (Pestell et al. Sec. III-A).
        let Some(f) = &sb.filling_gel else {
            return Ok(None);
        };
        let gel = cavity(0)
            .and_then(|c| filling_gel_solid(sb, input, c))
            .part(FILLING_GEL)?;
        Ok(Some(FillingPour {
            gel: f,
            volume_mm3: gel.volume(),
            holder_roles: &["printed_skin", "tip_fitting"],
            how: "Poured into the tip, pole-down, round the pins and up into the lip's opening; the lens window is then laid on (Pestell et al. Sec. III-A).",
            member: Some(Member {
                name: FILLING_GEL.into(),
                kind: MemberKind::Cast,
                description: format!(
                    "Clear gel ({}) between the skin and the lens window, round the pins",
                    f.material
                ),
                solid: gel,
                fix: vec!["shaft_body.tip_fitting.lip_width_mm".into()],
                // the skin's cavity less its pins and tips: nested with them by construction
                nested_by_stack: true,
                features: Default::default(),
                exact: None,
            }),
        }))
    }

    fn assembly_steps(sb: &ShaftBodyParams, input: AssemblyInput<'_>) -> Vec<AssemblyStep> {
        let AssemblyInput {
            ctx,
            parts,
            filling,
        } = input;
        let mut out = Vec::new();
        let body = named(parts, "shaft_body")
            .first()
            .cloned()
            .unwrap_or_else(|| "the body".into());
        let fitting = named(parts, "tip_fitting")
            .first()
            .cloned()
            .unwrap_or_else(|| "the tip's fitting".into());
        let screws = crate::parts::fasteners::metric_from_pilot(sb.camera.mount_pilot_diameter_mm)
            .map_or_else(String::new, |d| format!(" M{d}"));
        let bayonet = &ctx.printers.fdm.bayonet;
        out.push(AssemblyStep::Text(format!(
            "Press the LED ring PCB ({} LEDs, facing up) into its seat at the top of {body}, its \
             wires down the bore, through the ceiling's hole beside the lens and out through the \
             cable slot (Pestell et al. Sec. III-A).",
            sb.led_ring.led_count
        )));
        out.push(AssemblyStep::Text(format!(
            "Screw the camera board into the pocket under {body}, up against the ceiling, with 4 \
             self-tapping screws{screws} ({:.1} mm pilots), the lens up through the ceiling's \
             hole and the cable out through the slot; focus the adjustable lens on the pins once \
             the tip is on (Pestell et al. Sec. III-A2).",
            sb.camera.mount_pilot_diameter_mm
        )));
        if let Some(c) = filling {
            out.push(AssemblyStep::Step(tip_filling_step(c, &fitting)));
        }
        if let Some(m) = &sb.robot_mount {
            out.push(AssemblyStep::Text(format!(
                "Bolt `robot_mount` to the tool flange of the {} with {} socket head cap \
                 screws, its locating pin in the flange's pin hole; set the base of {body} into \
                 its cup, the {n} lugs down the entry grooves and the camera's cable out through \
                 the window, and turn {body} {:.0} deg clockwise (seen from the tip's pole) \
                 until it stops (Pestell et al. Sec. III-A3: the body attaches to the robot's \
                 mount by a bayonet).",
                m.robot,
                m.bolt_count,
                m.bayonet.lock_angle_deg,
                n = bayonet.lug_count
            )));
        }
        out.push(AssemblyStep::Text(format!(
            "Twist the tip onto {body}: the {n} lugs of {fitting} down the {n} entry grooves, \
             push it home, then turn it {:.0} deg counter-clockwise (seen from the tip's pole) \
             until the lugs stop at the grooves' closed ends; the {:.0} deg ramp draws it down \
             onto the shaft (Pestell et al. Sec. III-A: a bayonet mount for replacing tips).",
            sb.bayonet.lock_angle_deg,
            bayonet.ramp_deg,
            n = bayonet.lug_count
        )));
        out
    }
}

/// The filling gel's pour into the printed tip, pole-down, closed by the lens window
/// (Pestell et al. Sec. III-A).
pub fn tip_filling_step(c: &CastReport, fitting: &str) -> ProcedureStep {
    ProcedureStep {
        action: ProcedureAction::Pour,
        text: format!(
            "Step {}: stand the tip pole-down, {fitting} up, mix and degas {} and pour it into \
             the tip round the pins until it is level with the top of the lip's opening \
             ({:.2} mL to fill); lay the lens window into its seat in {fitting} on the lip, \
             sliding it on from one side so that no air is caught (Pestell et al. Sec. III-A). \
             Let it cure ({}) before the tip goes on the body.",
            c.step,
            c.mix_text(),
            c.layer_volume_ml.unwrap_or(c.cavity_volume_ml),
            crate::materials::cure_text(&c.notes)
        ),
    }
}
