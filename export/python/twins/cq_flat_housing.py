"""CadQuery twins of a flat sensor's housing (designs/src/parts/flat_housing.rs): the shell, the
base and the isolation ring, from the part's manifest `params` (`flat_housing`, `part`).

Sensor frame of a flat skin: the shell's top face (the skin's base plane) at z = 0, x across the
outline's width, y along its length, the cable out through the +y wall. Surfaces are exact: the
camera pocket's ceiling fillet is its quarter-circle section swept along the walls and revolved
about the bosses and corners (as fabkit builds it: OCCT's own fillet of those edges fails where a
boss meets a wall); the base's corners beside the cable channel are OCCT's rolling-ball fillets of
the solid's edges, the cable slot's corners 2D fillets of its sketch, the channel's ramp exact
arcs tangent to a straight.
"""

from __future__ import annotations

import math

import cadquery as cq

from . import cq_common as C
from .cq_flat import outline_prism

ROLES = ("flat_shell", "flat_base", "isolation_ring")


def _chamber(p: dict) -> dict:
    s = p["shell"]
    o, t = s["outline"], float(s["wall_mm"])
    return {"width_mm": float(o["width_mm"]) - 2 * t, "length_mm": float(o["length_mm"]) - 2 * t,
            "corner_radius_mm": float(s["chamber_corner_radius_mm"])}


def shell(p: dict):
    s = p["shell"]
    h, d, pl = float(s["height_mm"]), float(s["chamber_depth_mm"]), float(s["plate_mm"])
    outer = outline_prism(s["outline"], -h, 0.0)
    ch = _chamber(p)
    body = C.cut(outer, [outline_prism(ch, -d, 1.0), outline_prism(ch, -h - 1.0, -d - pl)])
    c = s["collar"]
    ci = float(c["inner_mm"]) / 2
    co = ci + float(c["width_mm"])
    ch_h = float(c["height_mm"])
    collar = C.cut(C.box([-co, -co, -d - 0.5], [co, co, -d + ch_h]),
                   [C.box([-ci, -ci, -d - 1.0], [ci, ci, -d + ch_h + 1.0])])
    rb = float(s["boss_radius_mm"])
    bosses = [C.cylinder_z(rb, -h, -d - pl + 0.5, x, y) for x, y in p["screws"]["xy_mm"]]
    bosses = C.common(C.fuse(bosses[0], bosses[1:]), outer)
    body = C.fuse(body, [collar, bosses])
    f = float(s.get("ceiling_fillet_mm", 0.0))
    if f > 0:
        body = C.fuse(body, [C.common(_ceiling_fillet(p, f, -d - pl), outer)])
    a = float(s["aperture_mm"]) / 2
    sc = p["screws"]
    cuts = [C.box([-a, -a, -d - pl - 1.0], [a, a, -d + 1.0])]
    cuts += [C.cylinder_z(float(sc["insert_diameter_mm"]) / 2, -h - 1.0,
                          -h + float(sc["insert_depth_mm"]), x, y) for x, y in sc["xy_mm"]]
    if s.get("cable_slot"):
        cuts.append(_slot(p, s["cable_slot"]))
    return C.cut(body, cuts)


def _ceiling_fillet(p: dict, f: float, zc: float):
    """The camera pocket's ceiling fillet: its exact section (a quarter circle of radius f between
    the wall and the ceiling, sunk 0.5 mm into both) extruded along each straight of the wall and
    revolved about each corner's centre (within its quadrant) and each boss. (OCCT's own fillet of
    the ceiling's edges fails where a boss meets a wall.)"""
    ch = _chamber(p)
    hw, hl, rc = ch["width_mm"] / 2, ch["length_mm"] / 2, ch["corner_radius_mm"]
    k = math.sqrt(0.5)

    def section(t, sign):
        """The section's (t, z) points, t = wall + sign * (distance into the pocket)."""
        return [(t - sign * 0.5, zc + 0.5), (t - sign * 0.5, zc - f), (t, zc - f),
                (t + sign * f * (1 - k), zc - f * (1 - k)), (t + sign * f, zc),
                (t + sign * f, zc + 0.5)]

    pieces = []
    # the -y wall's straight, drawn in (y, z) on the YZ plane and extruded both ways along x,
    # then turned onto each wall
    for dist, length, turn in ((hl, 2 * (hw - rc), 0), (hw, 2 * (hl - rc), 90),
                               (hl, 2 * (hw - rc), 180), (hw, 2 * (hl - rc), 270)):
        if length <= 0:
            continue
        pts = section(-dist, 1.0)
        wp = cq.Workplane(cq.Plane(origin=(0, 0, 0), xDir=(0, 1, 0), normal=(1, 0, 0)))
        wp = (wp.moveTo(*pts[0]).lineTo(*pts[1]).lineTo(*pts[2])
              .threePointArc(pts[3], pts[4]).lineTo(*pts[5]).close())
        straight = wp.extrude(length / 2, both=True).val()
        pieces.append(straight.rotate(cq.Vector(0, 0, 0), cq.Vector(0, 0, 1), turn))

    def revolved(r_wall, sign):
        pts = section(r_wall, sign)
        arc = cq.Edge.makeThreePointArc(C.vec(*pts[2]), C.vec(*pts[3]), C.vec(*pts[4]))
        return C.revolve([arc], [pts[5], pts[0], pts[1]])

    if rc > 0:
        corner = revolved(rc, -1.0)
        for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
            cx, cy = sx * (hw - rc), sy * (hl - rc)
            lo = [min(cx, cx + sx * (rc + 1)), min(cy, cy + sy * (rc + 1)), zc - f - 1]
            hi = [max(cx, cx + sx * (rc + 1)), max(cy, cy + sy * (rc + 1)), zc + 1]
            pieces.append(C.common(corner.translate(cq.Vector(cx, cy, 0)), C.box(lo, hi)))
    boss = revolved(float(p["shell"]["boss_radius_mm"]), 1.0)
    for x, y in p["screws"]["xy_mm"]:
        pieces.append(boss.translate(cq.Vector(x, y, 0)))
    return C.fuse(pieces[0], pieces[1:])


def _slot(p: dict, slot: dict):
    """The cable slot's cutter through the +y wall: its (x, z) outline sketched on an XZ plane
    outside the wall, its corners filleted, cut in along -y past the wall."""
    s = p["shell"]
    hw, c = float(slot["width_mm"]) / 2, float(slot["chamfer_mm"])
    z0 = -float(s["height_mm"]) + float(slot["above_bottom_mm"])
    z1 = z0 + float(slot["height_mm"])
    if c > 0:
        pts = [(-hw, z0), (hw, z0), (hw, z1 - c), (hw - c, z1), (-hw + c, z1), (-hw, z1 - c)]
    else:
        pts = [(-hw, z0), (hw, z0), (hw, z1), (-hw, z1)]
    l2 = float(s["outline"]["length_mm"]) / 2
    depth = float(s["wall_mm"]) + 1.5
    # the XZ plane's normal is -y: local (x, y) is the sensor's (x, z)
    plane = cq.Plane(origin=(0, l2 + 1.0, 0), xDir=(1, 0, 0), normal=(0, -1, 0))
    sk = cq.Sketch().polygon(pts + [pts[0]])
    r = float(slot["corner_radius_mm"])
    if r > 0:
        sk = sk.vertices().fillet(r)
    return cq.Workplane(plane).placeSketch(sk).extrude(depth).val()


def base(p: dict):
    s, b, sc = p["shell"], p["base"], p["screws"]
    zt = -float(s["height_mm"])
    zb = zt - float(b["thickness_mm"])
    body = outline_prism(s["outline"], zb, zt)
    adds, cuts = [], []
    for x, y in sc["xy_mm"]:
        cuts.append(C.cylinder_z(float(sc["counterbore_diameter_mm"]) / 2, zb - 1.0,
                                 zb + float(sc["counterbore_depth_mm"]), x, y))
        cuts.append(C.cylinder_z(float(sc["clearance_diameter_mm"]) / 2, zb - 1.0, zt + 1.0, x, y))
    k = b.get("camera_bosses")
    if k:
        top = zt + float(k["height_mm"])
        for x, y in k["xy_mm"]:
            adds.append(C.cylinder_z(float(k["diameter_mm"]) / 2, zt - 0.5, top, x, y))
            cuts.append(C.cylinder_z(float(k["hole_diameter_mm"]) / 2,
                                     zb + float(k["hole_floor_mm"]), top + 1.0, x, y))
            cuts.append(C.cylinder_z(float(k["through_diameter_mm"]) / 2, zb - 1.0,
                                     zb + float(k["hole_floor_mm"]) + 0.5, x, y))
    q = b.get("posts")
    if q:
        for x, y in q["xy_mm"]:
            adds.append(_post(q, zt).translate(cq.Vector(x, y, 0)))
    if adds:
        body = C.fuse(body, adds)
    pocket = b.get("camera_pocket")
    if pocket:
        w = float(pocket["width_mm"]) / 2
        y0, y1 = (float(v) for v in pocket["y_mm"])
        cuts.append(C.box([-w, y0, zt - float(pocket["depth_mm"])], [w, y1, zt + 1.0]))
        if pocket.get("channel"):
            cuts.append(_channel(p, pocket, pocket["channel"]))
    body = C.cut(body, cuts)
    if pocket and pocket.get("channel") and float(pocket["channel"]["corner_radius_mm"]) > 0:
        # the base's two vertical edges where the pocket's far end meets the channel's sides
        hw = float(pocket["channel"]["width_mm"]) / 2
        yf = float(pocket["y_mm"][1])
        edges = [e for e in body.Edges()
                 if e.geomType() == "LINE"
                 and abs(abs(e.startPoint().x) - hw) < 1e-9 and abs(abs(e.endPoint().x) - hw) < 1e-9
                 and abs(e.startPoint().y - yf) < 1e-9 and abs(e.endPoint().y - yf) < 1e-9]
        body = body.fillet(float(pocket["channel"]["corner_radius_mm"]), edges)
    return body


def _post(q: dict, zt: float):
    """A post with its pin at x = y = 0 on the top face zt, the pin's top edge an exact arc."""
    r, rp, f = float(q["diameter_mm"]) / 2, float(q["pin_diameter_mm"]) / 2, float(q["pin_fillet_mm"])
    z1 = zt + float(q["height_mm"])
    z2 = z1 + float(q["pin_height_mm"])
    pts = [(0.0, zt - 0.5), (r, zt - 0.5), (r, z1), (rp, z1)]
    if f > 0:
        a = C.vec(rp, z2 - f)
        m = C.vec(rp - f + f * math.cos(math.pi / 4), z2 - f + f * math.sin(math.pi / 4))
        e = C.vec(rp - f, z2)
        arc = cq.Edge.makeThreePointArc(a, m, e)
        return C.revolve([arc], [(0.0, z2), (0.0, zt - 0.5), (r, zt - 0.5), (r, z1), (rp, z1)])
    return C.revolve_polyline(pts + [(rp, z2), (0.0, z2)])


def _channel(p: dict, pocket: dict, ch: dict):
    """The cable channel's cutter: its (y, z) profile (the floor, an arc up, the straight tangent
    to both arcs, an arc over to the exit level, out past the +y edge) on a YZ plane, extruded
    both ways along x by half its width."""
    s = p["shell"]
    zt = -float(s["height_mm"])
    edge = float(s["outline"]["length_mm"]) / 2
    floor = zt - float(pocket["depth_mm"])
    exit_z = zt - float(ch["exit_depth_mm"])
    y0, y1 = (float(v) for v in ch["ramp_y_mm"])
    r1, r2 = (float(v) for v in ch["ramp_radii_mm"])
    c1 = (y0, floor + r1)
    c2 = (y1, exit_z - r2)
    dy, dz = c2[0] - c1[0], c2[1] - c1[1]
    dist = math.hypot(dy, dz)
    ang = math.atan2(dz, dy) + math.asin((r1 + r2) / dist)
    t1 = (c1[0] + r1 * math.sin(ang), c1[1] - r1 * math.cos(ang))
    t2 = (c2[0] - r2 * math.sin(ang), c2[1] + r2 * math.cos(ang))
    mid = lambda c, r, a: (c[0] + r * math.cos(a), c[1] + r * math.sin(a))  # noqa: E731
    m1 = mid(c1, r1, -math.pi / 2 + ang / 2)
    m2 = mid(c2, r2, math.pi / 2 + ang / 2)
    ystart = float(pocket["y_mm"][1]) - 0.5
    wp = (cq.Workplane(cq.Plane(origin=(0, 0, 0), xDir=(0, 1, 0), normal=(1, 0, 0)))
          .moveTo(ystart, zt + 1.0).lineTo(ystart, floor).lineTo(y0, floor)
          .threePointArc(m1, t1).lineTo(*t2).threePointArc(m2, (y1, exit_z))
          .lineTo(edge + 1.0, exit_z).lineTo(edge + 1.0, zt + 1.0).close())
    return wp.extrude(float(ch["width_mm"]) / 2, both=True).val()


def ring(p: dict):
    s, r = p["shell"], p["isolation_ring"]
    z0 = -float(s["chamber_depth_mm"]) - float(s["plate_mm"])
    z1 = -float(s["chamber_depth_mm"]) + float(s["collar"]["height_mm"])
    a = float(r["outer_mm"]) / 2
    rb = float(r["bore_diameter_mm"]) / 2
    c = float(r["countersink_mm"])
    tools = [C.cylinder_z(rb, z0 - 1.0, z1 + 1.0)]
    if c > 0:
        tools.append(cq.Solid.makeCone(rb, rb + c + 1.0, c + 1.0, cq.Vector(0, 0, z1 - c),
                                       cq.Vector(0, 0, 1)))
    return C.cut(C.box([-a, -a, z0], [a, a, z1]), tools)


def twin(part: dict):
    """The twin of a flat housing's part (sensor frame), or None when `part` is not one."""
    if part["role"] not in ROLES:
        return None
    p = part["params"]["flat_housing"]
    return {"flat_shell": shell, "flat_base": base, "isolation_ring": ring}[part["role"]](p)
