//! The casing of a sensor whose skin is glued onto a flat plate (ShadowTac, Sec. IV-B, Fig. 5:
//! "The casing consists of two filament-printed components: one that supports the camera,
//! LEDs, and sensing membrane, while the other is a base to mount the sensor on a robotic
//! gripper"), `casing` in a design.
//!
//! From the top down, in the sensor frame (mm):
//!
//! - The skin on its backing plate (`backing`, PMMA), the plate glued onto the casing's top
//!   face with cyanoacrylate (Sec. IV-B), over the casing's round window.
//! - The casing: a square block `outer_width_mm` wide and `height_mm` tall. Under the window a
//!   round light chamber down to a ledge; in the chamber's wall a vertical slot for each LED
//!   (a segment cut from an LED strip, its LED facing the axis), the LEDs at equal angles
//!   (Sec. IV-B: three RGB LEDs at 120 deg), each pushed up against the plate (Sec. IV-B:
//!   "close to the acrylic plate to avoid spurious reflections"), its wires down the slot,
//!   across the chamber's floor (behind the lens's front, out of its view) and through a hole
//!   in the ledge into the camera bay. Through the ledge the lens's bore; under
//!   it the square bay, open at the bottom, into which the camera board goes lens-up; a pilot
//!   hole in each corner of the wall for the screws that hold the casing on its base.
//! - The gripper base: a plate with a socket that takes the casing's foot, the board resting
//!   on the socket's floor; a slot under the floor leads the camera's cable out on +y; screws
//!   from below through counterbored holes hold the casing; counterbored bolt holes fasten the
//!   base to the gripper.
//!
//! The window must pass the camera's view of the whole skin: the ray from the lens's front to
//! the skin's rim, refracted by the plate, must cross the casing's top face inside the window.

use super::{ExactShape, Member, MemberKind};
use super::{Part, PrintTechnology};
use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{cuboid, ChordTolerance, GeometryError, Solid};
use crate::materials::MaterialKind;
use crate::optics::elements::{ring_of_lights, Lens, Light};
use crate::parts::context::Context;
use crate::parts::context::Stack;
use crate::parts::family::{named, AssemblyInput, AssemblyStep, Built, Family, FamilyInput};
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::shaft_body::{half_nozzle, OVERLAP_MM};
use crate::parts::z_cylinder;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The casing (see the module docs). Lengths in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CasingParams {
    /// Material key (printed FDM), e.g. `pla`.
    pub material: String,
    /// Width of the square casing, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_width_mm: f64,
    /// From the casing's bottom to its top face (under the backing plate), mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub height_mm: f64,
    /// Wall round the camera bay, mm; the bay is `outer_width_mm - 2 x wall_thickness_mm`
    /// square.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wall_thickness_mm: f64,
    /// The round opening in the top face, under the plate: the light chamber's diameter, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub window_diameter_mm: f64,
    /// From the casing's bottom up to the ledge, mm: holds the camera board.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bay_height_mm: f64,
    /// The ledge between the bay and the light chamber, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub ledge_thickness_mm: f64,
    /// Clearance round seated parts (the lens in its bore, the LEDs in their slots, the
    /// casing in the base's socket), mm, at least half the FDM nozzle.
    pub fit_clearance_mm: f64,
    pub camera: CasingCamera,
    pub leds: CasingLeds,
    pub screws: CasingScrews,
    /// The base that mounts the casing on a gripper; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gripper_base: Option<GripperBase>,
}

/// The camera: a square board with the lens standing on it (bought).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CasingCamera {
    /// The camera and lens, for the sheet.
    pub module: String,
    /// The board's side, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub board_width_mm: f64,
    /// The board with its components and connector, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub board_height_mm: f64,
    /// The lens with its holder: the cylinder round it, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lens_diameter_mm: f64,
    /// From the board's top to the lens's front, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lens_height_mm: f64,
}

/// The LEDs: segments cut from an LED strip (bought).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CasingLeds {
    /// The strip, for the sheet.
    pub description: String,
    /// LEDs round the chamber at equal angles, 1..=8 (Sec. IV-B: 3).
    #[schemars(extend("minimum" = 1, "maximum" = 8))]
    pub count: u32,
    /// Azimuth of the first LED from +x, degrees.
    pub first_azimuth_deg: f64,
    /// One segment: width across the strip, length along it (standing up), thickness with
    /// its LED, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width_mm: f64,
    /// Length of one segment along the strip, standing up in its slot from the casing's top
    /// face down, mm, > 0; the casing's height must hold the bay, the ledge and the LEDs over
    /// it with `fit_clearance_mm`.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub length_mm: f64,
    /// Thickness of one segment with its LED, radially, mm, > 0: its slot reaches this plus
    /// `fit_clearance_mm` out from the window's edge and must keep the FDM minimum wall inside
    /// the casing's side.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// Hole through the ledge for each segment's wires, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wire_hole_diameter_mm: f64,
}

/// The screws that hold the casing on its base: self-tapping into pilots in the casing's
/// corners, from below through counterbored holes in the base.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CasingScrews {
    /// Diameter of the pilots the screws cut their thread in, mm, > 0: up from the casing's
    /// bottom in the middle of the wall at each corner, each keeping the FDM minimum wall to
    /// the bay and to the outside.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pilot_diameter_mm: f64,
    /// Depth of the pilots up from the casing's bottom, mm, > 0; they must stay the FDM
    /// minimum wall under the casing's top.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pilot_depth_mm: f64,
    /// Diameter of the screws' clearance holes through the gripper base's floor, mm, above
    /// the pilot's diameter; it names the screw's size in the bought-items list.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub clearance_diameter_mm: f64,
    /// Diameter of the counterbores for the screws' heads in the gripper base's bottom, mm,
    /// above the clearance hole's diameter.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub head_diameter_mm: f64,
    /// Counterbore for the head, from the base's bottom, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub head_depth_mm: f64,
}

/// The gripper base (see the module docs). Lengths in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GripperBase {
    /// The gripper and its finger's fastening, for the sheet.
    pub gripper: String,
    /// Material key (printed FDM), e.g. `pla`.
    pub material: String,
    /// Side of the plate along x, mm, > 0; the bolts' counterbores must stay the FDM minimum
    /// wall inside it.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width_mm: f64,
    /// Side of the plate along y (the cable slot's side), mm, > 0; the bolts' counterbores
    /// must stay the FDM minimum wall inside it.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub length_mm: f64,
    /// Thickness of the plate along the axis, mm, > 0: its top face stands `socket_depth_mm`
    /// over the socket's floor, and the floor under the socket must hold the cable slot and
    /// the casing screws' counterbores, each over the FDM minimum wall.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// Depth of the socket that takes the casing's foot, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub socket_depth_mm: f64,
    /// The camera's cable slot under the socket's floor, out on +y: width and depth, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub cable_slot_width_mm: f64,
    /// Depth of the cable slot down from the socket's floor, mm, > 0; the base must keep the
    /// FDM minimum wall under it.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub cable_slot_depth_mm: f64,
    /// Bolts to the gripper on a rectangle centred on the axis: its sides along x and y, mm.
    #[schemars(extend("items" = {"type": "number", "exclusiveMinimum": 0}))]
    pub bolt_spacing_mm: [f64; 2],
    /// Diameter of the holes for the bolts to the gripper, through the plate, mm, > 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bolt_clearance_diameter_mm: f64,
    /// Diameter of the counterbores for the bolts' heads, down from the plate's top, mm,
    /// above the clearance hole's; they must stay the FDM minimum wall inside the plate and
    /// outside the casing's socket.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bolt_head_diameter_mm: f64,
    /// Counterbore for the bolts' heads, from the base's top, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bolt_head_depth_mm: f64,
}

/// Refractive index of the PMMA plate at visible wavelengths (about 1.49).
pub const PMMA_REFRACTIVE_INDEX: f64 = 1.49;

/// The plate needs this much of the casing's top face round the window to be glued on, mm.
pub const GLUE_LAND_MM: f64 = 1.0;

/// Levels of the casing and its base, sensor frame, mm (top to bottom).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CasingLevels {
    /// The base plane: the skin's bottom, the plate's top.
    pub skin_base_z_mm: f64,
    /// The plate's bottom, the casing's top face.
    pub top_z_mm: f64,
    /// The LEDs' bottom ends.
    pub led_bottom_z_mm: f64,
    /// The ledge's top face, the light chamber's floor.
    pub ledge_top_z_mm: f64,
    /// The ledge's underside, the bay's ceiling.
    pub ledge_bottom_z_mm: f64,
    /// The lens's front.
    pub lens_z_mm: f64,
    /// The board's top.
    pub board_top_z_mm: f64,
    /// The casing's bottom: the socket's floor, the board's bottom.
    pub bottom_z_mm: f64,
    /// The base's top and bottom faces (none without a base).
    pub base_top_z_mm: Option<f64>,
    pub base_bottom_z_mm: Option<f64>,
    /// From the sensor's bottom to the skin's pole, mm.
    pub envelope_height_mm: f64,
}

/// The casing's levels (see [`CasingLevels`]); the plate's thickness from `backing` (0 without).
pub fn levels(ctx: &Context<'_>, c: &CasingParams) -> CasingLevels {
    let zb = ctx.body.base_z_mm();
    let top = zb - ctx.backing.map_or(0.0, |b| b.thickness_mm);
    let bottom = top - c.height_mm;
    let ledge_bottom = bottom + c.bay_height_mm;
    let board_top = bottom + c.camera.board_height_mm;
    let base = c.gripper_base.as_ref().map(|g| {
        (
            bottom + g.socket_depth_mm,
            bottom + g.socket_depth_mm - g.thickness_mm,
        )
    });
    CasingLevels {
        skin_base_z_mm: zb,
        top_z_mm: top,
        led_bottom_z_mm: top - c.leds.length_mm,
        ledge_top_z_mm: ledge_bottom + c.ledge_thickness_mm,
        ledge_bottom_z_mm: ledge_bottom,
        lens_z_mm: board_top + c.camera.lens_height_mm,
        board_top_z_mm: board_top,
        bottom_z_mm: bottom,
        base_top_z_mm: base.map(|b| b.0),
        base_bottom_z_mm: base.map(|b| b.1),
        envelope_height_mm: ctx.body.pole_z_mm(0.0) - base.map_or(bottom, |b| b.1),
    }
}

/// Half the camera bay's side, mm.
pub fn bay_half_mm(c: &CasingParams) -> f64 {
    c.outer_width_mm / 2.0 - c.wall_thickness_mm
}

/// The LEDs' azimuths, degrees.
pub fn led_azimuths_deg(c: &CasingParams) -> Vec<f64> {
    let n = c.leds.count.max(1);
    (0..n)
        .map(|k| c.leds.first_azimuth_deg + f64::from(k) * 360.0 / f64::from(n))
        .collect()
}

/// Radii of an LED's slot, mm: (the chamber's wall, the slot's back face); and of its wire
/// hole's centre, on the LED's azimuth, the FDM minimum wall inside the bay's side.
fn slot_radii(ctx: &Context<'_>, c: &CasingParams) -> (f64, f64, f64) {
    let r = c.window_diameter_mm / 2.0;
    let back = r + c.leds.thickness_mm + c.fit_clearance_mm;
    let wire = bay_half_mm(c) - c.leds.wire_hole_diameter_mm / 2.0 - ctx.printers.fdm.min_wall_mm;
    (r, back, wire)
}

/// The corner pilots' centres, mm: in the middle of the wall, on the diagonals.
pub fn pilot_xy(c: &CasingParams) -> Vec<[f64; 2]> {
    let p = (bay_half_mm(c) + c.outer_width_mm / 2.0) / 2.0;
    vec![[p, p], [-p, p], [-p, -p], [p, -p]]
}

/// The gripper bolts' centres, mm.
pub fn bolt_xy(g: &GripperBase) -> Vec<[f64; 2]> {
    let [x, y] = g.bolt_spacing_mm.map(|s| s / 2.0);
    vec![[x, y], [-x, y], [-x, -y], [x, -y]]
}

/// Where the ray from the lens's front (on the axis, `h_mm` under the plate's bottom) to a
/// point `r_mm` from the axis on the plate's top crosses the plate's bottom, mm from the axis:
/// the ray refracted into the plate (thickness `t_mm`, index `n`) by Snell's law.
pub fn plate_crossing_radius_mm(r_mm: f64, h_mm: f64, t_mm: f64, n: f64) -> f64 {
    // r1 + t tan(theta2) grows with r1 from 0 (at r1 = 0) to beyond r (at r1 = r)
    let reach = |r1: f64| {
        let s1 = (r1 / h_mm).atan().sin();
        let s2 = s1 / n;
        r1 + t_mm * s2 / (1.0 - s2 * s2).sqrt()
    };
    let (mut lo, mut hi) = (0.0, r_mm);
    for _ in 0..80 {
        let mid = (lo + hi) / 2.0;
        if reach(mid) < r_mm {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo + hi) / 2.0
}

/// Rules on the casing and its base, paths under `casing`: walls print, parts are held, the
/// window passes the view. Overlaps between the casing and the parts it holds are the fit
/// check's ([`crate::assembly`]).
pub fn check_params(ctx: &Context<'_>, c: &CasingParams, errs: &mut Vec<ParamError>) {
    let before = errs.len();
    check_numbers(ctx, c, errs);
    let Some(backing) = ctx.backing else {
        errs.push(ParamError::new(
            "casing",
            "given",
            "the casing carries the skin's backing plate over its window: give backing:",
        ));
        return;
    };
    if errs.len() > before {
        return;
    }
    check_walls_and_fits(ctx, c, backing, errs);
    check_view(ctx, c, backing, errs);
    if let Some(g) = &c.gripper_base {
        check_gripper_base(ctx, c, g, errs);
    }
}

/// The casing's numbers that must be above 0 (the `gripper_base`'s among them when given),
/// `leds.first_azimuth_deg` finite, `leds.count` 1 to 8, and `fit_clearance_mm` at least half
/// the FDM nozzle; paths under `casing`.
fn check_numbers(ctx: &Context<'_>, c: &CasingParams, errs: &mut Vec<ParamError>) {
    let path = |p: &str| format!("casing.{p}");
    let led = &c.leds;
    crate::parts::check_above_zero("casing.", c, &[], errs);
    if !led.first_azimuth_deg.is_finite() {
        errs.push(ParamError::new(
            path("leds.first_azimuth_deg"),
            led.first_azimuth_deg,
            "must be a finite angle",
        ));
    }
    if !(1..=8).contains(&led.count) {
        errs.push(ParamError::new(
            path("leds.count"),
            led.count,
            "must be 1 to 8",
        ));
    }
    let fdm = &ctx.printers.fdm;
    half_nozzle(&path("fit_clearance_mm"), c.fit_clearance_mm, fdm, errs);
}

/// The casing's walls and what it holds, mm: the wall and the ledge at least the FDM minimum
/// wall, the height for the bay, the ledge and the LEDs, the LEDs' slots round the window,
/// the backing plate's glue land, the LEDs' wire holes, the lens's bore through the ledge and
/// the casing screws' pilots and counterbores.
fn check_walls_and_fits(
    ctx: &Context<'_>,
    c: &CasingParams,
    backing: &crate::schema::shared::Backing,
    errs: &mut Vec<ParamError>,
) {
    let path = |p: &str| format!("casing.{p}");
    let (cam, led, s) = (&c.camera, &c.leds, &c.screws);
    let fdm = &ctx.printers.fdm;
    let wall = fdm.min_wall_mm;
    let cl = c.fit_clearance_mm;
    let mut rule = |ok: bool, p: &str, v: f64, text: String| {
        if !ok {
            errs.push(ParamError::new(path(p), v, text));
        }
    };
    let half = c.outer_width_mm / 2.0;
    let bay = bay_half_mm(c);
    let (r_ch, back, r_wire) = slot_radii(ctx, c);
    rule(
        c.wall_thickness_mm >= wall,
        "wall_thickness_mm",
        c.wall_thickness_mm,
        format!("must be at least the FDM minimum wall ({wall:.2} mm)"),
    );
    rule(
        c.ledge_thickness_mm >= wall,
        "ledge_thickness_mm",
        c.ledge_thickness_mm,
        format!("must be at least the FDM minimum wall ({wall:.2} mm)"),
    );
    rule(
        c.bay_height_mm + c.ledge_thickness_mm + led.length_mm + cl <= c.height_mm,
        "height_mm",
        c.height_mm,
        format!(
            "must hold the camera bay ({:.2} mm), the ledge ({:.2} mm) and the LEDs standing over it ({:.2} mm and the {cl:.2} mm clearance)",
            c.bay_height_mm, c.ledge_thickness_mm, led.length_mm
        ),
    );
    rule(
        back + wall <= half,
        "window_diameter_mm",
        c.window_diameter_mm,
        format!(
            "the LEDs' slots round the window reach {back:.2} mm from the axis: the casing ({half:.2} mm) must keep a {wall:.2} mm wall outside them"
        ),
    );
    rule(
        c.window_diameter_mm / 2.0 + GLUE_LAND_MM <= backing.diameter_mm / 2.0,
        "window_diameter_mm",
        c.window_diameter_mm,
        format!(
            "the backing plate ({:.2} mm, backing.diameter_mm) must cover the window with a {GLUE_LAND_MM:.1} mm land all round to be glued on",
            backing.diameter_mm
        ),
    );
    let bore = cam.lens_diameter_mm / 2.0 + cl;
    let wire = led.wire_hole_diameter_mm / 2.0;
    rule(
        r_wire - wire >= bore + wall && r_wire + wire <= r_ch,
        "leds.wire_hole_diameter_mm",
        led.wire_hole_diameter_mm,
        format!(
            "the wire holes through the ledge (centred {r_wire:.2} mm from the axis, {wall:.2} mm inside the bay's side) must open from the light chamber's floor ({r_ch:.2} mm) and keep a {wall:.2} mm wall to the lens's bore ({bore:.2} mm)"
        ),
    );
    let slot_w = led.width_mm + 2.0 * cl;
    rule(
        f64::from(led.count) * (slot_w + wall) <= 2.0 * std::f64::consts::PI * r_ch,
        "leds.count",
        f64::from(led.count),
        format!(
            "{} slots {slot_w:.2} mm wide with a {wall:.2} mm wall between them must fit round the window ({:.2} mm)",
            led.count, c.window_diameter_mm
        ),
    );
    rule(
        cam.lens_diameter_mm / 2.0 + cl + wall <= bay,
        "camera.lens_diameter_mm",
        cam.lens_diameter_mm,
        format!(
            "the lens's bore through the ledge must leave a {wall:.2} mm ledge inside the bay ({:.2} mm square) to hold the board",
            2.0 * bay
        ),
    );
    rule(
        s.pilot_diameter_mm / 2.0 + wall <= c.wall_thickness_mm / 2.0,
        "screws.pilot_diameter_mm",
        s.pilot_diameter_mm,
        format!(
            "the pilots sit in the middle of the {:.2} mm wall: each must keep a {wall:.2} mm wall to the bay and to the outside",
            c.wall_thickness_mm
        ),
    );
    rule(
        s.pilot_depth_mm + wall <= c.height_mm,
        "screws.pilot_depth_mm",
        s.pilot_depth_mm,
        format!(
            "must stay {wall:.2} mm under the casing's top ({:.2} mm tall)",
            c.height_mm
        ),
    );
    rule(
        s.head_diameter_mm > s.clearance_diameter_mm,
        "screws.head_diameter_mm",
        s.head_diameter_mm,
        format!(
            "the counterbore must be wider than the screw's clearance hole ({:.2} mm)",
            s.clearance_diameter_mm
        ),
    );
    rule(
        s.clearance_diameter_mm > s.pilot_diameter_mm,
        "screws.clearance_diameter_mm",
        s.clearance_diameter_mm,
        format!(
            "must be wider than the pilot ({:.2} mm) that the screw cuts its thread in",
            s.pilot_diameter_mm
        ),
    );
}

/// The camera's view through the window: the ray from the lens's front to the skin's rim,
/// refracted by the backing plate (`backing.thickness_mm`), must cross the casing's top inside
/// the window.
fn check_view(
    ctx: &Context<'_>,
    c: &CasingParams,
    backing: &crate::schema::shared::Backing,
    errs: &mut Vec<ParamError>,
) {
    let path = |p: &str| format!("casing.{p}");
    let mut rule = |ok: bool, p: &str, v: f64, text: String| {
        if !ok {
            errs.push(ParamError::new(path(p), v, text));
        }
    };
    let (r_ch, _, _) = slot_radii(ctx, c);
    // the camera must see the skin's rim through the window (a lens that reaches the plate is
    // the fit check's)
    let lv = levels(ctx, c);
    let h = lv.top_z_mm - lv.lens_z_mm;
    if h > 0.0 {
        let rim = ctx.body.rim_radius_mm(0.0);
        let cross = plate_crossing_radius_mm(rim, h, backing.thickness_mm, PMMA_REFRACTIVE_INDEX);
        rule(
            cross <= r_ch,
            "window_diameter_mm",
            c.window_diameter_mm,
            format!(
                "the camera's view of the skin's rim (radius {rim:.2} mm, the lens's front {h:.2} mm under the plate) crosses the casing's top {cross:.2} mm from the axis: the window must pass it"
            ),
        );
    }
}

/// The gripper base under the casing, paths under `casing.gripper_base`, mm: the bolts'
/// counterbores inside the base and outside the casing's socket, the socket shallower than the
/// casing, the floor under the socket for the cable slot and the casing screws' counterbores,
/// the bolts' heads, and the cable slot clear of the casing screws.
fn check_gripper_base(
    ctx: &Context<'_>,
    c: &CasingParams,
    g: &GripperBase,
    errs: &mut Vec<ParamError>,
) {
    let path = |p: &str| format!("casing.{p}");
    let s = &c.screws;
    let wall = ctx.printers.fdm.min_wall_mm;
    let cl = c.fit_clearance_mm;
    let mut rule = |ok: bool, p: &str, v: f64, text: String| {
        if !ok {
            errs.push(ParamError::new(path(p), v, text));
        }
    };
    let half = c.outer_width_mm / 2.0;
    let gp = |p: &str| format!("gripper_base.{p}");
    let socket = half + cl;
    let [bx, by] = g.bolt_spacing_mm.map(|v| v / 2.0);
    for (i, (side, b, p)) in [(g.width_mm, bx, "width_mm"), (g.length_mm, by, "length_mm")]
        .into_iter()
        .enumerate()
    {
        rule(
            b + g.bolt_head_diameter_mm / 2.0 + wall <= side / 2.0,
            &gp(p),
            side,
            format!(
                "the bolts' counterbores ({:.2} mm on a {:.2} mm spacing) must stay {wall:.2} mm inside the base",
                g.bolt_head_diameter_mm, g.bolt_spacing_mm[i]
            ),
        );
        rule(
            b - g.bolt_head_diameter_mm / 2.0 >= socket + wall,
            &gp(&format!("bolt_spacing_mm[{i}]")),
            g.bolt_spacing_mm[i],
            format!(
                "the bolts' counterbores ({:.2} mm) must stay {wall:.2} mm outside the casing's socket ({:.2} mm square)",
                g.bolt_head_diameter_mm,
                2.0 * socket
            ),
        );
    }
    let floor = g.thickness_mm - g.socket_depth_mm;
    rule(
        g.socket_depth_mm < c.height_mm,
        "gripper_base.socket_depth_mm",
        g.socket_depth_mm,
        format!(
            "must be less than the casing's height ({:.2} mm)",
            c.height_mm
        ),
    );
    rule(
        g.cable_slot_depth_mm + wall <= floor && s.head_depth_mm + wall <= floor,
        "gripper_base.thickness_mm",
        g.thickness_mm,
        format!(
            "under the {:.2} mm socket, the floor must hold the cable slot ({:.2} mm) and the screws' counterbores ({:.2} mm) over a {wall:.2} mm wall",
            g.socket_depth_mm, g.cable_slot_depth_mm, s.head_depth_mm
        ),
    );
    rule(
        g.bolt_head_depth_mm + wall <= g.thickness_mm,
        "gripper_base.bolt_head_depth_mm",
        g.bolt_head_depth_mm,
        format!(
            "must leave {wall:.2} mm of the base ({:.2} mm) under the bolts' heads",
            g.thickness_mm
        ),
    );
    rule(
        g.bolt_head_diameter_mm > g.bolt_clearance_diameter_mm,
        "gripper_base.bolt_head_diameter_mm",
        g.bolt_head_diameter_mm,
        format!(
            "the counterbore must be wider than the bolt's clearance hole ({:.2} mm)",
            g.bolt_clearance_diameter_mm
        ),
    );
    let p = pilot_xy(c)[0][0];
    rule(
        g.cable_slot_width_mm / 2.0 + wall <= p - s.head_diameter_mm / 2.0,
        "gripper_base.cable_slot_width_mm",
        g.cable_slot_width_mm,
        format!(
            "the slot must pass {wall:.2} mm clear of the casing screws' counterbores ({:.2} mm, {p:.2} mm off each axis)",
            s.head_diameter_mm
        ),
    );
}

/// The casing's and base's parameters for their twins.
pub fn twin_params(ctx: &Context<'_>, c: &CasingParams) -> serde_json::Value {
    let (r_ch, back, r_wire) = slot_radii(ctx, c);
    json!({
        "casing": c,
        "levels": levels(ctx, c),
        "bay_half_mm": bay_half_mm(c),
        "chamber_radius_mm": r_ch,
        "slot_back_radius_mm": back,
        "wire_hole_radius_mm": r_wire,
        "led_azimuths_deg": led_azimuths_deg(c),
        "pilot_xy_mm": pilot_xy(c),
        "bolt_xy_mm": c.gripper_base.as_ref().map(bolt_xy),
        "overlap_mm": OVERLAP_MM,
    })
}

/// The casing, printed standing on its bottom (the ledge bridges the bay).
///
/// # Errors
/// [`DesignError::Geometry`] naming the part if the kernel fails.
pub fn build_casing(
    ctx: &Context<'_>,
    c: &CasingParams,
    tol: ChordTolerance,
) -> Result<Part, DesignError> {
    let g = |x: Result<Solid, GeometryError>| x.part("casing");
    let lv = levels(ctx, c);
    let (half, bay, e) = (c.outer_width_mm / 2.0, bay_half_mm(c), OVERLAP_MM);
    let (r_ch, back, r_wire) = slot_radii(ctx, c);
    let cl = c.fit_clearance_mm;
    let block = g(cuboid(
        [-half, -half, lv.bottom_z_mm],
        [half, half, lv.top_z_mm],
    ))?;
    let mut cuts = vec![
        g(cuboid(
            [-bay, -bay, lv.bottom_z_mm - 1.0],
            [bay, bay, lv.ledge_bottom_z_mm],
        ))?,
        g(z_cylinder(
            c.camera.lens_diameter_mm / 2.0 + cl,
            lv.ledge_bottom_z_mm - e,
            lv.ledge_top_z_mm + e,
            [0.0; 2],
            tol,
        ))?,
        g(z_cylinder(
            r_ch,
            lv.ledge_top_z_mm,
            lv.top_z_mm + 1.0,
            [0.0; 2],
            tol,
        ))?,
    ];
    let w = c.leds.width_mm / 2.0 + cl;
    for a in led_azimuths_deg(c) {
        let slot = g(cuboid(
            [r_ch - 1.0, -w, lv.ledge_top_z_mm],
            [back, w, lv.top_z_mm + 1.0],
        ))?;
        cuts.push(slot.rotate_deg(0.0, 0.0, a));
        let (s, co) = a.to_radians().sin_cos();
        cuts.push(g(z_cylinder(
            c.leds.wire_hole_diameter_mm / 2.0,
            lv.ledge_bottom_z_mm - e,
            lv.ledge_top_z_mm + e,
            [r_wire * co, r_wire * s],
            tol,
        ))?);
    }
    for xy in pilot_xy(c) {
        cuts.push(g(z_cylinder(
            c.screws.pilot_diameter_mm / 2.0,
            lv.bottom_z_mm - 1.0,
            lv.bottom_z_mm + c.screws.pilot_depth_mm,
            xy,
            tol,
        ))?);
    }
    let casing = g(block.difference(&g(Solid::union_all(&cuts))?))?;
    let (placed, pose) = place_posed(&casing, &crate::geometry::Affine::identity());
    Ok(Part {
        name: "casing".into(),
        role: "casing".into(),
        description: format!(
            "Casing: {:.1} x {:.1} x {:.1} mm; holds the camera in its bay, {} LEDs round the light chamber and the skin's plate on its top face (ShadowTac Sec. IV-B, Fig. 5)",
            c.outer_width_mm, c.outer_width_mm, c.height_mm, c.leds.count
        ),
        material: c.material.clone(),
        print_technology: PrintTechnology::Fdm,
        solid: placed,
        params: with_pose(twin_params(ctx, c), &pose),
        group: None,
    })
}

/// The gripper base, printed standing on its bottom.
///
/// # Errors
/// [`DesignError::Geometry`] naming the part if the kernel fails.
pub fn build_base(
    ctx: &Context<'_>,
    c: &CasingParams,
    gb: &GripperBase,
    tol: ChordTolerance,
) -> Result<Part, DesignError> {
    let g = |x: Result<Solid, GeometryError>| x.part("gripper_base");
    let lv = levels(ctx, c);
    let (top, bottom) = (
        lv.bottom_z_mm + gb.socket_depth_mm,
        lv.bottom_z_mm + gb.socket_depth_mm - gb.thickness_mm,
    );
    let floor = lv.bottom_z_mm;
    let e = OVERLAP_MM;
    let (x, y) = (gb.width_mm / 2.0, gb.length_mm / 2.0);
    let plate = g(cuboid([-x, -y, bottom], [x, y, top]))?;
    let sk = c.outer_width_mm / 2.0 + c.fit_clearance_mm;
    let sw = gb.cable_slot_width_mm / 2.0;
    let mut cuts = vec![
        g(cuboid([-sk, -sk, floor], [sk, sk, top + 1.0]))?,
        g(cuboid(
            [-sw, 0.0, floor - gb.cable_slot_depth_mm],
            [sw, y + 1.0, floor + e],
        ))?,
    ];
    let s = &c.screws;
    for xy in pilot_xy(c) {
        cuts.push(g(z_cylinder(
            s.clearance_diameter_mm / 2.0,
            bottom - 1.0,
            floor + e,
            xy,
            tol,
        ))?);
        cuts.push(g(z_cylinder(
            s.head_diameter_mm / 2.0,
            bottom - 1.0,
            bottom + s.head_depth_mm,
            xy,
            tol,
        ))?);
    }
    for xy in bolt_xy(gb) {
        cuts.push(g(z_cylinder(
            gb.bolt_clearance_diameter_mm / 2.0,
            bottom - 1.0,
            top + 1.0,
            xy,
            tol,
        ))?);
        cuts.push(g(z_cylinder(
            gb.bolt_head_diameter_mm / 2.0,
            top - gb.bolt_head_depth_mm,
            top + 1.0,
            xy,
            tol,
        ))?);
    }
    let base = g(plate.difference(&g(Solid::union_all(&cuts))?))?;
    let (placed, pose) = place_posed(&base, &crate::geometry::Affine::identity());
    Ok(Part {
        name: "gripper_base".into(),
        role: "gripper_base".into(),
        description: format!(
            "Gripper base: {:.1} x {:.1} x {:.1} mm plate with the casing's socket and the cable slot, bolted to the {} (ShadowTac Sec. IV-B, Fig. 5)",
            gb.width_mm, gb.length_mm, gb.thickness_mm, gb.gripper
        ),
        material: gb.material.clone(),
        print_technology: PrintTechnology::Fdm,
        solid: placed,
        params: with_pose(twin_params(ctx, c), &pose),
        group: None,
    })
}

/// The bought parts the casing holds, as assembly envelopes: the camera's board and lens,
/// and each LED segment.
///
/// # Errors
/// [`DesignError::Geometry`] naming the member if the kernel fails.
pub fn members(
    ctx: &Context<'_>,
    c: &CasingParams,
    tol: ChordTolerance,
) -> Result<Vec<Member>, DesignError> {
    let lv = levels(ctx, c);
    let member =
        |name: &str, description: String, solid: Solid, exact: Option<ExactShape>, fix: &[&str]| {
            Member {
                name: name.into(),
                kind: MemberKind::Bought,
                description,
                solid,
                fix: fix.iter().map(|f| format!("casing.{f}")).collect(),
                nested_by_stack: false,
                features: Default::default(),
                exact,
                material: None,
            }
        };
    let cam = &c.camera;
    let bw = cam.board_width_mm / 2.0;
    let (bmin, bmax) = ([-bw, -bw, lv.bottom_z_mm], [bw, bw, lv.board_top_z_mm]);
    let rl = cam.lens_diameter_mm / 2.0;
    let mut out = vec![
        member(
            "camera_board_envelope",
            format!("Camera board with its components (bought): {}", cam.module),
            cuboid(bmin, bmax).part("camera_board_envelope")?,
            Some(ExactShape::Box {
                min_mm: bmin,
                max_mm: bmax,
            }),
            &["camera.board_width_mm", "camera.board_height_mm"],
        ),
        member(
            "camera_lens_envelope",
            "Camera lens in its holder (bought)".into(),
            z_cylinder(rl, lv.board_top_z_mm, lv.lens_z_mm, [0.0; 2], tol)
                .part("camera_lens_envelope")?,
            Some(ExactShape::Cylinder {
                radius_mm: rl,
                z0_mm: lv.board_top_z_mm,
                z1_mm: lv.lens_z_mm,
            }),
            &["camera.lens_height_mm", "camera.lens_diameter_mm"],
        ),
    ];
    let (r_ch, _, _) = slot_radii(ctx, c);
    let w = c.leds.width_mm / 2.0;
    for (k, a) in led_azimuths_deg(c).into_iter().enumerate() {
        let name = format!("led_{}_envelope", k + 1);
        let solid = cuboid(
            [r_ch, -w, lv.led_bottom_z_mm],
            [r_ch + c.leds.thickness_mm, w, lv.top_z_mm],
        )
        .part(&name)?
        .rotate_deg(0.0, 0.0, a);
        out.push(member(
            &name,
            format!(
                "LED {} (bought): {}, at {a:.0} deg",
                k + 1,
                c.leds.description
            ),
            solid,
            None,
            &["leds.thickness_mm", "leds.width_mm"],
        ));
    }
    Ok(out)
}

/// The casing's bought items: the camera, the LEDs, the screws, the glue and (with a base)
/// the gripper bolts.
pub fn bought_items(c: &CasingParams) -> Vec<String> {
    let s = &c.screws;
    let mut out = vec![
        format!(
            "Camera: {} (board {:.1} mm square, {:.1} mm with its components; lens within {:.1} mm, its front {:.1} mm over the board), lens-up in the casing's bay (ShadowTac Sec. IV-B)",
            c.camera.module,
            c.camera.board_width_mm,
            c.camera.board_height_mm,
            c.camera.lens_diameter_mm,
            c.camera.lens_height_mm
        ),
        format!(
            "LEDs: {} segments of {} ({:.1} x {:.1} mm, {:.1} mm thick with the LED), wired to the camera's controller through the bay (ShadowTac Sec. IV-B)",
            c.leds.count, c.leds.description, c.leds.width_mm, c.leds.length_mm, c.leds.thickness_mm
        ),
        "Cyanoacrylate glue: the backing plate onto the casing's top face (ShadowTac Sec. IV-B)".into(),
    ];
    if let Some(g) = &c.gripper_base {
        let under_head = g.thickness_mm - g.socket_depth_mm - s.head_depth_mm;
        let screw =
            super::fasteners::screw_name(s.clearance_diameter_mm, under_head + s.pilot_depth_mm)
                .unwrap_or_else(|| format!("{:.1} mm", s.clearance_diameter_mm));
        out.push(format!(
            "Casing to base: 4 self-tapping screws {screw} up through the base's counterbored holes into the casing's {:.1} mm pilots ({:.1} mm deep)",
            s.pilot_diameter_mm, s.pilot_depth_mm
        ));
        out.push(format!(
            "Base to the {}: 4 socket head cap screws through {:.1} mm holes on a {:.1} x {:.1} mm rectangle, heads in {:.1} mm counterbores",
            g.gripper,
            g.bolt_clearance_diameter_mm,
            g.bolt_spacing_mm[0],
            g.bolt_spacing_mm[1],
            g.bolt_head_diameter_mm
        ));
    }
    out
}

/// The casing family (`casing`, with its `gripper_base`): the casing that holds the camera,
/// the LEDs and the skin's backing plate (ShadowTac Sec. IV-B).
pub struct CasingFamily;

impl Family for CasingFamily {
    type Params = CasingParams;
    const PATH: &'static str = "casing";
    const SENSOR_PARTS: &'static [(&'static str, &'static [&'static str])] = &[
        (
            "casing",
            &[
                "casing.wall_thickness_mm",
                "casing.bay_height_mm",
                "casing.window_diameter_mm",
            ],
        ),
        ("gripper_base", &["casing.gripper_base"]),
    ];

    fn materials(c: &CasingParams) -> Vec<(String, &str, &'static [MaterialKind])> {
        let mut v = vec![(
            "casing.material".to_string(),
            c.material.as_str(),
            &[MaterialKind::Print][..],
        )];
        if let Some(g) = &c.gripper_base {
            v.push((
                "casing.gripper_base.material".into(),
                &g.material,
                &[MaterialKind::Print],
            ));
        }
        v
    }

    fn lens(c: &CasingParams, ctx: &Context<'_>, _stack: &Stack) -> Option<Lens> {
        Some(Lens {
            front_z_mm: levels(ctx, c).lens_z_mm,
            view_angle_deg: None,
            what: "casing.camera.lens_height_mm: the lens's front over the board's top".into(),
        })
    }

    fn lights(c: &CasingParams, ctx: &Context<'_>, _stack: &Stack) -> Vec<Light> {
        // each LED at the chamber's wall, half-way down its segment, facing the axis;
        // three LEDs are red, green and blue in azimuth order (ShadowTac Sec. IV-B: "red,
        // green and blue LEDs ... at 120 deg"; which colour sits where is not given)
        let lv = levels(ctx, c);
        let rgb = c.leds.count == 3;
        ring_of_lights(
            c.leds.count,
            c.window_diameter_mm / 2.0,
            lv.top_z_mm - c.leds.length_mm / 2.0,
            c.leds.first_azimuth_deg,
            None,
            |k| match (rgb, k) {
                (true, 0) => [1.0, 0.0, 0.0],
                (true, 1) => [0.0, 1.0, 0.0],
                (true, _) => [0.0, 0.0, 1.0],
                (false, _) => [1.0, 1.0, 1.0],
            },
        )
    }

    fn estimated_triangles(c: &CasingParams, input: FamilyInput<'_>) -> f64 {
        // the casing's and the gripper base's holes, bores and pockets: about 36 circles of
        // the casing's half-width
        36.0 * input.tol.circle_segments(c.outer_width_mm / 2.0) as f64
    }

    fn check(c: &CasingParams, ctx: &Context<'_>, _stack: &Stack, errs: &mut Vec<ParamError>) {
        check_params(ctx, c, errs);
    }

    fn build(c: &CasingParams, input: FamilyInput<'_>) -> Result<Built, DesignError> {
        let FamilyInput { ctx, tol, .. } = input;
        // what the build reads, by its bits (`Debug` prints every number so that it reads
        // back to the same bits)
        let key = format!("{c:?}|{ctx:?}|{tol:?}");
        let kept = LAST_BUILT.with(|last| {
            last.borrow()
                .as_ref()
                .filter(|(k, _)| *k == key)
                .map(|(_, b)| b.clone())
        });
        if let Some(b) = kept {
            return Ok(b);
        }
        let built = build_family(ctx, c, tol)?;
        LAST_BUILT.with(|last| *last.borrow_mut() = Some((key, built.clone())));
        Ok(built)
    }

    fn members(c: &CasingParams, input: FamilyInput<'_>) -> Result<Vec<Member>, DesignError> {
        members(input.ctx, c, input.tol)
    }

    fn bought_items(c: &CasingParams) -> Vec<String> {
        bought_items(c)
    }

    fn assembly_steps(c: &CasingParams, input: AssemblyInput<'_>) -> Vec<AssemblyStep> {
        let AssemblyInput { parts, .. } = input;
        let mut out = Vec::new();
        let casing = named(parts, "casing")
            .first()
            .cloned()
            .unwrap_or_else(|| "the casing".into());
        let azimuths = led_azimuths_deg(c)
            .iter()
            .map(|a| format!("{a:.0}"))
            .collect::<Vec<_>>()
            .join(", ");
        out.push(AssemblyStep::Text(format!(
            "Cut {n} single-LED segments from the strip ({}) and push one into each slot in the light chamber's wall of {casing} (at {azimuths} deg from +x), LED facing the axis and its top end flush with the casing's top face, close under the plate; lead the wires down the slot, across the chamber's floor and through the ledge's hole into the camera bay (ShadowTac Sec. IV-B: red, green and blue at 120 deg, close to the acrylic plate).",
            c.leds.description,
            n = c.leds.count
        )));
        out.push(AssemblyStep::Text(format!(
            "Glue the backing plate, the skin up, onto the top face of {casing} with cyanoacrylate, centred over the window (ShadowTac Sec. IV-B)."
        )));
        out.push(AssemblyStep::Text(format!(
            "Set the camera board ({}) into the bay of {casing} from below, the lens up through the ledge's bore, the LEDs' wires beside it.",
            c.camera.module
        )));
        if let Some(g) = &c.gripper_base {
            out.push(AssemblyStep::Text(format!(
                "Set {casing} into the socket of `gripper_base`, the camera's cable out through the slot on +y, and fasten it with 4 screws up through the base's counterbored holes into the casing's pilots; bolt the base to the {} with 4 bolts (ShadowTac Sec. IV-B: a base to mount the sensor on a robotic gripper).",
                g.gripper
            )));
        }
        out
    }
}

/// The casing family's parts and summary ([`CasingFamily`]'s build, each time computed).
fn build_family(
    ctx: &Context<'_>,
    c: &CasingParams,
    tol: ChordTolerance,
) -> Result<Built, DesignError> {
    let mut parts = vec![build_casing(ctx, c, tol)?];
    if let Some(g) = &c.gripper_base {
        parts.push(build_base(ctx, c, g, tol)?);
    }
    let lv = levels(ctx, c);
    let w = c
        .gripper_base
        .as_ref()
        .map_or([c.outer_width_mm; 2], |g| [g.width_mm, g.length_mm]);
    let mut summary = vec![("casing_levels", json!(&lv))];
    if let Some(b) = ctx.backing {
        summary.push((
            "camera_view",
            json!({
                "rim_crossing_radius_mm": plate_crossing_radius_mm(
                    ctx.body.rim_radius_mm(0.0),
                    lv.top_z_mm - lv.lens_z_mm,
                    b.thickness_mm,
                    PMMA_REFRACTIVE_INDEX,
                ),
                "window_radius_mm": c.window_diameter_mm / 2.0,
                "lens_z_mm": lv.lens_z_mm,
                "rule": "the ray from the lens's front (on the axis) to the skin's rim, refracted by the backing plate, crosses the casing's top inside the window",
            }),
        ));
    }
    summary.push(("envelope_mm", json!([w[0], w[1], lv.envelope_height_mm])));
    Ok(Built { parts, summary })
}

thread_local! {
    /// Each thread's last casing build with what it read: the variants of a sweep that leave
    /// the casing alone build it once per thread (about a tenth of a ShadowTac variant's work).
    static LAST_BUILT: std::cell::RefCell<Option<(String, Built)>> =
        const { std::cell::RefCell::new(None) };
}
