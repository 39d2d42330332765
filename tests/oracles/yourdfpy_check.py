#!/usr/bin/env python3
"""yourdfpy oracle: validates the URDF of `fabkit export --format urdf` and reads it back, meshes
loaded (trimesh) from the file's folder.

Usage: python tests/oracles/yourdfpy_check.py MODEL.urdf   (with the oracle venv's python)

Prints ONE JSON document (the file's own numbers, SI units):

  {"yourdfpy_version": str, "valid": bool, "errors": [str], "name": str,
   "links": [str], "joints": [str], "base": str,
   "inertial": {"mass_kg": float, "origin": [[4] x 4], "inertia_kg_m2": [[3], [3], [3]]},
   "frames": {LINK: [[4] x 4]},        the link's pose in the base link's frame (forward kinematics)
   "meshes": int}                       meshes in the loaded scene

- valid/errors: URDF.validate() (unique names, joints naming existing links, one root) and the
  errors it logged.
Exit 0 when the file loads; 1 with yourdfpy's error otherwise.
"""

from __future__ import annotations

import json
import logging
import os
import sys
from importlib.metadata import version


class Collect(logging.Handler):
    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages = []

    def emit(self, record):
        self.messages.append(record.getMessage())


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    import yourdfpy

    errors = Collect()
    logging.getLogger("yourdfpy").addHandler(errors)
    path = argv[1]
    urdf = yourdfpy.URDF.load(path, mesh_dir=os.path.dirname(os.path.abspath(path)))
    valid = bool(urdf.validate())
    base = urdf.base_link
    link = urdf.link_map[base]
    out = {
        "yourdfpy_version": version("yourdfpy"), "valid": valid, "errors": errors.messages,
        "name": urdf.robot.name, "links": [l.name for l in urdf.robot.links],
        "joints": [j.name for j in urdf.robot.joints], "base": base,
        "inertial": None if link.inertial is None else {
            "mass_kg": float(link.inertial.mass),
            "origin": link.inertial.origin.tolist(),
            "inertia_kg_m2": link.inertial.inertia.tolist()},
        "frames": {l.name: urdf.get_transform(l.name, base).tolist() for l in urdf.robot.links},
        "meshes": len(urdf.scene.geometry) if urdf.scene is not None else 0,
    }
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
