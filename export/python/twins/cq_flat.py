"""CadQuery twins of flat skins' parts (designs/src/parts/flat.rs): the open casting tray of a layer,
with the ribs that form its channels' grooves or the holes that form its markers.

Built from the parameters alone, in the sensor frame (x across the outline's width, y along its
length, the layer's bottom face at z0_mm); the outline's corners are exact fillets.
"""

from __future__ import annotations

import cadquery as cq

from . import cq_common as C


def outline_prism(o: dict, z0: float, z1: float) -> cq.Solid:
    """The rounded rectangle `o` (width_mm, length_mm, corner_radius_mm) from z0 up to z1."""
    w, l, r = float(o["width_mm"]), float(o["length_mm"]), float(o.get("corner_radius_mm", 0.0))
    s = cq.Workplane("XY", origin=(0, 0, z0)).rect(w, l).extrude(z1 - z0)
    if r > 0:
        s = s.edges("|Z").fillet(r)
    return s.val()


def casting_tray(p: dict) -> cq.Solid:
    """The tray of one layer: a block `wall_mm` round the outline and `floor_mm` under the
    layer's bottom face (z0_mm), its cavity the outline `depth_mm` deep; ribs of the channels
    from inside the near wall to the closed far end, or holes of the markers below the floor;
    for a laser-cut tray also its registration holes, or its plate's outline and holes."""
    o = p["outline"]
    z0, t = float(p["z0_mm"]), float(p["depth_mm"])
    wall, floor = float(p["wall_mm"]), float(p["floor_mm"])
    # a laser-cut tray (designs/src/parts/lasercut.rs): the union of its sheets is this tray with
    # flat-ended marker holes and a registration hole through each corner of the wall
    laser = p.get("laser_cut")
    hw, hl = float(o["width_mm"]) / 2.0, float(o["length_mm"]) / 2.0
    # a wrapped stack's inner trays: the sheets are cut round the outermost pocket
    so = laser.get("sheets_round") if laser else None
    bw, bl = (float(so["width_mm"]) / 2.0, float(so["length_mm"]) / 2.0) if so else (hw, hl)
    plate = laser.get("plate") if laser else None
    if plate:
        # the published plate (mold.laser_cut.plate): its own rounded outline
        size = plate["size_mm"]
        block = outline_prism({"width_mm": size[0], "length_mm": size[1],
                               "corner_radius_mm": plate.get("corner_radius_mm", 0.0)},
                              z0 - floor, z0 + t)
    else:
        block = C.box([-bw - wall, -bl - wall, z0 - floor], [bw + wall, bl + wall, z0 + t])
    tray = C.cut(block, [outline_prism(o, z0, z0 + t + 1.0)])
    ch = p.get("channels")
    if ch:
        n, pitch = int(ch["count"]), float(ch["pitch_mm"])
        w, h, length = float(ch["width_mm"]), float(ch["height_mm"]), float(ch["length_mm"])
        ribs = []
        for i in range(n):
            x = (i - (n - 1) / 2.0) * pitch
            ribs.append(C.box([x - w / 2.0, -hl - wall / 2.0, z0 - 0.5],
                              [x + w / 2.0, -hl + length, z0 + h]))
        tray = C.fuse(tray, ribs)
    g = p.get("marker_grid")
    if g:
        rows, cols, pitch = int(g["rows"]), int(g["columns"]), float(g["pitch_mm"])
        f = g["feature"]
        d, h = float(f["diameter_mm"]), float(f["height_mm"])
        holes = []
        for r in range(rows):
            for c in range(cols):
                x, y = (c - (cols - 1) / 2.0) * pitch, (r - (rows - 1) / 2.0) * pitch
                if laser:
                    # straight through the marker sheet: flat-ended
                    holes.append(C.cylinder_z(d / 2.0, z0 - h, z0 + 1.0, x, y))
                else:
                    holes.append(C.place_along(C.feature(d, h, 1.0), (x, y, z0),
                                               (0.0, 0.0, -1.0)))
        tray = C.cut(tray, holes)
    if plate:
        # the plate's holes through the whole stack, and its base holes through the base sheet
        h = plate["holes"]
        tray = C.cut(tray, [C.cylinder_z(float(h["diameter_mm"]) / 2.0, z0 - floor - 1.0,
                                         z0 + t + 1.0, x, y) for x, y in h["xy_mm"]])
        b = plate.get("base_holes")
        if b:
            base = next(s for s in laser["sheets"] if s["role"] == "base")
            top = z0 - floor + float(base["level_mm"])
            tray = C.cut(tray, [C.cylinder_z(float(b["diameter_mm"]) / 2.0, z0 - floor - 1.0,
                                             top, x, y) for x, y in b["xy_mm"]])
    elif laser:
        # the registration holes through the whole stack
        r = float(laser["registration_diameter_mm"]) / 2.0
        tray = C.cut(tray, [C.cylinder_z(r, z0 - floor - 1.0, z0 + t + 1.0, x, y)
                            for x, y in laser["registration_xy_mm"]])
    return tray


def twin(part: dict):
    """The twin of a flat skin's casting tray (sensor frame), or None when `part` is not one."""
    return casting_tray(part["params"]) if part["role"] == "casting_tray" else None
