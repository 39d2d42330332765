#!/usr/bin/env python3
"""Mass-properties oracle: the assembled sensor's masses, centres of mass and inertias in an
export's manifest (`assembly_3mf.members[].mass`, `assembly_3mf.mass`) against trimesh's, on the
meshes of the export's assembly.3mf.

Usage: python tests/oracles/mass_check.py EXPORT_DIR   (with the oracle venv's python)

For each member with a material: its density is designs/materials.yaml's (density_g_per_cm3);
trimesh (an independent implementation of the polyhedral integrals) gives the mass, centre of
mass and inertia about it of the member's mesh as assembly.3mf holds it, at that density. The
sensor's are combined here with numpy (the parallel-axis theorem). Prints ONE JSON document:

  {"members": [{"name": str, "material": str, "mass_g": [manifest, trimesh],
                "worst_relative": float}], "sensor": {"mass_g": [manifest, here],
   "worst_relative": float}, "worst_relative": float}

where worst_relative is the largest difference, relative to the largest value of its kind (mass,
centre in mm scaled by the part's size, inertia). Exit 0 when every worst_relative is under 1e-6,
else 1; 2 on a usage error.
"""

from __future__ import annotations

import json
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import trimesh
import yaml

NS = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}
REPO = Path(__file__).resolve().parents[2]


def meshes_3mf(path):
    """{object name: trimesh.Trimesh} of a 3MF's mesh objects (mm)."""
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("3D/3dmodel.model"))
    out = {}
    for obj in root.iter(f"{{{NS['m']}}}object"):
        mesh = obj.find("m:mesh", NS)
        v = np.array([[float(e.get(k)) for k in "xyz"]
                      for e in mesh.find("m:vertices", NS)], dtype=np.float64)
        f = np.array([[int(e.get(k)) for k in ("v1", "v2", "v3")]
                      for e in mesh.find("m:triangles", NS)], dtype=np.int64)
        out[obj.get("name")] = trimesh.Trimesh(v, f, process=False)
    return out


def rel(a, b, scale):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / scale)


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    out_dir = Path(argv[1])
    manifest = json.loads((out_dir / "manifest.json").read_text())["assembly_3mf"]
    densities = {k: v["density_g_per_cm3"] for k, v in
                 yaml.safe_load((REPO / "designs" / "materials.yaml").read_text())["materials"].items()}
    meshes = meshes_3mf(out_dir / manifest["file"])
    report, worst = {"members": []}, 0.0
    parts = []  # (mass g, centre mm, inertia g mm^2) as trimesh has them
    for m in manifest["members"]:
        if m.get("material") is None:
            continue
        tm = meshes[m["name"]]
        tm.density = densities[m["material"]] * 1e-3  # g/mm^3
        mass, centre, inertia = tm.mass, tm.center_mass, tm.moment_inertia
        size = float(np.max(tm.extents))
        got = m["mass"]
        w = max(rel(got["mass_g"], mass, mass),
                rel(got["centre_of_mass_mm"], centre, size),
                rel(got["inertia_g_mm2"], inertia, np.max(np.abs(inertia))),
                rel(got["density_g_per_cm3"], densities[m["material"]], 1.0))
        report["members"].append({"name": m["name"], "material": m["material"],
                                  "mass_g": [got["mass_g"], mass], "worst_relative": w})
        worst = max(worst, w)
        parts.append((mass, centre, inertia))
    total = sum(p[0] for p in parts)
    c = sum(p[0] * p[1] for p in parts) / total
    inertia = np.zeros((3, 3))
    for m, ci, ii in parts:
        d = ci - c
        inertia += ii + m * (d @ d * np.eye(3) - np.outer(d, d))
    s = manifest["mass"]
    size = max(float(np.max(t.extents)) for t in meshes.values())
    w = max(rel(s["mass_g"], total, total), rel(s["centre_of_mass_mm"], c, size),
            rel(s["inertia_g_mm2"], inertia, np.max(np.abs(inertia))))
    report["sensor"] = {"mass_g": [s["mass_g"], total], "worst_relative": w}
    report["worst_relative"] = max(worst, w)
    print(json.dumps(report))
    return 0 if report["worst_relative"] < 1e-6 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
