//! The flat housing's rules ([`super::FlatHousingFamily`]'s `check`): the sizes and what fits
//! in what, each by its path under `flat_housing.`, then the housing against the skin.

use super::{CableChannel, CableSlot, CameraPocket, FlatHousingParams, IsolationRing, MAX_HOLES};
use crate::error::ParamError;
use crate::geometry::ChordTolerance;
use crate::parts::channels::FlatLayer;
use crate::parts::check_above_zero;
use crate::profile::FlatOutline;

/// The rules under one path prefix: [`Rules::check`] pushes the error at `prefix + path` when
/// its rule fails.
struct Rules<'a> {
    prefix: &'static str,
    errs: &'a mut Vec<ParamError>,
}

impl Rules<'_> {
    fn check(&mut self, path: &str, value: f64, ok: bool, text: String) {
        if !ok {
            self.errs.push(ParamError::new(
                format!("{}{path}", self.prefix),
                value,
                text,
            ));
        }
    }
}

/// The rules that need no skin: sizes, and what fits in what.
pub(super) fn check_sizes(p: &FlatHousingParams, errs: &mut Vec<ParamError>) {
    if check_above_zero("flat_housing.", p, &[], errs) {
        return;
    }
    let mut rule = Rules {
        prefix: "flat_housing.",
        errs,
    };
    let s = &p.shell;
    let o = &s.outline;
    let short = o.width_mm.min(o.length_mm);
    let mut outline_errs = o.errors("flat_housing.shell.outline.");
    let outline_ok = outline_errs.is_empty();
    rule.check(
        "shell.wall_mm",
        s.wall_mm,
        2.0 * s.wall_mm < short,
        format!(
            "must leave a chamber: below half the outline's shorter side ({} mm)",
            short / 2.0
        ),
    );
    let c = p.chamber();
    let c_short = c.width_mm.min(c.length_mm);
    rule.check(
        "shell.chamber_corner_radius_mm",
        s.chamber_corner_radius_mm,
        (0.0..c_short / 2.0).contains(&s.chamber_corner_radius_mm) || c_short <= 0.0,
        format!(
            "must be 0 or more and below half the chamber's shorter side ({} mm)",
            c_short / 2.0
        ),
    );
    rule.check(
        "shell.chamber_depth_mm",
        s.chamber_depth_mm,
        s.chamber_depth_mm + s.plate_mm < s.height_mm,
        format!("must leave room for the camera pocket: the chamber and the plate ({} mm) below the height ({} mm)", s.chamber_depth_mm + s.plate_mm, s.height_mm),
    );
    rule.check(
        "shell.collar.inner_mm",
        s.collar.inner_mm,
        s.collar.inner_mm > s.aperture_mm,
        format!(
            "must be above the aperture ({} mm): the window rests on the collar round it",
            s.aperture_mm
        ),
    );
    let collar_out = s.collar.inner_mm + 2.0 * s.collar.width_mm;
    rule.check(
        "shell.collar.width_mm",
        s.collar.width_mm,
        collar_out <= c_short,
        format!("must keep the collar ({collar_out} mm across) within the chamber's shorter side ({c_short} mm)"),
    );
    rule.check(
        "shell.collar.height_mm",
        s.collar.height_mm,
        s.collar.height_mm < s.chamber_depth_mm,
        format!(
            "must be below the chamber's depth ({} mm): the window lies on it",
            s.chamber_depth_mm
        ),
    );
    let depth = p.pocket_depth_mm();
    let f = s.ceiling_fillet_mm;
    let f_max = if s.chamber_corner_radius_mm > 0.0 {
        depth.min(s.chamber_corner_radius_mm)
    } else {
        depth
    };
    rule.check(
        "shell.ceiling_fillet_mm",
        f,
        f >= 0.0 && f < depth && f <= f_max,
        format!("must be 0 or more, below the camera pocket's depth ({depth:.3} mm) and at most the chamber's corner radius ({} mm)", s.chamber_corner_radius_mm),
    );
    let sc = &p.screws;
    rule.check(
        "screws.insert_depth_mm",
        sc.insert_depth_mm,
        sc.insert_depth_mm <= depth,
        format!("must be at most the camera pocket's depth ({depth:.3} mm): the boss stops at the plate"),
    );
    rule.check(
        "screws.insert_diameter_mm",
        sc.insert_diameter_mm,
        sc.insert_diameter_mm < 2.0 * s.boss_radius_mm,
        format!(
            "must be below the boss's diameter ({} mm)",
            2.0 * s.boss_radius_mm
        ),
    );
    rule.check(
        "screws.counterbore_diameter_mm",
        sc.counterbore_diameter_mm,
        sc.counterbore_diameter_mm > sc.clearance_diameter_mm,
        format!(
            "must be above the clearance hole ({} mm)",
            sc.clearance_diameter_mm
        ),
    );
    rule.check(
        "screws.counterbore_depth_mm",
        sc.counterbore_depth_mm,
        sc.counterbore_depth_mm < p.base.thickness_mm,
        format!(
            "must be below the base's thickness ({} mm)",
            p.base.thickness_mm
        ),
    );
    holes_within(
        "screws.xy_mm",
        &sc.xy_mm,
        s.boss_radius_mm.max(sc.counterbore_diameter_mm / 2.0),
        o,
        outline_ok,
        "its boss and counterbore",
        errs,
    );
    errs.append(&mut outline_errs);
    if let Some(slot) = &s.cable_slot {
        check_slot(slot, &c, depth, errs);
    }
    check_base(p, errs);
    if let Some(r) = &p.isolation_ring {
        check_ring(p, r, errs);
    }
    let w = p.window_outline();
    if !(w.width_mm > 0.0 && w.length_mm > 0.0) || p.window.clearance_mm < 0.0 {
        errs.push(ParamError::new(
            "flat_housing.window.clearance_mm",
            p.window.clearance_mm,
            format!("must be 0 or more and leave a window: below half the chamber's shorter side ({} mm)", c_short / 2.0),
        ));
    }
}

/// Each of `xy` (under `flat_housing.<path>`) at most `MAX_HOLES`, each a circle of `r_mm`
/// within `outline`.
fn holes_within(
    path: &str,
    xy: &[[f64; 2]],
    r_mm: f64,
    outline: &FlatOutline,
    outline_ok: bool,
    what: &str,
    errs: &mut Vec<ParamError>,
) {
    if xy.is_empty() || xy.len() > MAX_HOLES {
        errs.push(ParamError::new(
            format!("flat_housing.{path}"),
            xy.len(),
            format!("must give 1 to {MAX_HOLES} places"),
        ));
        return;
    }
    if !outline_ok {
        return;
    }
    for (i, q) in xy.iter().enumerate() {
        if outline.inset_mm(*q) < r_mm - 1e-9 {
            errs.push(ParamError::new(
                format!("flat_housing.{path}[{i}]"),
                format!("[{}, {}]", q[0], q[1]),
                format!("must keep {what} ({r_mm} mm radius) within the shell's outline"),
            ));
        }
    }
}

/// The cable slot's rules: within the wall's width and the pocket's depth, its corners
/// leaving every edge.
fn check_slot(slot: &CableSlot, chamber: &FlatOutline, depth: f64, errs: &mut Vec<ParamError>) {
    let mut rule = Rules {
        prefix: "flat_housing.shell.cable_slot.",
        errs,
    };
    let free = chamber.width_mm - 2.0 * chamber.corner_radius_mm;
    rule.check(
        "width_mm",
        slot.width_mm,
        slot.width_mm < free,
        format!("must lie in the straight of the +y wall: below {free} mm"),
    );
    rule.check(
        "above_bottom_mm",
        slot.above_bottom_mm,
        slot.above_bottom_mm >= 0.0 && slot.above_bottom_mm + slot.height_mm <= depth,
        format!("must be 0 or more, the slot's top ({} mm above the bottom) at most the camera pocket's depth ({depth:.3} mm)", slot.above_bottom_mm + slot.height_mm),
    );
    let c = slot.chamfer_mm;
    rule.check(
        "chamfer_mm",
        c,
        c >= 0.0 && c < slot.height_mm && 2.0 * c < slot.width_mm,
        format!(
            "must be 0 or more, below the height ({} mm) and half the width",
            slot.height_mm
        ),
    );
    let r_max = if c > 0.0 {
        0.5 * (slot.height_mm - c)
            .min(slot.width_mm - 2.0 * c)
            .min(c * std::f64::consts::SQRT_2)
    } else {
        0.5 * slot.height_mm.min(slot.width_mm)
    };
    rule.check(
        "corner_radius_mm",
        slot.corner_radius_mm,
        slot.corner_radius_mm >= 0.0 && slot.corner_radius_mm <= r_max,
        format!(
            "must be 0 or more and at most {r_max:.3} mm, so that every edge of the slot remains"
        ),
    );
}

/// The base's rules: its holes within its thickness, its bosses', posts' and pocket's sizes.
fn check_base(p: &FlatHousingParams, errs: &mut Vec<ParamError>) {
    let t = p.base.thickness_mm;
    let o = &p.shell.outline;
    let mut rule = Rules {
        prefix: "flat_housing.base.",
        errs,
    };
    if let Some(b) = &p.base.camera_bosses {
        rule.check(
            "camera_bosses.hole_diameter_mm",
            b.hole_diameter_mm,
            b.hole_diameter_mm < b.diameter_mm,
            format!("must be below the boss's diameter ({} mm)", b.diameter_mm),
        );
        rule.check(
            "camera_bosses.hole_floor_mm",
            b.hole_floor_mm,
            b.hole_floor_mm < t,
            format!("must be below the base's thickness ({t} mm)"),
        );
        rule.check(
            "camera_bosses.through_diameter_mm",
            b.through_diameter_mm,
            b.through_diameter_mm <= b.hole_diameter_mm,
            format!(
                "must be at most the hole's diameter ({} mm)",
                b.hole_diameter_mm
            ),
        );
    }
    if let Some(q) = &p.base.posts {
        rule.check(
            "posts.pin_diameter_mm",
            q.pin_diameter_mm,
            q.pin_diameter_mm < q.diameter_mm,
            format!("must be below the post's diameter ({} mm)", q.diameter_mm),
        );
        let f_max = (q.pin_diameter_mm / 2.0).min(q.pin_height_mm);
        rule.check(
            "posts.pin_fillet_mm",
            q.pin_fillet_mm,
            q.pin_fillet_mm >= 0.0 && q.pin_fillet_mm < f_max,
            format!("must be 0 or more and below the pin's radius and height ({f_max} mm)"),
        );
    }
    if let Some(k) = &p.base.camera_pocket {
        rule.check(
            "camera_pocket.depth_mm",
            k.depth_mm,
            k.depth_mm < t,
            format!("must be below the base's thickness ({t} mm)"),
        );
        rule.check(
            "camera_pocket.width_mm",
            k.width_mm,
            k.width_mm < o.width_mm - 2.0 * o.corner_radius_mm,
            format!(
                "must be below the outline's straight width ({} mm)",
                o.width_mm - 2.0 * o.corner_radius_mm
            ),
        );
        let edge = o.length_mm / 2.0;
        rule.check(
            "camera_pocket.y_mm[1]",
            k.y_mm[1],
            k.y_mm[1] > k.y_mm[0] && k.y_mm[0] > -edge && k.y_mm[1] < edge,
            format!(
                "must be above y_mm[0] ({}), the pocket within the outline (|y| below {edge} mm)",
                k.y_mm[0]
            ),
        );
        if let Some(ch) = &k.channel {
            check_channel(k, ch, edge, errs);
        }
    }
}

/// The cable channel's rules: its width within the pocket's, its ramp between the pocket's far
/// end and the edge, with room for a straight between the two arcs.
fn check_channel(k: &CameraPocket, ch: &CableChannel, edge: f64, errs: &mut Vec<ParamError>) {
    let mut rule = Rules {
        prefix: "flat_housing.base.camera_pocket.channel.",
        errs,
    };
    rule.check(
        "width_mm",
        ch.width_mm,
        ch.width_mm <= k.width_mm,
        format!("must be at most the pocket's width ({} mm)", k.width_mm),
    );
    let r_max = (k.width_mm - ch.width_mm) / 2.0;
    rule.check(
        "corner_radius_mm",
        ch.corner_radius_mm,
        ch.corner_radius_mm >= 0.0 && ch.corner_radius_mm <= r_max,
        format!(
            "must be 0 or more and at most half the pocket's width less the channel's ({r_max} mm)"
        ),
    );
    rule.check(
        "exit_depth_mm",
        ch.exit_depth_mm,
        ch.exit_depth_mm < k.depth_mm,
        format!("must be below the pocket's depth ({} mm)", k.depth_mm),
    );
    let [y0, y1] = ch.ramp_y_mm;
    rule.check(
        "ramp_y_mm[0]",
        y0,
        y0 >= k.y_mm[1] + ch.corner_radius_mm && y1 > y0 && y1 < edge,
        format!("must be at least the pocket's far end plus the corner radius ({} mm), below ramp_y_mm[1] ({y1} mm), which lies before the +y edge ({edge} mm)", k.y_mm[1] + ch.corner_radius_mm),
    );
    let [r1, r2] = ch.ramp_radii_mm;
    for (i, r) in [r1, r2].into_iter().enumerate() {
        rule.check(
            &format!("ramp_radii_mm[{i}]"),
            r,
            r > 0.0 && r.is_finite(),
            "must be above 0".into(),
        );
    }
    let rise = k.depth_mm - ch.exit_depth_mm;
    let (dy, dz) = (y1 - y0, rise - r1 - r2);
    let d = dy.hypot(dz);
    let rising = d > r1 + r2 && dz.atan2(dy) + ((r1 + r2) / d).asin() < std::f64::consts::FRAC_PI_2;
    rule.check(
        "ramp_radii_mm[0]",
        r1,
        !(r1 > 0.0 && r2 > 0.0) || rising,
        format!("with ramp_radii_mm[1] must leave a rising straight between the arcs: their sum below the distance of their centres ({d:.3} mm)"),
    );
}

/// The isolation ring's rules: it fits the aperture, its bore and countersink within it.
fn check_ring(p: &FlatHousingParams, r: &IsolationRing, errs: &mut Vec<ParamError>) {
    let a = p.shell.aperture_mm;
    let h = p.shell.plate_mm + p.shell.collar.height_mm;
    let mut rule = Rules {
        prefix: "flat_housing.isolation_ring.",
        errs,
    };
    rule.check(
        "outer_mm",
        r.outer_mm,
        r.outer_mm <= a,
        format!("must fit the aperture: at most {a} mm"),
    );
    rule.check(
        "bore_diameter_mm",
        r.bore_diameter_mm,
        r.bore_diameter_mm < r.outer_mm,
        format!("must be below the outer side ({} mm)", r.outer_mm),
    );
    let c_max = ((r.outer_mm - r.bore_diameter_mm) / 2.0).min(h);
    rule.check(
        "countersink_mm",
        r.countersink_mm,
        r.countersink_mm >= 0.0 && r.countersink_mm <= c_max && r.countersink_mm < h,
        format!("must be 0 or more, at most half the outer side less the bore and below the ring's height ({h} mm): at most {c_max} mm"),
    );
}

/// The rules between the housing and the skin: the skin lies within the shell's top face and
/// its innermost layer covers the chamber.
pub(super) fn check_skin(p: &FlatHousingParams, layers: &[FlatLayer], errs: &mut Vec<ParamError>) {
    let (Some(inner), Some(outer)) = (layers.first(), layers.last()) else {
        return;
    };
    let fine = ChordTolerance::new(0.001).expect("0.001 mm is a valid chord tolerance");
    let o = &p.shell.outline;
    if outer
        .outline
        .polygon(fine)
        .iter()
        .any(|q| o.inset_mm(*q) < -1e-9)
    {
        errs.push(ParamError::new(
            "flat_housing.shell.outline",
            format!("{} x {} mm, R{}", o.width_mm, o.length_mm, o.corner_radius_mm),
            format!(
                "must carry the skin: its outermost layer ({}, {} x {} mm, R{}) lies within the shell's top face",
                outer.name, outer.outline.width_mm, outer.outline.length_mm, outer.outline.corner_radius_mm
            ),
        ));
    }
    let c = p.chamber();
    if c.polygon(fine)
        .iter()
        .any(|q| inner.outline.inset_mm(*q) < -1e-9)
    {
        errs.push(ParamError::new(
            "flat_housing.shell.wall_mm",
            p.shell.wall_mm,
            format!(
                "must leave the chamber ({:.3} x {:.3} mm) under the skin's innermost layer ({}, {} x {} mm): the skin rests on the shell's rim round it",
                c.width_mm, c.length_mm, inner.name, inner.outline.width_mm, inner.outline.length_mm
            ),
        ));
    }
}
