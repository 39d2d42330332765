//! The housing's rules: its sizes, walls and seats, the square shell's and the round tube's,
//! the core's seat and the lens (`housing.*` paths), each reporting every violation.

use super::{
    fixture_dowel_holes, gel_free_surface_z_mm, lens_front_z_mm, levels, round_screw_radius_mm,
    screw_y_range, HousingParams, HousingStyle, RoundTube, CABLE_SLOT_XY_MM,
};
use crate::error::ParamError;
use crate::parts::context::{Context, ResolvedCore};

/// Rules on the housing: parts fit inside each other and the walls print.
pub fn check_housing_params(
    ctx: &Context<'_>,
    h: &HousingParams,
    core: Option<&ResolvedCore>,
    errs: &mut Vec<ParamError>,
) {
    if !check_housing_sizes(h, errs) {
        return;
    }
    crate::parts::check_led_count(
        "housing.led_pcb.led_count",
        h.led_pcb.led_count,
        h.led_pcb.outer_diameter_mm,
        h.led_pcb.inner_diameter_mm,
        errs,
    );
    if let Some(v) = h.camera.view_angle_deg {
        if !(v > 0.0 && v < 180.0) {
            errs.push(ParamError::new(
                "housing.camera.view_angle_deg",
                v,
                "must be in (0, 180)",
            ));
        }
    }
    check_housing_walls(ctx, h, errs);
    check_housing_seats(ctx, h, errs);
    match h.style {
        HousingStyle::SquareSplit => check_square_split(ctx, h, errs),
        HousingStyle::RoundTube => check_round_tube(ctx, h, core, errs),
    }
    if let Some(core) = core {
        check_housing_core(ctx, h, core, errs);
    }
}

/// Rules on the housing's sizes alone: each length and diameter must be above 0 (all are
/// checked). Pushes its errors to `errs`; false when any failed, which ends the checks.
pub(super) fn check_housing_sizes(h: &HousingParams, errs: &mut Vec<ParamError>) -> bool {
    let errors_before = errs.len();
    let mut pos = |path: &str, v: f64| {
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(path, v, "must be above 0"));
        }
    };
    for (p, v) in [
        ("housing.outer_width_mm", h.outer_width_mm),
        ("housing.camera.board_width_mm", h.camera.board_width_mm),
        ("housing.camera.bay_height_mm", h.camera.bay_height_mm),
        (
            "housing.camera.lens_hole_diameter_mm",
            h.camera.lens_hole_diameter_mm,
        ),
        (
            "housing.camera.mount_hole_spacing_mm",
            h.camera.mount_hole_spacing_mm,
        ),
        (
            "housing.camera.mount_pilot_diameter_mm",
            h.camera.mount_pilot_diameter_mm,
        ),
        ("housing.bulkhead_thickness_mm", h.bulkhead_thickness_mm),
        (
            "housing.led_pcb.outer_diameter_mm",
            h.led_pcb.outer_diameter_mm,
        ),
        ("housing.led_pcb.thickness_mm", h.led_pcb.thickness_mm),
        (
            "housing.diffuser.outer_diameter_mm",
            h.diffuser.outer_diameter_mm,
        ),
        ("housing.diffuser.thickness_mm", h.diffuser.thickness_mm),
        (
            "housing.diffuser.inner_diameter_mm",
            h.diffuser.inner_diameter_mm,
        ),
        (
            "housing.led_pcb.inner_diameter_mm",
            h.led_pcb.inner_diameter_mm,
        ),
        (
            "housing.diffuser.gap_above_pcb_mm",
            h.diffuser.gap_above_pcb_mm,
        ),
        (
            "housing.light_chamber_diameter_mm",
            h.light_chamber_diameter_mm,
        ),
        (
            "housing.joint_screw.clearance_diameter_mm",
            h.joint_screw.clearance_diameter_mm,
        ),
        (
            "housing.joint_screw.pilot_diameter_mm",
            h.joint_screw.pilot_diameter_mm,
        ),
        (
            "housing.joint_screw.head_diameter_mm",
            h.joint_screw.head_diameter_mm,
        ),
        (
            "housing.joint_screw.clamp_length_mm",
            h.joint_screw.clamp_length_mm,
        ),
        (
            "housing.joint_screw.pilot_depth_mm",
            h.joint_screw.pilot_depth_mm,
        ),
    ] {
        pos(p, v);
    }
    errs.len() == errors_before
}

/// Rules on the housing's walls and clearances: `housing.fit_clearance_mm` at least half the
/// nozzle width, the minimum wall of printer profile `fdm` beside the camera bay and around the
/// LED PCB and diffuser seats (or, for the round tube, the diffuser no wider than the shell),
/// and the fixture dowel holes clear of the skin's footprint.
pub(super) fn check_housing_walls(
    ctx: &Context<'_>,
    h: &HousingParams,
    errs: &mut Vec<ParamError>,
) {
    let fdm = &ctx.printers.fdm;
    let half = h.outer_width_mm / 2.0;
    let c = h.fit_clearance_mm;
    let wall = |errs: &mut Vec<ParamError>, path: &str, value: f64, room: f64, what: &str| {
        if room < fdm.min_wall_mm {
            errs.push(ParamError::new(
                path,
                value,
                format!("leaves {room:.2} mm of wall {what}, below the minimum wall {} mm of printer profile 'fdm'", fdm.min_wall_mm),
            ));
        }
    };
    // Every seated part (core, LED PCB, camera board, the base's spigot) fits with this radial
    // clearance: together the two sides must pass one nozzle width.
    if c < fdm.xy_resolution_mm / 2.0 {
        errs.push(ParamError::new(
            "housing.fit_clearance_mm",
            c,
            format!(
                "the seated parts fit with this radial clearance; it must be at least half the nozzle width {} mm of printer profile 'fdm' ({} mm)",
                fdm.xy_resolution_mm,
                fdm.xy_resolution_mm / 2.0
            ),
        ));
    }
    if h.style == HousingStyle::SquareSplit {
        wall(
            errs,
            "housing.camera.board_width_mm",
            h.camera.board_width_mm,
            half - (h.camera.board_width_mm / 2.0 + c),
            "beside the camera bay",
        );
    }
    wall(
        errs,
        "housing.led_pcb.outer_diameter_mm",
        h.led_pcb.outer_diameter_mm,
        half - (h.led_pcb.outer_diameter_mm / 2.0 + c),
        "around the LED PCB seat",
    );
    if h.style == HousingStyle::SquareSplit {
        wall(
            errs,
            "housing.diffuser.outer_diameter_mm",
            h.diffuser.outer_diameter_mm,
            half - (h.diffuser.outer_diameter_mm / 2.0 + c),
            "around the diffuser seat",
        );
    } else if h.diffuser.outer_diameter_mm > h.outer_width_mm {
        errs.push(ParamError::new(
            "housing.diffuser.outer_diameter_mm",
            h.diffuser.outer_diameter_mm,
            format!(
                "must not exceed the shell's diameter (housing.outer_width_mm = {}): the disc lies between the tube and the collar",
                h.outer_width_mm
            ),
        ));
    }
    if let Some(dowels) = fixture_dowel_holes(h) {
        let [dx, dy] = dowels.positions_xy_mm[0];
        let skin_r = ctx.body.rim_radius_mm(0.0);
        if (dx * dx + dy * dy).sqrt() - dowels.diameter_mm / 2.0 < skin_r + c {
            errs.push(ParamError::new(
                "housing.outer_width_mm",
                h.outer_width_mm,
                format!(
                    "too narrow for the fixture dowel holes at the corners: they would cut into the skin's footprint (radius {skin_r:.2} mm)"
                ),
            ));
        }
    }
}

/// Rules on the seated parts against each other: a ledge under the diffuser and (square split)
/// the LED PCB, the LED PCB's bore passing the lens barrel, inner diameters below outer ones,
/// the camera's mounting holes on its board, and the printed pilot holes at least the minimum
/// hole of printer profile `fdm`.
pub(super) fn check_housing_seats(
    ctx: &Context<'_>,
    h: &HousingParams,
    errs: &mut Vec<ParamError>,
) {
    let fdm = &ctx.printers.fdm;
    let ledge =
        |errs: &mut Vec<ParamError>, path: &str, v: f64, inner: f64, outer: f64, what: &str| {
            if inner >= outer {
                errs.push(ParamError::new(
                    path,
                    v,
                    format!(
                        "must be smaller than {what} ({outer:.2} mm) so it has a ledge to rest on"
                    ),
                ));
            }
        };
    ledge(
        errs,
        "housing.light_chamber_diameter_mm",
        h.light_chamber_diameter_mm,
        h.light_chamber_diameter_mm,
        h.diffuser.outer_diameter_mm,
        "the diffuser",
    );
    if h.style == HousingStyle::SquareSplit {
        ledge(
            errs,
            "housing.camera.lens_hole_diameter_mm",
            h.camera.lens_hole_diameter_mm,
            h.camera.lens_hole_diameter_mm,
            h.led_pcb.outer_diameter_mm,
            "the LED PCB",
        );
    }
    if h.led_pcb.inner_diameter_mm < h.camera.lens_hole_diameter_mm {
        errs.push(ParamError::new(
            "housing.led_pcb.inner_diameter_mm",
            h.led_pcb.inner_diameter_mm,
            format!(
                "must pass the lens barrel (housing.camera.lens_hole_diameter_mm = {})",
                h.camera.lens_hole_diameter_mm
            ),
        ));
    }
    for (path, inner, outer) in [
        (
            "housing.led_pcb.inner_diameter_mm",
            h.led_pcb.inner_diameter_mm,
            h.led_pcb.outer_diameter_mm,
        ),
        (
            "housing.diffuser.inner_diameter_mm",
            h.diffuser.inner_diameter_mm,
            h.diffuser.outer_diameter_mm,
        ),
    ] {
        if inner >= outer {
            errs.push(ParamError::new(
                path,
                inner,
                format!("must be below the outer diameter ({outer} mm)"),
            ));
        }
    }
    if h.camera.mount_hole_spacing_mm > h.camera.board_width_mm {
        errs.push(ParamError::new(
            "housing.camera.mount_hole_spacing_mm",
            h.camera.mount_hole_spacing_mm,
            "must fit on the camera board",
        ));
    }
    // each printed pilot hole under its own path
    for (path, d) in [
        (
            "housing.camera.mount_pilot_diameter_mm",
            h.camera.mount_pilot_diameter_mm,
        ),
        (
            "housing.joint_screw.pilot_diameter_mm",
            h.joint_screw.pilot_diameter_mm,
        ),
    ] {
        if d < fdm.min_hole_diameter_mm {
            errs.push(ParamError::new(
                path,
                d,
                format!(
                    "below the minimum hole {} mm of printer profile 'fdm'",
                    fdm.min_hole_diameter_mm
                ),
            ));
        }
    }
}

/// Rules on the split square shell (`housing.style: square_split`): the camera's mounting
/// pilots beside the LED PCB seat, and the joint screws (along x beside the light chamber) with
/// their counterbores and pilots inside the shell and under the diffuser.
pub(super) fn check_square_split(ctx: &Context<'_>, h: &HousingParams, errs: &mut Vec<ParamError>) {
    let fdm = &ctx.printers.fdm;
    let half = h.outer_width_mm / 2.0;
    let c = h.fit_clearance_mm;
    // Mount pilots stay in solid material beside the PCB seat and inside the outer wall.
    let r_mount = h.camera.mount_hole_spacing_mm / 2.0 * std::f64::consts::SQRT_2;
    if r_mount - h.camera.mount_pilot_diameter_mm / 2.0
        < h.led_pcb.outer_diameter_mm / 2.0 + c + fdm.min_wall_mm
    {
        errs.push(ParamError::new(
            "housing.camera.mount_hole_spacing_mm",
            h.camera.mount_hole_spacing_mm,
            "puts the board's mounting holes under the LED PCB seat",
        ));
    }
    // Joint screws run along x at y = +-screw_y beside the light chamber.
    let (lo, hi) = screw_y_range(ctx, h);
    if lo > hi {
        errs.push(ParamError::new(
            "housing.joint_screw.head_diameter_mm",
            h.joint_screw.head_diameter_mm,
            format!(
                "the joint screws do not fit between the light chamber and the outer wall with {} mm walls (short by {:.2} mm)",
                fdm.min_wall_mm,
                lo - hi
            ),
        ));
    }
    if h.joint_screw.clamp_length_mm + 1.0 > half {
        errs.push(ParamError::new(
            "housing.joint_screw.clamp_length_mm",
            h.joint_screw.clamp_length_mm,
            "leaves no room for the screw head counterbore",
        ));
    }
    if h.joint_screw.pilot_depth_mm > half - fdm.min_wall_mm {
        errs.push(ParamError::new(
            "housing.joint_screw.pilot_depth_mm",
            h.joint_screw.pilot_depth_mm,
            "runs through the far wall of the shell",
        ));
    }
    if h.diffuser.gap_above_pcb_mm
        < h.joint_screw
            .head_diameter_mm
            .max(h.joint_screw.clearance_diameter_mm)
            + 2.0 * fdm.min_wall_mm
    {
        errs.push(ParamError::new(
            "housing.diffuser.gap_above_pcb_mm",
            h.diffuser.gap_above_pcb_mm,
            "leaves no height for the joint screws beside the light chamber",
        ));
    }
}

/// Rules on the housing around the resolved core: the core's rim resting on the diffuser, the
/// shell fitting around the core, a hollow core for `housing.filling_gel`, and the core reaching
/// at least 1 mm below the base plane.
pub(super) fn check_housing_core(
    ctx: &Context<'_>,
    h: &HousingParams,
    core: &ResolvedCore,
    errs: &mut Vec<ParamError>,
) {
    let fdm = &ctx.printers.fdm;
    let half = h.outer_width_mm / 2.0;
    let c = h.fit_clearance_mm;
    let r_core = ctx.body.rim_radius_mm(core.outer_offset_mm);
    if r_core + c >= h.diffuser.outer_diameter_mm / 2.0 {
        errs.push(ParamError::new(
            "housing.diffuser.outer_diameter_mm",
            h.diffuser.outer_diameter_mm,
            format!("must exceed the core's outer diameter ({:.2} mm): the core's rim rests on the diffuser", 2.0 * r_core),
        ));
    }
    if h.diffuser.inner_diameter_mm >= 2.0 * r_core {
        errs.push(ParamError::new(
            "housing.diffuser.inner_diameter_mm",
            h.diffuser.inner_diameter_mm,
            format!("must be below the core's outer diameter ({:.2} mm): the core's rim rests on the diffuser", 2.0 * r_core),
        ));
    }
    if r_core + c + fdm.min_wall_mm > half {
        errs.push(ParamError::new(
            "housing.outer_width_mm",
            h.outer_width_mm,
            "does not fit around the core",
        ));
    }
    if h.filling_gel.is_some() && !ctx.body.offset_is_valid(core.inner_offset_mm) {
        errs.push(ParamError::new(
            "housing.filling_gel",
            "given",
            "needs a hollow core: the core's inner surface (its wall inside the outer surface) folds or vanishes",
        ));
    }
    check_lens(ctx, h, core, errs);
    if core.below_base_mm < 1.0 {
        errs.push(ParamError::new(
            "core.length_mm",
            ctx.core.map_or(0.0, |c| c.length_mm),
            "the core must reach at least 1 mm below the base plane to seat in the housing",
        ));
    }
}

/// Rules on the lens when it is placed, with the resolved core (which places the gel's free
/// surface): `camera.lens_height_mm` above 0 with the lens's front in air under the optical
/// path (below the filling gel's free surface, or the diffuser without a gel).
pub(super) fn check_lens(
    ctx: &Context<'_>,
    h: &HousingParams,
    core: &ResolvedCore,
    errs: &mut Vec<ParamError>,
) {
    let Some(l) = h.camera.lens_height_mm else {
        return;
    };
    if !(l > 0.0 && l.is_finite()) {
        errs.push(ParamError::new(
            "housing.camera.lens_height_mm",
            l,
            "must be above 0",
        ));
        return;
    }
    let lv = levels(ctx, h, core);
    let (limit, what) = match gel_free_surface_z_mm(h, &lv) {
        Some(z) => (z, "the filling gel's free surface"),
        None => (lv.diffuser_z_mm, "the diffuser's underside"),
    };
    if let Some(front) = lens_front_z_mm(h, &lv) {
        if front >= limit {
            errs.push(ParamError::new(
                "housing.camera.lens_height_mm",
                l,
                format!(
                    "puts the lens's front at z = {front:.2} mm, not below {what} (z = {limit:.2} mm): the camera looks from the air under it"
                ),
            ));
        }
    }
}

/// Rules on the round tube and its base (`housing.style: round_tube`).
pub(super) fn check_round_tube(
    ctx: &Context<'_>,
    h: &HousingParams,
    core: Option<&ResolvedCore>,
    errs: &mut Vec<ParamError>,
) {
    let Some(t) = &h.round_tube else {
        errs.push(ParamError::new(
            "housing.round_tube",
            "missing",
            "is required with housing.style = round_tube (height_mm, bay_diameter_mm, base_spigot_height_mm)",
        ));
        return;
    };
    let before = errs.len();
    for (path, v) in [
        ("housing.round_tube.height_mm", t.height_mm),
        ("housing.round_tube.bay_diameter_mm", t.bay_diameter_mm),
        (
            "housing.round_tube.base_spigot_height_mm",
            t.base_spigot_height_mm,
        ),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(path, v, "must be above 0"));
        }
    }
    if errs.len() > before {
        return;
    }
    check_round_tube_bay(ctx, h, t, errs);
    check_round_tube_heights(ctx, h, t, core, errs);
}

/// Rules on the camera bay of the round tube `t` (`housing.round_tube`): the ledge under the
/// LED PCB, the light chamber passing the LED PCB, the tube wall around the bay holding the
/// joint screw pilots, the camera board in the bay, and its mounting holes on the base's
/// spigot clear of the cable slot.
pub(super) fn check_round_tube_bay(
    ctx: &Context<'_>,
    h: &HousingParams,
    t: &RoundTube,
    errs: &mut Vec<ParamError>,
) {
    let fdm = &ctx.printers.fdm;
    let c = h.fit_clearance_mm;
    let r_out = h.outer_width_mm / 2.0;
    let r_bay = t.bay_diameter_mm / 2.0;
    let r_spigot = r_bay - c;
    let js = &h.joint_screw;
    // The PCB rests on the ledge between the bay and the PCB seat: at least one nozzle wide.
    let ledge = h.led_pcb.outer_diameter_mm / 2.0 + c - r_bay;
    if ledge < fdm.xy_resolution_mm {
        errs.push(ParamError::new(
            "housing.round_tube.bay_diameter_mm",
            t.bay_diameter_mm,
            format!(
                "leaves a ledge of {ledge:.2} mm under the LED PCB (seat diameter {:.2} mm), below one nozzle width {} mm of printer profile 'fdm'",
                h.led_pcb.outer_diameter_mm + 2.0 * c,
                fdm.xy_resolution_mm
            ),
        ));
    }
    // The LED PCB goes in from the tube's top, down the light chamber.
    if h.light_chamber_diameter_mm < h.led_pcb.outer_diameter_mm + 2.0 * c {
        errs.push(ParamError::new(
            "housing.light_chamber_diameter_mm",
            h.light_chamber_diameter_mm,
            format!(
                "must pass the LED PCB (housing.led_pcb.outer_diameter_mm = {}) with the fit clearance {c} mm: the PCB goes in from the tube's top",
                h.led_pcb.outer_diameter_mm
            ),
        ));
    }
    // The joint screw pilots go up into the tube wall around the bay.
    let wall = r_out - r_bay;
    let need = js.pilot_diameter_mm + 2.0 * fdm.min_wall_mm;
    if wall < need {
        errs.push(ParamError::new(
            "housing.round_tube.bay_diameter_mm",
            t.bay_diameter_mm,
            format!(
                "leaves {wall:.2} mm of tube wall around the camera bay; the joint screw pilots ({} mm) need {need:.2} mm with the minimum wall {} mm of printer profile 'fdm'",
                js.pilot_diameter_mm, fdm.min_wall_mm
            ),
        ));
    }
    let half_diag = h.camera.board_width_mm / std::f64::consts::SQRT_2;
    if half_diag + c > r_bay {
        errs.push(ParamError::new(
            "housing.camera.board_width_mm",
            h.camera.board_width_mm,
            format!(
                "the square board (diagonal {:.2} mm) does not fit the camera bay (housing.round_tube.bay_diameter_mm = {}) with the fit clearance {c} mm",
                2.0 * half_diag,
                t.bay_diameter_mm
            ),
        ));
    }
    let s = h.camera.mount_hole_spacing_mm / 2.0;
    let mp = h.camera.mount_pilot_diameter_mm / 2.0;
    if s * std::f64::consts::SQRT_2 + mp + fdm.min_wall_mm > r_spigot {
        errs.push(ParamError::new(
            "housing.camera.mount_hole_spacing_mm",
            h.camera.mount_hole_spacing_mm,
            format!("puts the board's mounting holes outside the base's spigot (radius {r_spigot:.2} mm) with the minimum wall {} mm", fdm.min_wall_mm),
        ));
    } else if s - mp - fdm.min_wall_mm < CABLE_SLOT_XY_MM[0] / 2.0 {
        errs.push(ParamError::new(
            "housing.camera.mount_hole_spacing_mm",
            h.camera.mount_hole_spacing_mm,
            format!(
                "puts the board's mounting holes into the base's cable slot ({} mm wide)",
                CABLE_SLOT_XY_MM[0]
            ),
        ));
    }
}

/// Rules on the round tube `t` (`housing.round_tube`) and its base along the sensor axis: the
/// joint screw heads inside the tube's diameter, the base's flange and the pilots' walls to the
/// light chamber and the tube's top face, room in the base's spigot for the camera board's
/// pilot holes, and (with a core) a camera bay between the spigot and the LED PCB.
pub(super) fn check_round_tube_heights(
    ctx: &Context<'_>,
    h: &HousingParams,
    t: &RoundTube,
    core: Option<&ResolvedCore>,
    errs: &mut Vec<ParamError>,
) {
    let fdm = &ctx.printers.fdm;
    let r_out = h.outer_width_mm / 2.0;
    let js = &h.joint_screw;
    let r_js = round_screw_radius_mm(h, t);
    if r_js + js.head_diameter_mm / 2.0 > r_out {
        errs.push(ParamError::new(
            "housing.joint_screw.head_diameter_mm",
            js.head_diameter_mm,
            format!(
                "the joint screw heads under the base (at radius {r_js:.2} mm) reach past the tube's outer diameter {} mm",
                h.outer_width_mm
            ),
        ));
    }
    if js.clamp_length_mm < fdm.min_wall_mm {
        errs.push(ParamError::new(
            "housing.joint_screw.clamp_length_mm",
            js.clamp_length_mm,
            format!(
                "is the thickness of the base's flange: below the minimum wall {} mm of printer profile 'fdm'",
                fdm.min_wall_mm
            ),
        ));
    }
    // Above the PCB's level the tube is bored out to the light chamber: a pilot that reaches
    // up there needs its wall to the chamber too.
    let pilot_top = t.height_mm - js.pilot_depth_mm;
    let pcb_below_top = core.map_or(0.0, |k| k.below_base_mm)
        + h.diffuser.thickness_mm
        + h.diffuser.gap_above_pcb_mm
        + h.led_pcb.thickness_mm;
    let to_chamber = r_js - js.pilot_diameter_mm / 2.0 - h.light_chamber_diameter_mm / 2.0;
    if pilot_top < pcb_below_top && to_chamber < fdm.min_wall_mm {
        errs.push(ParamError::new(
            "housing.joint_screw.pilot_depth_mm",
            js.pilot_depth_mm,
            format!(
                "reaches {:.2} mm above the LED PCB's underside, where {to_chamber:.2} mm of wall is left to the light chamber, below the minimum wall {} mm of printer profile 'fdm'",
                pcb_below_top - pilot_top,
                fdm.min_wall_mm
            ),
        ));
    }
    let tube_height = t.height_mm - core.map_or(0.0, |k| k.below_base_mm) - h.diffuser.thickness_mm;
    if js.pilot_depth_mm > tube_height - fdm.min_wall_mm {
        errs.push(ParamError::new(
            "housing.joint_screw.pilot_depth_mm",
            js.pilot_depth_mm,
            format!(
                "runs through the tube's top face (tube height {tube_height:.2} mm under the diffuser and the collar)"
            ),
        ));
    }
    let depth = js.clamp_length_mm + t.base_spigot_height_mm - fdm.min_wall_mm;
    if depth < h.camera.mount_pilot_diameter_mm {
        errs.push(ParamError::new(
            "housing.round_tube.base_spigot_height_mm",
            t.base_spigot_height_mm,
            format!(
                "leaves {depth:.2} mm for the camera board's pilot holes in the base, less than their diameter {} mm",
                h.camera.mount_pilot_diameter_mm
            ),
        ));
    }
    // The bay must exist for the shell to be built; whether the camera board with its
    // components fits in it (housing.camera.bay_height_mm) is the fit check's, which names both
    // parts and the overlap.
    if core.is_some() {
        let room = t.height_mm - pcb_below_top - t.base_spigot_height_mm;
        if room <= 0.0 {
            errs.push(ParamError::new(
                "housing.round_tube.height_mm",
                t.height_mm,
                format!(
                    "leaves no camera bay between the base's spigot and the LED PCB ({room:.2} mm)"
                ),
            ));
        }
    }
}
