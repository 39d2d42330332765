"""CadQuery twins of the parts built from a layer and its marker features (ShadowTac
Sec. III-IV, UVDtact Sec. III, Pestell et al. Sec. III-A): one-piece open molds (dimples) and
the insert that forms a solid layer's recess (DIGIT Pinki),
printed skins with pins and their tips, and the boundary strategy's master, mold box and
inner negative (slots and protrusions). From a part's manifest `params` alone: the body, the
layer offsets, and per marker set the feature, direction and (polar, azimuth) placements."""

from __future__ import annotations

import math

from . import cq_common as C
from .cq_molds import drafted_box

# How far a feature solid reaches behind its surface (into material it joins or into empty
# space it does not touch): any depth above the sagitta of its base disc and below the wall
# gives the same solid. mm.
EMBED_MM = 0.1


def placements(body: C.Body, ms: dict):
    """(origin, unit direction) of every feature of the marker set `ms`."""
    d = ms["surface_offset_mm"]
    sign = ms["direction"]
    out = []
    for polar, az in ms["placements_deg"]:
        r, z, nr, nz = body.surface_point(d, polar)
        ca, sa = math.cos(math.radians(az)), math.sin(math.radians(az))
        out.append(((r * ca, r * sa, z), (sign * nr * ca, sign * nr * sa, sign * nz)))
    return out


def feature_solids(body: C.Body, ms: dict, stems_only: bool):
    f = ms["feature"]
    t = ms.get("dilation_mm", 0.0)
    if stems_only:
        local = C.stem(f["diameter_mm"], f["height_mm"], EMBED_MM)
    else:
        # features grown by a coat (a mold's cavity, a coat's faces) reach back as far
        local = C.feature(f["diameter_mm"], f["height_mm"], EMBED_MM + t, ms["direction"] * t)
    return [C.place_along(local, o, u) for o, u in placements(body, ms)]


def with_features(base, body: C.Body, sets: list, sign: float, stems_only: bool = False):
    """Adds the features pointing out of `base` (direction x sign > 0) and cuts the others."""
    add, sub = [], []
    for ms in sets:
        (add if ms["direction"] * sign > 0 else sub).extend(feature_solids(body, ms, stems_only))
    s = C.fuse(base, add) if add else base
    return C.cut(s, sub) if sub else s


def enclosed(body: C.Body, d: float, below: float, extra=None):
    """The solid enclosed by the offset surface `d`, closed `below` mm under the base plane (or
    by the (r, z) points `extra` after the rim)."""
    zb = body.base_z()
    pts = [(body.rim_radius(d), zb)]
    pts += extra if extra is not None else [(body.rim_radius(d), zb - below), (0.0, zb - below)]
    return C.revolve(body.curve_edges(d), pts)


def recess_solid(r: dict, zb: float, below: float):
    """The recess under a solid layer (the optic's seat, DIGIT Pinki) from its resolved outline
    `r` ((r, h) points, h up from the base plane `zb`): the roof's arc from the apex, the
    fillet's arc, the wall's line to the mouth, continued `below` mm under the base plane and
    closed there; exact arcs."""
    import cadquery as cq
    R, hs = r["cap_radius_mm"], r["cap_centre_h_mm"]
    er, eh = r["roof_edge"]
    a_edge = math.atan2(eh - hs, er)
    mid = (math.pi / 2 + a_edge) / 2
    edges = [cq.Edge.makeThreePointArc(C.vec(0.0, zb + r["depth_mm"]),
                                       C.vec(R * math.cos(mid), zb + hs + R * math.sin(mid)),
                                       C.vec(er, zb + eh))]
    draft = math.radians(r["draft_angle_deg"])
    rf = r["fillet_radius_mm"]
    if rf > 0:
        fr, fh = r["fillet_centre"]
        wr, wh = r["wall_top"]
        m = (a_edge + draft) / 2
        edges.append(cq.Edge.makeThreePointArc(C.vec(er, zb + eh),
                                               C.vec(fr + rf * math.cos(m), zb + fh + rf * math.sin(m)),
                                               C.vec(wr, zb + wh)))
    r0 = r["mouth_radius_mm"]
    pts = [(r0, zb)]
    if below > 0:
        pts += [(r0 + below * math.tan(draft), zb - below), (0.0, zb - below)]
    else:
        pts += [(0.0, zb)]
    return C.revolve(edges, pts)


def marker_sets(base: dict, surface: str) -> list:
    return [m for m in base["markers"] if m["surface"] == surface]


def open_mold(params: dict):
    base = params["base"]
    body = C.Body(base["body"])
    b = params["block_mm"]
    mold = C.cut(C.box(b["min"], b["max"]), [enclosed(body, base["outer_offset_mm"], 1.0)])
    return with_features(mold, body, marker_sets(base, "outer"), -1.0)


def open_mold_piece(params: dict):
    """A piece of the two_piece_open mold from its recorded frame: the cavity block (outline
    from the parting face to the wall beyond the pole, less the cavity, the pocket and the bolt
    holes, with the features) or the reservoir top (plate and boss, less the bore and the bolt
    holes)."""
    base, f = params["base"], params["frame"]
    body = C.Body(base["body"])
    zb, zp = f["base_z_mm"], f["parting_z_mm"]
    ox, oy = f["outer_half_mm"]
    z0, z1 = params["bolt_holes_z_mm"]
    piece = params["piece"]
    r_bolt = f[f"{'cavity_block' if piece == 'cavity_block' else 'top_piece'}_bolt_hole_mm"] / 2.0
    bolts = [C.cylinder_z(r_bolt, z0, z1, x, y) for x, y in f["bolts_xy_mm"]]
    if piece == "cavity_block":
        zlo, zhi = params["cavity_block_z_mm"]
        px, py = f["pocket_half_mm"]
        block = C.box((-ox, -oy, zlo), (ox, oy, zhi))
        pocket = C.box((-px, -py, zp - 1.0), (px, py, zb))
        block = C.cut(block, [enclosed(body, base["outer_offset_mm"], 1.0), pocket] + bolts)
        return with_features(block, body, marker_sets(base, "outer"), -1.0)
    bx, by = f["boss_half_mm"]
    top = C.fuse(C.box((-ox, -oy, f["top_z_mm"]), (ox, oy, zp)), [C.box((-bx, -by, zp), (bx, by, zb))])
    bore = C.cylinder_z(f["reservoir_radius_mm"], f["top_z_mm"] - 1.0, zb + 1.0)
    return C.cut(top, [bore] + bolts)


def printed_skin(params: dict, tips: bool):
    """The printed layer (stems only when its features have separate tips) or its tips."""
    body = C.Body(params["body"])
    sets = params["markers"]
    stems_only = any(m.get("tip_material") for m in sets)
    if tips:
        out = []
        for ms in sets:
            f = ms["feature"]
            hc = f["height_mm"] - f["diameter_mm"] / 2.0
            local = C.hemisphere_tip(f["diameter_mm"])
            for (x, y, z), u in placements(body, ms):
                out.append(C.place_along(local, (x + hc * u[0], y + hc * u[1], z + hc * u[2]), u))
        import cadquery as cq
        return cq.Compound.makeCompound(out)
    outer = with_features(enclosed(body, params["outer_offset_mm"], 0.0), body,
                          marker_sets(params, "outer"), 1.0, stems_only)
    if params["solid"]:
        if params.get("recess"):
            return C.cut(outer, [recess_solid(params["recess"], body.base_z(), 1.0)])
        return outer
    inner = with_features(enclosed(body, params["inner_offset_mm"], 1.0), body,
                          marker_sets(params, "inner"), 1.0, stems_only)
    return C.cut(outer, [inner])


def inner_cavity(params: dict, r: float, z0: float, z1: float):
    """The space inside the layer above the base plane less its inner features, whole (stems
    and tips as one solid each; designs/src/parts/layers.rs `inner_cavity`), united with the
    disc of radius `r` from `z0` to `z1` about the z axis: the filling gel of a printed TacTip
    tip (Pestell et al. Sec. III-A)."""
    body = C.Body(params["body"])
    cavity = with_features(enclosed(body, params["inner_offset_mm"], 0.0), body,
                           marker_sets(params, "inner"), 1.0)
    return C.fuse(cavity, [C.cylinder_z(r, z0, z1)])


def boundary_master(params: dict):
    base, bd = params["base"], params["boundary"]
    body = C.Body(base["body"])
    zb = body.base_z()
    r_p = params["plinth_radius_mm"]
    z_lo = zb - params["plinth_height_mm"]
    pin = bd["locating_pin"]
    master = enclosed(body, base["outer_offset_mm"], 0.0,
                      [(r_p, zb), (r_p, z_lo), (pin["radius_mm"], z_lo),
                       (pin["radius_mm"], z_lo - pin["height_mm"]), (0.0, z_lo - pin["height_mm"])])
    return with_features(master, body, marker_sets(base, "outer"), 1.0)


def boundary_box(params: dict):
    base, bd = params["base"], params["boundary"]
    body = C.Body(base["body"])
    z_lo = body.base_z() - params["plinth_height_mm"]
    return drafted_box(params["plinth_radius_mm"], z_lo, bd["master_top_z_mm"],
                       params["silicone_wall_mm"], params["draft_angle_deg"], bd["box_floor_mm"],
                       bd["box_wall_mm"], bd["box_freeboard_mm"], bd["pin_socket_radius_mm"])


def boundary_negative(params: dict):
    base, bd = params["base"], params["boundary"]
    body = C.Body(base["body"])
    zb = body.base_z()
    r = params["plinth_radius_mm"] - params["fit_clearance_mm"]
    z_b = bd["inner_plinth_bottom_z_mm"]
    core = with_features(enclosed(body, base["inner_offset_mm"], 0.0, [(r, zb), (r, z_b), (0.0, z_b)]),
                         body, marker_sets(base, "inner"), 1.0)
    cup = bd["cup"]
    return C.cut(C.cylinder_z(cup["radius_mm"], cup["bottom_z_mm"], cup["top_z_mm"]), [core])


def core_shell(params: dict):
    """The core with a bore (designs/src/parts/core_shell.rs), sensor frame: between the body's
    offset at `outer_offset_mm` and the inner surface, both continued straight down
    `below_base_mm` under the base plane to the open end. The inner surface, by the rule of
    BodyProfile::shell_inner_surface: on a half ellipsoid, the half ellipsoid of the outer
    surface's rim radius and pole height less `wall_thickness_mm` (exact points, B-spline fit);
    on spherical profiles, the concentric sphere."""
    body = C.Body(params["body"])
    d = float(params["outer_offset_mm"])
    w = float(params["wall_thickness_mm"])
    below = float(params["below_base_mm"])
    zb = body.base_z()
    rim_out = body.rim_radius(d)
    if body.kind == "half_ellipsoid":
        rim_in = rim_out - w
        height_in = body.pole_z(d) - w - zb
        if rim_in <= 0 or height_in <= 0:
            raise C.TwinError(f"a {w} mm wall leaves no bore")
        inner, d_in = C.Body({"profile": "half_ellipsoid", "diameter_mm": 2.0 * rim_in,
                              "height_mm": height_in}), 0.0
    else:
        inner, d_in = body, d - w
    # the solid under the outer surface less the solid under the inner one (run 1 mm past the
    # open end): booleans, as the other twins, so that the same parameters give the same B-rep
    return C.cut(enclosed(body, d, below), [enclosed(inner, d_in, below + 1.0)])


def twin(part: dict):
    """The twin of a layer's part (sensor frame), or None when `part` is not one: the open
    molds, the printed skin and its tips, the boundary strategy's master, box and negative."""
    role, p = part["role"], part["params"]
    if role == "master_pattern" and "master" not in p:
        return boundary_master(p)
    if role == "mold_box" and "master" not in p:
        return boundary_box(p)
    if role == "open_mold":
        return open_mold(p)
    if role == "open_mold_piece":
        return open_mold_piece(p)
    if role == "recess_insert":
        return recess_solid(p["recess"], p["base_z_mm"], 0.0)
    if role == "printed_skin":
        return printed_skin(p, tips=False)
    if role == "marker_tips":
        return printed_skin(p, tips=True)
    if role == "negative_mold":
        return boundary_negative(p)
    return None
