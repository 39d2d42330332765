"""The manifold3d twin: each part's booleans redone in manifold3d from its primitives (the leaf
meshes of the fabkit-csg/1 tree that `fabkit export --csg` / `fabkit fixtures --csg` write),
with tests/oracles/replay_csg.py's evaluator."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

# replay_csg lives with the other oracles: <repo>/tests/oracles (this file: <repo>/export/python/twins)
sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "oracles"))

import manifold3d  # noqa: E402
import replay_csg  # noqa: E402


def replay(csg_path: Path) -> dict:
    """name -> {status, volume_mm3, volume_rel_diff (vs fabkit's recorded f64 volume), genus,
    mesh: (vertices (N, 3) mm, triangles (M, 3))} for every part of the CSG file."""
    doc = replay_csg.load_doc(Path(csg_path))
    nodes, parts = doc["nodes"], doc["parts"]
    leaves = {i: replay_csg.leaf_manifold(i, n) for i, n in enumerate(nodes) if n["op"] == "mesh"}
    out = {}
    results = replay_csg.evaluate(nodes, leaves, [p["root"] for p in parts])
    for p, m in zip(parts, results):
        vol = float(m.volume())
        rec = float(p["volume_mm3"])
        mesh = m.to_mesh64() if hasattr(m, "to_mesh64") else m.to_mesh()
        v = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
        f = np.asarray(mesh.tri_verts, dtype=np.int64)
        out[p["name"]] = {"status": m.status().name, "volume_mm3": vol,
                          "volume_rel_diff": abs(vol - rec) / max(abs(rec), 1e-300),
                          # fabkit counts genus as shells - chi / 2; manifold3d as 1 - chi / 2
                          "genus": int(m.genus()) + len(m.decompose()) - 1, "mesh": (v, f)}
    return out
