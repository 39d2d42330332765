"""The manifold3d twin: each part's booleans redone in manifold3d from its primitives (the leaf
meshes of the fabkit-csg/1 tree that `fabkit export --csg` / `fabkit fixtures --csg` write),
with tests/oracles/replay_csg.py's evaluator."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

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


def clip_to_wedge(v, f, sample: dict, T_print_sensor):
    """The mesh (print frame) cut to the sampled wedge of azimuths about the sensor axis
    (cq_twin.sampling), by manifold3d: (vertices, triangles, genus as fabkit counts it)."""
    import math
    lo, hi = (math.radians(a) for a in sample["wedge_deg"])
    size = 1000.0
    mid = 0.5 * (lo + hi)
    far = size / math.cos(0.5 * (hi - lo))
    pts = [(0.0, 0.0), (far * math.cos(lo), far * math.sin(lo)),
           (size * 2 * math.cos(mid), size * 2 * math.sin(mid)), (far * math.cos(hi), far * math.sin(hi))]
    w = manifold3d.Manifold.extrude(manifold3d.CrossSection([pts]), 2 * size).translate((0, 0, -size))
    w = w.transform(np.asarray(T_print_sensor, dtype=np.float64))
    m = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=np.ascontiguousarray(v, dtype=np.float64),
                                              tri_verts=np.ascontiguousarray(f, dtype=np.uint64)))
    c = m ^ w
    g = c.to_mesh64()
    genus = int(c.genus()) + len(c.decompose()) - 1
    return (np.array(np.asarray(g.vert_properties, dtype=np.float64)[:, :3]),
            np.array(g.tri_verts, dtype=np.int64), genus)
