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
    mesh: (vertices (N, 3) mm, triangles (M, 3)), manifold: the manifold3d solid} for every part
    of the CSG file."""
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
                          "genus": int(m.genus()) + len(m.decompose()) - 1, "mesh": (v, f),
                          "manifold": m}
    return out


SLAB_INSET_MM = 1e-4


def slab(m, z0: float, z1: float):
    """The part of manifold3d solid `m` between the planes z0 and z1, moved down by z0 (a
    laser-cut sheet of a tray: the tray, the union of its sheets, cut at the sheet's faces):
    (status, volume_mm3, genus, mesh). The cut is made [`SLAB_INSET_MM`] inside each plane, since
    the tray's own faces lie in them (the floor under a hole) and a coplanar cut may keep them
    as zero-volume skins; the volume returned is scaled back to the full thickness (exact for
    a sheet, a prism), the mesh lies within the inset of the sheet's."""
    d = SLAB_INSET_MM
    lo, hi = np.asarray(m.bounding_box()[:3]), np.asarray(m.bounding_box()[3:])
    size = hi - lo + 2.0
    box = manifold3d.Manifold.cube([size[0], size[1], z1 - z0 - 2.0 * d]).translate(
        [lo[0] - 1.0, lo[1] - 1.0, z0 + d])
    s = (m ^ box).translate([0.0, 0.0, -z0])
    mesh = s.to_mesh64() if hasattr(s, "to_mesh64") else s.to_mesh()
    v = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    f = np.asarray(mesh.tri_verts, dtype=np.int64)
    return (s.status().name, float(s.volume()) * (z1 - z0) / (z1 - z0 - 2.0 * d),
            int(s.genus()) + len(s.decompose()) - 1, (v, f))
