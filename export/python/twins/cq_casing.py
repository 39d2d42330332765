"""CadQuery twins of the sensors' casings and bases, from the part's manifest `params`:
ShadowTac's casing and gripper base (Sec. IV-B, Fig. 5: the casing's parameters, its levels, the
LEDs' azimuths, the slots' and wire holes' radii, the corner pilots and the gripper bolts) and
UVDtact's fingertip base (Sec. III-C, Fig. 2: shell holder, sensor base, camera holder,
diffusion ring)."""

from __future__ import annotations

import math

from . import cq_common as C


def casing(params: dict):
    """The casing, sensor frame: the square block less the camera bay, the lens's bore through
    the ledge, the light chamber under the window, an LED slot in the chamber's wall and a
    wire hole through the ledge per LED, and the corner pilots."""
    c, lv = params["casing"], params["levels"]
    e = params["overlap_mm"]
    cl = c["fit_clearance_mm"]
    h, b = c["outer_width_mm"] / 2.0, params["bay_half_mm"]
    r_ch, back, r_wire = (params["chamber_radius_mm"], params["slot_back_radius_mm"],
                          params["wire_hole_radius_mm"])
    bottom, top = lv["bottom_z_mm"], lv["top_z_mm"]
    ledge0, ledge1 = lv["ledge_bottom_z_mm"], lv["ledge_top_z_mm"]
    cyl = C.cylinder_z
    cuts = [
        C.box([-b, -b, bottom - 1.0], [b, b, ledge0]),
        cyl(c["camera"]["lens_diameter_mm"] / 2.0 + cl, ledge0 - e, ledge1 + e),
        cyl(r_ch, ledge1, top + 1.0),
    ]
    w = c["leds"]["width_mm"] / 2.0 + cl
    for a in params["led_azimuths_deg"]:
        slot = C.box([r_ch - 1.0, -w, ledge1], [back, w, top + 1.0])
        cuts.append(C.transformed(slot, C.rotation_deg(0.0, 0.0, a)))
        t = math.radians(a)
        cuts.append(cyl(c["leds"]["wire_hole_diameter_mm"] / 2.0, ledge0 - e, ledge1 + e,
                        r_wire * math.cos(t), r_wire * math.sin(t)))
    s = c["screws"]
    for x, y in params["pilot_xy_mm"]:
        cuts.append(cyl(s["pilot_diameter_mm"] / 2.0, bottom - 1.0, bottom + s["pilot_depth_mm"],
                        x, y))
    return C.cut(C.box([-h, -h, bottom], [h, h, top]), cuts)


def gripper_base(params: dict):
    """The gripper base, sensor frame: the plate less the casing's socket, the cable slot under
    its floor, the casing screws' holes counterbored from below and the gripper bolts' holes
    counterbored from the top."""
    c, lv = params["casing"], params["levels"]
    g = c["gripper_base"]
    e = params["overlap_mm"]
    floor = lv["bottom_z_mm"]
    top, bottom = lv["base_top_z_mm"], lv["base_bottom_z_mm"]
    x, y = g["width_mm"] / 2.0, g["length_mm"] / 2.0
    sk = c["outer_width_mm"] / 2.0 + c["fit_clearance_mm"]
    sw = g["cable_slot_width_mm"] / 2.0
    cyl = C.cylinder_z
    cuts = [
        C.box([-sk, -sk, floor], [sk, sk, top + 1.0]),
        C.box([-sw, 0.0, floor - g["cable_slot_depth_mm"]], [sw, y + 1.0, floor + e]),
    ]
    s = c["screws"]
    for px, py in params["pilot_xy_mm"]:
        cuts.append(cyl(s["clearance_diameter_mm"] / 2.0, bottom - 1.0, floor + e, px, py))
        cuts.append(cyl(s["head_diameter_mm"] / 2.0, bottom - 1.0, bottom + s["head_depth_mm"],
                        px, py))
    for bx, by in params["bolt_xy_mm"]:
        cuts.append(cyl(g["bolt_clearance_diameter_mm"] / 2.0, bottom - 1.0, top + 1.0, bx, by))
        cuts.append(cyl(g["bolt_head_diameter_mm"] / 2.0, top - g["bolt_head_depth_mm"],
                        top + 1.0, bx, by))
    return C.cut(C.box([-x, -y, bottom], [x, y, top]), cuts)


def _ring(ri: float, ro: float, z0: float, z1: float):
    return C.cut(C.cylinder_z(ro, z0, z1), [C.cylinder_z(ri, z0 - 1.0, z1 + 1.0)])


def fingertip_part(params: dict, role: str):
    """UVDtact's shell holder, sensor base, camera holder or diffusion ring (Sec. III-C,
    Fig. 2), sensor frame (designs/src/parts/fingertip_base.rs)."""
    f, lv, r = params["fingertip_base"], params["levels"], params["radii"]
    e = params["overlap_mm"]
    b = f["bolts"]
    end, floor, bottom = lv["shell_end_z_mm"], lv["pocket_floor_z_mm"], lv["bottom_z_mm"]
    cyl = C.cylinder_z
    if role == "shell_holder":
        cuts = [cyl(b["pilot_diameter_mm"] / 2.0, end - 1.0, end + b["pilot_depth_mm"], x, y)
                for x, y in params["bolt_xy_mm"]]
        return C.cut(_ring(r["holder_bore_mm"], r["outside_mm"], end, 0.0), cuts)
    if role == "sensor_base":
        wx, wy = params["pcb_wire_xy_mm"]
        cuts = [
            cyl(r["pocket_mm"], floor, end + 1.0),
            cyl(f["camera"]["wire_hole_diameter_mm"] / 2.0, bottom - 1.0, floor + e),
            cyl(f["led_pcb"]["wire_hole_diameter_mm"] / 2.0, bottom - 1.0, floor + e, wx, wy),
        ]
        for x, y in params["bolt_xy_mm"]:
            cuts.append(cyl(b["clearance_diameter_mm"] / 2.0, bottom - 1.0, end + 1.0, x, y))
            cuts.append(cyl(b["head_diameter_mm"] / 2.0, bottom - 1.0, bottom + b["head_depth_mm"],
                            x, y))
        return C.cut(cyl(r["outside_mm"], bottom, end), cuts)
    if role == "camera_holder":
        return _ring(f["camera"]["diameter_mm"] / 2.0 + f["fit_clearance_mm"],
                     f["camera_holder"]["outer_diameter_mm"] / 2.0, floor, end)
    # the diffusion ring, a hole over each UV LED
    rl = f["led_pcb"]["led_circle_diameter_mm"] / 2.0
    holes = [cyl(f["diffusion_ring"]["uv_hole_diameter_mm"] / 2.0, lv["ring_bottom_z_mm"] - 1.0,
                 end + 1.0, rl * math.cos(math.radians(a)), rl * math.sin(math.radians(a)))
             for a, uv in params["leds"] if uv]
    ring = _ring(f["diffusion_ring"]["inner_diameter_mm"] / 2.0,
                 f["led_pcb"]["outer_diameter_mm"] / 2.0, lv["ring_bottom_z_mm"], end)
    return C.cut(ring, holes)


def twin(part: dict):
    """The twin of a casing or fingertip-base family part (sensor frame), or None when `part`
    is not one."""
    role, p = part["role"], part["params"]
    if role == "casing":
        return casing(p)
    if role == "gripper_base":
        return gripper_base(p)
    if role in ("shell_holder", "sensor_base", "camera_holder", "diffusion_ring"):
        return fingertip_part(p, role)
    return None
