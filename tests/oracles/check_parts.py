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

If the manifest has ``kit_3mf``, the 3MF is loaded as a trimesh Scene and must hold exactly one
geometry per part, named as the parts, each placed once, each watertight, each with the part's
volume (within --kit-vol-rel-tol relative); its sha256 and ``objects`` must match and its model
must say unit="millimeter" (or no unit: the 3MF default). Parts that share a ``group`` (one
multi-material print, built in shared coordinates) must be placed by the same transform, in the
3MF and in the manifest's ``objects[].translation_mm``, so they stay registered.

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
# Members of a group must have the same placement; the transforms are parsed from the same
# decimal text, so this only absorbs a reader that composes matrices.
GROUP_PLACEMENT_TOL_MM = 1e-9


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


def model_units(path: Path) -> list[str | None]:
    """The unit attribute of each .model part of a 3MF (None where absent)."""
    units = []
    with zipfile.ZipFile(path) as z:
        for info in z.infolist():
            if info.filename.lower().endswith(".model"):
                root = ET.fromstring(z.read(info))
                units.append(root.get("unit"))
    return units


def check_kit(out_dir: Path, kit: dict, parts: list[dict], args: argparse.Namespace) -> dict:
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
        units = model_units(path)
        measured["units"] = units
        bad = [u for u in units if u not in (None, "millimeter")]
        if not units:
            reasons.append("no .model part in the 3MF package")
        elif bad:
            reasons.append(f"unit {bad[0]!r}: must be millimeter")
    except (zipfile.BadZipFile, ET.ParseError) as e:
        reasons.append(f"not a readable 3MF package: {e}")
        return item

    try:
        scene = trimesh.load(str(path), file_type="3mf", force="scene", process=False)
    except Exception as e:
        reasons.append(f"trimesh cannot read the 3MF: {e}")
        return item

    part_names = [p.get("name") for p in parts]
    geoms = dict(scene.geometry)
    measured["geometries"] = sorted(geoms)
    objects = kit.get("objects")
    if isinstance(objects, int) and objects != len(geoms):
        reasons.append(f"manifest objects {objects} != {len(geoms)} geometries in the 3MF")
    elif isinstance(objects, list):
        names = [o.get("name") if isinstance(o, dict) else o for o in objects]
        if sorted(map(str, names)) != sorted(geoms):
            reasons.append(f"manifest objects {names} != 3MF geometries {sorted(geoms)}")
    if len(geoms) != len(parts):
        reasons.append(f"{len(geoms)} geometries, {len(parts)} parts")
    missing = [n for n in part_names if n not in geoms]
    extra = sorted(set(geoms) - set(part_names))
    if missing:
        reasons.append(f"no geometry named {missing}")
    if extra:
        reasons.append(f"geometries not in the manifest: {extra}")

    instances = scene.graph.geometry_nodes
    vols = {}
    for part in parts:
        name = part.get("name")
        g = geoms.get(name)
        if g is None:
            continue
        n_inst = len(instances.get(name, []))
        if n_inst != 1:
            reasons.append(f"{name}: placed {n_inst} times in the build")
        if not g.is_watertight:
            reasons.append(f"{name}: not watertight")
        vol = float(g.volume)
        vols[name] = vol
        exp = float(part.get("volume_mm3", float("nan")))
        if not close(vol, exp, args.kit_vol_rel_tol, 0.0):
            reasons.append(f"{name}: volume {vol:.12g} != part's {exp:.12g} "
                           f"(rel diff {rel_diff(vol, exp):.2e})")
    measured["volume_mm3"] = vols
    check_groups(scene, objects, parts, reasons)
    item["ok"] = not reasons
    return item


def check_groups(scene, objects, parts: list[dict], reasons: list[str]) -> None:
    """Members of one group have one placement: the same 3MF build transform and, where the
    manifest lists objects with translation_mm, the same translation."""
    groups: dict[str, list[str]] = {}
    for p in parts:
        if isinstance(p.get("group"), str):
            groups.setdefault(p["group"], []).append(p.get("name"))
    if not groups:
        return
    instances = scene.graph.geometry_nodes
    manifest_t = {}
    if isinstance(objects, list):
        manifest_t = {o.get("name"): o.get("translation_mm") for o in objects
                      if isinstance(o, dict) and "translation_mm" in o}
    for g, names in groups.items():
        placements = {}
        for n in names:
            nodes = instances.get(n, [])
            if len(nodes) == 1:
                placements[n] = np.asarray(scene.graph[nodes[0]][0], dtype=np.float64)
        if len(placements) > 1:
            first_name, first = next(iter(placements.items()))
            for n, t in placements.items():
                if not np.allclose(t, first, rtol=0.0, atol=GROUP_PLACEMENT_TOL_MM):
                    reasons.append(f"group {g!r}: {n} is placed by {t[:3, 3].tolist()}, "
                                   f"{first_name} by {first[:3, 3].tolist()} (transform "
                                   f"differs): the group must keep its registration")
        ts = {n: manifest_t[n] for n in names if n in manifest_t}
        if len({json.dumps(t) for t in ts.values()}) > 1:
            reasons.append(f"group {g!r}: manifest translations differ: {ts}")


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
        items.append(check_kit(out_dir, manifest["kit_3mf"], parts, args))
    return items


def describe(item: dict) -> str:
    if item["ok"]:
        m = item["measured"]
        if item["kind"] == "part":
            detail = (f"volume_mm3={m.get('trimesh_volume_mm3', float('nan')):.6f} "
                      f"triangles={m.get('triangles')} genus={m.get('genus')}")
        else:
            detail = f"geometries={len(m.get('geometries', []))}"
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
