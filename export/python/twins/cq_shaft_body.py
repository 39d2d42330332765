"""CadQuery twin of the dual-modal TacTip's body and its tip's bayonet fitting (Pestell et al.
Sec. III-A, Fig. 1), from the part's manifest `params`: levels, radii, the bayonet (sizes,
lug azimuths, ramp), the camera's pilots and the cable slot. The bayonet's bands are exact:
revolved for the lugs and entry grooves, swept along a helix for the ramped locking grooves."""

from __future__ import annotations

import math

import cadquery as cq

from . import cq_common as C

# how far a solid reaches into the one it is united with or cut from (OVERLAP_MM in
# designs/src/parts/shaft_body.rs; the parts' params also carry it)
OVERLAP_MM = 0.01


def _sector(r0: float, r1: float, a0: float, span: float, z0: float, z1: float):
    """The flat annular sector r0..r1, azimuth a0..a0 + span (radians), z0..z1."""
    pts = [cq.Vector(r0, 0, z0), cq.Vector(r1, 0, z0), cq.Vector(r1, 0, z1), cq.Vector(r0, 0, z1)]
    face = cq.Face.makeFromWires(cq.Wire.makePolygon(pts, close=True))
    s = cq.Solid.revolve(face, math.degrees(span), cq.Vector(0, 0, 0), cq.Vector(0, 0, 1))
    return s.rotate(cq.Vector(0, 0, 0), cq.Vector(0, 0, 1), math.degrees(a0))


def band(r0: float, r1: float, a0: float, a1: float, z0: float, z1: float, slope: float):
    """The annular sector r0..r1, azimuth a0..a1 (radians), whose z range z0..z1 at a0 moves by
    `slope` mm per radian of azimuth. Flat: revolved. Ramped: the flat sector over the whole z
    range cut down to a helical slab, the (r, z) rectangle swept along a helix (its Frenet
    frame turns the rectangle about z, as a revolve would). Made so, the band's cylindrical and
    end faces are exact cylinders and planes, which meet the entry grooves' faces cleanly."""
    span = a1 - a0
    if abs(slope) < 1e-12:
        return _sector(r0, r1, a0, span, z0, z1)
    lo, hi = min(z0, z0 + slope * span), max(z1, z1 + slope * span)
    sector = _sector(r0, r1, a0, span, lo - 1.0, hi + 1.0)
    # the slab reaches past the sector on every side: no coincident faces
    d = 0.05
    if slope < 0.0:
        # walked from a1 + d back to a0 - d the slab rises: a left-handed helix
        start, dz, left = a1 + d, slope * (span + d), True
    else:
        start, dz, left = a0 - d, -slope * d, False
    pts = [cq.Vector(r0 - 1.0, 0, z0 + dz), cq.Vector(r1 + 1.0, 0, z0 + dz),
           cq.Vector(r1 + 1.0, 0, z1 + dz), cq.Vector(r0 - 1.0, 0, z1 + dz)]
    helix = cq.Wire.makeHelix(2.0 * math.pi * abs(slope), abs(slope) * (span + 2.0 * d),
                              (r0 + r1) / 2.0, center=cq.Vector(0, 0, z0 + dz), lefthand=left)
    slab = cq.Solid.sweep(cq.Wire.makePolygon(pts, close=True), [], helix, makeSolid=True,
                          isFrenet=True)
    slab = slab.rotate(cq.Vector(0, 0, 0), cq.Vector(0, 0, 1), math.degrees(start))
    return C.common(sector, slab)


def lugs(b: dict, azimuths_deg: list, attach_radius_mm: float) -> list:
    """The lugs, locked, from lug_depth past the grooved surface back to `attach_radius_mm`."""
    r = b["spigot_radius_mm"]
    half = b["lug_width_mm"] / 2.0 / r
    z0 = b["lug_z_mm"] - b["lug_height_mm"] / 2.0
    r0, r1 = ((attach_radius_mm, r + b["lug_depth_mm"]) if b["outward"]
              else (r - b["lug_depth_mm"], attach_radius_mm))
    return [band(r0, r1, math.radians(a) - half, math.radians(a) + half, z0,
                 z0 + b["lug_height_mm"], 0.0) for a in azimuths_deg]


def grooves(b: dict, azimuths_deg: list) -> list:
    """Per lug the entry groove from the spigot's end (the cup's rim) down and the ramped
    locking groove."""
    r, c = b["spigot_radius_mm"], b["clearance_mm"]
    r0, r1 = ((r - 1.0, r + b["lug_depth_mm"] + c) if b["outward"]
              else (r - b["lug_depth_mm"] - c, r + 1.0))
    half = b["groove_width_mm"] / 2.0 / r
    lock = math.radians(b["lock_angle_deg"])
    h = b["lug_height_mm"] / 2.0 + c
    turn = -1.0 if b["clockwise"] else 1.0
    tan = math.tan(math.radians(b["ramp_deg"]))
    slope = -turn * r * tan
    out = []
    for a in azimuths_deg:
        a = math.radians(a)
        entry = a - turn * lock

        def z_at(az):
            return b["lug_z_mm"] + turn * r * tan * (a - az)

        a0, a1 = min(entry, a) - half, max(entry, a) + half
        out.append(band(r0, r1, a0, a1, z_at(a0) - h, z_at(a0) + h, slope))
        out.append(band(r0, r1, entry - half, entry + half, z_at(entry) - h,
                        b["spigot_end_z_mm"] + 1.0, 0.0))
    return out


def tip_fitting(params: dict):
    """The fitting, sensor frame: the skirt with the window's seat and the lip, and the lugs."""
    lv, r = params["levels"], params["radii"]
    ring = C.revolve_polyline([
        (r["skirt_bore_mm"], lv["fitting_bottom_z_mm"]),
        (r["fitting_outer_mm"], lv["fitting_bottom_z_mm"]),
        (r["fitting_outer_mm"], lv["skin_base_z_mm"]),
        (r["lip_inner_mm"], lv["skin_base_z_mm"]),
        (r["lip_inner_mm"], lv["lip_z_mm"]),
        (r["window_seat_mm"], lv["lip_z_mm"]),
        (r["window_seat_mm"], lv["shaft_top_z_mm"]),
        (r["skirt_bore_mm"], lv["shaft_top_z_mm"]),
    ])
    return C.fuse(ring, lugs(params["bayonet"], params["lug_azimuths_deg"],
                             r["skirt_bore_mm"] + params["overlap_mm"]))


def shaft_body(params: dict):
    """The body, sensor frame: base and shaft (with the mount's lugs on the base) less the LED ring's seat, the bore, the lens's
    hole, the board's pocket, the cable slot, the bayonet's grooves and the camera's pilots."""
    lv, r, sb = params["levels"], params["radii"], params["shaft_body"]
    e = params["overlap_mm"]
    cyl = C.cylinder_z
    body = C.fuse(cyl(r["base_outer_mm"], lv["bottom_z_mm"], lv["base_top_z_mm"]),
                  [cyl(r["shaft_outer_mm"], lv["base_top_z_mm"] - e, lv["shaft_top_z_mm"])])
    mp = params.get("mount")
    if mp:
        # the lugs that lock the base into the robot's mount
        body = C.fuse(body, lugs(mp["bayonet"], mp["lug_azimuths_deg"],
                                 mp["lug_attach_radius_mm"]))
    p = r["board_pocket_half_mm"]
    sw, sh = params["cable_slot_mm"][0] / 2.0, params["cable_slot_mm"][1]
    bottom = lv["bottom_z_mm"]
    cuts = [
        cyl(r["led_seat_mm"], lv["led_pcb_z_mm"], lv["shaft_top_z_mm"] + 1.0),
        cyl(r["shaft_bore_mm"], lv["base_top_z_mm"], lv["led_pcb_z_mm"] + e),
        cyl(r["lens_hole_mm"], lv["ceiling_z_mm"] - e, lv["base_top_z_mm"] + e),
        C.box([-p, -p, bottom - 1.0], [p, p, lv["ceiling_z_mm"]]),
        C.box([-sw, 0.0, bottom - 1.0], [sw, r["base_outer_mm"] + 1.0, bottom + sh]),
    ]
    cuts += grooves(params["bayonet"], params["lug_azimuths_deg"])
    cam = sb["camera"]
    for x, y in params["mount_holes_xy_mm"]:
        cuts.append(cyl(cam["mount_pilot_diameter_mm"] / 2.0, lv["ceiling_z_mm"] - e,
                        lv["ceiling_z_mm"] + cam["mount_pilot_depth_mm"], x, y))
    return C.cut(body, cuts)


def robot_mount(params: dict):
    """The robot mount, sensor frame: the plate with its counterbored bolt holes and locating
    pin hole, and the cup over it less its cable window and the bayonet's grooves."""
    mp, lv = params["mount"], params["levels"]
    m = mp["robot_mount"]
    e = OVERLAP_MM
    cyl = C.cylinder_z
    zb = lv["bottom_z_mm"]
    z0 = zb - m["plate_thickness_mm"]
    bore, outside = mp["bore_radius_mm"], mp["outside_radius_mm"]
    top = zb + m["cup_height_mm"]
    cup = C.cut(cyl(outside, zb - e, top), [cyl(bore, zb - 2.0 * e, top + 1.0)])
    w0, w1 = mp["window_azimuths_rad"]
    window = band(bore - 1.0, outside + 1.0, w0, w1, zb - 1.0, top + 1.0, 0.0)
    cup = C.cut(cup, [window] + grooves(mp["bayonet"], mp["lug_azimuths_deg"]))
    mount = C.fuse(cyl(outside, z0, zb), [cup])
    cuts = []
    for x, y in mp["bolt_xy_mm"]:
        cuts.append(cyl(m["bolt_clearance_diameter_mm"] / 2.0, z0 - 1.0, zb + 1.0, x, y))
        cuts.append(cyl(m["bolt_head_diameter_mm"] / 2.0, zb - m["bolt_head_depth_mm"], zb + 1.0,
                        x, y))
    px, py = mp["pin_xy_mm"]
    cuts.append(cyl(m["pin_hole_diameter_mm"] / 2.0, z0 - 1.0, z0 + m["pin_hole_depth_mm"],
                    px, py))
    return C.cut(mount, cuts)


def twin(part: dict):
    """The twin of a shaft-body family part (sensor frame), or None when `part` is not one."""
    builder = {"tip_fitting": tip_fitting, "shaft_body": shaft_body,
               "robot_mount": robot_mount}.get(part["role"])
    return builder(part["params"]) if builder else None
