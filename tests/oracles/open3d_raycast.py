"""Open3D RaycastingScene oracle for fabkit's ground-truth ray caster.

Usage: python open3d_raycast.py DIR [--time N]
DIR holds vertices.npy (V, 3) float32, triangles.npy (T, 3) uint32 and rays.npy (N, 6) float32
(origin, unit direction), all in one frame (mm). Writes DIR/t_hit.npy (N,) float32 (inf where
the ray misses) and DIR/primitive_ids.npy (N,) uint32 (Open3D's INVALID_ID where it misses), and
prints JSON {"open3d_version", "rays", "hits"}. With --time N it also casts the rays N times
on one thread (nthreads=1) and adds "best_cpu_s" (process CPU time of the fastest cast) and
"best_wall_s"; scene construction is not timed.
"""
import json
import sys
import time

import numpy as np
import open3d as o3d


def main():
    d = sys.argv[1]
    reps = int(sys.argv[sys.argv.index("--time") + 1]) if "--time" in sys.argv else 0
    v = np.load(f"{d}/vertices.npy").astype(np.float32)
    t = np.load(f"{d}/triangles.npy").astype(np.uint32)
    rays = np.load(f"{d}/rays.npy").astype(np.float32)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(t))
    r = o3d.core.Tensor(rays)
    ans = scene.cast_rays(r, nthreads=1)
    t_hit = ans["t_hit"].numpy()
    np.save(f"{d}/t_hit.npy", t_hit)
    np.save(f"{d}/primitive_ids.npy", ans["primitive_ids"].numpy())
    out = {
        "open3d_version": o3d.__version__,
        "rays": int(rays.shape[0]),
        "hits": int(np.isfinite(t_hit).sum()),
    }
    if reps:
        best_cpu, best_wall = float("inf"), float("inf")
        for _ in range(reps):
            c0, w0 = time.process_time(), time.perf_counter()
            scene.cast_rays(r, nthreads=1)
            best_cpu = min(best_cpu, time.process_time() - c0)
            best_wall = min(best_wall, time.perf_counter() - w0)
        out["best_cpu_s"] = best_cpu
        out["best_wall_s"] = best_wall
    print(json.dumps(out))


if __name__ == "__main__":
    main()
