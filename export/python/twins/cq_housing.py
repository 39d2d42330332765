"""CadQuery twin of the sensor shell (R-Tac0 Sec. III-B2..B4, Fig. 2), from the part's manifest
`params`: levels, housing parameters, seats, joint screws, dowels. Two arrangements: the round
tube with its collar and camera base (`shell_collar`, `shell_tube`, `shell_base`), the square
split halves (`shell_half`)."""

from __future__ import annotations

from . import cq_common as C


def shell_half(params: dict, half: str):
    """Half `a` (x >= 0, screw heads) or `b` (x <= 0, pilots), sensor frame."""
    lv, h = params["levels"], params["housing"]
    w = h["outer_width_mm"] / 2.0
    c = h["fit_clearance_mm"]
    e = params["overlap_mm"]
    bw = h["camera"]["board_width_mm"] / 2.0 + c
    cyl = C.cylinder_z
    cuts = [
        C.box([-bw, -bw, lv["bottom_z_mm"] - 1.0], [bw, bw, lv["bulkhead_z_mm"]]),
        cyl(h["camera"]["lens_hole_diameter_mm"] / 2.0, lv["bulkhead_z_mm"] - e, lv["pcb_z_mm"] + e),
        cyl(h["led_pcb"]["outer_diameter_mm"] / 2.0 + c, lv["pcb_z_mm"], lv["chamber_z_mm"] + e),
        cyl(h["light_chamber_diameter_mm"] / 2.0, lv["chamber_z_mm"], lv["diffuser_z_mm"] + e),
        cyl(h["diffuser"]["outer_diameter_mm"] / 2.0 + c, lv["diffuser_z_mm"], lv["seat_z_mm"] + e),
        cyl(params["core_seat_radius_mm"], lv["seat_z_mm"], lv["top_z_mm"] + 1.0),
    ]
    z0, z1 = params["camera_mount_pilot_z_mm"]
    for x, y in params["camera_mount_holes_xy_mm"]:
        cuts.append(cyl(h["camera"]["mount_pilot_diameter_mm"] / 2.0, z0, z1, x, y))
    js = h["joint_screw"]
    z = params["joint_screws"]["z_mm"]
    for y in params["joint_screws"]["y_mm"]:
        for r, x0, x1 in ((js["pilot_diameter_mm"] / 2.0, -js["pilot_depth_mm"], e),
                          (js["clearance_diameter_mm"] / 2.0, 0.0, js["clamp_length_mm"] + e),
                          (js["head_diameter_mm"] / 2.0, js["clamp_length_mm"], w + 1.0)):
            cuts.append(C.cylinder_between((x0, y, z), (x1, y, z), r))
    dw = params["fixture_dowel_holes"]
    for x, y in dw["positions_xy_mm"]:
        cuts.append(cyl(dw["diameter_mm"] / 2.0, lv["top_z_mm"] - dw["depth_mm"],
                        lv["top_z_mm"] + 1.0, x, y))
    lo = [0.0 if half == "a" else -w, -w, lv["bottom_z_mm"]]
    hi = [w if half == "a" else 0.0, w, lv["top_z_mm"]]
    return C.cut(C.box(lo, hi), cuts)


def _bores(params: dict) -> list:
    """The square shell's seats, from the LED PCB seat up to the top face."""
    lv, h = params["levels"], params["housing"]
    c = h["fit_clearance_mm"]
    e = params["overlap_mm"]
    cyl = C.cylinder_z
    return [
        cyl(h["led_pcb"]["outer_diameter_mm"] / 2.0 + c, lv["pcb_z_mm"], lv["chamber_z_mm"] + e),
        cyl(h["light_chamber_diameter_mm"] / 2.0, lv["chamber_z_mm"], lv["diffuser_z_mm"] + e),
        cyl(h["diffuser"]["outer_diameter_mm"] / 2.0 + c, lv["diffuser_z_mm"], lv["seat_z_mm"] + e),
        cyl(params["core_seat_radius_mm"], lv["seat_z_mm"], lv["top_z_mm"] + 1.0),
    ]


def shell_tube(params: dict):
    """The round tube, from its bottom up to the diffuser disc on its top face: outer cylinder
    less the camera bay, the light chamber (the LED PCB goes down it) and the screw pilots."""
    lv, h = params["levels"], params["housing"]
    e = params["overlap_mm"]
    r = h["outer_width_mm"] / 2.0
    tb, dz = lv["tube_bottom_z_mm"], lv["diffuser_z_mm"]
    cyl = C.cylinder_z
    cuts = [cyl(params["bay_radius_mm"], tb - 1.0, lv["pcb_z_mm"] + e),
            cyl(h["light_chamber_diameter_mm"] / 2.0, lv["pcb_z_mm"], dz + 1.0)]
    js = params["joint_screws"]
    z0, z1 = js["pilot_z_mm"]
    for x, y in js["xy_mm"]:
        cuts.append(cyl(h["joint_screw"]["pilot_diameter_mm"] / 2.0, z0, z1, x, y))
    return C.cut(cyl(r, tb, dz), cuts)


def shell_collar(params: dict):
    """The collar on the diffuser disc: a ring from the disc up to the base plane, bored to the
    core's seat."""
    lv, h = params["levels"], params["housing"]
    r = h["outer_width_mm"] / 2.0
    seat, top = lv["seat_z_mm"], lv["top_z_mm"]
    cyl = C.cylinder_z
    return C.cut(cyl(r, seat, top), [cyl(params["core_seat_radius_mm"], seat - 1.0, top + 1.0)])


def shell_base(params: dict):
    """The base: flange under the tube and spigot into the bay, less the camera pilots, the
    screws' clearance holes and the cable slot."""
    lv, h = params["levels"], params["housing"]
    e = params["overlap_mm"]
    r = h["outer_width_mm"] / 2.0
    tb, top, bottom = lv["tube_bottom_z_mm"], lv["base_top_z_mm"], lv["bottom_z_mm"]
    cyl = C.cylinder_z
    base = C.fuse(cyl(r, bottom, tb), [cyl(params["spigot_radius_mm"], tb - e, top)])
    z0, z1 = params["camera_mount_pilot_z_mm"]
    cuts = [cyl(h["camera"]["mount_pilot_diameter_mm"] / 2.0, z0, z1, x, y)
            for x, y in params["camera_mount_holes_xy_mm"]]
    js = params["joint_screws"]
    c0, c1 = js["clearance_z_mm"]
    cuts += [cyl(h["joint_screw"]["clearance_diameter_mm"] / 2.0, c0, c1, x, y)
             for x, y in js["xy_mm"]]
    sx, sy = params["cable_slot_xy_mm"]
    cuts.append(C.box([-sx / 2.0, -sy / 2.0, bottom - 1.0], [sx / 2.0, sy / 2.0, top + 1.0]))
    return C.cut(base, cuts)


def twin(part: dict):
    """The twin of a shell part (sensor frame), or None when `part` is not one."""
    role, name, p = part["role"], part["name"], part["params"]
    if role == "shell_half":
        return shell_half(p, name.rsplit("_", 1)[1])
    builder = {"shell_tube": shell_tube, "shell_collar": shell_collar,
               "shell_base": shell_base}.get(role)
    return builder(p) if builder else None
