#!/usr/bin/env python3
"""Independent oracle for a fabkit output directory.

Usage: check_parts.py OUT_DIR [--json] [--vol-rel-tol R] [--bbox-tol-mm T] [--kit-vol-rel-tol R]

Reads OUT_DIR/manifest.json (written by fabkit's export crate) and checks every part's STL with
two readers that share no code with fabkit:

* trimesh: closed (every edge in exactly two faces: ``is_watertight``), consistently wound
  (``is_winding_consistent``), volume > 0;
* manifold3d: the same vertices/faces give a Manifold whose ``status()`` is ``Error.NoError``
  (built as float64 ``Mesh64`` where the installed manifold3d has it);
* against the manifest: volume_mm3 (trimesh's and manifold3d's, within --vol-rel-tol relative plus
  1e-6 mm^3), surface_area_mm2 (same tolerance), bbox_mm (within --bbox-tol-mm), triangles (exact),
  genus (exact), sha256 of the file (exact), print_technology (FDM, SLA or PolyJet), group (a
  string or null when present).

genus is fabkit's: the sum of the genera of the shells, shells - chi/2, so a part made of N
disjoint balls has genus 0 (manifold3d's ``genus()`` is 1 - chi/2 over the whole mesh, -1 for two
balls). chi = V - E + F comes from manifold3d's vertex, edge and triangle counts; shells are the
edge-connected components of trimesh's face adjacency, counted here.

If the manifest has ``kit_3mf``, the 3MF is loaded as a trimesh Scene (the meshes) and read with
ElementTree (units, object names and ids, build items, and PrusaSlicer's
``Metadata/Slic3r_PE_model.config``). It must hold exactly one geometry per part, named as the part:
an object of its own (object name = part name), or a volume of an object that the PrusaSlicer
config splits into named triangle ranges (``<volume firstid lastid>`` with ``name`` metadata; the
ranges must split the object's triangles exactly). Each part's object is placed by exactly one
build item; each part is watertight, has the part's volume (within --kit-vol-rel-tol relative) and
in its object's coordinates the bounding box of the part's STL (of bbox_mm without an STL; within
--bbox-tol-mm: objects hold parts in part coordinates). The 3MF's sha256 must match, its model must say unit="millimeter" (or no unit: the
3MF default), and ``objects`` must describe it (a count, or per object id, name, translation_mm of
its build item and volumes: part, first_triangle, last_triangle). Parts that share a ``group``
(one multi-material print, built in shared coordinates) must be the volumes of one object holding
nothing else, so one build item places the whole group and it stays registered; parts of
different groups or ungrouped parts never share an object.

STL is a triangle soup: vertices are welded only where their coordinates are bit-identical (what a
float32 STL of a closed mesh has); nothing else is merged or repaired, so a gap of one float32 ulp
is a FAIL, as it should be.

Prints one line per checked item (each part, then the kit 3MF) starting with PASS or FAIL, and a
last line ``N passed, M failed``. With --json those lines go to stderr and stdout gets one JSON
object: {"passed", "failed", "manifold3d_mesh", "items": [{"kind", "name", "file", "ok", "reasons",
"measured"}]}. Exit status: 0 all passed, 1 any failure, 2 unreadable manifest or usage error.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
import zipfile
import xml.etree.ElementTree as ET
from pathlib import Path

import manifold3d
import numpy as np
import trimesh

VOL_ABS_TOL_MM3 = 1e-6
PRINT_TECHNOLOGIES = ("FDM", "SLA", "PolyJet")
# The manifest's translation and the build item's are the same decimal text; this only absorbs a
# reader that composes matrices.
PLACEMENT_TOL_MM = 1e-9


class ManifestError(Exception):
    """The manifest cannot be read or lacks what the checks need."""


def sha256_file(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def load_stl_welded(path: Path) -> tuple[np.ndarray, np.ndarray, int]:
    """(vertices (V, 3) float64, faces (F, 3) int64, triangles in file).

    Welds bit-identical vertices only (STL stores each triangle's corners separately)."""
    soup = trimesh.load_mesh(str(path), file_type="stl", process=False)
    v = np.asarray(soup.vertices, dtype=np.float64)
    f = np.asarray(soup.faces, dtype=np.int64)
    if len(f) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), 0
    uniq, inverse = np.unique(v, axis=0, return_inverse=True)
    faces = inverse.reshape(-1)[f]
    return uniq, faces, len(f)


def to_manifold(vertices: np.ndarray, faces: np.ndarray) -> manifold3d.Manifold:
    """Manifold from an indexed mesh; float64 when manifold3d has Mesh64."""
    if hasattr(manifold3d, "Mesh64"):
        mesh = manifold3d.Mesh64(
            vert_properties=np.ascontiguousarray(vertices, dtype=np.float64),
            tri_verts=np.ascontiguousarray(faces, dtype=np.uint64),
        )
    else:
        mesh = manifold3d.Mesh(
            vert_properties=np.ascontiguousarray(vertices, dtype=np.float32),
            tri_verts=np.ascontiguousarray(faces, dtype=np.uint32),
        )
    return manifold3d.Manifold(mesh)


def manifold_mesh_kind() -> str:
    return "Mesh64 (float64)" if hasattr(manifold3d, "Mesh64") else "Mesh (float32)"


def shell_count(n_faces: int, face_pairs: np.ndarray) -> int:
    """Number of edge-connected components of a mesh with n_faces faces, given the (P, 2) pairs
    of faces that share an edge (trimesh's ``face_adjacency``).

    Union-find by label hooking and pointer jumping, vectorised with numpy (networkx takes
    seconds on a mesh of 10^5 faces)."""
    label = np.arange(n_faces)
    if n_faces == 0:
        return 0
    a = np.asarray(face_pairs, dtype=np.int64).reshape(-1, 2)
    fa, fb = a[:, 0], a[:, 1]
    while True:
        la, lb = label[fa], label[fb]
        if np.array_equal(la, lb):
            break
        # hook each root on the smaller root of a neighbour (labels only decrease: no cycle)
        np.minimum.at(label, np.maximum(la, lb), np.minimum(la, lb))
        while True:  # pointer jumping until every label is a root
            jumped = label[label]
            if np.array_equal(jumped, label):
                break
            label = jumped
    return int(np.unique(label).size)


def close(measured: float, expected: float, rel: float, abs_tol: float) -> bool:
    return math.isfinite(measured) and abs(measured - expected) <= rel * abs(expected) + abs_tol


def rel_diff(measured: float, expected: float) -> float:
    return abs(measured - expected) / max(abs(expected), 1e-300)


def check_part(out_dir: Path, part: dict, args: argparse.Namespace) -> dict:
    name = part.get("name", "?")
    rel_file = part.get("file", "")
    item = {"kind": "part", "name": name, "file": rel_file, "ok": False, "reasons": [],
            "measured": {}}
    reasons: list[str] = item["reasons"]
    measured: dict = item["measured"]

    missing = [k for k in ("name", "file", "volume_mm3", "bbox_mm", "triangles", "sha256")
               if k not in part]
    if missing:
        reasons.append(f"manifest part lacks {', '.join(missing)}")
        return item
    if part.get("print_technology") not in PRINT_TECHNOLOGIES:
        reasons.append(f"print_technology = {part.get('print_technology')!r}: must be one of "
                       f"{', '.join(PRINT_TECHNOLOGIES)}")
    if not isinstance(part.get("group"), (str, type(None))) or part.get("group") == "":
        reasons.append(f"group = {part.get('group')!r}: must be a non-empty string or null")
    path = (out_dir / rel_file)
    if Path(rel_file).is_absolute() or ".." in Path(rel_file).parts:
        reasons.append(f"file = {rel_file!r}: must be a relative path inside OUT_DIR")
        return item
    if not path.is_file():
        reasons.append(f"file {rel_file} not found")
        return item

    digest = sha256_file(path)
    measured["sha256"] = digest
    if digest != part["sha256"]:
        reasons.append(f"sha256 {digest} != manifest {part['sha256']}")

    try:
        vertices, faces, n_tri = load_stl_welded(path)
    except Exception as e:  # a reader error is a FAIL of this part, not a crash of the oracle
        reasons.append(f"trimesh cannot read the STL: {e}")
        return item
    measured["triangles"] = n_tri
    if n_tri != part["triangles"]:
        reasons.append(f"triangles {n_tri} != manifest {part['triangles']}")
    if n_tri == 0:
        reasons.append("no triangles")
        return item

    tm = trimesh.Trimesh(vertices=vertices, faces=faces, process=False, validate=False)
    watertight = bool(tm.is_watertight)
    winding = bool(tm.is_winding_consistent)
    tm_volume = float(tm.volume)
    tm_area = float(tm.area)
    measured.update(trimesh_watertight=watertight, trimesh_winding_consistent=winding,
                    trimesh_volume_mm3=tm_volume, surface_area_mm2=tm_area)
    if not watertight:
        reasons.append("trimesh: not watertight")
    if not winding:
        reasons.append("trimesh: winding not consistent")
    if not tm_volume > 0:
        reasons.append(f"trimesh: volume {tm_volume:.9g} <= 0")

    exp_vol = float(part["volume_mm3"])
    if not close(tm_volume, exp_vol, args.vol_rel_tol, VOL_ABS_TOL_MM3):
        reasons.append(f"trimesh volume {tm_volume:.12g} != manifest {exp_vol:.12g} "
                       f"(rel diff {rel_diff(tm_volume, exp_vol):.2e})")
    if part.get("surface_area_mm2") is not None:
        exp_area = float(part["surface_area_mm2"])
        if not close(tm_area, exp_area, args.vol_rel_tol, VOL_ABS_TOL_MM3):
            reasons.append(f"surface area {tm_area:.12g} != manifest {exp_area:.12g} "
                           f"(rel diff {rel_diff(tm_area, exp_area):.2e})")

    bb_min = vertices.min(axis=0)
    bb_max = vertices.max(axis=0)
    measured["bbox_mm"] = {"min": bb_min.tolist(), "max": bb_max.tolist()}
    try:
        exp_min = np.asarray(part["bbox_mm"]["min"], dtype=np.float64)
        exp_max = np.asarray(part["bbox_mm"]["max"], dtype=np.float64)
        bbox_err = float(max(np.max(np.abs(bb_min - exp_min)), np.max(np.abs(bb_max - exp_max))))
        measured["bbox_max_abs_diff_mm"] = bbox_err
        if not bbox_err <= args.bbox_tol_mm:
            reasons.append(f"bbox min {bb_min.tolist()} max {bb_max.tolist()} != manifest "
                           f"min {exp_min.tolist()} max {exp_max.tolist()} "
                           f"(max diff {bbox_err:.2e} mm)")
    except (KeyError, TypeError, ValueError) as e:
        reasons.append(f"manifest bbox_mm unreadable: {e!r}")

    m = to_manifold(vertices, faces)
    status = m.status()
    measured["manifold3d_status"] = getattr(status, "name", str(status))
    if status != manifold3d.Error.NoError:
        reasons.append(f"manifold3d: status {measured['manifold3d_status']}")
    else:
        mf_volume = float(m.volume())
        n_vert, n_edge, n_tri = int(m.num_vert()), int(m.num_edge()), int(m.num_tri())
        chi = n_vert - n_edge + n_tri
        shells = shell_count(len(faces), tm.face_adjacency)
        genus = shells - chi // 2
        measured.update(manifold3d_volume_mm3=mf_volume, manifold3d_triangles=n_tri,
                        manifold3d_genus=int(m.genus()), euler_characteristic=chi, shells=shells,
                        genus=genus)
        if not close(mf_volume, exp_vol, args.vol_rel_tol, VOL_ABS_TOL_MM3):
            reasons.append(f"manifold3d volume {mf_volume:.12g} != manifest {exp_vol:.12g} "
                           f"(rel diff {rel_diff(mf_volume, exp_vol):.2e})")
        if chi % 2:
            reasons.append(f"Euler characteristic {chi} is odd: not a closed oriented surface")
        elif part.get("genus") is not None and genus != int(part["genus"]):
            reasons.append(f"genus {genus} ({shells} shells, chi {chi}) != manifest "
                           f"{part['genus']}")

    item["ok"] = not reasons
    return item


PRUSA_CONFIG = "Metadata/Slic3r_PE_model.config"


def read_package(path: Path) -> dict:
    """What the 3MF package says besides the meshes, read with ElementTree (not trimesh):
    {"units": [unit of each .model part (None where absent)],
     "objects": {id: name} of the root model, in file order,
     "items": {objectid: [12 transform numbers or None], ...} (lists: one per build item),
     "volumes": {object id: [{"name", "first", "last", "extruder"}]} from PrusaSlicer's
                ``Metadata/Slic3r_PE_model.config`` ({} without one)}."""
    out = {"units": [], "objects": {}, "items": {}, "volumes": {}}
    with zipfile.ZipFile(path) as z:
        names = {i.filename for i in z.infolist()}
        for name in sorted(names):
            if not name.lower().endswith(".model"):
                continue
            root = ET.fromstring(z.read(name))
            out["units"].append(root.get("unit"))
            if name.lower() != "3d/3dmodel.model":
                continue
            for obj in root.iter():
                if obj.tag.endswith("}object"):
                    out["objects"][obj.get("id")] = obj.get("name")
                elif obj.tag.endswith("}item"):
                    t = obj.get("transform")
                    out["items"].setdefault(obj.get("objectid"), []).append(
                        [float(x) for x in t.split()] if t else None)
        if PRUSA_CONFIG in names:
            root = ET.fromstring(z.read(PRUSA_CONFIG))
            for obj in root.iter("object"):
                vols = []
                for v in obj.iter("volume"):
                    meta = {m.get("key"): m.get("value") for m in v.iter("metadata")
                            if m.get("type") == "volume"}
                    vols.append({"name": meta.get("name"), "first": int(v.get("firstid")),
                                 "last": int(v.get("lastid")), "extruder": meta.get("extruder")})
                out["volumes"][obj.get("id")] = vols
    return out


def submesh(geom: trimesh.Trimesh, first: int, last: int) -> trimesh.Trimesh:
    """Triangles first..last (inclusive) of geom with the vertices they use; nothing merged."""
    faces = np.asarray(geom.faces)[first:last + 1]
    used, inverse = np.unique(faces.reshape(-1), return_inverse=True)
    return trimesh.Trimesh(vertices=np.asarray(geom.vertices)[used],
                           faces=inverse.reshape(-1, 3), process=False, validate=False)


def check_kit(out_dir: Path, kit: dict, parts: list[dict], args: argparse.Namespace,
              stl_boxes: dict | None = None) -> dict:
    """stl_boxes: {part name: {"min", "max"}} as measured on the STLs (check_part)."""
    rel_file = kit.get("file", "")
    item = {"kind": "kit_3mf", "name": "kit_3mf", "file": rel_file, "ok": False, "reasons": [],
            "measured": {}}
    reasons: list[str] = item["reasons"]
    measured: dict = item["measured"]
    path = out_dir / rel_file
    if not rel_file or not path.is_file():
        reasons.append(f"file {rel_file!r} not found")
        return item

    digest = sha256_file(path)
    measured["sha256"] = digest
    if kit.get("sha256") is not None and digest != kit["sha256"]:
        reasons.append(f"sha256 {digest} != manifest {kit['sha256']}")

    try:
        pkg = read_package(path)
        units = pkg["units"]
        measured["units"] = units
        bad = [u for u in units if u not in (None, "millimeter")]
        if not units:
            reasons.append("no .model part in the 3MF package")
        elif bad:
            reasons.append(f"unit {bad[0]!r}: must be millimeter")
    except (zipfile.BadZipFile, ET.ParseError, ValueError, TypeError, AttributeError) as e:
        reasons.append(f"not a readable 3MF package: {e}")
        return item

    try:
        scene = trimesh.load(str(path), file_type="3mf", force="scene", process=False)
    except Exception as e:
        reasons.append(f"trimesh cannot read the 3MF: {e}")
        return item

    geoms = dict(scene.geometry)
    instances = scene.graph.geometry_nodes
    measured["geometries"] = sorted(geoms)
    obj_names = list(pkg["objects"].values())
    if len(set(obj_names)) != len(obj_names):
        reasons.append(f"3MF object names are not unique: {obj_names}")
        return item

    # The parts the 3MF holds: one per object, or one per volume of an object that PrusaSlicer's
    # config splits into volumes. name -> (mesh in object coordinates, object id).
    held: dict[str, tuple[trimesh.Trimesh, str]] = {}
    for oid, oname in pkg["objects"].items():
        g = geoms.get(oname)
        if g is None:
            continue  # an object without a mesh (e.g. components): not a part
        vols = pkg["volumes"].get(oid)
        if not vols:
            pieces = [(oname, g)]
        else:
            n_faces = len(g.faces)
            spans = sorted((v["first"], v["last"]) for v in vols)
            covered = [i for a, b in spans for i in (a, b)]
            if (spans[0][0] != 0 or spans[-1][1] != n_faces - 1
                    or any(b + 1 != c for (_, b), (c, _) in zip(spans, spans[1:]))
                    or any(a > b for a, b in spans)):
                reasons.append(f"object {oname}: volume triangle ranges {covered} do not split "
                               f"its {n_faces} triangles")
                continue
            pieces = [(v["name"], submesh(g, v["first"], v["last"])) for v in vols]
        for name, mesh in pieces:
            if name in held:
                reasons.append(f"part {name!r} appears twice in the 3MF")
            held[name] = (mesh, oid)
    measured["parts"] = sorted(held)
    measured["objects"] = {oid: [n for n, (_, o) in held.items() if o == oid]
                           for oid in pkg["objects"]}

    part_names = [p.get("name") for p in parts]
    if len(held) != len(parts):
        reasons.append(f"{len(held)} parts in the 3MF, {len(parts)} in the manifest")
    missing = [n for n in part_names if n not in held]
    extra = sorted(set(held) - set(part_names))
    if missing:
        reasons.append(f"no geometry named {missing}")
    if extra:
        reasons.append(f"geometries not in the manifest: {extra}")

    vols = {}
    for part in parts:
        name = part.get("name")
        if name not in held:
            continue
        mesh, oid = held[name]
        oname = pkg["objects"][oid]
        n_inst = len(instances.get(oname, []))
        n_items = len(pkg["items"].get(oid, []))
        if n_inst != 1 or n_items != 1:
            reasons.append(f"{name}: placed {n_inst} times in the scene ({n_items} build items)")
        if not mesh.is_watertight:
            reasons.append(f"{name}: not watertight")
        vol = float(mesh.volume)
        vols[name] = vol
        exp = float(part.get("volume_mm3", float("nan")))
        if not close(vol, exp, args.kit_vol_rel_tol, 0.0):
            reasons.append(f"{name}: volume {vol:.12g} != part's {exp:.12g} "
                           f"(rel diff {rel_diff(vol, exp):.2e})")
        # Objects hold parts in part coordinates (the build item moves them), so each part's
        # box in its object is its STL's (the manifest's without an STL): this is what keeps
        # the volumes of a group registered.
        ref = (stl_boxes or {}).get(name) or part.get("bbox_mm")
        try:
            exp_min = np.asarray(ref["min"], dtype=np.float64)
            exp_max = np.asarray(ref["max"], dtype=np.float64)
            bounds = np.asarray(mesh.bounds, dtype=np.float64)
            err = float(max(np.max(np.abs(bounds[0] - exp_min)),
                            np.max(np.abs(bounds[1] - exp_max))))
            if not err <= args.bbox_tol_mm:
                src = "STL" if (stl_boxes or {}).get(name) else "manifest bbox_mm"
                reasons.append(f"{name}: box in its object min {bounds[0].tolist()} max "
                               f"{bounds[1].tolist()} != the part's {src} (max diff "
                               f"{err:.2e} mm)")
        except (KeyError, TypeError, ValueError):
            pass  # the part's own item reports an unreadable bbox_mm
    measured["volume_mm3"] = vols
    check_groups(pkg, held, parts, reasons)
    check_manifest_objects(pkg, held, kit.get("objects"), reasons)
    item["ok"] = not reasons
    return item


def check_groups(pkg: dict, held: dict, parts: list[dict], reasons: list[str]) -> None:
    """The parts of one group are the volumes of one 3MF object, which holds nothing else (one
    object, one build item: one placement for the whole group); an ungrouped part is an object
    of its own."""
    group_of = {p.get("name"): p.get("group") for p in parts}
    groups: dict[str, list[str]] = {}
    for p in parts:
        if isinstance(p.get("group"), str):
            groups.setdefault(p["group"], []).append(p.get("name"))
    for g, names in groups.items():
        oids = sorted({held[n][1] for n in names if n in held}, key=int)
        if len(oids) > 1:
            where = ", ".join(f"{pkg['objects'][o]} (id {o})" for o in oids)
            reasons.append(f"group {g!r}: its parts are in {len(oids)} objects: {where}; a "
                           f"group must be one object so it keeps its registration")
    for oid, oname in pkg["objects"].items():
        inside = [n for n, (_, o) in held.items() if o == oid]
        if len(inside) < 2:
            continue
        gs = {group_of.get(n) for n in inside}
        if len(gs) != 1 or None in gs:
            reasons.append(f"object {oname}: holds parts {inside} of groups "
                           f"{sorted(map(str, gs))}: only one group's parts share an object")


def check_manifest_objects(pkg: dict, held: dict, objects, reasons: list[str]) -> None:
    """The manifest's ``kit_3mf.objects`` describe the 3MF: a count, or per object its id,
    name, build translation and volumes (part and triangle range)."""
    if isinstance(objects, int):
        if objects != len(pkg["objects"]):
            reasons.append(f"manifest objects {objects} != {len(pkg['objects'])} objects in "
                           f"the 3MF")
        return
    if not isinstance(objects, list):
        return
    names = [o.get("name") if isinstance(o, dict) else o for o in objects]
    if sorted(map(str, names)) != sorted(map(str, pkg["objects"].values())):
        reasons.append(f"manifest objects {names} != 3MF objects "
                       f"{list(pkg['objects'].values())}")
        return
    for o in objects:
        if not isinstance(o, dict) or "id" not in o:
            continue
        oid = str(o["id"])
        if pkg["objects"].get(oid) != o.get("name"):
            reasons.append(f"manifest object {o.get('name')!r} has id {oid}, the 3MF's object "
                           f"{oid} is {pkg['objects'].get(oid)!r}")
            continue
        t = o.get("translation_mm")
        items = pkg["items"].get(oid, [])
        if t is not None and len(items) == 1:
            m = items[0] or [1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0]
            if not np.allclose(m[9:12], t, rtol=0.0, atol=PLACEMENT_TOL_MM):
                reasons.append(f"object {o['name']}: manifest translation {t} != build item "
                               f"translation {m[9:12]}")
        mvols = o.get("volumes")
        if isinstance(mvols, list):
            want = [(v.get("part"), v.get("first_triangle"), v.get("last_triangle"))
                    for v in mvols]
            cfg = pkg["volumes"].get(oid)
            if cfg:
                have = [(v["name"], v["first"], v["last"]) for v in cfg]
            else:
                name = o.get("name")
                n = len(held[name][0].faces) if name in held else -1
                have = [(name, 0, n - 1)]
            if want != have:
                reasons.append(f"object {o['name']}: manifest volumes {want} != 3MF volumes "
                               f"{have}")


def run(out_dir: Path, args: argparse.Namespace) -> list[dict]:
    manifest_path = out_dir / "manifest.json"
    try:
        manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise ManifestError(f"{manifest_path}: {e}") from e
    parts = manifest.get("parts")
    if not isinstance(parts, list) or not parts:
        raise ManifestError(f"{manifest_path}: no parts")
    items = []
    names = [p.get("name") for p in parts]
    for part in parts:
        item = check_part(out_dir, part, args)
        if names.count(part.get("name")) > 1:
            item["reasons"].append("part name not unique")
            item["ok"] = False
        items.append(item)
    if manifest.get("kit_3mf"):
        stl_boxes = {i["name"]: i["measured"]["bbox_mm"] for i in items
                     if "bbox_mm" in i["measured"]}
        items.append(check_kit(out_dir, manifest["kit_3mf"], parts, args, stl_boxes))
    return items


def describe(item: dict) -> str:
    if item["ok"]:
        m = item["measured"]
        if item["kind"] == "part":
            detail = (f"volume_mm3={m.get('trimesh_volume_mm3', float('nan')):.6f} "
                      f"triangles={m.get('triangles')} genus={m.get('genus')}")
        else:
            detail = (f"parts={len(m.get('parts', []))} "
                      f"objects={len(m.get('objects', {}))}")
        return f"PASS {item['name']} ({item['file']}) {detail}"
    return f"FAIL {item['name']} ({item['file']}): " + "; ".join(item["reasons"])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out_dir", type=Path, help="fabkit output directory holding manifest.json")
    ap.add_argument("--json", action="store_true", help="JSON result on stdout, lines on stderr")
    ap.add_argument("--vol-rel-tol", type=float, default=1e-6,
                    help="relative tolerance of volume and surface area (default 1e-6)")
    ap.add_argument("--bbox-tol-mm", type=float, default=1e-5,
                    help="absolute tolerance of the bounding box, mm (default 1e-5)")
    ap.add_argument("--kit-vol-rel-tol", type=float, default=1e-5,
                    help="relative tolerance of the 3MF geometries' volumes (default 1e-5)")
    args = ap.parse_args(argv)

    try:
        items = run(args.out_dir, args)
    except ManifestError as e:
        print(f"check_parts: error: {e}", file=sys.stderr)
        return 2

    lines = sys.stderr if args.json else sys.stdout
    for item in items:
        print(describe(item), file=lines)
    passed = sum(1 for i in items if i["ok"])
    failed = len(items) - passed
    print(f"{passed} passed, {failed} failed", file=lines)
    if args.json:
        json.dump({"passed": passed, "failed": failed, "manifold3d_mesh": manifold_mesh_kind(),
                   "items": items}, sys.stdout, indent=1)
        sys.stdout.write("\n")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
