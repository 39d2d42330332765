"""CadQuery twins of the calibration fixtures (R-Tac0 Sec. IV-A/B, Fig. 5 and 6; indenters of
issue 4): pin-hole dome and its pin, semi-dome holder and halves with their protrusions, and
the indenters. From a part's manifest `params` alone."""

from __future__ import annotations

import math

import cadquery as cq

from . import cq_common as C


def dome_shell(body: C.Body, d_in: float, d_out: float):
    """The shell between two offsets of the body surface, closed on the base plane."""
    zb = body.base_z()
    inner = [e for e in reversed(body.curve_edges(d_in))]
    outer = body.curve_edges(d_out)
    edges = list(outer) + [cq.Edge.makeLine(C.vec(body.rim_radius(d_out), zb),
                                            C.vec(body.rim_radius(d_in), zb))]
    edges += [cq.Edge.makeLine(e.endPoint(), e.startPoint()) if e.geomType() == "LINE" else
              _reversed(e) for e in inner]
    edges.append(cq.Edge.makeLine(C.vec(0.0, body.pole_z(d_in)), C.vec(0.0, body.pole_z(d_out))))
    face = cq.Face.makeFromWires(cq.Wire.assembleEdges(edges))
    return cq.Solid.revolve(face, 360.0, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1))


def _reversed(edge):
    """The same curve traversed the other way (arcs: through the same middle point)."""
    if edge.geomType() == "CIRCLE":
        return cq.Edge.makeThreePointArc(edge.endPoint(), edge.positionAt(0.5), edge.startPoint())
    return cq.Edge(edge.wrapped.Reversed())


def ring(r0, r1, z0, z1):
    return C.revolve_polyline([(r0, z0), (r1, z0), (r1, z1), (r0, z1)])


def base_dowel_holes(base: dict):
    d = base["dowel_hole_diameter_mm"] / 2.0
    z0 = base["bottom_z_mm"] - 1.0
    return [C.cylinder_z(d, z0, z0 + base["dowel_hole_depth_mm"] + 1.0, x, y)
            for x, y in base["dowel_xy_mm"]]


def pyramid(corners):
    """The pyramid with its apex at the origin and the base quad `corners` (mm)."""
    o = cq.Vector(0.0, 0.0, 0.0)
    c = [cq.Vector(*q) for q in corners]
    polys = [[o, c[0], c[1]], [o, c[1], c[2]], [o, c[2], c[3]], [o, c[3], c[0]],
             [c[0], c[3], c[2], c[1]]]
    faces = [cq.Face.makeFromWires(cq.Wire.makePolygon(p + [p[0]])) for p in polys]
    return cq.Solid.makeSolid(cq.Shell.makeShell(faces)).fix()


def groove(body: C.Body, g: dict):
    """The orientation groove: the band between two offsets of the body surface, within the
    pyramid from the origin through the groove's corners."""
    band = dome_shell(body, g["band_offsets_mm"][0], g["band_offsets_mm"][1])
    return C.common(band, pyramid(g["pyramid_corners_mm"]))


def pin_dome(params: dict):
    pd, base = params["pin_dome"], params["base"]
    body = C.Body(params["body"])
    d_in, d_out = params["shell_offsets_mm"]
    adds = [C.primitive(t) for t in base.get("tabs", [])]
    if base.get("ring", True):
        adds.append(ring(base["inner_radius_mm"], base["outer_radius_mm"], base["bottom_z_mm"],
                         base["top_z_mm"]))
    shell = C.fuse(dome_shell(body, d_in, d_out), adds)
    cuts = []
    hole_r = params["modelled_hole_diameter_mm"] / 2.0
    for polar, az in params["holes_deg"]:
        r, z, nr, nz = body.surface_point(0.0, polar)
        ca, sa = math.cos(math.radians(az)), math.sin(math.radians(az))
        c = (r * ca, r * sa, z)
        n = (nr * ca, nr * sa, nz)
        at = lambda s: tuple(c[k] + s * n[k] for k in range(3))
        cuts.append(C.cylinder_between(at(d_in - 0.5), at(d_out + 0.5), hole_r))
        if pd["counterbore_depth_mm"] > 0:
            cuts.append(C.cylinder_between(at(d_out - pd["counterbore_depth_mm"]), at(d_out + 1.5),
                                           pd["counterbore_diameter_mm"] / 2.0))
    cuts += [C.primitive(b) for b in params["label_boxes"]]
    cuts += base_dowel_holes(base)
    if params.get("groove"):
        cuts.append(groove(body, params["groove"]))
    return C.cut(shell, cuts)


def pin(params: dict):
    """The pin in its own frame: tip at the origin, +z towards the head."""
    p = params["pin"]
    rt, rs, rh = p["tip_radius_mm"], p["shaft_diameter_mm"] / 2.0, p["head_diameter_mm"] / 2.0
    L, hh = params["length_mm"], p["head_height_mm"]
    arc = cq.Edge.makeThreePointArc(C.vec(0.0, 0.0), C.vec(rt * math.cos(-math.pi / 4),
                                                           rt + rt * math.sin(-math.pi / 4)),
                                    C.vec(rt, rt))
    pts = []
    if rs > rt:
        pts.append((rs, rt + (rs - rt)))
    pts += [(rs, L), (rh, L), (rh, L + hh), (0.0, L + hh)]
    return C.revolve([arc], pts)


def pin_dome_ring(params: dict):
    """The pin dome's holder ring (fixtures/src/ring.rs), sensor frame: the outer cylinder less
    the bore over the floor, the upstand's bore over the seat, the tab notches, the cable
    channel and the screw pockets."""
    r = params["ring"]
    cyl = C.cylinder_z
    ro, zb, zf, zs, zt = (r["outer_radius_mm"], r["bottom_z_mm"], r["floor_top_z_mm"],
                          r["seat_z_mm"], r["top_z_mm"])
    e = 0.01
    cuts = [cyl(r["bore_radius_mm"], zf, zt + 1.0), cyl(r["upstand_inner_radius_mm"], zs, zt + 1.0)]
    w = r["notch_width_mm"] / 2.0
    for a in r["notch_azimuths_deg"]:
        cuts.append(C.box([0.0, -w, zs], [ro + 1.0, w, zt + 1.0])
                    .rotate(cq.Vector(0, 0, 0), cq.Vector(0, 0, 1), a))
    cw = r["cable_channel_width_mm"] / 2.0
    cuts.append(C.box([r["cable_channel_start_x_mm"], -cw, zb - 1.0], [ro + 1.0, cw, zf + e]))
    cuts += [cyl(r["screw_pocket_radius_mm"], zb - 1.0, zf + e, x, y)
             for x, y in r["screw_pockets_xy_mm"]]
    return C.cut(cyl(ro, zb, zt), cuts)


def semidome_holder(params: dict):
    base = params["base"]
    zt = params["holder_top_z_mm"]
    cuts = base_dowel_holes(base)
    d = base["dowel_hole_diameter_mm"] / 2.0
    for x, y in params["top_dowels_xy_mm"]:
        cuts.append(C.cylinder_z(d, zt - base["dowel_hole_depth_mm"], zt + 1.0, x, y))
    return C.cut(ring(base["inner_radius_mm"], base["outer_radius_mm"], base["bottom_z_mm"], zt),
                 cuts)


def semidome_half(params: dict):
    sd, base = params["semidomes"], params["base"]
    body = C.Body(params["body"])
    d_in = sd["clearance_mm"]
    d_out = d_in + sd["wall_thickness_mm"]
    zt = params["holder_top_z_mm"]
    big = 4.0 * (base["outer_radius_mm"] + abs(body.pole_z(d_out)) + 10.0)
    s = C.fuse(dome_shell(body, d_in, d_out),
               [ring(params["flange_inner_radius_mm"], base["outer_radius_mm"], zt,
                     zt + sd["flange_thickness_mm"])])
    s = C.common(s, C.box([0.0, -big, zt], [big, big, big]))
    x, y = params["half_dowel_xy_mm"]
    s = C.cut(s, [C.cylinder_z(base["dowel_hole_diameter_mm"] / 2.0, zt - 1.0,
                               zt + sd["flange_thickness_mm"] + 1.0, x, y)])
    g = params.get("protrusions")
    if g:
        s = C.fuse(s, [C.primitive(p) for p in g["primitives"]])
    return s


def volute_plate(derived: dict, thickness: float):
    """The volute plate, exact: log spiral r = c exp(k phi), phi in [0, 2 pi] about the pole,
    closed by the radial step, in the indenter frame (origin at the outline's centroid)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.GeomAbs import GeomAbs_C2
    from OCP.GeomAPI import GeomAPI_PointsToBSpline
    from OCP.gp import gp_Pnt
    from OCP.TColgp import TColgp_Array1OfPnt
    k, c = derived["k"], derived["c_mm"]
    px, py = derived["pole_mm"]
    spiral = lambda f: (px + c * math.exp(k * f) * math.cos(f), py + c * math.exp(k * f) * math.sin(f))
    n = 4000
    arr = TColgp_Array1OfPnt(1, n + 1)
    for i in range(n + 1):
        arr.SetValue(i + 1, gp_Pnt(*spiral(2 * math.pi * i / n), 0.0))
    curve = GeomAPI_PointsToBSpline(arr, 3, 8, GeomAbs_C2, C.SPLINE_TOL_MM / 10).Curve()
    e = cq.Edge(BRepBuilderAPI_MakeEdge(curve).Edge())
    worst = max(C._edge_distance(e, cq.Vector(*spiral(2 * math.pi * (i + 0.5) / n), 0.0))
                for i in range(0, n, 7))
    if worst > C.SPLINE_TOL_MM:
        raise C.TwinError(f"volute: B-spline fit {worst:.2e} mm")
    pts = [e.startPoint(), e.endPoint()]
    pts = [pts[1], pts[0]]
    wire = cq.Wire.assembleEdges([e, cq.Edge.makeLine(pts[0], pts[1])])
    face = cq.Face.makeFromWires(wire)
    return cq.Solid.extrudeLinear(face, cq.Vector(0, 0, thickness))


def indenter(params: dict):
    """The indenter in its own frame (origin at the contact, +z along the stem)."""
    shape = params["shape"]
    if shape["type"] == "volute":
        body = volute_plate(params["derived"], shape["thickness_mm"])
    else:
        prims = params["contact_geometry"]["primitives"]
        body = C.primitive(prims[0])
        if len(prims) > 1:
            body = C.fuse(body, [C.primitive(p) for p in prims[1:]])
    sg = params["stem_geometry"]
    rs = sg["radius_mm"]
    add = [C.cylinder_z(rs, sg["start_z_mm"], sg["end_z_mm"])]
    neck = sg.get("neck_cone")
    if neck:
        add.append(cq.Solid.makeCone(neck["base_radius_mm"], 0.0,
                                     neck["apex_z_mm"] - neck["base_z_mm"],
                                     cq.Vector(0, 0, neck["base_z_mm"]), cq.Vector(0, 0, 1)))
    s = C.fuse(body, add)
    z_end = sg["end_z_mm"]
    mount = params["stem"]["mount"]
    if mount["type"] == "flat":
        cutter = C.box([-rs - 1.0, rs - mount["depth_mm"], z_end - mount["length_mm"]],
                       [rs + 1.0, rs + 1.0, z_end + 1.0])
    else:
        cutter = C.cylinder_z(mount["diameter_mm"] / 2.0, z_end - mount["depth_mm"], z_end + 1.0)
    return C.cut(s, [cutter])


def grid_plate(params: dict):
    """The indenter grid plate of a flat skin (fixtures/src/gridplate.rs), sensor frame: the
    outline grown by the clearance and the wall from the base plane to the plate's top, less
    the outline grown by the clearance up to the plate's underside, less a bore per hole."""
    from . import cq_flat
    g, o = params["grid_plate"], params["outline"]
    face, top = float(params["face_z_mm"]), float(params["top_z_mm"])
    under = face + float(g["standoff_mm"])

    def grown(d):
        return _grown(o, d)

    c, w = float(g["skin_clearance_mm"]), float(g["wall_mm"])
    r = (float(g["pin"]["shaft_diameter_mm"]) + float(g["hole_clearance_mm"])) / 2.0
    bores = [C.cylinder_z(r, under - 1.0, top + 1.0, x, y)
             for x, y in params["holes_xy_mm"]]
    return C.cut(cq_flat.outline_prism(grown(c + w), 0.0, top),
                 [cq_flat.outline_prism(grown(c), -1.0, under)] + bores)


def calibration_board(params: dict):
    """The calibration board of a flat sensor (fixtures/src/board.rs), sensor frame, pressed
    on: the pocket grown by the wall from the pocket's rim up to the floor's outer face, less
    the pocket below the contact face, with a bump (a cylinder and a hemispherical cap) per
    grid point down from the floor."""
    from . import cq_flat
    b, pocket = params["board"], params["pocket"]
    face, top = float(params["face_z_mm"]), float(params["top_z_mm"])
    rim = face - float(b["pocket_depth_mm"])
    r, h = float(b["bump_radius_mm"]), float(b["bump_height_mm"])
    cup = C.cut(cq_flat.outline_prism(_grown(pocket, float(b["wall_mm"])), rim, top),
                [cq_flat.outline_prism(pocket, rim - 1.0, face)])
    bumps = []
    for x, y in params["bumps_xy_mm"]:
        bumps.append(C.cylinder_z(r, face - (h - r), face + 0.01, x, y))
        bumps.append(cq.Solid.makeSphere(r, cq.Vector(x, y, face - (h - r)), angleDegrees1=-90, angleDegrees2=90))
    return C.fuse(cup, bumps)


def _grown(o: dict, d: float) -> dict:
    """The outline `o` grown by `d` all round (corner radius grown too)."""
    return {"width_mm": o["width_mm"] + 2 * d, "length_mm": o["length_mm"] + 2 * d,
            "corner_radius_mm": o.get("corner_radius_mm", 0.0) + d}


SEMIPLATE_DOWEL_HOLE_DEPTH_MM = 3.0  # fixtures/src/semiplate.rs DOWEL_HOLE_DEPTH_MM


def semiplate_holder(params: dict):
    """The semi-plates' holder frame of a flat skin (fixtures/src/semiplate.rs), sensor frame:
    the outline grown by the clearance and the wall from the base plane to the contact face,
    less the outline grown by the clearance, less two dowel holes in its top."""
    from . import cq_flat
    sp, o = params["semiplates"], params["outline"]
    face = float(params["face_z_mm"])
    c, w = float(sp["skin_clearance_mm"]), float(sp["wall_mm"])
    r = float(sp["dowel_diameter_mm"]) / 2.0
    dowels = [C.cylinder_z(r, face - SEMIPLATE_DOWEL_HOLE_DEPTH_MM, face + 1.0, x, y)
              for x, y in params["dowels_xy_mm"]]
    return C.cut(cq_flat.outline_prism(_grown(o, c + w), 0.0, face),
                 [cq_flat.outline_prism(_grown(o, c), -1.0, face + 1.0)] + dowels)


def semiplate_half(params: dict):
    """A semi-plate half (+x side), sensor frame: the plate over the grown outline on its
    flange, cut at x = 0, less its dowel hole, with the pattern's protrusions."""
    from . import cq_flat
    sp, o = params["semiplates"], params["outline"]
    face, top = float(params["face_z_mm"]), float(params["top_z_mm"])
    under = face + float(sp["clearance_mm"])
    c, w = float(sp["skin_clearance_mm"]), float(sp["wall_mm"])
    big = 2.0 * (o["width_mm"] + o["length_mm"]) + 4.0 * w + 10.0
    s = C.cut(cq_flat.outline_prism(_grown(o, c + w), face, top),
              [cq_flat.outline_prism(_grown(o, c), face - 1.0, under)])
    s = C.common(s, C.box([0.0, -big, face - 1.0], [big, big, top + 1.0]))
    x, y = params["dowel_xy_mm"]
    s = C.cut(s, [C.cylinder_z(float(sp["dowel_diameter_mm"]) / 2.0, face - 1.0,
                               face + SEMIPLATE_DOWEL_HOLE_DEPTH_MM, x, y)])
    g = params.get("protrusions")
    if g:
        s = C.fuse(s, [C.primitive(p) for p in g["primitives"]])
    return s


def twin(part: dict):
    """The twin of a calibration fixture (sensor frame; indenter frame for an indenter), or
    None when `part` is not one."""
    role, name, p = part["role"], part["name"], part["params"]
    if role == "indenter":
        return indenter(p)
    if name == "grid_plate":
        return grid_plate(p)
    if name == "calibration_board":
        return calibration_board(p)
    if name == "pin_dome":
        return pin_dome(p)
    if name == "pin_dome_ring":
        return pin_dome_ring(p)
    if role == "calibration pin":
        return pin(p)
    if name == "semiplate_holder":
        return semiplate_holder(p)
    if name.startswith("semiplate_"):
        return semiplate_half(p)
    if name == "semidome_holder":
        return semidome_holder(p)
    if name.startswith("semidome_"):
        return semidome_half(p)
    return None
