"""CadQuery twins of the cast-layer molds (R-Tac0 Sec. III-B1, Fig. 4): master patterns and
drafted mold boxes (master strategy), two-piece mold halves (direct strategy), and the core
holder / casting jig. Built from a part's manifest `params` alone."""

from __future__ import annotations

import math

from . import cq_common as C


def cavity(params: dict, with_pin: bool):
    """The cavity (offset surface + plinth recess), with the master's locating pin."""
    body = C.Body(params["body"])
    f = params["frame"]
    d = params["cavity_offset_mm"]
    pts = [(f["plinth_radius_mm"], f["base_z_mm"]), (f["plinth_radius_mm"], f["open_face_z_mm"])]
    if with_pin:
        pin = params["master"]["locating_pin"]
        z = f["open_face_z_mm"]
        pts += [(pin["radius_mm"], z), (pin["radius_mm"], z - pin["height_mm"]),
                (0.0, z - pin["height_mm"])]
    else:
        pts.append((0.0, f["open_face_z_mm"]))
    cav = C.revolve(body.curve_edges(d), [(body.rim_radius(d), body.base_z())] + pts)
    if params.get("markers"):
        # the layer's features, grown by the coats sprayed into the cavity
        from .cq_layers import with_features
        cav = with_features(cav, body, params["markers"], 1.0)
    return cav


def master_pattern(params: dict):
    return cavity(params, with_pin=True)


def drafted_box(plinth_radius, z0, pole_z, silicone_wall, draft_deg, floor, wall, freeboard,
                socket_radius):
    """The drafted cup as one revolve: floor with the pin socket through it, drafted inner wall
    (radius plinth + silicone wall at the plinth face, growing by tan(draft) per mm up),
    cylindrical outer wall."""
    z_top = pole_z + silicone_wall + freeboard
    r0 = plinth_radius + silicone_wall
    r_top = r0 + math.tan(math.radians(draft_deg)) * (z_top - z0)
    r_out = r_top + wall
    return C.revolve_polyline([(socket_radius, z0 - floor), (r_out, z0 - floor), (r_out, z_top),
                               (r_top, z_top), (r0, z0), (socket_radius, z0)])


def mold_box(params: dict):
    f, m = params["frame"], params["master"]
    return drafted_box(f["plinth_radius_mm"], f["open_face_z_mm"], f["cavity_pole_z_mm"],
                       m["silicone_wall_mm"], m["draft_angle_deg"], m["box_floor_mm"],
                       m["box_wall_mm"], m["box_freeboard_mm"], m["pin_socket_radius_mm"])


def core_holder(params: dict):
    f = params["frame"]
    fit = params["fit_clearance_mm"]
    z_f0 = f["open_face_z_mm"] - params["flange_thickness_mm"]
    z_bottom = params["bottom_z_mm"]
    r_f = params["flange_radius_mm"]
    pts = [(0.0, z_bottom)]
    if z_bottom < z_f0:
        pts += [(params["boss_radius_mm"], z_bottom), (params["boss_radius_mm"], z_f0)]
    pin_top = params["pin_top_z_mm"]
    pts += [(r_f, z_f0), (r_f, f["open_face_z_mm"]),
            (f["plinth_radius_mm"] - fit, f["open_face_z_mm"]),
            (f["plinth_radius_mm"] - fit, f["spigot_top_z_mm"]),
            (f["core_outer_radius_mm"] + fit, f["spigot_top_z_mm"]),
            (f["core_outer_radius_mm"] + fit, f["core_end_z_mm"]),
            (f["core_inner_radius_mm"] - fit, f["core_end_z_mm"]),
            (f["core_inner_radius_mm"] - fit, pin_top), (0.0, pin_top)]
    body = C.revolve_polyline(pts)
    z0, z1 = params["holes_z_mm"]
    s = params["sprue"]
    a = math.radians(s["azimuth_deg"])
    holes = [C.cylinder_z(s["diameter_mm"] / 2.0, z0, z1, s["radius_mm"] * math.cos(a),
                          s["radius_mm"] * math.sin(a))]
    rv = params["vent_radius_mm"]
    for az in params["vent_azimuths_deg"]:
        b = math.radians(az)
        holes.append(C.cylinder_z(params["vent"]["diameter_mm"] / 2.0, z0, z1,
                                  rv * math.cos(b), rv * math.sin(b)))
    return C.cut(body, holes)


def mold_half(params: dict, half: str):
    """Half `a` (y >= 0, male keys) or `b` (y <= 0, female keys) in the sensor frame."""
    dp = params["direct"]
    b, z_lo, z_hi = dp["half_width_mm"], dp["z_min_mm"], dp["z_max_mm"]
    block = C.cut(C.box([-b, 0.0, z_lo], [b, b, z_hi]) if half == "a"
                  else C.box([-b, -b, z_lo], [b, 0.0, z_hi]), [cavity(params, with_pin=False)])
    x_f = dp["feature_x_mm"]
    e = (b - params["frame"]["plinth_radius_mm"]) / 2.0  # half the flange width
    z_mid = 0.5 * (z_lo + z_hi)
    key = dp["registration_key"]
    r_key = key["diameter_mm"] / 2.0
    bolts = [C.cylinder_between((x, -b - 1.0, z), (x, b + 1.0, z),
                                dp["clamp_bolt"]["clearance_diameter_mm"] / 2.0)
             for x in (x_f, -x_f) for z in (z_lo + e, z_hi - e)]
    if half == "a":
        keys = [C.primitive({"type": "sphere", "centre_mm": [x, 0.0, z_mid], "radius_mm": r_key})
                for x in (x_f, -x_f)]
        return C.cut(C.fuse(block, keys), bolts)
    keys = [C.primitive({"type": "sphere", "centre_mm": [x, 0.0, z_mid],
                         "radius_mm": r_key + key["clearance_mm"]}) for x in (x_f, -x_f)]
    return C.cut(block, keys + bolts)


def twin(part: dict):
    """The twin of a mold part (sensor frame), or None when `part` is not one: the master
    strategy's master pattern and mold box, the direct strategy's halves, the core holder and
    casting jig."""
    role, name, p = part["role"], part["name"], part["params"]
    if role == "master_pattern" and "master" in p:
        return master_pattern(p)
    if role == "mold_box" and "master" in p:
        return mold_box(p)
    if role in ("core_holder", "casting_jig"):
        return core_holder(p)
    if role == "mold_half":
        return mold_half(p, name.rsplit("_", 1)[1])
    return None
