//! The rules of the mold parameters (`mold`) and of the molds against their layers and the
//! printers.

use super::frame::MoldFrame;
use crate::error::ParamError;
use crate::parts::context::ResolvedCore;
use crate::parts::stack_input::StackInput;

/// Rules on mold parameters alone (sizes, printability).
pub fn check_mold_params(si: &StackInput<'_>, errs: &mut Vec<ParamError>) {
    let m = &si.mold;
    if !check_mold_sizes(si, errs) {
        return;
    }
    if m.plinth.reservoir_depth_mm >= m.plinth.height_mm {
        errs.push(ParamError::new(
            "mold.plinth.reservoir_depth_mm",
            m.plinth.reservoir_depth_mm,
            format!(
                "must be below mold.plinth.height_mm ({}) so the spigot can centre the holder",
                m.plinth.height_mm
            ),
        ));
    }
    check_mold_printability(si, errs);
}

/// Rules on the mold's sizes alone: lengths and diameters above 0 (all are checked),
/// clearances 0 or more, at least one vent, and `mold.draft_angle_deg` in [0, 10). Pushes its
/// errors to `errs`; false when a length or diameter is not above 0, which ends the checks.
fn check_mold_sizes(si: &StackInput<'_>, errs: &mut Vec<ParamError>) -> bool {
    let m = &si.mold;
    let mut pos = |path: &str, v: f64| {
        if !(v > 0.0 && v.is_finite()) {
            errs.push(ParamError::new(path, v, "must be above 0"));
            false
        } else {
            true
        }
    };
    let checks = [
        ("mold.wall_thickness_mm", m.wall_thickness_mm),
        ("mold.flange_width_mm", m.flange_width_mm),
        ("mold.plinth.margin_mm", m.plinth.margin_mm),
        ("mold.plinth.height_mm", m.plinth.height_mm),
        (
            "mold.plinth.reservoir_depth_mm",
            m.plinth.reservoir_depth_mm,
        ),
        (
            "mold.registration_key.diameter_mm",
            m.registration_key.diameter_mm,
        ),
        (
            "mold.clamp_bolt.clearance_diameter_mm",
            m.clamp_bolt.clearance_diameter_mm,
        ),
        ("mold.sprue.diameter_mm", m.sprue.diameter_mm),
        ("mold.vent.diameter_mm", m.vent.diameter_mm),
        (
            "mold.core_holder.flange_thickness_mm",
            m.core_holder.flange_thickness_mm,
        ),
        (
            "mold.core_holder.pin_length_mm",
            m.core_holder.pin_length_mm,
        ),
        ("mold.core_holder.min_wall_mm", m.core_holder.min_wall_mm),
        ("mold.silicone_wall_mm", m.silicone_wall_mm),
    ];
    let all_positive = checks.iter().fold(true, |ok, (p, v)| pos(p, *v) && ok);
    for (p, v) in [
        ("mold.cavity_clearance_mm", m.cavity_clearance_mm),
        (
            "mold.registration_key.clearance_mm",
            m.registration_key.clearance_mm,
        ),
        (
            "mold.core_holder.fit_clearance_mm",
            m.core_holder.fit_clearance_mm,
        ),
    ] {
        if !(v >= 0.0 && v.is_finite()) {
            errs.push(ParamError::new(p, v, "must be 0 or more"));
        }
    }
    if m.vent.count == 0 {
        errs.push(ParamError::new(
            "mold.vent.count",
            0,
            "at least one vent is needed to let air out of the cavity",
        ));
    }
    if !(0.0..10.0).contains(&m.draft_angle_deg) {
        errs.push(ParamError::new(
            "mold.draft_angle_deg",
            m.draft_angle_deg,
            "must be in [0, 10)",
        ));
    }
    all_positive
}

/// Rules on printability: each hole, wall and feature of the mold at least the minimum of the
/// printer profile of the part that carries it (the fixtures' for the sprue, vents and core
/// holder, the cavities' for the keys, bolt holes and walls), and `mold.flange_width_mm` wide
/// enough for the registration keys and clamp bolts with the minimum wall around them.
fn check_mold_printability(si: &StackInput<'_>, errs: &mut Vec<ParamError>) {
    let m = &si.mold;
    let fix = si.ctx.printers.get(m.fixture_print_technology);
    let cav = si.ctx.printers.get(m.cavity_print_technology);
    let fixture = format!("{:?}", m.fixture_print_technology).to_lowercase();
    let cavity = format!("{:?}", m.cavity_print_technology).to_lowercase();
    // Printability: every feature against the profile of the part that carries it.
    let below =
        |errs: &mut Vec<ParamError>, path: &str, v: f64, min: f64, what: &str, profile: &str| {
            if v < min {
                errs.push(ParamError::new(
                    path,
                    v,
                    format!("below the {what} {min} mm of printer profile '{profile}'"),
                ));
            }
        };
    below(
        errs,
        "mold.sprue.diameter_mm",
        m.sprue.diameter_mm,
        fix.min_hole_diameter_mm,
        "minimum hole",
        &fixture,
    );
    below(
        errs,
        "mold.vent.diameter_mm",
        m.vent.diameter_mm,
        fix.min_hole_diameter_mm,
        "minimum hole",
        &fixture,
    );
    below(
        errs,
        "mold.core_holder.min_wall_mm",
        m.core_holder.min_wall_mm,
        fix.min_wall_mm,
        "minimum wall",
        &fixture,
    );
    below(
        errs,
        "mold.registration_key.diameter_mm",
        m.registration_key.diameter_mm,
        cav.min_feature_mm,
        "minimum feature",
        &cavity,
    );
    below(
        errs,
        "mold.clamp_bolt.clearance_diameter_mm",
        m.clamp_bolt.clearance_diameter_mm,
        cav.min_hole_diameter_mm,
        "minimum hole",
        &cavity,
    );
    below(
        errs,
        "mold.wall_thickness_mm",
        m.wall_thickness_mm,
        cav.min_wall_mm,
        "minimum wall",
        &cavity,
    );
    if m.registration_key.diameter_mm
        + 2.0 * m.registration_key.clearance_mm
        + 2.0 * cav.min_wall_mm
        > m.flange_width_mm
        || m.clamp_bolt.clearance_diameter_mm + 2.0 * cav.min_wall_mm > m.flange_width_mm
    {
        errs.push(ParamError::new(
            "mold.flange_width_mm",
            m.flange_width_mm,
            "too narrow for the registration keys and clamp bolts with the printer's minimum wall around them",
        ));
    }
}

/// Rules that need the resolved core: does the holder fit between the core and the plinth.
/// `first_cavity_offset_mm` is the cavity of the innermost cast, the tightest one.
pub fn check_mold_fit(
    si: &StackInput<'_>,
    core: &ResolvedCore,
    first_cavity_offset_mm: f64,
    errs: &mut Vec<ParamError>,
) {
    let m = &si.mold;
    let ch = &m.core_holder;
    let f = MoldFrame::new(si, core, first_cavity_offset_mm + m.cavity_clearance_mm);
    let room = f.plinth_radius_mm
        - f.core_outer_radius_mm
        - 2.0 * ch.fit_clearance_mm
        - 2.0 * ch.min_wall_mm;
    if m.sprue.diameter_mm > room {
        errs.push(ParamError::new(
            "mold.sprue.diameter_mm",
            m.sprue.diameter_mm,
            format!(
                "does not fit between the core groove and the spigot edge of the core holder ({room:.2} mm of room); enlarge mold.plinth.margin_mm"
            ),
        ));
    }
    if m.vent.diameter_mm > room {
        errs.push(ParamError::new(
            "mold.vent.diameter_mm",
            m.vent.diameter_mm,
            format!("does not fit in the holder ({room:.2} mm of room)"),
        ));
    }
    // The sprue (azimuth 0) and the vents share the circle at equal steps of 360 / (count + 1)
    // deg; neighbouring holes must keep the holder's minimum wall between them. This also
    // bounds the count before any vent is built (10,000 vents once ran a minute into a mesh
    // error naming no parameter).
    let r_v = f.plinth_radius_mm - ch.fit_clearance_mm - ch.min_wall_mm - m.vent.diameter_mm / 2.0;
    let need = m.vent.diameter_mm.max(m.sprue.diameter_mm) + ch.min_wall_mm;
    if r_v > 0.0 && need > 0.0 && m.vent.count > 0 {
        // Most holes on the circle: a chord of `need` between neighbours.
        let max_holes = if need >= 2.0 * r_v {
            1.0
        } else {
            (std::f64::consts::PI / (need / (2.0 * r_v)).asin()).floor()
        };
        let max_vents = (max_holes - 1.0).max(0.0);
        if f64::from(m.vent.count) > max_vents {
            errs.push(ParamError::new(
                "mold.vent.count",
                m.vent.count,
                format!(
                    "at most {max_vents:.0} vents fit beside the sprue on the holder's vent circle ({:.2} mm across) with mold.core_holder.min_wall_mm ({}) between neighbouring holes",
                    2.0 * r_v,
                    ch.min_wall_mm
                ),
            ));
        }
    }
    if f.core_end_z_mm > f.spigot_top_z_mm - 1.0 {
        errs.push(ParamError::new(
            "core.length_mm",
            si.ctx.core.as_ref().map_or(0.0, |c| c.length_mm),
            format!(
                "the core must reach at least {:.3} mm below the base plane so the holder can seat it (1 mm below the spigot top)",
                f.base_z_mm - (f.spigot_top_z_mm - 1.0)
            ),
        ));
    }
    if f.core_inner_radius_mm - ch.fit_clearance_mm
        < si.ctx
            .printers
            .get(m.fixture_print_technology)
            .min_feature_mm
            / 2.0
    {
        errs.push(ParamError::new(
            "core.wall_thickness_mm",
            si.ctx.core.as_ref().map_or(0.0, |c| c.wall_thickness_mm),
            "leaves no room for the holder's centring pin inside the core",
        ));
    }
    if f.pin_top_z_mm(si) - f.core_end_z_mm < 1.0 {
        errs.push(ParamError::new(
            "mold.core_holder.pin_length_mm",
            ch.pin_length_mm,
            "the centring pin would be shorter than 1 mm inside the core's straight bore",
        ));
    }
}
