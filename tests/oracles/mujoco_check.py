#!/usr/bin/env python3
"""MuJoCo oracle: loads the MJCF model of `fabkit export --format mjcf`, steps it, and reads back
what MuJoCo made of it.

Usage: python tests/oracles/mujoco_check.py MODEL.xml BODY STEPS   (with the oracle venv's python)

Prints ONE JSON document (SI units, MuJoCo's own numbers):

  {"mujoco_version": str, "nbody": int, "ngeom": int, "nmesh": int, "nlight": int,
   "body": {"mass_kg": float, "com_m": [3], "inertia_kg_m2": [[3], [3], [3]]},
   "camera": null | {"pos_m": [3], "R_body_cam": [[3], [3], [3]], "fovy_deg": float,
                     "resolution": [w, h]},
   "site": null | {"pos_m": [3]}, "steps": int, "time_s": float,
   "collision_geoms": {NAME: {"type": "mesh" | "box" | "cylinder", "size": [3], "pos_m": [3]}}}

- body.inertia_kg_m2: the full tensor about the centre of mass in the body's frame, rebuilt from
  MuJoCo's principal moments (body_inertia) and their frame (body_iquat): R diag(I) R^T.
- camera.R_body_cam: the columns are MuJoCo's camera axes (x right, y up, looking along -z) in
  the body's frame.
Exit 0 when the model loads and steps; MuJoCo's error otherwise (exit 1).
"""

from __future__ import annotations

import json
import sys

import mujoco
import numpy as np


def rot(q):
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, np.asarray(q, dtype=np.float64))
    return m.reshape(3, 3)


def main(argv):
    if len(argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    path, body, steps = argv[1], argv[2], int(argv[3])
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    r = rot(model.body_iquat[b])
    out = {
        "mujoco_version": mujoco.__version__,
        "nbody": int(model.nbody), "ngeom": int(model.ngeom), "nmesh": int(model.nmesh),
        "nlight": int(model.nlight),
        "body": {"mass_kg": float(model.body_mass[b]), "com_m": model.body_ipos[b].tolist(),
                 "inertia_kg_m2": (r @ np.diag(model.body_inertia[b]) @ r.T).tolist()},
        "camera": None, "site": None, "steps": steps, "time_s": float(data.time),
        "collision_geoms": {},
    }
    types = {int(mujoco.mjtGeom.mjGEOM_MESH): "mesh", int(mujoco.mjtGeom.mjGEOM_BOX): "box",
             int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder"}
    for g in range(model.ngeom):
        if model.geom_contype[g] or model.geom_conaffinity[g]:
            out["collision_geoms"][model.geom(g).name] = {
                "type": types.get(int(model.geom_type[g]), str(int(model.geom_type[g]))),
                "size": model.geom_size[g].tolist(), "pos_m": model.geom_pos[g].tolist()}
    c = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "camera")
    if c >= 0:
        out["camera"] = {"pos_m": model.cam_pos[c].tolist(),
                         "R_body_cam": rot(model.cam_quat[c]).tolist(),
                         "fovy_deg": float(model.cam_fovy[c]),
                         "resolution": [int(v) for v in model.cam_resolution[c]]}
    s = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "contact_surface")
    if s >= 0:
        out["site"] = {"pos_m": model.site_pos[s].tolist()}
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
