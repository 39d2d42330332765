#!/usr/bin/env python3
"""published_step.py - the distance between a part fabkit exported and an authors' published STEP.

Usage: published_step.py PUBLISHED.STEP PART.stl T_PRINT_SENSOR T_STEP_SENSOR
       (run by a Python with CadQuery/OCP, trimesh and libigl)

T_PRINT_SENSOR is the part's `params.T_print_sensor` from the manifest, T_STEP_SENSOR the map from
the sensor frame into the published file's frame; both JSON, 3 x 4 rows. The STL is mapped back
into the sensor frame and on into the STEP's frame; the STEP is tessellated by OCCT to 0.002 mm.
Both meshes are sampled every 0.25 mm or closer (`dense`), and each one's samples measured to the
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


def ranks(counts):
    """0, 1, ..., c - 1 for each count c in turn (each entry's place within its group)."""
    return np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)


def dense(mesh, edge_mm=0.25):
    """Points of the mesh's surface no farther than `edge_mm` apart: each triangle in rows
    parallel to its longest edge, the rows at most edge_mm apart (the base row on that edge, the
    last on the opposite corner) and each row's points at most edge_mm apart, its ends on the
    triangle's other two edges. A sliver (a fan of a holed face) gets one or two rows, not the
    square of its length / edge_mm points an even subdivision gives it."""
    v = np.asarray(mesh.vertices, dtype=float)
    f = np.asarray(mesh.faces, dtype=np.int64)
    tri = v[f]
    lens = np.linalg.norm(tri[:, [1, 2, 0]] - tri, axis=2)  # edge k: corner k to corner k + 1
    k = lens.argmax(axis=1)
    faces = np.arange(len(f))
    p0, p1, p2 = tri[faces, k], tri[faces, (k + 1) % 3], tri[faces, (k + 2) % 3]
    base = lens[faces, k]
    twice_area = np.linalg.norm(np.cross(p1 - p0, p2 - p0), axis=1)
    height = np.divide(twice_area, base, out=np.zeros_like(base), where=base > 0)
    m = np.maximum(1, np.ceil(height / edge_mm)).astype(np.int64)
    # rows r = 0..m of each face, at t = r / m of the way from the base to the opposite corner
    row_face = np.repeat(faces, m + 1)
    t = (ranks(m + 1) / m[row_face])[:, None]
    a = p0[row_face] + t * (p2 - p0)[row_face]
    b = p1[row_face] + t * (p2 - p1)[row_face]
    n = np.maximum(1, np.ceil((1.0 - t[:, 0]) * base[row_face] / edge_mm)).astype(np.int64)
    pt_row = np.repeat(np.arange(len(n)), n + 1)
    s = (ranks(n + 1) / n[pt_row])[:, None]
    return a[pt_row] + s * (b - a)[pt_row]


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
