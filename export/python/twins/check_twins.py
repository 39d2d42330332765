#!/usr/bin/env python3
"""Cross-verify fabkit exports against their twins and write the Markdown report (issue 7).

Usage: python export/python/twins/check_twins.py EXPORT_DIR... --report REPORT.md
                                   [--json OUT.json] [--tier fast|full] [--skip-manifold3d]
                                   [--exact-from-step]   (from any directory)

Each EXPORT_DIR is a `fabkit export` or `fabkit fixtures` output (manifest.json, parts/*.stl)
with the CSG tree of its parts beside it as EXPORT_DIR.csg.json (`--csg`). Per part:
- manifold3d twin (both tiers): the part's booleans redone from its primitives (the CSG leaf
  meshes): status NoError, volume within 1e-6 relative of fabkit's, genus equal, bounding box
  and symmetric Hausdorff distance to the written mesh within tol + 1 um;
- CadQuery twin (full tier): the exact B-rep rebuilt from the manifest's params alone: volume
  within the chord-tolerance bound, symmetric Hausdorff distance <= tol + 1 um, bounding box
  within tol + 1 um, genus equal, its tessellation watertight once OCCT's zero-area pole facets
  are dropped (see compare.py).
--skip-manifold3d leaves the manifold3d twin out of the full tier (for exports whose manifold3d
twin a fast-tier run checks).
--exact-from-step (full tier, exports made with `--format step`): the exact solid of each part is
its STEP file read back (CadQuery import) instead of a twin built here: the STEP export built it
from the same params with the same twin (and checked its volume and box against fabkit's before
writing), so each twin is built once per export. The file must be the one the manifest hashes
(step_sha256) and import as a valid shape with at least one solid; its row then holds the same
comparisons as a twin's. A machined part's STEP file (made to order, no mesh) gets a row of its
own: valid, one solid, its volume within 1e-6 relative of the exact shape the manifest gives.
The written mesh itself must be watertight and consistently oriented. One report row per part; exit status 1 when any row is out of bounds, 2 on unreadable
input.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from twins import compare as K  # noqa: E402
from twins import m3d_twin  # noqa: E402


def read_step(d: Path, entry: dict, row: dict):
    """The STEP file of a manifest entry (a part or a machined part) read back by CadQuery: the
    file the manifest names and hashes, a valid shape with at least one solid. Raises ValueError
    naming what is wrong; records `step_solids` in `row`."""
    import hashlib

    import cadquery as cq
    name = entry.get("step_file")
    if not name:
        raise ValueError("no step_file in the manifest")
    path = d / name
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    if digest != entry.get("step_sha256"):
        raise ValueError(f"{name}: sha256 {digest} is not the manifest's {entry.get('step_sha256')}")
    shape = cq.importers.importStep(str(path)).val()
    row["step_solids"] = K._solids(shape)
    if not shape.isValid():
        raise ValueError(f"{name}: not a valid shape once read back")
    if row["step_solids"] < 1:
        raise ValueError(f"{name}: no solid")
    return shape


def exact_solid(d: Path, part: dict, from_step: bool, row: dict):
    """The exact solid of `part` in print orientation: its STEP file read back (`from_step`) or
    the CadQuery twin built from its params."""
    row["exact_source"] = "step" if from_step else "twin"
    if from_step:
        return read_step(d, part, row)
    from twins import cq_twin
    return cq_twin.build(part)


def check_machined(d: Path, mp: dict, tol: float, design_name: str) -> dict:
    """A machined part's STEP file (made to order: no mesh, an exact shape in the manifest) read
    back: valid, one solid, volume within 1e-6 relative of the exact shape."""
    from twins import cq_common, step_export
    row = {"design": d.name, "design_name": design_name, "part": mp["name"],
           "role": "machined", "family": "machined part (exact shape)", "tol_mm": tol,
           "triangles": None, "genus_fabkit": None, "exact_source": "step", "problems": []}
    try:
        shape = read_step(d, mp, row)
        v_step = cq_common.exact_volume(shape)
        v_exact = cq_common.exact_volume(step_export.exact_member(mp["exact"]))
        rel = abs(v_step - v_exact) / abs(v_exact)
        row.update({"volume_step_mm3": v_step, "volume_exact_mm3": v_exact,
                    "step_volume_rel_diff": rel})
        if not rel <= 1e-6:
            row["problems"].append(f"STEP volume {v_step:.6f} mm3 vs exact {v_exact:.6f} "
                                   f"(rel {rel:.1e} > 1e-6)")
        if row["step_solids"] != 1:
            row["problems"].append(f"{row['step_solids']} solids in the STEP file, not 1")
    except Exception as ex:
        row["problems"].append(f"STEP read-back failed: {type(ex).__name__}: {ex}")
    row["ok"] = not row["problems"]
    return row


def check_export(d: Path, tier: str, log, manifold3d: bool = True,
                 from_step: bool = False) -> list[dict]:
    man = json.loads((d / "manifest.json").read_text())
    tol = float(man["chord_tolerance_mm"])
    csg_path = Path(str(d) + ".csg.json")
    m3d = m3d_twin.replay(csg_path) if manifold3d and csg_path.exists() else None
    rows = []
    exact = {}  # part name -> its exact solid (full tier), for the sheets cut from a tray
    for part in man["parts"]:
        name = part["name"]
        row = {"design": d.name, "design_name": man["design"]["name"], "part": name,
               "role": part["role"],
               "tol_mm": tol, "triangles": part["triangles"], "genus_fabkit": part["genus"],
               "problems": []}
        fv, ff = K.load_stl(d / part["file"])
        ok, _ = K.edge_stats(ff)
        if not ok:
            row["problems"].append("written mesh not watertight / not consistently oriented")
        hb = K.hausdorff_bound(tol)
        # manifold3d twin
        if manifold3d and m3d is None:
            row["problems"].append(f"no CSG file {csg_path.name}")
        elif manifold3d:
            r = m3d.get(name)
            if r is None:
                row["problems"].append("part missing from the CSG file")
            else:
                row.update({"m3d_status": r["status"], "m3d_volume_rel_diff": r["volume_rel_diff"],
                            "m3d_genus": r["genus"]})
                mv, mf = r["mesh"]
                placed = mv  # the CSG root is the part in print orientation
                row["m3d_hausdorff_mm"] = K.mesh_hausdorff(placed, mf, fv, ff, dense=False)
                row["m3d_bbox_dev_mm"] = K.bbox_dev(placed.min(axis=0), placed.max(axis=0),
                                                    part["bbox_mm"]["min"], part["bbox_mm"]["max"])
                if r["status"] != "NoError":
                    row["problems"].append(f"manifold3d status {r['status']}")
                if not r["volume_rel_diff"] <= 1e-6:
                    row["problems"].append(f"manifold3d volume rel diff {r['volume_rel_diff']:.2e} > 1e-6")
                if r["genus"] != part["genus"]:
                    row["problems"].append(f"manifold3d genus {r['genus']} != {part['genus']}")
                if not row["m3d_hausdorff_mm"] <= hb:
                    row["problems"].append(f"manifold3d Hausdorff {row['m3d_hausdorff_mm']:.2e} mm > {hb}")
                if not row["m3d_bbox_dev_mm"] <= hb:
                    row["problems"].append(f"manifold3d bbox off by {row['m3d_bbox_dev_mm']:.2e} mm")
        if tier == "full":
            from twins import cq_twin
            row["family"] = cq_twin.family(part)
            t0 = time.perf_counter()
            try:
                shape = exact_solid(d, part, from_step, row)
                exact[name] = shape
                row["cq_build_s"] = time.perf_counter() - t0
                t1 = time.perf_counter()
                e = K.compare_exact(fv, ff, shape, tol)
                row["cq_compare_s"] = time.perf_counter() - t1
                row.update(e)
                if not abs(e["volume_diff_mm3"]) <= e["volume_bound_mm3"]:
                    row["problems"].append(
                        f"volume off the exact solid by {e['volume_diff_mm3']:.4g} mm3 "
                        f"(bound {e['volume_bound_mm3']:.4g})")
                if not e["hausdorff_mm"] <= hb:
                    row["problems"].append(f"Hausdorff {e['hausdorff_mm']:.4g} mm > {hb:.4g}")
                if not e["hausdorff_seam_mm"] <= hb:
                    row["problems"].append(
                        f"Hausdorff at seams {e['hausdorff_seam_mm']:.4g} mm > {hb:.4g}")
                if not e["bbox_dev_mm"] <= hb:
                    row["problems"].append(f"bbox off by {e['bbox_dev_mm']:.4g} mm")
                if not e["exact_mesh_watertight"]:
                    row["problems"].append("exact twin's tessellation not watertight")
                g_f = part["genus"]
                if e["genus_exact"] != g_f:
                    row["problems"].append(f"genus {g_f} vs exact {e['genus_exact']}")
            except Exception as ex:  # a twin that cannot be built or read is a failed row
                row["cq_build_s"] = time.perf_counter() - t0
                what = "STEP read-back" if from_step else "CadQuery twin"
                row["problems"].append(f"{what} failed: {type(ex).__name__}: {ex}")
        else:
            from twins.families import family
            row["family"] = family(part)
        row["ok"] = not row["problems"]
        log(f"{'PASS' if row['ok'] else 'FAIL'} {row['design']}/{name}"
            + ("" if row["ok"] else ": " + "; ".join(row["problems"])))
        rows.append(row)
    rows += _check_sheets(d, man, tol, tier, log, m3d, exact)
    if tier == "full" and from_step:
        for mp in man.get("machined_parts") or []:
            row = check_machined(d, mp, tol, man["design"]["name"])
            log(f"{'PASS' if row['ok'] else 'FAIL'} {row['design']}/{row['part']} (machined)"
                + ("" if row["ok"] else ": " + "; ".join(row["problems"])))
            rows.append(row)
    return rows


def _check_sheets(d: Path, man: dict, tol: float, tier: str, log, m3d,
                  exact: dict) -> list[dict]:
    """The laser-cut sheets of the trays (`cut/<sheet>.stl`; designs/src/parts/lasercut.rs): each is
    its tray (the union of the sheets) between the planes of its faces, so the twins are the
    tray's twins cut there: manifold3d (the tray's replayed booleans, both tiers) and CadQuery
    (the tray's exact solid, full tier: `exact`, the part loop's, else its twin built here),
    with the parts' bounds."""
    sheets = {s["name"]: (p, s) for p in man["parts"]
              for s in ((p.get("params") or {}).get("laser_cut") or {}).get("sheets", [])}
    rows = []
    for c in man.get("cut_parts", []):
        if "stl" not in c:
            continue
        name = c["name"]
        row = {"design": d.name, "design_name": man["design"]["name"], "part": name,
               "role": "laser_cut_sheet", "family": "laser-cut sheets (flat skins)",
               "tol_mm": tol, "problems": []}
        fv, ff = K.load_stl(d / c["stl"])
        row["triangles"] = len(ff)
        ok, _ = K.edge_stats(ff)
        if not ok:
            row["problems"].append("written mesh not watertight / not consistently oriented")
        hb = K.hausdorff_bound(tol)
        found = sheets.get(name)
        if found is None:
            row["problems"].append("no tray lists this sheet")
            row["genus_fabkit"] = None
        else:
            tray, s = found
            z0, z1 = float(s["z0_mm"]), float(s["z0_mm"]) + float(s["stock"]["thickness_mm"])
            if m3d is not None and tray["name"] in m3d:
                status, vol, genus, (mv, mf) = m3d_twin.slab(m3d[tray["name"]]["manifold"], z0, z1)
                v_f = K.mesh_volume(fv, ff)
                row.update({"m3d_status": status, "m3d_genus": genus,
                            "m3d_volume_rel_diff": abs(vol - v_f) / abs(v_f),
                            "m3d_hausdorff_mm": K.mesh_hausdorff(mv, mf, fv, ff, dense=False)})
                # the STL's float32 vertices: its volume within 1e-6
                if not row["m3d_volume_rel_diff"] <= 1e-6:
                    row["problems"].append(f"manifold3d volume rel diff {row['m3d_volume_rel_diff']:.2e} > 1e-6")
                if not row["m3d_hausdorff_mm"] <= hb:
                    row["problems"].append(f"manifold3d Hausdorff {row['m3d_hausdorff_mm']:.2e} mm > {hb}")
            elif m3d is not None:
                row["problems"].append(f"tray {tray['name']} missing from the CSG file")
            row["genus_fabkit"] = row.get("m3d_genus")
            if tier == "full":
                from twins import cq_twin
                import cadquery as cq
                t0 = time.perf_counter()
                try:
                    t = exact[tray["name"]] if tray["name"] in exact else cq_twin.build(tray)
                    bb = t.BoundingBox()
                    box = cq.Solid.makeBox(bb.xlen + 2.0, bb.ylen + 2.0, z1 - z0,
                                           cq.Vector(bb.xmin - 1.0, bb.ymin - 1.0, z0))
                    shape = t.intersect(box).translate(cq.Vector(0.0, 0.0, -z0))
                    row["cq_build_s"] = time.perf_counter() - t0
                    e = K.compare_exact(fv, ff, shape, tol)
                    row.update(e)
                    if not abs(e["volume_diff_mm3"]) <= e["volume_bound_mm3"]:
                        row["problems"].append(f"volume off the exact solid by {e['volume_diff_mm3']:.4g} mm3")
                    if not e["hausdorff_mm"] <= hb or not e["hausdorff_seam_mm"] <= hb:
                        row["problems"].append(f"Hausdorff {e['hausdorff_mm']:.4g} / {e['hausdorff_seam_mm']:.4g} mm > {hb:.4g}")
                    if not e["bbox_dev_mm"] <= hb:
                        row["problems"].append(f"bbox off by {e['bbox_dev_mm']:.4g} mm")
                    if row["genus_fabkit"] is not None and e["genus_exact"] != row["genus_fabkit"]:
                        row["problems"].append(f"genus {row['genus_fabkit']} vs exact {e['genus_exact']}")
                except Exception as ex:  # a twin that cannot be built is a failed row
                    row["problems"].append(f"CadQuery twin failed: {type(ex).__name__}: {ex}")
        row["ok"] = not row["problems"]
        log(f"{'PASS' if row['ok'] else 'FAIL'} {row['design']}/{name}"
            + ("" if row["ok"] else ": " + "; ".join(row["problems"])))
        rows.append(row)
    return rows


def fmt(x, spec=".3g", scale=1.0):
    return "n/a" if x is None else format(x * scale, spec)


def report(rows: list[dict], tier: str, meta: dict, manifold3d: bool = True) -> str:
    what = ("manifold3d only" if tier != "full" else "CadQuery exact twins and manifold3d"
            if manifold3d else "CadQuery exact twins; manifold3d not checked here")
    out = ["# fabkit twin cross-verification", "",
           f"Tier: {tier} ({what}). "
           + ", ".join(f"{k} {v}" for k, v in meta.items()), "",
           "Bounds: volume vs exact <= area x tol + 1e-6 V; vs manifold3d <= 1e-6 relative; "
           "symmetric Hausdorff (over faces and at the exact solid's edges) and bounding box "
           "<= tol + 1 um (see export/python/twins/compare.py); genus equal.", ""]
    if tier == "full":
        out += ["| export | part | family | triangles | V fabkit mm3 | V exact mm3 | dV / bound | "
                "V m3d rel diff | Hausdorff exact um (bound) | at seams um (bound) | Hausdorff m3d um | bbox dev um | "
                "genus fabkit/exact/m3d | pole facets dropped | CadQuery s | result |",
                "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---|"]
        for r in rows:
            ratio = (abs(r["volume_diff_mm3"]) / r["volume_bound_mm3"]
                     if r.get("volume_bound_mm3") else None)
            out.append(
                f"| {r['design']} | {r['part']} | {r.get('family', '')} | {r['triangles']} | "
                f"{fmt(r.get('volume_fabkit_mm3'), '.2f')} | {fmt(r.get('volume_exact_mm3'), '.2f')} | "
                f"{fmt(ratio, '.2f')} | {fmt(r.get('m3d_volume_rel_diff'), '.1e')} | "
                f"{fmt(r.get('hausdorff_mm'), '.2f', 1e3)} ({fmt(K.hausdorff_bound(r['tol_mm']), '.1f', 1e3)}) | "
                f"{fmt(r.get('hausdorff_seam_mm'), '.2f', 1e3)} ({fmt(K.hausdorff_bound(r['tol_mm']), '.1f', 1e3)}) | "
                f"{fmt(r.get('m3d_hausdorff_mm'), '.3f', 1e3)} | {fmt(r.get('bbox_dev_mm'), '.2f', 1e3)} | "
                f"{r['genus_fabkit']}/{r.get('genus_exact', 'n/a')}/{r.get('m3d_genus', 'n/a')} | "
                f"{r.get('exact_mesh_pole_facets_dropped', 'n/a')} | "
                f"{fmt((r.get('cq_build_s') or 0) + (r.get('cq_compare_s') or 0), '.1f')} | "
                f"{'ok' if r['ok'] else 'FAIL: ' + '; '.join(r['problems'])}"
                " |")
    else:
        out += ["| export | part | family | triangles | V m3d rel diff | Hausdorff m3d um | "
                "bbox dev um | genus fabkit/m3d | result |",
                "|---|---|---|---:|---:|---:|---:|---|---|"]
        for r in rows:
            out.append(
                f"| {r['design']} | {r['part']} | {r.get('family', '')} | {r['triangles']} | "
                f"{fmt(r.get('m3d_volume_rel_diff'), '.1e')} | {fmt(r.get('m3d_hausdorff_mm'), '.3f', 1e3)} | "
                f"{fmt(r.get('m3d_bbox_dev_mm'), '.3f', 1e3)} | {r['genus_fabkit']}/{r.get('m3d_genus', 'n/a')} | "
                f"{'ok' if r['ok'] else 'FAIL: ' + '; '.join(r['problems'])} |")
    bad = [r for r in rows if not r["ok"]]
    out += ["", f"{len(rows) - len(bad)} passed, {len(bad)} failed", ""]
    return "\n".join(out)


def _log(s: str) -> None:
    print(s, flush=True)


def _check_export_logged(d: Path, tier: str, manifold3d: bool, from_step: bool) -> list[dict]:
    return check_export(d, tier, _log, manifold3d, from_step)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("exports", nargs="+", type=Path)
    ap.add_argument("--report", type=Path, required=True, help="Markdown report to write")
    ap.add_argument("--json", type=Path, help="also write the rows as JSON")
    ap.add_argument("--tier", choices=["fast", "full"], default="full")
    ap.add_argument("--skip-manifold3d", action="store_true",
                    help="full tier: the CadQuery twin only (for exports whose manifold3d twin "
                         "another run of the fast tier checks)")
    ap.add_argument("--exact-from-step", action="store_true",
                    help="full tier: each part's exact solid is its STEP file read back (exports "
                         "made with --format step), not a twin built here")
    ap.add_argument("--jobs", type=int, default=0,
                    help="exports checked in parallel processes (default: one per CPU)")
    args = ap.parse_args(argv)
    for d in args.exports:
        if not (d / "manifest.json").is_file():
            print(f"check_twins: {d}: no manifest.json", file=sys.stderr)
            return 2
    t0 = time.perf_counter()
    jobs = min(len(args.exports), args.jobs if args.jobs > 0 else (os.cpu_count() or 1))
    if args.skip_manifold3d and args.tier != "full":
        print("check_twins: --skip-manifold3d leaves the fast tier nothing to check", file=sys.stderr)
        return 2
    if args.exact_from_step and args.tier != "full":
        print("check_twins: --exact-from-step is for the full tier", file=sys.stderr)
        return 2
    m3d = not args.skip_manifold3d
    step = args.exact_from_step
    rows = []
    if jobs <= 1:
        for d in args.exports:
            rows += check_export(d, args.tier, _log, m3d, step)
    else:
        # one export per task, in the given order; the rows keep that order
        n = len(args.exports)
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            for r in pool.map(_check_export_logged, args.exports, [args.tier] * n, [m3d] * n,
                              [step] * n):
                rows += r
    meta = {"seconds": f"{time.perf_counter() - t0:.1f}"}
    if args.tier == "full":
        meta["exact solids"] = "the exports' STEP files read back" if step else "twins built here"
    try:
        from importlib import metadata
        meta["manifold3d"] = metadata.version("manifold3d")
        if args.tier == "full":
            meta["cadquery"] = metadata.version("cadquery")
    except Exception:
        pass
    text = report(rows, args.tier, meta, m3d)
    args.report.parent.mkdir(parents=True, exist_ok=True)
    args.report.write_text(text)
    if args.json:
        clean = [{k: v for k, v in r.items()} for r in rows]
        args.json.write_text(json.dumps(clean, indent=1, default=float))
    bad = sum(not r["ok"] for r in rows)
    print(f"check_twins: {len(rows) - bad} passed, {bad} failed; report {args.report}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
