#!/usr/bin/env python3
"""PyBullet oracle: loads the URDF of `fabkit export --format urdf` in DIRECT mode (no GUI) and
reads back what Bullet made of it.

Usage: python tests/oracles/pybullet_check.py MODEL.urdf   (with the oracle venv's python)

Prints ONE JSON document (SI units, PyBullet's numbers, the base at the world's origin):

  {"base": {"name": str, "mass_kg": float, "com_m": [3], "principal_kg_m2": [3],
            "inertia_kg_m2": [[3], [3], [3]]},
   "links": {NAME: {"pos_m": [3], "R": [[3], [3], [3]]}}, "link_masses_kg": [...],
   "visual_shapes": int,
   "collision_shapes": int}

- base.inertia_kg_m2: the full tensor about the centre of mass in the base's frame, rebuilt from
  Bullet's principal moments and the inertial frame's orientation: R diag(I) R^T.
- links: each fixed child link's frame in the world frame, where the base's link frame is at
  its origin (loaded there, read before the first step); R's columns are its axes.
Exit 0 when the file loads; 1 with Bullet's error otherwise.
"""

from __future__ import annotations

import json
import sys

import numpy as np
import pybullet as p


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(argv[1], useFixedBase=False, flags=p.URDF_USE_INERTIA_FROM_FILE,
                          physicsClientId=client)
        masses = [p.getDynamicsInfo(body, j, physicsClientId=client)[0]
                  for j in range(p.getNumJoints(body, physicsClientId=client))]
        info = p.getDynamicsInfo(body, -1, physicsClientId=client)
        mass, principal, ipos, iorn = info[0], info[2], info[3], info[4]
        r = np.array(p.getMatrixFromQuaternion(iorn)).reshape(3, 3)
        links = {}
        for j in range(p.getNumJoints(body, physicsClientId=client)):
            name = p.getJointInfo(body, j, physicsClientId=client)[12].decode()
            s = p.getLinkState(body, j, computeForwardKinematics=True, physicsClientId=client)
            # the link's URDF frame: worldLinkFramePosition / Orientation
            links[name] = {"pos_m": list(s[4]),
                           "R": np.array(p.getMatrixFromQuaternion(s[5])).reshape(3, 3).tolist()}
        p.stepSimulation(physicsClientId=client)  # it steps
        out = {
            "base": {"name": p.getBodyInfo(body, physicsClientId=client)[0].decode(),
                     "mass_kg": mass, "com_m": list(ipos), "principal_kg_m2": list(principal),
                     "inertia_kg_m2": (r @ np.diag(principal) @ r.T).tolist()},
            "links": links,
            "link_masses_kg": masses,
            "visual_shapes": len(p.getVisualShapeData(body, physicsClientId=client)),
            "collision_shapes": len(p.getCollisionShapeData(body, -1, physicsClientId=client)),
        }
    finally:
        p.disconnect(client)
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
