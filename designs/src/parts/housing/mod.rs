//! The sensor shell (R-Tac0 Sec. III-B2..B4, Fig. 2), in one of two arrangements
//! (`housing.style`).
//!
//! Inside, from the top down in the sensor frame: the contact-module seat (a bore that takes
//! the part of the core below the base plane; the skin's base rests on the shell's top face,
//! the base plane), the diffuser seat whose floor carries the core's rim, the light chamber,
//! the LED ring PCB seat `gap_above_pcb_mm` (10 mm in the paper) under the diffuser, and the
//! camera under the PCB.
//!
//! - `round_tube` (the authors' CAD, measured: a round shell of 30 mm outer diameter, 21.65 mm
//!   from the base plane to its bottom, closed by a separate base that carries the camera; the
//!   diffuser is a 30 mm disc with a 19.6 mm opening): from the top, a collar that takes the
//!   core's end below the base plane, the diffuser disc (the core's rim rests on its inner edge),
//!   and the tube. The tube's light chamber is wide enough for the LED PCB to go in from the
//!   top; below the PCB the tube is bored out to the camera bay and the PCB rests on the ledge
//!   this leaves. The base is a flange under the tube with a spigot that enters the bay; the
//!   camera board is screwed onto the spigot, its cable leaves through a slot in the base, and
//!   two screws from below through the flange hold the base to the tube wall. The collar and
//!   the diffuser are glued onto the tube (fabkit's layout: the authors' base, bolts and
//!   collar are not published).
//! - `square_split`: a square shell with the camera bay open at the bottom (the board screws
//!   up against a bulkhead with the lens hole); the shell splits on the plane x = 0 into two
//!   halves joined by two screws across it.

mod family;
pub use family::HousingFamily;

mod checks;

use crate::error::{DesignError, GeometryContext, ParamError};
use crate::geometry::{cuboid, cylinder, ChordTolerance, Solid};
use crate::parts::context::Context;
use crate::parts::context::ResolvedCore;
use crate::parts::family::FamilyInput;
use crate::parts::placement::{place_posed, with_pose};
use crate::parts::{Part, PrintTechnology};
use crate::schema::shared::{FillingGel, GelFill};
pub use checks::check_housing_params;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The two-piece sensor shell (R-Tac0 Sec. III-B4, Fig. 2): camera bay, LED ring seat,
/// diffuser seat, contact-module seat. Two arrangements (`style`): a round tube closed by a
/// separate base that carries the camera (the authors' CAD), or a square shell split into
/// two halves on a plane through the axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HousingParams {
    /// Material key of the printed shell parts (printed FDM), a print material of the
    /// materials table (R-Tac0: black PLA, `pla_black`, Sec. III-B4).
    pub material: String,
    /// The arrangement of the shell; `square_split` when not given.
    #[serde(default)]
    pub style: HousingStyle,
    /// Side of the square shell (`square_split`) or outer diameter of the tube
    /// (`round_tube`), mm (R-Tac0 envelope 30 x 30 x 43 mm, Sec. III-B).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_width_mm: f64,
    /// The tube and its base; required with `style: round_tube`, unused otherwise.
    #[serde(default)]
    pub round_tube: Option<RoundTube>,
    /// The camera board and its bay under the LED PCB (R-Tac0 Sec. III-B3).
    pub camera: CameraBay,
    /// `square_split`: thickness along the axis of the bulkhead between the camera bay and the
    /// LED PCB's seat, mm, > 0; the lens hole goes through it and the board's mounting pilots
    /// go up into it. Unused with `round_tube` (the PCB rests on the bay's ledge), but still
    /// checked above 0.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bulkhead_thickness_mm: f64,
    /// The LED ring PCB (bought; R-Tac0 Sec. III-B2), LEDs up, its top face
    /// `diffuser.gap_above_pcb_mm` under the diffuser.
    pub led_pcb: LedPcb,
    pub diffuser: Diffuser,
    /// Diameter of the light chamber between the LED PCB and the diffuser, mm (`round_tube`:
    /// at least the LED PCB's seat, since the PCB goes in through it).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub light_chamber_diameter_mm: f64,
    /// Radial clearance around seated parts, mm.
    pub fit_clearance_mm: f64,
    /// The internal filling gel, cast into the assembled shell; none when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filling_gel: Option<FillingGel>,
    /// The two screws that join the shell: across the parting plane along x
    /// (`square_split`), or up through the base's flange into the tube wall (`round_tube`)
    /// (R-Tac0 Sec. III-B4: "small bolts").
    pub joint_screw: JointScrew,
}

/// How the sensor shell is arranged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum HousingStyle {
    /// A round tube (outer diameter `outer_width_mm`) holding the contact module, diffuser
    /// and LED PCB, closed at the bottom by a separate base that carries the camera; the base
    /// is screwed up into the tube wall (R-Tac0 authors' CAD, measured: a 30 mm tube 21.65 mm
    /// tall; the paper, Sec. III-B3: "The camera module is secured to the sensor base").
    RoundTube,
    /// A square shell split on the plane x = 0 into two halves joined by two screws across it;
    /// the camera bay is in the shell.
    #[default]
    SquareSplit,
}

/// The round shell (`housing.style: round_tube`), from the top down: a collar that takes the
/// core's end below the base plane, the diffuser disc, the tube (light chamber, LED PCB, camera
/// bay) and the base. Below the LED PCB the tube is bored out to `bay_diameter_mm`, and the PCB
/// rests on the ledge this leaves; the light chamber above is wide enough for the PCB to go in
/// from the tube's top. The base is a flange under the tube (as thick as
/// `joint_screw.clamp_length_mm`) with a spigot that enters the bay; the camera board is
/// screwed onto the spigot.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RoundTube {
    /// Height from the tube's bottom to the base plane (tube, diffuser and collar), mm, > 0.
    pub height_mm: f64,
    /// Bore of the camera bay under the LED PCB, mm; smaller than the LED PCB seat.
    pub bay_diameter_mm: f64,
    /// Height of the base's spigot inside the bay (the camera board rests on it), mm, > 0.
    pub base_spigot_height_mm: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CameraBay {
    /// Camera module name, for the fabrication sheet.
    pub module: String,
    /// Side of the square camera board, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub board_width_mm: f64,
    /// Height of the bay under the bulkhead (board + components), mm (`square_split`); with
    /// `round_tube`, the least height the board with its components needs between the base
    /// and the LED PCB.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bay_height_mm: f64,
    /// Hole in the bulkhead for the lens barrel, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lens_hole_diameter_mm: f64,
    /// Square pattern of the board's mounting holes, centre to centre, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub mount_hole_spacing_mm: f64,
    /// Pilot hole for the self-tapping mounting screws, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub mount_pilot_diameter_mm: f64,
    /// Height of the lens's front, taken as the camera's centre of projection, over the face
    /// the board is mounted by, mm, > 0: the base spigot's top (`round_tube`, the board's
    /// underside) or the bulkhead's underside (`square_split`, the board's top face). The
    /// front must sit in air under the optical path: below the filling gel's free surface,
    /// or the diffuser without a gel. Optional: without it the design places no lens, and
    /// the pin dome's default rings are not kept inside the camera's view.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub lens_height_mm: Option<f64>,
    /// Full view angle of the lens, degrees, in (0, 180); optional.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0, "exclusiveMaximum" = 180))]
    pub view_angle_deg: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LedPcb {
    /// Outer diameter of the ring PCB, mm, > 0; its seat is this plus `fit_clearance_mm` on
    /// each side and must keep the FDM minimum wall inside the shell.
    ///
    /// `round_tube`: the light chamber must pass it (the PCB goes in from the tube's top) and
    /// its seat must overhang the camera bay by at least one nozzle width, the ledge it rests
    /// on. `square_split`: above the lens hole, and the board's mounting pilots must lie
    /// outside its seat.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Diameter of the PCB's bore, mm, > 0: below the outer diameter and at least
    /// `camera.lens_hole_diameter_mm`, to pass the lens barrel.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inner_diameter_mm: f64,
    /// Thickness of the PCB along the axis, mm, > 0: the height of its seat under the light
    /// chamber.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// LEDs on the ring, for the bought-items list and the assembly steps (R-Tac0 Sec.
    /// III-B2: eight LUXEON 2835 white LEDs); no part's shape depends on it.
    pub led_count: u32,
}

/// The laser-cut diffuser (R-Tac0 Sec. III-B2): a ring whose inner edge carries the core's rim.
/// `round_tube`: a disc between the tube's top face and the collar, at most the shell's
/// diameter; `square_split`: a ring in a seat inside the shell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Diffuser {
    /// Outer diameter of the diffuser, mm, > 0: above the core's outer diameter plus twice
    /// `fit_clearance_mm` (the core's rim rests on it) and above `light_chamber_diameter_mm`.
    ///
    /// `round_tube`: at most `outer_width_mm` (R-Tac0 authors' CAD, measured: 30 mm, the
    /// shell's full diameter). `square_split`: its seat (this plus `fit_clearance_mm` on each
    /// side) must keep the FDM minimum wall inside the shell.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_diameter_mm: f64,
    /// Diameter of the diffuser's opening, mm, > 0: below its outer diameter and below the
    /// core's outer diameter, since the core's rim rests on its edge (R-Tac0 authors' CAD,
    /// measured: 19.6 mm under the 20 mm core). The filling gel, when given, fills it.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inner_diameter_mm: f64,
    /// Thickness of the diffuser along the axis (the frosted acrylic sheet it is laser-cut
    /// from), mm, > 0 (R-Tac0 authors' CAD, measured: 2 mm).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// Distance from the top of the LED PCB to the diffuser, mm (R-Tac0: 10 mm).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub gap_above_pcb_mm: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JointScrew {
    /// Diameter of the screw's clearance hole, mm, > 0: through the +x half (`square_split`)
    /// or the base's flange (`round_tube`). It names the screw's size in the bought-items
    /// list (R-Tac0: 2.2 mm for M2).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub clearance_diameter_mm: f64,
    /// Diameter of the pilot hole the screw is driven into, mm, at least the FDM printer's
    /// `min_hole_diameter_mm`: in the -x half (`square_split`) or up into the tube wall round
    /// the camera bay (`round_tube`, where the wall must hold it between two FDM minimum
    /// walls).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pilot_diameter_mm: f64,
    /// Diameter of the screw's head, mm, > 0. `square_split`: its counterbore in the +x half,
    /// which with the clearance hole must fit between the light chamber and the outer wall
    /// with FDM minimum walls; `round_tube`: the heads under the base's flange must stay
    /// inside the tube's outer diameter.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub head_diameter_mm: f64,
    /// Material clamped under the head, mm (`round_tube`: the thickness of the base's flange
    /// under the tube).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub clamp_length_mm: f64,
    /// Depth of the pilot hole in the other half (`round_tube`: up into the tube wall), mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub pilot_depth_mm: f64,
}

/// z levels of the shell, sensor frame, mm (bottom to top).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ShellLevels {
    /// Bottom of the sensor: of the shell (`square_split`) or of the base's flange
    /// (`round_tube`).
    pub bottom_z_mm: f64,
    /// Underside of the bulkhead (`square_split`); `round_tube` has no bulkhead (the PCB rests
    /// on the bay's ledge) and this equals `pcb_z_mm`.
    pub bulkhead_z_mm: f64,
    pub pcb_z_mm: f64,
    pub chamber_z_mm: f64,
    pub diffuser_z_mm: f64,
    pub seat_z_mm: f64,
    pub top_z_mm: f64,
    /// Bottom of the tube, where the base's flange meets it (`round_tube` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tube_bottom_z_mm: Option<f64>,
    /// Top of the base's spigot, on which the camera board rests (`round_tube` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base_top_z_mm: Option<f64>,
    /// Overall sensor height from the bottom to the skin's pole, mm.
    pub envelope_height_mm: f64,
}

/// The shell's z levels for `design` with its housing `h` and resolved core (sensor frame, mm):
/// what fixtures that hold the sensor (the pin dome's holder ring) are sized from.
pub fn levels(ctx: &Context<'_>, h: &HousingParams, core: &ResolvedCore) -> ShellLevels {
    let top = ctx.body.base_z_mm();
    let seat = top - core.below_base_mm;
    let diffuser = seat - h.diffuser.thickness_mm;
    let chamber = diffuser - h.diffuser.gap_above_pcb_mm;
    let pcb = chamber - h.led_pcb.thickness_mm;
    let (bulkhead, bottom, tube_bottom, base_top) = match round_tube(h) {
        Some(t) => {
            let tb = top - t.height_mm;
            (
                pcb,
                tb - h.joint_screw.clamp_length_mm,
                Some(tb),
                Some(tb + t.base_spigot_height_mm),
            )
        }
        None => {
            let b = pcb - h.bulkhead_thickness_mm;
            (b, b - h.camera.bay_height_mm, None, None)
        }
    };
    ShellLevels {
        bottom_z_mm: bottom,
        bulkhead_z_mm: bulkhead,
        pcb_z_mm: pcb,
        chamber_z_mm: chamber,
        diffuser_z_mm: diffuser,
        seat_z_mm: seat,
        top_z_mm: top,
        tube_bottom_z_mm: tube_bottom,
        base_top_z_mm: base_top,
        envelope_height_mm: ctx.body.pole_z_mm(0.0) - bottom,
    }
}

/// Height of the lens's front (sensor frame z, mm) with the shell's levels `lv`:
/// `camera.lens_height_mm` over the face the board is mounted by (the base spigot's top of a
/// round tube, the bulkhead's underside of a square shell); `None` when it is not given.
pub fn lens_front_z_mm(h: &HousingParams, lv: &ShellLevels) -> Option<f64> {
    let mount = lv.base_top_z_mm.unwrap_or(lv.bulkhead_z_mm);
    h.camera.lens_height_mm.map(|l| mount + l)
}

/// The tube parameters when the housing is a round tube (and they are given).
fn round_tube(h: &HousingParams) -> Option<&RoundTube> {
    match h.style {
        HousingStyle::RoundTube => h.round_tube.as_ref(),
        HousingStyle::SquareSplit => None,
    }
}

/// Cable slot through the round tube's base, under the camera board: 2 x 12 mm, long along y.
/// ASSUMPTION: the camera's flat cable is at most 11 mm wide (measure yours).
pub const CABLE_SLOT_XY_MM: [f64; 2] = [2.0, 12.0];

/// Radius of the round tube's joint screws (parallel to z, at azimuths 0 and 180 deg): the
/// middle of the tube wall around the camera bay, mm.
pub fn round_screw_radius_mm(h: &HousingParams, t: &RoundTube) -> f64 {
    0.5 * (t.bay_diameter_mm / 2.0 + h.outer_width_mm / 2.0)
}

/// y position of the joint screws (they run along x across the parting plane): centred
/// between the clearance hole's wall to the light chamber and the head's wall to the outside.
fn screw_y_mm(ctx: &Context<'_>, h: &HousingParams) -> f64 {
    let (lo, hi) = screw_y_range(ctx, h);
    0.5 * (lo + hi)
}

fn screw_y_range(ctx: &Context<'_>, h: &HousingParams) -> (f64, f64) {
    let m = ctx.printers.fdm.min_wall_mm;
    (
        h.light_chamber_diameter_mm / 2.0 + h.joint_screw.clearance_diameter_mm / 2.0 + m,
        h.outer_width_mm / 2.0 - h.joint_screw.head_diameter_mm / 2.0 - m,
    )
}

/// The two blind dowel holes in the shell's top face that key calibration fixtures (pin dome,
/// semi-dome holder) to the sensor in one orientation only: at two adjacent corners (azimuths
/// 45 and 135 deg), so no rotation of a square fixture by 90, 180 or 270 deg fits.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FixtureDowelHoles {
    pub diameter_mm: f64,
    pub depth_mm: f64,
    /// Hole centres in the sensor frame (x, y), mm; the holes go down from the base plane.
    pub positions_xy_mm: [[f64; 2]; 2],
}

/// Dowel hole diameter (a 2 mm printed peg with clearance), depth, and inset of the hole centre
/// from the two outer faces at the corner, mm.
const DOWEL_HOLE_DIAMETER_MM: f64 = 2.0;
const DOWEL_HOLE_DEPTH_MM: f64 = 3.0;
const DOWEL_INSET_MM: f64 = 1.8;

/// Where the fixture dowel holes of a housing are: at the square shell's corners
/// (`square_split`), or `None` for the round tube, whose top face lies wholly under the skin
/// (both are `outer_width_mm` across) and whose base is no wider, so it has no face to key a
/// fixture to: a fixture is then keyed to the user's mount.
pub fn fixture_dowel_holes(h: &HousingParams) -> Option<FixtureDowelHoles> {
    match h.style {
        HousingStyle::RoundTube => None,
        HousingStyle::SquareSplit => {
            let a = h.outer_width_mm / 2.0 - DOWEL_INSET_MM;
            Some(FixtureDowelHoles {
                diameter_mm: DOWEL_HOLE_DIAMETER_MM,
                depth_mm: DOWEL_HOLE_DEPTH_MM,
                positions_xy_mm: [[a, a], [-a, a]],
            })
        }
    }
}

/// Builds the shell in print orientation: the round tube (top face down) and its base
/// (flange down) for `round_tube`, the two halves (parting face down) for `square_split`.
///
/// # Errors
/// [`DesignError::Params`] when the design has no core to seat, [`DesignError::Geometry`]
/// if the kernel fails.
pub fn build_shell(
    h: &HousingParams,
    input: FamilyInput<'_>,
) -> Result<(Vec<Part>, ShellLevels), DesignError> {
    build_shell_parts(h, input).map_err(|e| e.from_params(&["housing".to_string()]))
}

fn build_shell_parts(
    h: &HousingParams,
    input: FamilyInput<'_>,
) -> Result<(Vec<Part>, ShellLevels), DesignError> {
    let FamilyInput { ctx, stack, tol } = input;
    let core = stack.core.as_ref().ok_or_else(|| {
        DesignError::Params(crate::error::ParamErrors(vec![ParamError::new(
            "housing",
            "given",
            "the housing seats a core",
        )]))
    })?;
    let lv = levels(ctx, h, core);
    match (h.style, &h.round_tube) {
        (HousingStyle::RoundTube, Some(t)) => build_round_tube(ctx, h, t, core, lv, tol),
        (HousingStyle::RoundTube, None) => {
            Err(DesignError::Params(crate::error::ParamErrors(vec![
                ParamError::new(
                    "housing.round_tube",
                    "missing",
                    "is required with housing.style = round_tube",
                ),
            ])))
        }
        (HousingStyle::SquareSplit, _) => build_square_split(ctx, h, core, lv, tol),
    }
}

/// The square shell's bores above the camera, from the LED PCB's level up: the
/// PCB pocket, the light chamber, the diffuser's seat and the contact module's seat (radius
/// `r_core_mm` plus the fit clearance), each overlapping the next by 0.01 mm so that their
/// union is clean. Sensor frame, mm.
fn upper_bores(
    h: &HousingParams,
    lv: &ShellLevels,
    r_core_mm: f64,
    tol: ChordTolerance,
) -> Result<Vec<Solid>, crate::geometry::GeometryError> {
    let c = h.fit_clearance_mm;
    let e = 0.01;
    let cyl =
        |r: f64, z0: f64, z1: f64| cylinder(z1 - z0, r, tol).map(|s| s.translate([0.0, 0.0, z0]));
    Ok(vec![
        cyl(
            h.led_pcb.outer_diameter_mm / 2.0 + c,
            lv.pcb_z_mm,
            lv.chamber_z_mm + e,
        )?,
        cyl(
            h.light_chamber_diameter_mm / 2.0,
            lv.chamber_z_mm,
            lv.diffuser_z_mm + e,
        )?,
        cyl(
            h.diffuser.outer_diameter_mm / 2.0 + c,
            lv.diffuser_z_mm,
            lv.seat_z_mm + e,
        )?,
        cyl(r_core_mm + c, lv.seat_z_mm, lv.top_z_mm + 1.0)?,
    ])
}

/// The round tube and its base (see the module docs).
fn build_round_tube(
    ctx: &Context<'_>,
    h: &HousingParams,
    t: &RoundTube,
    core: &ResolvedCore,
    lv: ShellLevels,
    tol: ChordTolerance,
) -> Result<(Vec<Part>, ShellLevels), DesignError> {
    let r_out = h.outer_width_mm / 2.0;
    let c = h.fit_clearance_mm;
    let r_core = ctx.body.rim_radius_mm(core.outer_offset_mm);
    let r_bay = t.bay_diameter_mm / 2.0;
    let tube_bottom = lv.tube_bottom_z_mm.unwrap_or(lv.bottom_z_mm);
    let base_top = lv.base_top_z_mm.unwrap_or(tube_bottom);
    let fdm = &ctx.printers.fdm;
    let cyl =
        |r: f64, z0: f64, z1: f64| cylinder(z1 - z0, r, tol).map(|s| s.translate([0.0, 0.0, z0]));
    let e = 0.01;
    let js = &h.joint_screw;
    let r_js = round_screw_radius_mm(h, t);
    let screws_xy = [[r_js, 0.0], [-r_js, 0.0]];

    // The tube, from its bottom up to the diffuser on its top face: the camera bay, then the
    // light chamber that the LED PCB goes down (overlapping by a hair so the union is clean).
    let g = |r: Result<Solid, _>| r.part("shell_tube");
    let mut cut = vec![
        g(cyl(r_bay, tube_bottom - 1.0, lv.pcb_z_mm + e))?,
        g(cyl(
            h.light_chamber_diameter_mm / 2.0,
            lv.pcb_z_mm,
            lv.diffuser_z_mm + 1.0,
        ))?,
    ];
    // Joint screw pilots, up into the tube wall from its bottom.
    let mut pilots = Vec::new();
    for [x, y] in screws_xy {
        pilots.push(g(cyl(
            js.pilot_diameter_mm / 2.0,
            tube_bottom - 1.0,
            tube_bottom + js.pilot_depth_mm,
        )
        .map(|p| p.translate([x, y, 0.0])))?);
    }
    cut.push(Solid::compose(&pilots));
    let tube = g(cyl(r_out, tube_bottom, lv.diffuser_z_mm))?
        .difference(&Solid::union_all(&cut).part("shell_tube")?)
        .part("shell_tube")?;

    // The collar on the diffuser: the seat of the core's end below the base plane.
    let gc = |r: Result<Solid, _>| r.part("shell_collar");
    let collar = gc(cyl(r_out, lv.seat_z_mm, lv.top_z_mm))?
        .difference(&gc(cyl(r_core + c, lv.seat_z_mm - 1.0, lv.top_z_mm + 1.0))?)
        .part("shell_collar")?;

    // The base: flange under the tube, spigot into the bay; camera pilots, cable slot and the
    // joint screws' clearance holes.
    let gb = |r: Result<Solid, _>| r.part("shell_base");
    let base = Solid::union_all(&[
        gb(cyl(r_out, lv.bottom_z_mm, tube_bottom))?,
        gb(cyl(r_bay - c, tube_bottom - e, base_top))?,
    ])
    .part("shell_base")?;
    let s = h.camera.mount_hole_spacing_mm / 2.0;
    let mount_xy = [[s, s], [-s, s], [-s, -s], [s, -s]];
    let mount_z = [lv.bottom_z_mm + fdm.min_wall_mm, base_top + 1.0];
    let mut holes = Vec::new();
    for [x, y] in mount_xy {
        holes.push(gb(cyl(
            h.camera.mount_pilot_diameter_mm / 2.0,
            mount_z[0],
            mount_z[1],
        )
        .map(|p| p.translate([x, y, 0.0])))?);
    }
    for [x, y] in screws_xy {
        holes.push(gb(cyl(
            js.clearance_diameter_mm / 2.0,
            lv.bottom_z_mm - 1.0,
            tube_bottom + 1.0,
        )
        .map(|p| p.translate([x, y, 0.0])))?);
    }
    let [sx, sy] = CABLE_SLOT_XY_MM;
    holes.push(gb(cuboid(
        [-sx / 2.0, -sy / 2.0, lv.bottom_z_mm - 1.0],
        [sx / 2.0, sy / 2.0, base_top + 1.0],
    ))?);
    let base = base
        .difference(&Solid::union_all(&holes).part("shell_base")?)
        .part("shell_base")?;

    let params = json!({
        "style": h.style,
        "levels": lv,
        "housing": h,
        "core_seat_radius_mm": r_core + c,
        "bay_radius_mm": r_bay,
        "spigot_radius_mm": r_bay - c,
        "joint_screws": {"xy_mm": screws_xy, "axis": "z",
            "pilot_z_mm": [tube_bottom - 1.0, tube_bottom + js.pilot_depth_mm],
            "clearance_z_mm": [lv.bottom_z_mm - 1.0, tube_bottom + 1.0]},
        "fixture_dowel_holes": null,
        "camera_mount_holes_xy_mm": mount_xy,
        "camera_mount_pilot_z_mm": mount_z,
        "cable_slot_xy_mm": CABLE_SLOT_XY_MM,
        // Each bore overlaps the next one up by this much (a hair, see above).
        "overlap_mm": e,
    });
    let part = |(solid, pose): (Solid, crate::geometry::Affine),
                name: &str,
                description: &str,
                orientation: &str| {
        let mut p = params.clone();
        if let Some(o) = p.as_object_mut() {
            o.insert("print_orientation".into(), json!(orientation));
        }
        Part {
            name: name.into(),
            role: name.into(),
            description: description.into(),
            material: h.material.clone(),
            print_technology: PrintTechnology::Fdm,
            solid,
            params: with_pose(p, &pose),
            group: None,
        }
    };
    let parts = vec![
        part(
            place_posed(&collar, &crate::geometry::rotation_deg(180.0, 0.0, 0.0)),
            "shell_collar",
            "Sensor shell: collar on the diffuser disc; the contact module's core seats in it and the skin rests on its top face",
            "top face down",
        ),
        part(
            place_posed(&tube, &crate::geometry::rotation_deg(180.0, 0.0, 0.0)),
            "shell_tube",
            "Sensor shell: round tube with the light chamber, the LED PCB's ledge and the camera bay; the diffuser disc lies on its top face and the base screws up into its wall",
            "top face down",
        ),
        part(
            place_posed(&base, &crate::geometry::Affine::identity()),
            "shell_base",
            "Sensor base: closes the tube and carries the camera board (4 pilots on its spigot); the camera cable leaves through its slot; 2 joint screws up through its flange into the tube",
            "flange down",
        ),
    ];
    Ok((parts, lv))
}

/// The two square halves (see the module docs).
fn build_square_split(
    ctx: &Context<'_>,
    h: &HousingParams,
    core: &ResolvedCore,
    lv: ShellLevels,
    tol: ChordTolerance,
) -> Result<(Vec<Part>, ShellLevels), DesignError> {
    let w = h.outer_width_mm / 2.0;
    let c = h.fit_clearance_mm;
    let r_core = ctx.body.rim_radius_mm(core.outer_offset_mm);
    let g = |r: Result<Solid, _>| r.part("shell");
    let shell = g(cuboid([-w, -w, lv.bottom_z_mm], [w, w, lv.top_z_mm]))?;
    let bw = h.camera.board_width_mm / 2.0 + c;
    let cyl =
        |r: f64, z0: f64, z1: f64| cylinder(z1 - z0, r, tol).map(|s| s.translate([0.0, 0.0, z0]));
    // Stacked internal cavities, each overlapping the next by a hair so the union is clean.
    let e = 0.01;
    let mut cut = vec![
        g(cuboid(
            [-bw, -bw, lv.bottom_z_mm - 1.0],
            [bw, bw, lv.bulkhead_z_mm],
        ))?,
        g(cyl(
            h.camera.lens_hole_diameter_mm / 2.0,
            lv.bulkhead_z_mm - e,
            lv.pcb_z_mm + e,
        ))?,
    ];
    cut.extend(upper_bores(h, &lv, r_core, tol).part("shell")?);
    let mut holes = Vec::new();
    // Camera board mounting pilots, up from the bay through the bulkhead into solid material.
    let s = h.camera.mount_hole_spacing_mm / 2.0;
    let pilot_depth = h.bulkhead_thickness_mm + 4.0;
    for (x, y) in [(s, s), (-s, s), (-s, -s), (s, -s)] {
        holes.push(g(cyl(
            h.camera.mount_pilot_diameter_mm / 2.0,
            lv.bulkhead_z_mm - 1.0,
            lv.bulkhead_z_mm + pilot_depth,
        )
        .map(|p| p.translate([x, y, 0.0])))?);
    }
    // Joint screws along x: counterbore and clearance in the +x half, pilot in the -x half.
    let js = &h.joint_screw;
    let y = screw_y_mm(ctx, h);
    let z = 0.5 * (lv.chamber_z_mm + lv.diffuser_z_mm);
    let along_x = |r: f64, x0: f64, x1: f64| {
        cylinder(x1 - x0, r, tol).map(|p| p.rotate_deg(0.0, 90.0, 0.0).translate([x0, 0.0, 0.0]))
    };
    let screw = Solid::union_all(&[
        g(along_x(js.pilot_diameter_mm / 2.0, -js.pilot_depth_mm, e))?,
        g(along_x(
            js.clearance_diameter_mm / 2.0,
            0.0,
            js.clamp_length_mm + e,
        ))?,
        g(along_x(
            js.head_diameter_mm / 2.0,
            js.clamp_length_mm,
            w + 1.0,
        ))?,
    ])
    .part("shell")?;
    for sy in [y, -y] {
        holes.push(screw.translate([0.0, sy, z]));
    }
    // Fixture dowel holes, down from the top face.
    let dowels = fixture_dowel_holes(h);
    if let Some(d) = &dowels {
        for [x, y] in d.positions_xy_mm {
            holes.push(g(cyl(
                d.diameter_mm / 2.0,
                lv.top_z_mm - d.depth_mm,
                lv.top_z_mm + 1.0,
            )
            .map(|p| p.translate([x, y, 0.0])))?);
        }
    }
    cut.push(Solid::compose(&holes));
    let body = shell
        .difference(&Solid::union_all(&cut).part("shell")?)
        .part("shell")?;
    let (pos, neg) = body.split_by_plane([1.0, 0.0, 0.0], 0.0);
    let params = json!({
        "style": h.style,
        "levels": lv,
        "housing": h,
        "core_seat_radius_mm": r_core + c,
        "parting_plane": "x = 0 (through the sensor axis)",
        "joint_screws": {"y_mm": [y, -y], "z_mm": z, "axis": "x"},
        "fixture_dowel_holes": dowels,
        "camera_mount_holes_xy_mm": [[s, s], [-s, s], [-s, -s], [s, -s]],
        "camera_mount_pilot_z_mm": [lv.bulkhead_z_mm - 1.0, lv.bulkhead_z_mm + pilot_depth],
        // Each internal cavity overlaps the next one up by this much (a hair, see above).
        "overlap_mm": e,
        "print_orientation": "parting face down",
    });
    let tech = PrintTechnology::Fdm;
    let part = |(solid, pose): (Solid, crate::geometry::Affine), tag: &str, what: &str| {
        Part {
        name: format!("shell_half_{tag}"),
        role: "shell_half".into(),
        description: format!("Sensor shell half {tag} ({what}); camera bay, LED PCB, diffuser and contact-module seats"),
        material: h.material.clone(),
        print_technology: tech,
        solid,
        params: with_pose(params.clone(), &pose),
        group: None,
    }
    };
    let parts = vec![
        part(
            place_posed(&pos, &crate::geometry::rotation_deg(0.0, -90.0, 0.0)),
            "a",
            "screw heads",
        ),
        part(
            place_posed(&neg, &crate::geometry::rotation_deg(0.0, 90.0, 0.0)),
            "b",
            "screw pilots",
        ),
    ];
    Ok((parts, lv))
}

/// How far the housing's filling gel reaches ([`FillingGel::fills`]; `chamber` when not given).
pub fn gel_fill(h: &HousingParams) -> Option<GelFill> {
    h.filling_gel
        .as_ref()
        .map(|f| f.fills.unwrap_or(GelFill::Chamber))
}

/// The height of the filling gel's flat free surface, sensor frame z, mm: the core's open end
/// (`fills: core`) or the LED PCB's face (`chamber`); `None` without a filling gel.
pub fn gel_free_surface_z_mm(h: &HousingParams, lv: &ShellLevels) -> Option<f64> {
    gel_fill(h).map(|f| match f {
        GelFill::Core => lv.seat_z_mm,
        GelFill::Chamber => lv.chamber_z_mm,
    })
}

/// The internal filling gel's region (R-Tac0 Sec. III-B1; [`crate::schema::FillingGel`]) as a
/// closed profile in the (r, z) half-plane of the sensor frame, mm: the inside of the core
/// down to its open end, then (`fills: chamber`) the diffuser's opening under it and the light
/// chamber down to the LED PCB's face, closed on the axis. The core's inner surface is
/// tessellated as the core's own (`tol` halved, as in the assembly), so the two share it.
pub fn filling_gel_profile(
    ctx: &Context<'_>,
    h: &HousingParams,
    core: &ResolvedCore,
    lv: &ShellLevels,
    tol: ChordTolerance,
) -> crate::geometry::Polyline2 {
    let mut pl = ctx
        .body
        .offset_polyline(core.inner_offset_mm, core.below_base_mm, tol.half());
    if gel_fill(h) == Some(GelFill::Core) {
        pl.push([0.0, lv.seat_z_mm]);
        return pl;
    }
    let (r_open, r_chamber) = (
        h.diffuser.inner_diameter_mm / 2.0,
        h.light_chamber_diameter_mm / 2.0,
    );
    for p in [
        [r_open, lv.seat_z_mm],
        [r_open, lv.diffuser_z_mm],
        [r_chamber, lv.diffuser_z_mm],
        [r_chamber, lv.chamber_z_mm],
        [0.0, lv.chamber_z_mm],
    ] {
        pl.push(p);
    }
    pl
}

/// The filling gel's volume from the exact surfaces, mm^3: the solid inside the core's inner
/// surface down to its open end, plus (`fills: chamber`) the cylinders of the diffuser's
/// opening and of the light chamber. LEDs and wires inside the chamber are not subtracted
/// (about 60 mm^3 for eight 2835 LEDs, covered by the pour's waste allowance).
pub fn filling_gel_volume_mm3(
    ctx: &Context<'_>,
    h: &HousingParams,
    core: &ResolvedCore,
    lv: &ShellLevels,
) -> f64 {
    let disc = |d: f64, height: f64| std::f64::consts::PI * d * d / 4.0 * height;
    let core_part = ctx
        .body
        .analytic_solid_volume_mm3(core.inner_offset_mm, core.below_base_mm);
    if gel_fill(h) == Some(GelFill::Core) {
        return core_part;
    }
    core_part
        + disc(
            h.diffuser.inner_diameter_mm,
            lv.seat_z_mm - lv.diffuser_z_mm,
        )
        + disc(
            h.light_chamber_diameter_mm,
            lv.diffuser_z_mm - lv.chamber_z_mm,
        )
}

/// The joint screws of a housing by standard size and length (`M2 x 6`): the longest standard
/// length within the clamp length plus the pilot depth, less 0.5 mm.
pub fn joint_screw_name(h: &HousingParams) -> Option<String> {
    crate::parts::fasteners::screw_name(
        h.joint_screw.clearance_diameter_mm,
        h.joint_screw.clamp_length_mm + h.joint_screw.pilot_depth_mm - 0.5,
    )
}
