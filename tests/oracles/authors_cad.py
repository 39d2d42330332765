#!/usr/bin/env python3
"""authors_cad.py - fabkit's seed presets measured against the authors' published CAD.

Usage: authors_cad.py FABKIT_BINARY WORKDIR [--markdown]

Runs `fabkit export` / `fabkit fixtures` into WORKDIR and measures fabkit's exported files (STL
meshes mapped back into the sensor frame through each part's `T_print_sensor`, the manifest, the
point table) with numpy/trimesh, independently of fabkit's own code. Each row compares one
quantity with the authors' CAD (their STL/STEP files, measured: the ShadowTac repository's mold
STEP, the R-Tac0 files of the PP-Tac repository, the DIGIT Pinki gel and gel mold STEP files of
facebookresearch/digit-design) or TacTipGenerator's default layout, within a stated tolerance. Rows marked `differs` are known, documented differences (they are printed, not
asserted). With --markdown the table is printed in the form of docs/src/validation.md.

Exit status: 0 when every asserted row holds, 1 otherwise (each failure printed), 2 on a usage or
run error.
"""

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import trimesh

ROWS = []  # (sensor, quantity, authors, fabkit, ok or None)


def row(sensor, quantity, authors, fabkit_value, fmt="{}", tol=None, want=None, note=""):
    """Adds a row; asserted when `tol` is given (|fabkit - want| <= tol)."""
    text = fmt.format(fabkit_value) if not isinstance(fabkit_value, str) else fabkit_value
    ok = None
    if tol is not None:
        ok = bool(abs(fabkit_value - want) <= tol)
    ROWS.append((sensor, quantity, authors, text + (f" ({note})" if note else ""), ok))


def run(fabkit, args, cwd):
    o = subprocess.run([fabkit, *args], cwd=cwd, capture_output=True, text=True)
    if o.returncode != 0:
        sys.stderr.write(f"fabkit {' '.join(args)} failed ({o.returncode}):\n{o.stderr}")
        sys.exit(2)


def manifest(d):
    return json.loads((d / "manifest.json").read_text())


def part(m, name):
    for p in m["parts"]:
        if p["name"] == name:
            return p
    sys.stderr.write(f"no part {name} in the manifest\n")
    sys.exit(2)


def sensor_vertices(d, p):
    """The part's STL vertices in the sensor frame (T_print_sensor: 3x4 rows, sensor -> print)."""
    mesh = trimesh.load(d / p["file"], force="mesh", process=False)
    t = np.array(p["params"]["T_print_sensor"], dtype=float)
    return (np.asarray(mesh.vertices, dtype=float) - t[:, 3]) @ t[:, :3]


def print_mesh(d, p):
    return trimesh.load(d / p["file"], force="mesh", process=False)


def shadowtac(fabkit, work):
    run(fabkit, ["export", "shadowtac", "--out", "out/shadowtac", "--chord-tolerance-mm", "0.005"], work)
    d = work / "out/shadowtac"
    m = manifest(d)
    block, top = part(m, "skin_cavity_block"), part(m, "skin_reservoir_top")
    v = sensor_vertices(d, block)
    r = np.linalg.norm(v, axis=1)
    rho = 22.5
    z_rim = math.sqrt(rho * rho - 17.5 * 17.5)
    # the cavity wall: vertices on a sphere about the origin, at or above the rim plane
    wall = v[(np.abs(r - rho) < 0.05) & (v[:, 2] > z_rim - 1e-4)]
    # least-squares sphere centred on the axis, |p - (0, 0, c)|^2 = R^2, refitted without the
    # vertices inside the last fit: the booleans leave vertices on the facets where the pins
    # meet the wall, up to the chord tolerance inside the sphere (never outside it)
    keep = np.ones(len(wall), dtype=bool)
    for _ in range(8):
        a = np.c_[2 * wall[keep, 2], np.ones(keep.sum())]
        b = (wall[keep] ** 2).sum(axis=1)
        (c, k), *_ = np.linalg.lstsq(a, b, rcond=None)
        radius = math.sqrt(k + c * c)
        keep = np.linalg.norm(wall - [0, 0, c], axis=1) > radius - 1e-5
    rim = wall[np.abs(wall[:, 2] - z_rim) < 1e-3]
    rim_d = 2 * np.hypot(rim[:, 0], rim[:, 1]).max()
    depth = c + radius - rim[:, 2].mean()
    row("ShadowTac", "cavity sphere radius", "22.500 mm", radius, "{:.3f} mm", 0.002, 22.5)
    row("ShadowTac", "cavity rim diameter", "35.000 mm", rim_d, "{:.3f} mm", 0.002, 35.0)
    row("ShadowTac", "cavity depth", "8.358 mm", depth, "{:.3f} mm", 0.002, rho - z_rim)

    # pins standing into the cavity: vertices inside the sphere, above the rim plane
    pins = v[(r < rho - 0.01) & (v[:, 2] > z_rim + 0.01)]
    pr = np.linalg.norm(pins, axis=1)
    step = 3.9474
    want = [(0.0, 0.0)] + [(k * step, j * 360.0 / (6 * k)) for k in range(1, 13) for j in range(6 * k)]
    dirs = np.array([[math.sin(math.radians(p)) * math.cos(math.radians(a)),
                      math.sin(math.radians(p)) * math.sin(math.radians(a)),
                      math.cos(math.radians(p))] for p, a in want])
    # each pin vertex belongs to the authors' position whose axis it lies nearest to
    u = pins / pr[:, None]
    owner = np.argmax(u @ dirs.T, axis=1)
    lateral = np.linalg.norm(pins - (pins * dirs[owner]).sum(axis=1)[:, None] * dirs[owner], axis=1)
    stray = int((lateral > 0.225 + 0.01).sum())
    counts = np.bincount(owner, minlength=len(want))
    deepest = np.full(len(want), np.inf)
    np.minimum.at(deepest, owner, pr)
    # a pin's axis: the mean direction of its vertices beyond the base of its cylinder
    dev = 0.0
    polar = np.full(len(want), np.nan)
    for i in range(len(want)):
        sel = owner == i
        tipward = sel & (pr < rho - 0.3)
        if tipward.sum() < 3:
            continue
        centre = pins[tipward].mean(axis=0)
        off = centre - (centre @ dirs[i]) * dirs[i]
        dev = max(dev, float(np.linalg.norm(off) * rho / np.linalg.norm(centre)))
        polar[i] = math.degrees(math.acos(centre[2] / np.linalg.norm(centre)))
    n_pins = int((counts > 0).sum())
    row("ShadowTac", "pins in the cavity (dimples on the skin)", "469", float(n_pins), "{:.0f}", 0, 469)
    row("ShadowTac", "pin vertices off every authors' pin axis", "0", float(stray), "{:.0f}", 0, 0)
    height = rho - deepest[counts > 0]
    row("ShadowTac", "pin height (dimple depth)", "0.500 mm", float(height.min()), "{:.3f} mm",
        0.003, 0.5, note=f"max {height.max():.3f}")
    row("ShadowTac", "pin axes from the authors' positions", "0", dev, "{:.4f} mm", 0.01, 0.0)
    ring = np.array([0] + [k for k in range(1, 13) for _ in range(6 * k)])
    outer = float(np.nanmean(polar[ring == 12]))
    steps = [float(np.nanmean(polar[ring == k])) / k for k in range(1, 13)]
    row("ShadowTac", "ring step / outer ring", "3.9474 / 47.37 deg",
        f"{min(steps):.4f}-{max(steps):.4f} / {outer:.2f} deg", "{}")
    ROWS[-1] = ROWS[-1][:4] + (bool(abs(outer - 47.37) < 0.005 and max(abs(x - step) for x in steps) < 1e-3),)
    mk = m["summary"]["markers"][0]
    row("ShadowTac", "dimples listed in the manifest", "469", float(mk["count"]), "{:.0f}", 0, 469)

    # the top piece, in its print frame: 14 mm tall, 45 mm bore, boss 60 x 65 x 2
    tm = print_mesh(d, top)
    tv = np.asarray(tm.vertices, dtype=float)
    lo, hi = tv.min(axis=0), tv.max(axis=0)
    row("ShadowTac", "top piece height", "14.000 mm", hi[2] - lo[2], "{:.3f} mm", 1e-3, 14.0)
    cxy = (lo[:2] + hi[:2]) / 2
    rxy = np.hypot(tv[:, 0] - cxy[0], tv[:, 1] - cxy[1])
    row("ShadowTac", "reservoir bore diameter", "45.000 mm", 2 * rxy.min(), "{:.3f} mm", 2e-3, 45.0)
    bands = []
    for band in (tv[:, 2] > hi[2] - 2.0 + 1e-4, tv[:, 2] < lo[2] + 2.0 - 1e-4):
        ext = tv[band].max(axis=0) - tv[band].min(axis=0)
        bands.append((ext[0] * ext[1], ext))
    boss = min(bands, key=lambda b: b[0])[1]
    row("ShadowTac", "registration boss", "60 x 65 x 2 mm", f"{boss[0]:.3f} x {boss[1]:.3f} x 2 mm",
        "{}", None)
    ok_boss = abs(boss[0] - 60.0) < 1e-3 and abs(boss[1] - 65.0) < 1e-3
    ROWS[-1] = ROWS[-1][:4] + (bool(ok_boss),)
    holes = int(top["genus"]) - 1
    row("ShadowTac", "bolts", "20", float(holes), "{:.0f}", 0, 20)
    # bolt hole diameters measured on each piece's mesh: the wall vertices within 2.5 mm of each
    # bolt axis (the flange's edges are 4 mm away) lie on the hole's circle
    axes = np.asarray(top["params"]["frame"]["bolts_xy_mm"], dtype=float)

    def hole_diameters(p):
        pv = sensor_vertices(d, p)
        out = []
        for x, y in axes:
            rr = np.hypot(pv[:, 0] - x, pv[:, 1] - y)
            near = rr[rr < 2.5]
            out.append(2.0 * float(near.max()) if len(near) else float("nan"))
        return np.array(out)

    hb, ht = hole_diameters(block), hole_diameters(top)
    row("ShadowTac", "bolt holes, bottom / top piece", "3.5 / 3.4 mm",
        f"{hb.min():.3f}-{hb.max():.3f} / {ht.min():.3f}-{ht.max():.3f} mm", "{}")
    ok_holes = bool(np.all(np.abs(hb - 3.5) < 1e-3) and np.all(np.abs(ht - 3.4) < 1e-3)
                    and len(hb) == 20)
    ROWS[-1] = ROWS[-1][:4] + (ok_holes,)


def rtac0(fabkit, work):
    run(fabkit, ["export", "rtac0", "--out", "out/rtac0"], work)
    d = work / "out/rtac0"
    m = manifest(d)
    for name, want, what in [("translucent_gel_master_pattern", 15.0, "outer casting mold cavity"),
                             ("transparent_gel_master_pattern", 13.5, "transparent-layer mold cavity")]:
        v = sensor_vertices(d, part(m, name))
        r = np.linalg.norm(v[v[:, 2] > 1.0], axis=1)
        r = r[np.abs(r - want) < 0.5]
        row("R-Tac0", what, f"R{want:.3f}", float(np.median(r)), "R{:.3f}", 1e-4, want,
            note=f"{len(r)} vertices, at most {max(abs(r.max() - want), abs(r.min() - want)) * 1000:.1f} um off")
    tube = part(m, "shell_tube")
    v = sensor_vertices(d, tube)
    row("R-Tac0", "shell: round tube, outer diameter", "30.000 mm",
        2 * float(np.hypot(v[:, 0], v[:, 1]).max()), "{:.3f} mm", 2e-3, 30.0)
    collar = part(m, "shell_collar")
    cv = sensor_vertices(d, collar)
    row("R-Tac0", "shell height (collar, diffuser disc, tube)", "21.650 mm",
        float(cv[:, 2].max() - v[:, 2].min()), "{:.3f} mm", 1e-3, 21.65)
    base = part(m, "shell_base")
    row("R-Tac0", "shell material (tube + base)", "6,009 mm3",
        f"{tube['volume_mm3'] + collar['volume_mm3'] + base['volume_mm3']:,.0f} mm3 "
        f"(tube {tube['volume_mm3']:,.0f}, collar {collar['volume_mm3']:,.0f})", "{}",
        note="differs: the tube's bay and chamber, the collar and the base are fabkit's own")
    cut = next(c for c in m["cut_parts"] if c["name"] == "diffuser")
    row("R-Tac0", "diffuser disc (laser-cut)", "30 x 2 mm, 19.6 mm opening",
        f"{cut['thickness_mm']:g} mm, area {cut['area_mm2']:.2f} mm2", "{}")
    want = np.pi * (15.0 ** 2 - 9.8 ** 2)
    ROWS[-1] = ROWS[-1][:4] + (bool(abs(cut["area_mm2"] - want) < 1e-6 * want and cut["thickness_mm"] == 2.0),)
    sheet = (d / "FABRICATION.md").read_text()
    ok = "| `translucent_gel` | Smooth-On Ecoflex 00-30 | cast | 1.400 | R14.900 |" in sheet and \
        "| `black_coating` | Yonglihua PTG-501 black mill-resistant coating mixture | sprayed | 0.100 | R15.000 |" in sheet
    row("R-Tac0", "layers in FABRICATION.md", "(paper: 1.5 mm Ecoflex + coat)",
        "Ecoflex 1.400 mm to R14.9, coat 0.100 mm to R15.0", "{}")
    ROWS[-1] = ROWS[-1][:4] + (bool(ok),)


def pin_dome(fabkit, work):
    run(fabkit, ["fixtures", "rtac0", "--pins-preset", "rtac0", "--semidomes", "0",
                 "--out", "out/rtac0_fixtures"], work)
    d = work / "out/rtac0_fixtures"
    m = manifest(d)
    dome = part(m, "pin_dome")
    v = sensor_vertices(d, dome)
    r = np.linalg.norm(v, axis=1)
    up = v[:, 2] > 2.0
    # the median: vertices that booleans put on the facets (hole edges) sit up to the chord
    # tolerance inside the sphere
    inner = r[up & (r < 17.5)]
    row("R-Tac0 pin dome", "inner radius", "16.650 mm", float(np.median(inner)), "{:.3f} mm", 1e-3, 16.65)
    row("R-Tac0 pin dome", "outer radius", "19.100 mm", float(r[up].max()), "{:.3f} mm", 1e-3, 19.1)
    # the pole hole's counterbore: vertices on its wall (2.5 mm across) below the outer surface
    rxy = np.hypot(v[:, 0], v[:, 1])
    cb = v[(np.abs(rxy - 1.25) < 0.01) & (v[:, 2] > 17.0)]
    row("R-Tac0 pin dome", "counterbore depth on the hole axis", "0.350 mm",
        19.1 - float(cb[:, 2].min()), "{:.3f} mm", 1e-3, 0.35)
    # the groove: vertices on its floor sphere R18.5
    # (vertices where the groove's end faces meet its floor lie on the floor's facets, up to the
    # chord tolerance inside R18.5)
    g = v[(np.abs(r - 18.5) < 0.01) & (np.hypot(v[:, 0], v[:, 1]) > 1.0)]
    az = np.degrees(np.arctan2(g[:, 1], g[:, 0]))
    pol = np.degrees(np.arccos(np.clip(g[:, 2] / np.linalg.norm(g, axis=1), -1, 1)))
    row("R-Tac0 pin dome", "groove floor / azimuth / polar", "R18.50, 65-66 deg, 5.6-86.5 deg",
        f"R18.50, {az.min():.1f}-{az.max():.1f} deg, {pol.min():.1f}-{pol.max():.1f} deg", "{}")
    ok = len(g) > 10 and abs(az.min() - 65) < 0.05 and abs(az.max() - 66) < 0.05 \
        and abs(pol.min() - 5.6) < 0.05 and abs(pol.max() - 86.5) < 0.05
    ROWS[-1] = ROWS[-1][:4] + (bool(ok),)
    span = float(max(np.ptp(v[:, 0]), np.ptp(v[:, 1])))
    row("R-Tac0 pin dome", "base with two tabs, across", "43.000 mm", span, "{:.3f} mm", 1e-3, 43.0)

    pin = print_mesh(d, part(m, "pin"))
    pv = np.asarray(pin.vertices, dtype=float)
    lo, hi = pv.min(axis=0), pv.max(axis=0)
    c = (lo[:2] + hi[:2]) / 2
    pr = np.hypot(pv[:, 0] - c[0], pv[:, 1] - c[1])
    head = pv[pr > 1.49]
    row("R-Tac0 pin", "length overall", "8.800 mm", hi[2] - lo[2], "{:.3f} mm", 1e-3, 8.8)
    row("R-Tac0 pin", "head diameter x height", "3.000 x 3.200 mm",
        f"{2 * pr.max():.3f} x {np.ptp(head[:, 2]):.3f} mm", "{}")
    ROWS[-1] = ROWS[-1][:4] + (bool(abs(2 * pr.max() - 3.0) < 2e-3 and abs(np.ptp(head[:, 2]) - 3.2) < 1e-3),)
    shaft = pr[pr < 1.4]
    row("R-Tac0 pin", "shaft diameter", "1.600 mm", 2 * float(shaft.max()), "{:.3f} mm", 2e-3, 1.6)

    lines = [ln for ln in (d / "points/point_table.csv").read_text().splitlines() if not ln.startswith("#")]
    table = list(csv.DictReader(lines))
    tips = np.array([[float(t["tip_x_mm"]), float(t["tip_y_mm"]), float(t["tip_z_mm"])] for t in table])
    tr = np.linalg.norm(tips, axis=1)
    row("R-Tac0 pin dome", "seated pin tips", "R14.50 (authors' hand-typed table)",
        float(tr.mean()), "R{:.2f}", note="differs: the authors' own dome and pin seat the tips here, below their table")
    ids = {int(t["id"]): tip for t, tip in zip(table, tips)}

    def az_of(i):
        return math.degrees(math.atan2(ids[i][1], ids[i][0])) % 360

    numbering = [az_of(2), az_of(3), az_of(4), az_of(5)]
    ok = all(abs(((a - w + 180) % 360) - 180) < 1e-6 for a, w in zip(numbering, [0, 270, 180, 90]))
    for first in (6, 14, 22):
        ok &= abs(((az_of(first) + 180) % 360) - 180) < 1e-6
        ok &= abs(((az_of(first + 1) - 315 + 180) % 360) - 180) < 1e-6
    row("R-Tac0 pin dome", "hole ids", "ring 1: 2 +x, 3 -y, 4 -x, 5 +y; 6, 14, 22 at +x, then -45 deg",
        "the same", "{}")
    ROWS[-1] = ROWS[-1][:4] + (bool(ok),)

    ring = part(m, "pin_dome_ring")
    rv = sensor_vertices(d, ring)
    ext = rv.max(axis=0) - rv.min(axis=0)
    row("R-Tac0 calibration ring", "outer diameter", "42.300 mm", float(max(ext[0], ext[1])),
        "{:.3f} mm", 2e-3, 42.3, note="the dome's tabs make the authors' 43 mm across")
    row("R-Tac0 calibration ring", "height", "28.150 mm", float(ext[2]), "{:.3f} mm", 1e-3, 28.15)


def tactip(fabkit, work):
    run(fabkit, ["export", "tactip_dualmodal", "--preset", "tactipgenerator_217", "--out",
                 "out/tactip_217"], work)
    m = manifest(work / "out/tactip_217")
    mk = m["summary"]["markers"][0]
    row("TacTip", "TacTipGenerator default layout: pins", "217", float(mk["count"]), "{:.0f}", 0, 217)


def pinki_surfaces(z_shift):
    """The published DIGIT Pinki surfaces (`Pinki Gel.step`, `Pinki Gel Mold.step`, exact
    B-rep faces, mm) as distance functions of (rho, z) in fabkit's sensor frame, whose z is the
    CAD's plus `z_shift`."""
    t = math.tan(math.radians(2.0))
    c = math.cos(math.radians(2.0))
    zs = -12.6400119738395 + z_shift   # the recess roof's sphere centre
    zt = -7.13970690406748 + z_shift   # the fillet torus's centre plane
    zr = -7.02109322044459 + z_shift   # the cone's reference circle R4.875
    zb = -8.5 + z_shift                # the gel's base (the mold's open face)
    return {
        "tip sphere R7.5": lambda r, z: np.where(z >= -0.4 + z_shift - 1e-9,
                                                 np.abs(np.hypot(r, z + 0.4 - z_shift) - 7.5), np.inf),
        "cylinder R7.5": lambda r, z: np.where((z <= -0.4 + z_shift + 1e-9) & (z >= zb - 1e-9),
                                               np.abs(r - 7.5), np.inf),
        "base plane": lambda r, z: np.abs(z - zb),
        "recess cone 2 deg": lambda r, z: np.abs((r - (4.87499999999981 + (zr - z) * t)) * c),
        "recess fillet torus": lambda r, z: np.abs(np.hypot(r - 4.62898969502947, z - zt) - 0.25),
        "recess roof R7.438943": lambda r, z: np.abs(np.hypot(r, z - zs) - 7.438943),
        "block top": lambda r, z: np.abs(z - (8.5 + z_shift)),
    }


def off_surfaces(points, surfaces, names):
    """The largest distance of `points` (N x 3, sensor frame) from the nearest of `names`."""
    r, z = np.hypot(points[:, 0], points[:, 1]), points[:, 2]
    return float(np.min([surfaces[n](r, z) for n in names], axis=0).max())


def digit_pinki(fabkit, work):
    run(fabkit, ["export", "digit_pinki", "--out", "out/digit_pinki", "--chord-tolerance-mm", "0.005"], work)
    d = work / "out/digit_pinki"
    m = manifest(d)
    sf = pinki_surfaces(0.4)  # fabkit's frame: the tip sphere's centre at the origin
    # the gel: the assembly's cast member (assembly.3mf, sensor frame)
    import xml.etree.ElementTree as ET
    import zipfile
    ns = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}
    with zipfile.ZipFile(d / m["assembly_3mf"]["file"]) as z:
        root = ET.fromstring(z.read("3D/3dmodel.model"))
    obj = next(o for o in root.iterfind(".//m:object", ns) if o.get("name") == "gel")
    gv = np.array([[float(v.get(k)) for k in "xyz"] for v in obj.iterfind(".//m:vertex", ns)])
    gt = np.array([[int(t.get(k)) for k in ("v1", "v2", "v3")] for t in obj.iterfind(".//m:triangle", ns)])
    gel = trimesh.Trimesh(gv, gt, process=False)
    gel_faces = ["tip sphere R7.5", "cylinder R7.5", "base plane", "recess cone 2 deg",
                 "recess fillet torus", "recess roof R7.438943"]
    insert_faces = ["base plane", "recess cone 2 deg", "recess fillet torus", "recess roof R7.438943"]
    block_faces = ["tip sphere R7.5", "cylinder R7.5", "base plane", "block top"]
    for what, mesh, faces in [
        ("gel", gel, gel_faces),
        ("mold cavity block", None, block_faces),
        ("mold insert", None, insert_faces),
    ]:
        if mesh is None:
            p = part(m, "gel_open_mold" if what == "mold cavity block" else "gel_recess_insert")
            v = sensor_vertices(d, p)
            mesh = trimesh.Trimesh(v, np.asarray(print_mesh(d, p).faces), process=False)
        # every vertex and every facet's centre (a facet's sag is largest near it)
        pts = np.vstack([np.asarray(mesh.vertices, dtype=float), mesh.triangles_center])
        if what == "mold cavity block":
            # less the block's four sides: the 25.4 mm square
            side = (np.abs(np.abs(pts[:, 0]) - 12.7) < 1e-4) | (np.abs(np.abs(pts[:, 1]) - 12.7) < 1e-4)
            pts = pts[~side]
        worst = off_surfaces(pts, sf, faces)
        row("DIGIT Pinki", f"{what}: vertices and facet centres off the published faces",
            "0 (exact faces)", worst * 1000, "{:.1f} um", 10.0, 0.0)
    # volumes: the published gel 2132.3 mm3; the mold's two solids 8835.4 mm3 together
    row("DIGIT Pinki", "gel volume", "2,132.3 mm3", float(gel.volume), "{:,.1f} mm3",
        0.001 * 2132.3, 2132.3)
    mold = part(m, "gel_open_mold")["volume_mm3"] + part(m, "gel_recess_insert")["volume_mm3"]
    row("DIGIT Pinki", "mold volume (cavity block + insert)", "8,835.4 mm3", float(mold),
        "{:,.1f} mm3", 0.001 * 8835.4, 8835.4)
    bv = sensor_vertices(d, part(m, "gel_open_mold"))
    ext = bv.max(axis=0) - bv.min(axis=0)
    row("DIGIT Pinki", "mold block", "25.4 x 25.4 x 17.0 mm",
        f"{ext[0]:.3f} x {ext[1]:.3f} x {ext[2]:.3f} mm", "{}")
    ROWS[-1] = ROWS[-1][:4] + (bool(np.all(np.abs(ext - [25.4, 25.4, 17.0]) < 1e-4)),)


def main():
    if len(sys.argv) < 3:
        sys.stderr.write(__doc__)
        sys.exit(2)
    fabkit, work = str(Path(sys.argv[1]).resolve()), Path(sys.argv[2])
    work.mkdir(parents=True, exist_ok=True)
    for f in (shadowtac, rtac0, pin_dome, tactip, digit_pinki):
        f(fabkit, work)
    failed = [r for r in ROWS if r[4] is False]
    if "--markdown" in sys.argv:
        print("| sensor | quantity | authors' CAD | fabkit |")
        print("|---|---|---|---|")
        for s, q, a, f, _ in ROWS:
            print(f"| {s} | {q} | {a} | {f} |")
    else:
        for s, q, a, f, ok in ROWS:
            mark = {True: "ok  ", False: "FAIL", None: "info"}[ok]
            print(f"{mark} {s}: {q}: authors {a}, fabkit {f}")
    print(f"authors_cad: {sum(1 for r in ROWS if r[4])} ok, {len(failed)} failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
