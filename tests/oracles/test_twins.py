#!/usr/bin/env python3
"""Self-test of the twins (export/python/twins): the mesh measures with known answers (always), and with
CadQuery importable, the exact building blocks and the exact comparison against closed forms.

Usage: python tests/oracles/test_twins.py   (exit 0 when every check passes)
"""

from __future__ import annotations

import math
import sys
import unittest
from pathlib import Path

import manifold3d
import numpy as np

# the twins package: <repo>/export/python/twins (this file: <repo>/tests/oracles)
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "export" / "python"))

from twins import compare as K  # noqa: E402

try:
    import cadquery  # noqa: F401
    HAS_CQ = True
except ImportError:
    HAS_CQ = False


def mesh_of(m: manifold3d.Manifold):
    g = m.to_mesh()
    return (np.asarray(g.vert_properties, dtype=np.float64)[:, :3],
            np.asarray(g.tri_verts, dtype=np.int64))


class MeshMeasures(unittest.TestCase):
    def test_genus_watertight_volume_of_a_ring(self):
        ring = manifold3d.Manifold.cube((10, 10, 2), True) - manifold3d.Manifold.cylinder(
            4, 2, 2, 64, True)
        v, f = mesh_of(ring)
        ok, n_edges = K.edge_stats(f)
        self.assertTrue(ok)
        self.assertEqual(K.genus_from(len(v), n_edges, len(f), 1), 1)
        self.assertAlmostEqual(K.mesh_volume(v, f), ring.volume(), places=6)
        # an open mesh is caught
        ok, _ = K.edge_stats(f[1:])
        self.assertFalse(ok)

    def test_degenerate_pole_facets_are_dropped(self):
        v, f = mesh_of(manifold3d.Manifold.cube((1, 1, 1)))
        v = np.vstack([v, v[f[0, 0]]])  # a duplicate of a vertex: a zero-area facet on it
        f2 = np.vstack([f, [[f[0, 0], f[0, 1], len(v) - 1]]])
        vw, fw = K.weld(v, f2)
        kept, dropped = K.drop_degenerate(vw, fw)
        self.assertEqual(dropped, 1)
        self.assertEqual(len(kept), len(f))

    def test_point_mesh_distance_of_slivers_is_exact_with_the_right_triangle(self):
        # a 100 x 0.2 mm face in long slivers (two triangles) and points above it, beside its
        # long edge and past its ends: distances in closed form, the nearest triangle as given
        v = np.array([[0, 0, 0], [100, 0, 0], [100, 0.2, 0], [0, 0.2, 0]], dtype=np.float64)
        f = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
        sv, sf, parent = K.split_long_edges(v, f, 4.0)
        self.assertGreater(len(sf), 2 * 25)
        e = np.linalg.norm(sv[sf] - sv[np.roll(sf, 1, axis=1)], axis=2)
        self.assertLessEqual(e.max(), 4.0)
        self.assertAlmostEqual(sum(K.mesh_area(sv, sf[parent == i]) for i in (0, 1)),
                               K.mesh_area(v, f), places=9)
        p = np.array([[37.3, 0.15, 0.5], [61.0, -0.3, 0.0], [103.0, 0.1, 4.0],
                      [10.0, 0.01, -0.01]])
        d, tri = K.point_mesh_distance(p, v, f)
        np.testing.assert_allclose(d, [0.5, 0.3, 5.0, 0.01], rtol=0, atol=1e-12)
        self.assertEqual(tri[3], 0)  # below the diagonal y = 0.002 x: the first triangle
        self.assertEqual(tri[0], 1)  # above it: the second

    def test_hausdorff_of_a_shifted_mesh(self):
        v, f = mesh_of(manifold3d.Manifold.cube((2, 2, 2), True))
        h = K.mesh_hausdorff(v, f, v + [0.0, 0.0, 0.01], f)
        self.assertAlmostEqual(h, 0.01, places=9)


@unittest.skipUnless(HAS_CQ, "CadQuery not installed (full tier)")
class ExactTwins(unittest.TestCase):
    def test_ellipse_offset_spline_and_surface_points(self):
        from twins import cq_common as C
        body = C.Body({"profile": "half_ellipsoid", "diameter_mm": 18.0, "height_mm": 24.0})
        for d in (-2.4, 0.0, 0.5):
            e = body.curve_edges(d)[0]
            for polar in (0.0, 10.0, 45.0, 80.0):
                r, z, nr, nz = body.surface_point(d, polar)
                self.assertLess(C._edge_distance(e, C.vec(r, z)), 1e-6)
                self.assertAlmostEqual(math.degrees(math.atan2(r, z)), polar, places=9)
                self.assertAlmostEqual(math.hypot(nr, nz), 1.0, places=12)
        cap = C.Body({"profile": "spherical_cap", "base_diameter_mm": 35.0, "height_mm": 8.0})
        self.assertAlmostEqual(cap.rim_radius(0.0), 17.5, places=12)
        self.assertAlmostEqual(cap.pole_z(0.0) - cap.base_z(), 8.0, places=12)

    def test_exact_comparison_of_a_sphere_mesh(self):
        from twins import cq_common as C
        r, tol = 5.0, 0.01
        # a UV sphere with its vertices on the sphere, each direction within tol / 2
        n = 4 * math.ceil(math.pi / math.acos(1 - tol / 2 / r) / 4)
        lat = [math.pi * i / (n // 2) for i in range(1, n // 2)]
        v = [[0.0, 0.0, r]] + [[r * math.sin(a) * math.cos(2 * math.pi * j / n),
                                 r * math.sin(a) * math.sin(2 * math.pi * j / n), r * math.cos(a)]
                                for a in lat for j in range(n)] + [[0.0, 0.0, -r]]
        f = []
        rings = len(lat)
        idx = lambda i, j: 1 + i * n + j % n
        for j in range(n):
            f.append([0, idx(0, j), idx(0, j + 1)])
            f.append([len(v) - 1, idx(rings - 1, j + 1), idx(rings - 1, j)])
        for i in range(rings - 1):
            for j in range(n):
                f.append([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)])
                f.append([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)])
        v, f = np.asarray(v), np.asarray(f, dtype=np.int64)
        exact = C.primitive({"type": "sphere", "centre_mm": [0, 0, 0], "radius_mm": r})
        e = K.compare_exact(v, f, exact, tol)
        self.assertAlmostEqual(e["volume_exact_mm3"], 4 / 3 * math.pi * r ** 3, places=6)
        self.assertLessEqual(abs(e["volume_diff_mm3"]), e["volume_bound_mm3"])
        self.assertLessEqual(e["hausdorff_mm"], K.hausdorff_bound(tol))
        self.assertGreater(e["hausdorff_mm"], 0.2 * tol)  # the facets do leave the sphere
        self.assertEqual(e["genus_exact"], 0)
        self.assertTrue(e["exact_mesh_watertight"])
        self.assertGreater(e["exact_mesh_pole_facets_dropped"], 0)
        # a mesh 3 tol too big is caught
        e2 = K.compare_exact(v * (1 + 3 * tol / r), f, exact, tol)
        self.assertGreater(e2["hausdorff_mm"], K.hausdorff_bound(tol))


@unittest.skipUnless(HAS_CQ, "CadQuery not importable")
class StepReadBack(unittest.TestCase):
    """check_twins --exact-from-step: the exact solid is the export's STEP file, the one the
    manifest hashes; a machined part's file against its exact shape."""

    def setUp(self):
        import hashlib
        import tempfile
        from twins import cq_common as C
        from twins.step_export import write_step
        self.tmp = tempfile.TemporaryDirectory()
        self.d = Path(self.tmp.name)
        (self.d / "step").mkdir()
        # a ring 10 mm high: outer radius 5, inner 3 (volume pi (25 - 9) 10)
        self.ring = {"shape": "ring", "outer_radius_mm": 5.0, "inner_radius_mm": 3.0,
                     "z0_mm": 0.0, "z1_mm": 10.0}
        write_step(C.cut(C.cylinder_z(5.0, 0.0, 10.0), [C.cylinder_z(3.0, -1.0, 11.0)]),
                   self.d / "step" / "ring.step", "ring")
        self.sha = hashlib.sha256((self.d / "step" / "ring.step").read_bytes()).hexdigest()

    def tearDown(self):
        self.tmp.cleanup()

    def test_the_hashed_file_reads_back_as_the_solid(self):
        from twins import check_twins, cq_common
        row = {}
        entry = {"step_file": "step/ring.step", "step_sha256": self.sha}
        shape = check_twins.exact_solid(self.d, entry, True, row)
        self.assertEqual((row["exact_source"], row["step_solids"]), ("step", 1))
        self.assertAlmostEqual(cq_common.exact_volume(shape), math.pi * 16 * 10, places=6)

    def test_another_file_or_none_is_refused(self):
        from twins import check_twins
        with self.assertRaisesRegex(ValueError, "is not the manifest's"):
            check_twins.read_step(self.d, {"step_file": "step/ring.step",
                                           "step_sha256": "0" * 64}, {})
        with self.assertRaisesRegex(ValueError, "no step_file"):
            check_twins.read_step(self.d, {"step_sha256": self.sha}, {})

    def test_a_machined_part_against_its_exact_shape(self):
        from twins import check_twins
        mp = {"name": "ring", "step_file": "step/ring.step", "step_sha256": self.sha,
              "exact": self.ring}
        row = check_twins.check_machined(self.d, mp, 0.01, "test")
        self.assertTrue(row["ok"], row["problems"])
        self.assertLess(row["step_volume_rel_diff"], 1e-9)
        # a thicker ring is not this file
        row = check_twins.check_machined(self.d, dict(mp, exact=dict(self.ring, outer_radius_mm=5.1)),
                                         0.01, "test")
        self.assertFalse(row["ok"])
        self.assertIn("STEP volume", row["problems"][0])


if __name__ == "__main__":
    res = unittest.main(exit=False, verbosity=1).result
    print(f"test_twins: {res.testsRun - len(res.failures) - len(res.errors) - len(res.skipped)} passed, "
          f"{len(res.failures) + len(res.errors)} failed, {len(res.skipped)} skipped")
    sys.exit(0 if res.wasSuccessful() else 1)
