//! The flat housing's solids in the sensor frame ([`super`]'s frame): the shell, the base and the
//! isolation ring, and the sweeps and profiles they are made of.

use super::{CableChannel, CableSlot, CameraPocket, FlatHousingParams, IsolationRing, Posts};
use crate::geometry::{
    cuboid, extrude, profile2d::push_arc, revolve, transform::from_columns, ChordTolerance,
    GeometryError, Polyline2, Solid,
};
use crate::parts::z_cylinder;

/// The shell, sensor frame: from its bottom face `z = -height_mm` up to its top face z = 0.
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn shell_solid(p: &FlatHousingParams, tol: ChordTolerance) -> Result<Solid, GeometryError> {
    let s = &p.shell;
    let (h, d, pl) = (s.height_mm, s.chamber_depth_mm, s.plate_mm);
    let outer = extrude(&[s.outline.polygon(tol)], -h, 0.0)?;
    let c = p.chamber().polygon(tol);
    let chamber = extrude(std::slice::from_ref(&c), -d, 1.0)?;
    let pocket = extrude(&[c], -h - 1.0, -d - pl)?;
    let ci = s.collar.inner_mm / 2.0;
    let co = ci + s.collar.width_mm;
    let ch = s.collar.height_mm;
    let collar = cuboid([-co, -co, -d - 0.5], [co, co, -d + ch])?
        .difference(&cuboid([-ci, -ci, -d - 1.0], [ci, ci, -d + ch + 1.0])?)?;
    let bosses = p
        .screws
        .xy_mm
        .iter()
        .map(|q| z_cylinder(s.boss_radius_mm, -h, -d - pl + 0.5, *q, tol))
        .collect::<Result<Vec<_>, _>>()?;
    let bosses = Solid::union_all(&bosses)?.intersection(&outer)?;
    let a = s.aperture_mm / 2.0;
    let mut cuts = vec![cuboid([-a, -a, -d - pl - 1.0], [a, a, -d + 1.0])?];
    for q in &p.screws.xy_mm {
        cuts.push(z_cylinder(
            p.screws.insert_diameter_mm / 2.0,
            -h - 1.0,
            -h + p.screws.insert_depth_mm,
            *q,
            tol,
        )?);
    }
    if let Some(slot) = &s.cable_slot {
        cuts.push(slot_solid(p, slot, tol)?);
    }
    let mut shell = outer
        .difference(&chamber)?
        .difference(&pocket)?
        .union(&collar)?
        .union(&bosses)?;
    if s.ceiling_fillet_mm > 0.0 {
        shell = shell.union(&ceiling_fillet(p, tol)?.intersection(&outer)?)?;
    }
    shell.difference(&Solid::union_all(&cuts)?)
}

/// The camera pocket's ceiling fillet, sensor frame: the fillet's section swept along each
/// straight of the pocket's wall, revolved about each corner's centre (within its quadrant)
/// and about each boss; each sunk half a millimetre into the wall and the plate so that the
/// union overlaps.
fn ceiling_fillet(p: &FlatHousingParams, tol: ChordTolerance) -> Result<Solid, GeometryError> {
    use std::f64::consts::{FRAC_PI_2, PI};
    let s = &p.shell;
    let f = s.ceiling_fillet_mm;
    let zc = -s.chamber_depth_mm - s.plate_mm;
    let c = p.chamber();
    let (hw, hl, rc) = (c.width_mm / 2.0, c.length_mm / 2.0, c.corner_radius_mm);
    // (t, z): t from the wall into the pocket
    let mut pl = Polyline2::default();
    pl.push([-0.5, zc + 0.5]);
    pl.push([-0.5, zc - f]);
    push_arc(&mut pl, [f, zc - f], f, PI, FRAC_PI_2, tol);
    pl.push([f, zc + 0.5]);
    let mut section = pl.points;
    if crate::parts::cut_part::ring_area_mm2(&section) < 0.0 {
        section.reverse();
    }
    let mut pieces = Vec::new();
    // the -y wall's straight, turned onto each wall: (distance, length, turn)
    for (dist, len, turn) in [
        (hl, 2.0 * (hw - rc), 0.0),
        (hw, 2.0 * (hl - rc), 90.0),
        (hl, 2.0 * (hw - rc), 180.0),
        (hw, 2.0 * (hl - rc), 270.0),
    ] {
        if len <= 0.0 {
            continue;
        }
        let straight =
            extrude(&[section.clone()], -len / 2.0, len / 2.0)?.transform(&from_columns(
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 0.0],
                [0.0, -dist, 0.0],
            ));
        pieces.push(straight.rotate_deg(0.0, 0.0, turn));
    }
    // (r, z) about an axis: the wall at r = r_wall, the pocket towards r + dir * t
    let revolved = |r_wall: f64, dir: f64| -> Result<Solid, GeometryError> {
        let mut pl = Polyline2::default();
        for q in &section {
            pl.push([r_wall + dir * q[0], q[1]]);
        }
        Solid::from_mesh(&revolve(&pl, tol)?)
    };
    if rc > 0.0 {
        let corner = revolved(rc, -1.0)?;
        for (sx, sy) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
            let (cx, cy) = (sx * (hw - rc), sy * (hl - rc));
            let quadrant = cuboid(
                [
                    cx.min(cx + sx * (rc + 1.0)),
                    cy.min(cy + sy * (rc + 1.0)),
                    zc - f - 1.0,
                ],
                [
                    cx.max(cx + sx * (rc + 1.0)),
                    cy.max(cy + sy * (rc + 1.0)),
                    zc + 1.0,
                ],
            )?;
            pieces.push(corner.translate([cx, cy, 0.0]).intersection(&quadrant)?);
        }
    }
    let boss = revolved(s.boss_radius_mm, 1.0)?;
    for q in &p.screws.xy_mm {
        pieces.push(boss.translate([q[0], q[1], 0.0]));
    }
    Solid::union_all(&pieces)
}

/// The cable slot's cutter through the +y wall, sensor frame.
fn slot_solid(
    p: &FlatHousingParams,
    slot: &CableSlot,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let (hw, c) = (slot.width_mm / 2.0, slot.chamfer_mm);
    let z0 = -p.shell.height_mm + slot.above_bottom_mm;
    let z1 = z0 + slot.height_mm;
    let corners = if c > 0.0 {
        vec![
            [-hw, z0],
            [hw, z0],
            [hw, z1 - c],
            [hw - c, z1],
            [-hw + c, z1],
            [-hw, z1 - c],
        ]
    } else {
        vec![[-hw, z0], [hw, z0], [hw, z1], [-hw, z1]]
    };
    let ring = rounded_convex(&corners, slot.corner_radius_mm, tol);
    // (x, z) drawn in the local (u, v) plane, extruded along w = -y through the wall
    let l2 = p.shell.outline.length_mm / 2.0;
    let local = extrude(&[ring], -l2 - 1.0, -(l2 - p.shell.wall_mm - 0.5))?;
    Ok(local.transform(&from_columns(
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, -1.0, 0.0],
        [0.0; 3],
    )))
}

/// The convex counter-clockwise polygon `corners` with every corner rounded to radius `r_mm`
/// (the polygon's inset by `r_mm` grown back by a disc of `r_mm`); `corners` itself when
/// `r_mm` is 0. Each arc within `tol`.
pub fn rounded_convex(corners: &[[f64; 2]], r_mm: f64, tol: ChordTolerance) -> Vec<[f64; 2]> {
    if r_mm <= 0.0 {
        return corners.to_vec();
    }
    let n = corners.len();
    let normal = |i: usize| {
        let (a, b) = (corners[i], corners[(i + 1) % n]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        [dy / len, -dx / len]
    };
    let mut pl = Polyline2::default();
    for (i, &v) in corners.iter().enumerate() {
        let (na, nb) = (normal((i + n - 1) % n), normal(i));
        let k = r_mm / (1.0 + na[0] * nb[0] + na[1] * nb[1]);
        let centre = [v[0] - k * (na[0] + nb[0]), v[1] - k * (na[1] + nb[1])];
        let a0 = na[1].atan2(na[0]);
        let mut a1 = nb[1].atan2(nb[0]);
        while a1 < a0 {
            a1 += 2.0 * std::f64::consts::PI;
        }
        push_arc(&mut pl, centre, r_mm, a0, a1, tol);
    }
    pl.points
}

/// The base, sensor frame: its plate from `z = -height - thickness` up to the shell's bottom
/// face, its bosses and posts above.
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn base_solid(p: &FlatHousingParams, tol: ChordTolerance) -> Result<Solid, GeometryError> {
    let b = &p.base;
    let zt = -p.shell.height_mm;
    let zb = zt - b.thickness_mm;
    let mut solid = extrude(&[p.shell.outline.polygon(tol)], zb, zt)?;
    let mut adds = Vec::new();
    let mut cuts = Vec::new();
    let sc = &p.screws;
    for q in &sc.xy_mm {
        cuts.push(z_cylinder(
            sc.counterbore_diameter_mm / 2.0,
            zb - 1.0,
            zb + sc.counterbore_depth_mm,
            *q,
            tol,
        )?);
        cuts.push(z_cylinder(
            sc.clearance_diameter_mm / 2.0,
            zb - 1.0,
            zt + 1.0,
            *q,
            tol,
        )?);
    }
    if let Some(k) = &b.camera_bosses {
        for q in &k.xy_mm {
            let top = zt + k.height_mm;
            adds.push(z_cylinder(k.diameter_mm / 2.0, zt - 0.5, top, *q, tol)?);
            cuts.push(z_cylinder(
                k.hole_diameter_mm / 2.0,
                zb + k.hole_floor_mm,
                top + 1.0,
                *q,
                tol,
            )?);
            cuts.push(z_cylinder(
                k.through_diameter_mm / 2.0,
                zb - 1.0,
                zb + k.hole_floor_mm + 0.5,
                *q,
                tol,
            )?);
        }
    }
    if let Some(q) = &b.posts {
        for xy in &q.xy_mm {
            adds.push(post_solid(q, zt, tol)?.translate([xy[0], xy[1], 0.0]));
        }
    }
    if !adds.is_empty() {
        solid = solid.union(&Solid::union_all(&adds)?)?;
    }
    if let Some(k) = &b.camera_pocket {
        cuts.push(cuboid(
            [-k.width_mm / 2.0, k.y_mm[0], zt - k.depth_mm],
            [k.width_mm / 2.0, k.y_mm[1], zt + 1.0],
        )?);
        if let Some(ch) = &k.channel {
            cuts.extend(channel_solids(p, k, ch, tol)?);
        }
    }
    solid.difference(&Solid::union_all(&cuts)?)
}

/// A post with its pin, standing on the base's top face `zt` at x = y = 0 (its foot sunk half
/// a millimetre into the plate so that the union overlaps).
fn post_solid(q: &Posts, zt: f64, tol: ChordTolerance) -> Result<Solid, GeometryError> {
    let (r, rp, f) = (
        q.diameter_mm / 2.0,
        q.pin_diameter_mm / 2.0,
        q.pin_fillet_mm,
    );
    let z1 = zt + q.height_mm;
    let z2 = z1 + q.pin_height_mm;
    let mut pl = Polyline2::default();
    pl.push([0.0, zt - 0.5]);
    pl.push([r, zt - 0.5]);
    pl.push([r, z1]);
    pl.push([rp, z1]);
    if f > 0.0 {
        push_arc(
            &mut pl,
            [rp - f, z2 - f],
            f,
            0.0,
            std::f64::consts::FRAC_PI_2,
            tol,
        );
    } else {
        pl.push([rp, z2]);
    }
    pl.push([0.0, z2]);
    Solid::from_mesh(&revolve(&pl, tol)?)
}

/// The cable channel's cutters, sensor frame: its ramped channel from the pocket's far end out
/// through the +y edge, and the rounding of the base's two corners between them.
fn channel_solids(
    p: &FlatHousingParams,
    k: &CameraPocket,
    ch: &CableChannel,
    tol: ChordTolerance,
) -> Result<Vec<Solid>, GeometryError> {
    let zt = -p.shell.height_mm;
    let edge = p.shell.outline.length_mm / 2.0;
    let floor = zt - k.depth_mm;
    let exit = zt - ch.exit_depth_mm;
    let [y0, y1] = ch.ramp_y_mm;
    let [r1, r2] = ch.ramp_radii_mm;
    // the (y, z) profile: the floor, the lower arc about c1, the straight, the upper arc
    // about c2, the exit level, closed above the top face
    let c1 = [y0, floor + r1];
    let c2 = [y1, exit - r2];
    let (dy, dz) = (c2[0] - c1[0], c2[1] - c1[1]);
    let dist = dy.hypot(dz);
    // the inner tangent: the straight's direction is the centres' turned by asin((r1 + r2) / d)
    let angle = dz.atan2(dy) + ((r1 + r2) / dist).asin();
    let mut pl = Polyline2::default();
    pl.push([k.y_mm[1] - 0.5, zt + 1.0]);
    pl.push([k.y_mm[1] - 0.5, floor]);
    let down = -std::f64::consts::FRAC_PI_2;
    push_arc(&mut pl, c1, r1, down, down + angle, tol);
    // the upper arc clockwise, from the straight's end down to its top point
    push_arc(
        &mut pl,
        c2,
        r2,
        std::f64::consts::FRAC_PI_2 + angle,
        std::f64::consts::FRAC_PI_2,
        tol,
    );
    pl.push([edge + 1.0, exit]);
    pl.push([edge + 1.0, zt + 1.0]);
    let mut ring = pl.points;
    ring.dedup();
    if crate::parts::cut_part::ring_area_mm2(&ring) < 0.0 {
        ring.reverse();
    }
    let hw = ch.width_mm / 2.0;
    // (y, z) drawn in the local (u, v) plane, extruded along w = x
    let channel = extrude(&[ring], -hw, hw)?.transform(&from_columns(
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0; 3],
    ));
    let mut out = vec![channel];
    let r = ch.corner_radius_mm;
    if r > 0.0 {
        for side in [-1.0, 1.0] {
            // the corner at (side * hw, y_far): the square r x r less the disc about its far
            // corner
            let x0 = side * hw;
            let mut pl = Polyline2::default();
            let cx = x0 + side * r;
            let cy = k.y_mm[1] + r;
            pl.push([x0, k.y_mm[1] - 0.01]);
            pl.push([cx, k.y_mm[1] - 0.01]);
            let (a0, a1) = if side > 0.0 {
                (-std::f64::consts::FRAC_PI_2, -std::f64::consts::PI)
            } else {
                (-std::f64::consts::FRAC_PI_2, 0.0)
            };
            push_arc(&mut pl, [cx, cy], r, a0, a1, tol);
            let mut ring = pl.points;
            ring.dedup();
            if crate::parts::cut_part::ring_area_mm2(&ring) < 0.0 {
                ring.reverse();
            }
            out.push(extrude(&[ring], floor, zt + 1.0)?);
        }
    }
    Ok(out)
}

/// The isolation ring, sensor frame: filling the aperture from the plate's underside up to the
/// collar's top, its countersink at the top.
///
/// # Errors
/// [`GeometryError`] if the kernel fails.
pub fn ring_solid(
    p: &FlatHousingParams,
    r: &IsolationRing,
    tol: ChordTolerance,
) -> Result<Solid, GeometryError> {
    let s = &p.shell;
    let z0 = -s.chamber_depth_mm - s.plate_mm;
    let z1 = -s.chamber_depth_mm + s.collar.height_mm;
    let a = r.outer_mm / 2.0;
    let block = cuboid([-a, -a, z0], [a, a, z1])?;
    let rb = r.bore_diameter_mm / 2.0;
    let c = r.countersink_mm;
    let mut pl = Polyline2::default();
    pl.push([0.0, z0 - 1.0]);
    pl.push([rb, z0 - 1.0]);
    pl.push([rb, z1 - c]);
    pl.push([rb + c + 1.0, z1 + 1.0]);
    pl.push([0.0, z1 + 1.0]);
    // turned by half a segment, so that no vertex of the bore's polygon touches a side when
    // the countersink reaches the outer side (9DTact's does)
    let n = tol.half().circle_segments(rb + c + 1.0) as f64;
    let bore = Solid::from_mesh(&revolve(&pl, tol)?)?.rotate_deg(0.0, 0.0, 180.0 / n);
    block.difference(&bore)
}
