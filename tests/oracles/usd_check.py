#!/usr/bin/env python3
"""USD oracle: opens the layer of `fabkit export --format usd` with Pixar's USD (usd-core) and
reads back what USD makes of it.

Usage: python tests/oracles/usd_check.py LAYER.usda   (with the oracle venv's python)

Prints ONE JSON document (the stage's units):

  {"usd_version": str, "default_prim": str, "meters_per_unit": float,
   "kilograms_per_unit": float, "up_axis": str,
   "mass": {"mass": float, "center_of_mass": [3], "inertia": [[3], [3], [3]]},
   "meshes": {NAME: {"extent": [[3], [3]], "points_box": [[3], [3]], "triangles": int,
                     "collision": bool}},
   "camera": null | {"transform": [[4] x 4] (row vectors, USD's), "focal_length": float,
                     "horizontal_aperture": float, "vertical_aperture": float},
   "contact_surface": null | [3], "lights": int, "errors": [str],
   "collisions": [names of the prims with CollisionAPI]}

- mass.inertia: the tensor rebuilt from physics:diagonalInertia in physics:principalAxes,
  R diag(I) R^T.
- points_box: the box of the mesh's points as USD reads them (the authored extent is checked
  against it by the test).
- errors: what validating the stage found (UsdPhysics schema application, prim validity).
Exit 0 when the layer opens; 1 otherwise.
"""

from __future__ import annotations

import json
import sys

import numpy as np
from pxr import Gf, Usd, UsdGeom, UsdLux, UsdPhysics


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    stage = Usd.Stage.Open(argv[1])
    if stage is None:
        print(json.dumps({"errors": ["the stage does not open"]}))
        return 1
    root = stage.GetDefaultPrim()
    errors = []
    if not root.HasAPI(UsdPhysics.MassAPI) or not root.HasAPI(UsdPhysics.RigidBodyAPI):
        errors.append("the default prim lacks MassAPI or RigidBodyAPI")
    m = UsdPhysics.MassAPI(root)
    q = m.GetPrincipalAxesAttr().Get()
    # Gf matrices act on row vectors (v M): the rotation is the transpose
    rotate = Gf.Matrix3d().SetRotate(Gf.Quatd(q.GetReal(), Gf.Vec3d(q.GetImaginary())))
    r = np.array(rotate).T
    diag = np.array(m.GetDiagonalInertiaAttr().Get(), dtype=np.float64)
    out = {
        "usd_version": ".".join(map(str, Usd.GetVersion())),
        "default_prim": root.GetName(),
        "meters_per_unit": UsdGeom.GetStageMetersPerUnit(stage),
        "kilograms_per_unit": UsdPhysics.GetStageKilogramsPerUnit(stage),
        "up_axis": UsdGeom.GetStageUpAxis(stage),
        "mass": {"mass": m.GetMassAttr().Get(),
                 "center_of_mass": list(m.GetCenterOfMassAttr().Get()),
                 "inertia": (r @ np.diag(diag) @ r.T).tolist()},
        "meshes": {}, "camera": None, "contact_surface": None, "lights": 0, "errors": errors,
        "collisions": [p.GetName() for p in root.GetChildren() if p.HasAPI(UsdPhysics.CollisionAPI)],
    }
    for prim in root.GetChildren():
        if prim.IsA(UsdGeom.Mesh):
            mesh = UsdGeom.Mesh(prim)
            pts = np.array(mesh.GetPointsAttr().Get(), dtype=np.float64)
            counts = mesh.GetFaceVertexCountsAttr().Get()
            if any(c != 3 for c in counts):
                errors.append(f"{prim.GetName()}: a face is not a triangle")
            out["meshes"][prim.GetName()] = {
                "extent": [list(v) for v in mesh.GetExtentAttr().Get()],
                "points_box": [pts.min(axis=0).tolist(), pts.max(axis=0).tolist()],
                "triangles": len(counts),
                "collision": prim.HasAPI(UsdPhysics.CollisionAPI),
            }
        elif prim.IsA(UsdGeom.Camera):
            cam = UsdGeom.Camera(prim)
            xf = UsdGeom.Xformable(prim).GetLocalTransformation()
            out["camera"] = {"transform": [list(xf.GetRow(i)) for i in range(4)],
                             "focal_length": cam.GetFocalLengthAttr().Get(),
                             "horizontal_aperture": cam.GetHorizontalApertureAttr().Get(),
                             "vertical_aperture": cam.GetVerticalApertureAttr().Get()}
        elif prim.IsA(UsdLux.SphereLight):
            out["lights"] += 1
        elif prim.GetName() == "contact_surface":
            out["contact_surface"] = list(
                UsdGeom.Xformable(prim).GetLocalTransformation().ExtractTranslation())
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
