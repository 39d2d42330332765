#!/usr/bin/env python3
"""published_step.py - the distance between a part fabkit exported and an authors' published STEP.

Usage: published_step.py PUBLISHED.STEP PART.stl T_PRINT_SENSOR T_STEP_SENSOR
       (run by a Python with CadQuery/OCP, trimesh and libigl)

T_PRINT_SENSOR is the part's `params.T_print_sensor` from the manifest, T_STEP_SENSOR the map from
the sensor frame into the published file's frame; both JSON, 3 x 4 rows. The STL is mapped back
into the sensor frame and on into the STEP's frame; the STEP is tessellated by OCCT to 0.002 mm.
Both meshes are subdivided to edges of at most 0.25 mm, and each one's vertices measured to the
other's surface (libigl's exact point-to-triangle distance): the two one-sided distances and their maximum
(the Hausdorff distance, sampled every 0.25 mm), the worst point of each, and both volumes.

Prints one JSON object; exit status 0, or 2 when a file cannot be read.
"""

import json
import sys

import numpy as np
import trimesh


def rigid(rows):
    m = np.eye(4)
    m[:3, :] = np.asarray(rows, dtype=float)
    return m


def step_mesh(path):
    import cadquery as cq

    shape = cq.importers.importStep(path).val()
    verts, tris = shape.tessellate(0.002, 0.1)
    v = np.array([[p.x, p.y, p.z] for p in verts])
    return trimesh.Trimesh(v, np.array(tris), process=True), shape.Volume()


def dense(mesh, edge_mm=0.25):
    v, _ = trimesh.remesh.subdivide_to_size(mesh.vertices, mesh.faces, max_edge=edge_mm)
    return v


def one_sided(points, mesh):
    import igl

    d2 = igl.point_mesh_squared_distance(
        np.ascontiguousarray(points, dtype=float),
        np.ascontiguousarray(mesh.vertices, dtype=float),
        np.ascontiguousarray(mesh.faces, dtype=np.int64))[0]
    d = np.sqrt(d2)
    i = int(np.argmax(d))
    return float(d[i]), [round(float(x), 4) for x in points[i]]


def main() -> int:
    if len(sys.argv) != 5:
        sys.stderr.write(__doc__)
        return 2
    step_path, stl_path, t_print, t_step = sys.argv[1:]
    try:
        published, step_volume = step_mesh(step_path)
        ours = trimesh.load(stl_path, force="mesh")
    except Exception as e:  # noqa: BLE001 - any reader failure is the same usage error
        sys.stderr.write(f"cannot read: {e}\n")
        return 2
    to_step = rigid(json.loads(t_step)) @ np.linalg.inv(rigid(json.loads(t_print)))
    ours.apply_transform(to_step)
    from_step, worst_step = one_sided(dense(published), ours)
    from_ours, worst_ours = one_sided(dense(ours), published)
    print(json.dumps({
        "hausdorff_mm": max(from_step, from_ours),
        "published_to_ours_mm": from_step,
        "worst_published_point": worst_step,
        "ours_to_published_mm": from_ours,
        "worst_our_point": worst_ours,
        "published_volume_mm3": step_volume,
        "our_volume_mm3": float(ours.volume),
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
