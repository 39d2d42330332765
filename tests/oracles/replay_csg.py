#!/usr/bin/env python3
"""Replay a recorded fabkit CSG tree ("fabkit-csg/1") in manifold3d: benchmark and oracle.

Usage: replay_csg.py CSG.json [--repeat N] [--json] [--vol-rel-tol R]

The file: {"format": "fabkit-csg/1",
           "parts": [{"name", "root": ID, "volume_mm3", "triangles"}, ...],
           "nodes": [node, ...]}
A node's id is its index; its children have smaller ids (topological order). Nodes:
  {"op": "mesh", "vertices": [[x, y, z], ...], "triangles": [[a, b, c], ...]}   closed, CCW outward
  {"op": "union", "children": [ids...]}                  n-ary boolean union
  {"op": "difference", "children": [a, b]}               a minus b
  {"op": "intersection", "children": [a, b]}
  {"op": "compose", "children": [ids...]}                disjoint solids, no boolean (Manifold.compose)
  {"op": "transform", "matrix": [[r00, r01, r02, t0], [r10, ...], [r20, ...]], "children": [a]}
                                                         p' = R p + t (row-major 3x4)
  {"op": "split_keep", "normal": [nx, ny, nz], "offset": d, "side": "positive"|"negative",
   "children": [a]}                                      split_by_plane(normal, d)[0] or [1]

Leaf meshes are turned into Manifolds first (untimed; float64 Mesh64 where manifold3d has it,
float32 Mesh otherwise, which the output says). Then every part's root is evaluated with shared
nodes memoised, forced (manifold3d is lazy: num_tri() on each root), best of --repeat runs.
Per part it prints manifold3d's volume against the recorded volume_mm3 (relative difference), the
triangle counts, status and genus; then the best total seconds. --json prints
{"seconds_best", "seconds_runs", "seconds_load_leaves", "manifold3d", "mesh", "parts": [...]}.
Exit status: 0 when every root has status NoError and its volume is within --vol-rel-tol
(default 1e-6, relative, plus 1e-9 mm^3) of the recorded one; 1 otherwise; 2 unreadable input.
Triangle counts are reported, not checked (another kernel may triangulate differently).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from importlib import metadata
from pathlib import Path

import manifold3d
import numpy as np

FORMAT = "fabkit-csg/1"
HAS_MESH64 = hasattr(manifold3d, "Mesh64")
MESH_KIND = "Mesh64 (float64)" if HAS_MESH64 else "Mesh (float32: coordinates rounded!)"
VOL_ABS_TOL_MM3 = 1e-9

ARITY = {"mesh": (0, 0), "union": (1, None), "difference": (2, 2), "intersection": (2, 2),
         "compose": (1, None), "transform": (1, 1), "split_keep": (1, 1)}


class CsgError(Exception):
    """The CSG file is unreadable or malformed."""


def load_doc(path: Path) -> dict:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise CsgError(f"{path}: {e}") from e
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise CsgError(f"{path}: format must be {FORMAT!r}")
    nodes, parts = doc.get("nodes"), doc.get("parts")
    if not isinstance(nodes, list) or not isinstance(parts, list) or not parts:
        raise CsgError(f"{path}: needs non-empty 'parts' and a 'nodes' array")
    for i, node in enumerate(nodes):
        op = node.get("op") if isinstance(node, dict) else None
        if op not in ARITY:
            raise CsgError(f"nodes[{i}].op = {op!r}: must be one of {sorted(ARITY)}")
        children = node.get("children", [])
        lo, hi = ARITY[op]
        if not isinstance(children, list) or len(children) < lo or (hi is not None and
                                                                      len(children) > hi):
            raise CsgError(f"nodes[{i}] ({op}): {len(children)} children, expected "
                           f"{lo}{'' if hi == lo else '..' + (str(hi) if hi else 'n')}")
        for c in children:
            if not isinstance(c, int) or not 0 <= c < i:
                raise CsgError(f"nodes[{i}].children contains {c!r}: must be an id below {i}")
        if op == "transform":
            m = np.asarray(node.get("matrix"), dtype=np.float64)
            if m.shape != (3, 4) or not np.all(np.isfinite(m)):
                raise CsgError(f"nodes[{i}].matrix: must be 3x4 finite numbers")
        if op == "split_keep":
            n = np.asarray(node.get("normal"), dtype=np.float64)
            if n.shape != (3,) or not np.linalg.norm(n) > 0:
                raise CsgError(f"nodes[{i}].normal: must be a non-zero 3-vector")
            if node.get("side") not in ("positive", "negative"):
                raise CsgError(f"nodes[{i}].side = {node.get('side')!r}: positive or negative")
            if not isinstance(node.get("offset"), (int, float)):
                raise CsgError(f"nodes[{i}].offset: must be a number")
    for j, part in enumerate(parts):
        root = part.get("root")
        if not isinstance(root, int) or not 0 <= root < len(nodes):
            raise CsgError(f"parts[{j}].root = {root!r}: must be a node id")
    return doc


def leaf_manifold(i: int, node: dict) -> manifold3d.Manifold:
    v = np.asarray(node.get("vertices"), dtype=np.float64)
    t = np.asarray(node.get("triangles"), dtype=np.int64)
    if v.ndim != 2 or v.shape[1] != 3 or t.ndim != 2 or t.shape[1] != 3 or len(t) == 0:
        raise CsgError(f"nodes[{i}] (mesh): vertices must be (N, 3), triangles (M, 3), M > 0")
    if t.min() < 0 or t.max() >= len(v):
        raise CsgError(f"nodes[{i}] (mesh): triangle index out of range")
    if HAS_MESH64:
        mesh = manifold3d.Mesh64(vert_properties=np.ascontiguousarray(v),
                                 tri_verts=np.ascontiguousarray(t, dtype=np.uint64))
    else:
        mesh = manifold3d.Mesh(vert_properties=np.ascontiguousarray(v, dtype=np.float32),
                               tri_verts=np.ascontiguousarray(t, dtype=np.uint32))
    m = manifold3d.Manifold(mesh)
    m.num_tri()
    return m


def compose(children: list) -> manifold3d.Manifold:
    if hasattr(manifold3d.Manifold, "compose"):
        return manifold3d.Manifold.compose(children)
    # Newer manifold3d drops compose in favour of a batch union (a real boolean, slower).
    return manifold3d.Manifold.batch_boolean(children, manifold3d.OpType.Add)


def evaluate(nodes: list, leaves: dict, roots: list[int]) -> list:
    """Manifolds of the roots; every needed node is built once (shared nodes memoised)."""
    needed = set()
    stack = list(roots)
    while stack:
        i = stack.pop()
        if i not in needed:
            needed.add(i)
            stack.extend(nodes[i].get("children", []))
    memo = {}
    for i in sorted(needed):  # ids are topological: children first
        node = nodes[i]
        op = node["op"]
        ch = [memo[c] for c in node.get("children", [])]
        if op == "mesh":
            memo[i] = leaves[i]
        elif op == "union":
            memo[i] = ch[0] if len(ch) == 1 else manifold3d.Manifold.batch_boolean(
                ch, manifold3d.OpType.Add)
        elif op == "difference":
            memo[i] = ch[0] - ch[1]
        elif op == "intersection":
            memo[i] = ch[0] ^ ch[1]
        elif op == "compose":
            memo[i] = ch[0] if len(ch) == 1 else compose(ch)
        elif op == "transform":
            memo[i] = ch[0].transform(np.asarray(node["matrix"], dtype=np.float64))
        elif op == "split_keep":
            pos, neg = ch[0].split_by_plane(tuple(float(x) for x in node["normal"]),
                                            float(node["offset"]))
            memo[i] = pos if node["side"] == "positive" else neg
    return [memo[r] for r in roots]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("csg", type=Path, help="fabkit-csg/1 JSON file")
    ap.add_argument("--repeat", type=int, default=5, help="timed runs, best is reported (5)")
    ap.add_argument("--json", action="store_true", help="print a JSON result")
    ap.add_argument("--vol-rel-tol", type=float, default=1e-6,
                    help="relative volume tolerance against the recorded volume (1e-6)")
    args = ap.parse_args(argv)
    if args.repeat < 1:
        ap.error("--repeat must be >= 1")

    try:
        doc = load_doc(args.csg)
        nodes, parts = doc["nodes"], doc["parts"]
        t0 = time.perf_counter()
        leaves = {i: leaf_manifold(i, n) for i, n in enumerate(nodes) if n["op"] == "mesh"}
        load_s = time.perf_counter() - t0
    except CsgError as e:
        print(f"replay_csg: error: {e}", file=sys.stderr)
        return 2
    bad_leaves = {i: m.status().name for i, m in leaves.items()
                  if m.status() != manifold3d.Error.NoError}

    roots = [p["root"] for p in parts]
    runs = []
    results = None
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        out = evaluate(nodes, leaves, roots)
        for m in out:
            m.num_tri()  # forces the lazy CSG tree
        runs.append(time.perf_counter() - t0)
        results = out

    rows = []
    ok_all = not bad_leaves
    for part, m in zip(parts, results):
        status = m.status()
        volume = float(m.volume())
        rec_vol = part.get("volume_mm3")
        rec_tri = part.get("triangles")
        rel = (abs(volume - rec_vol) / max(abs(rec_vol), 1e-300)) if rec_vol is not None else None
        ok = status == manifold3d.Error.NoError and rec_vol is not None and \
            abs(volume - rec_vol) <= args.vol_rel_tol * abs(rec_vol) + VOL_ABS_TOL_MM3
        ok_all &= ok
        bb = m.bounding_box()
        rows.append({"name": part.get("name"), "root": part["root"], "ok": bool(ok),
                     "status": status.name, "volume_mm3": volume, "recorded_volume_mm3": rec_vol,
                     "volume_rel_diff": rel, "triangles": int(m.num_tri()),
                     "recorded_triangles": rec_tri, "genus": int(m.genus()),
                     "bbox_mm": {"min": list(bb[:3]), "max": list(bb[3:])}})

    version = metadata.version("manifold3d")
    if args.json:
        json.dump({"seconds_best": min(runs), "seconds_runs": runs, "seconds_load_leaves": load_s,
                   "manifold3d": version, "mesh": MESH_KIND, "bad_leaves": bad_leaves,
                   "parts": rows}, sys.stdout, indent=1)
        sys.stdout.write("\n")
    else:
        print(f"manifold3d {version}, leaf meshes as {MESH_KIND}, {len(nodes)} nodes, "
              f"{len(leaves)} leaves loaded in {load_s:.3f} s")
        for i, s in bad_leaves.items():
            print(f"FAIL leaf nodes[{i}]: status {s}")
        for r in rows:
            rel = "n/a" if r["volume_rel_diff"] is None else f"{r['volume_rel_diff']:.2e}"
            print(f"{'PASS' if r['ok'] else 'FAIL'} {r['name']}: volume_mm3 {r['volume_mm3']:.9g} "
                  f"vs recorded {r['recorded_volume_mm3']} (rel diff {rel}), "
                  f"triangles {r['triangles']} vs recorded {r['recorded_triangles']}, "
                  f"genus {r['genus']}, status {r['status']}")
        print(f"seconds_best {min(runs):.6f} (best of {len(runs)}; runs "
              + " ".join(f"{s:.6f}" for s in runs) + ")")
    return 0 if ok_all else 1


if __name__ == "__main__":
    sys.exit(main())
