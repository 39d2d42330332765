"""Per-part comparison of fabkit's written mesh with a twin, and the bounds (issue 7).

Mesh-only helpers (no CadQuery) are used by both tiers; `compare_exact` needs OCP (CadQuery).

Bounds, for a part written at chord tolerance `tol` (mm):
- volume vs the exact CadQuery solid: |V_fabkit - V_exact| <= A_fabkit x tol + 1e-6 x V_exact
  (every facet lies within tol of the true surface, so the enclosed volumes differ by at most the
  area times tol; the second term covers the f32 rounding of the written vertices);
- volume vs manifold3d (same leaf meshes, same booleans): relative difference <= 1e-6;
- symmetric Hausdorff distance <= tol + 1 um (0.001 mm), over the faces of the exact solid and
  at its edges where faces meet (seams). fabkit meshes every surface to tol / sqrt(2) (see
  `ChordTolerance::facet_mm`) because two surfaces each meshed within d meet in a mesh corner up
  to d / sin(beta / 2) from the exact edge (beta the angle between them, sqrt(2) d for
  perpendicular faces); the seam distance is reported in its own column, with the same bound;
- bounding box: every face of the box within tol + 1 um;
- genus: equal (exact solid: from its tessellation with OCCT's zero-area pole facets dropped).
"""

from __future__ import annotations

import numpy as np

UM = 1e-3  # mm


def hausdorff_bound(tol: float) -> float:
    return tol + UM


def weld(v: np.ndarray, f: np.ndarray):
    """Vertices merged by exact position (the STL and OCCT per-face meshes repeat them)."""
    uniq, inv = np.unique(np.round(v, 12), axis=0, return_inverse=True)
    return uniq, inv.reshape(-1)[f]


def drop_degenerate(v: np.ndarray, f: np.ndarray):
    """Drops facets with a repeated vertex or zero area (OCCT writes them at the poles of
    spheres and surfaces of revolution). Returns (faces, number dropped)."""
    rep = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 0] == f[:, 2])
    a = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    bad = rep | (a <= 1e-18)
    return f[~bad], int(bad.sum())


def edge_stats(f: np.ndarray):
    """(watertight and consistently oriented: every directed edge once and its reverse once,
    number of undirected edges)."""
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]).astype(np.int64)
    n = int(f.max()) + 1 if len(f) else 1
    key = e[:, 0] * n + e[:, 1]
    rkey = e[:, 1] * n + e[:, 0]
    uniq, counts = np.unique(key, return_counts=True)
    ok = bool(np.all(counts == 1)) and bool(np.all(np.isin(rkey, uniq)))
    return ok, len(uniq) // 2


def closed_edges(f: np.ndarray):
    """(watertight: every undirected edge shared by exactly two facets, number of edges). Used
    for OCCT's tessellation, whose per-face winding is not checked here."""
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1).astype(np.int64)
    n = int(f.max()) + 1 if len(f) else 1
    _, counts = np.unique(e[:, 0] * n + e[:, 1], return_counts=True)
    return bool(np.all(counts == 2)), len(counts)


def genus_from(n_vertices: int, n_edges: int, n_faces: int, shells: int) -> int:
    """Genus as fabkit's manifest counts it: shells - chi / 2 (chi = V - E + F)."""
    return int(shells - (n_vertices - n_edges + n_faces) // 2)


def mesh_volume(v, f) -> float:
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def mesh_area(v, f) -> float:
    return float(0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]],
                                               v[f[:, 2]] - v[f[:, 0]]), axis=1).sum())


def samples(v, f):
    """Vertices, edge midpoints and centroids of a mesh (where a facet is farthest from the
    surface it approximates: its vertices lie on it)."""
    e = np.unique(np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1),
                  axis=0)
    return np.concatenate([v[np.unique(f)], 0.5 * (v[e[:, 0]] + v[e[:, 1]]),
                           v[f].mean(axis=1)])


# Longest edge, mm, of the triangles libigl's AABB tree is given (see point_mesh_distance).
SPLIT_EDGE_MM = 4.0


def split_long_edges(v, f, max_edge_mm: float = SPLIT_EDGE_MM):
    """The same surface with no edge longer than `max_edge_mm`: each longer triangle is cut in
    two at the midpoint of its longest edge, until none is left. Returns (vertices, faces,
    parent) with parent[i] the index in `f` of the triangle that face i is a piece of. The
    pieces of a triangle cover exactly it (the midpoints lie on its edges to 1 ulp), so the
    distance from any point to the surface is unchanged; T-junctions do not matter to it."""
    v = np.asarray(v, dtype=np.float64)
    f = np.asarray(f, dtype=np.int64)
    parent = np.arange(len(f))
    while len(f):
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        lens = np.stack([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                         np.linalg.norm(a - c, axis=1)], axis=1)
        k = lens.argmax(axis=1)
        big = lens[np.arange(len(f)), k] > max_edge_mm
        if not big.any():
            break
        # rotate each long triangle so that its longest edge is its first: (r0, r1), opposite r2
        r = np.stack([np.take_along_axis(f[big], ((k[big] + j) % 3)[:, None], axis=1)[:, 0]
                      for j in range(3)], axis=1)
        mid = np.arange(len(v), len(v) + len(r))
        v = np.concatenate([v, 0.5 * (v[r[:, 0]] + v[r[:, 1]])])
        f = np.concatenate([f[~big], np.stack([r[:, 0], mid, r[:, 2]], axis=1),
                            np.stack([mid, r[:, 1], r[:, 2]], axis=1)])
        parent = np.concatenate([parent[~big], parent[big], parent[big]])
    return v, f, parent


def point_mesh_distance(p, v, f):
    """(distances, nearest triangle) of points p to the mesh (exact, libigl's AABB tree).
    The tree is built on the mesh's long triangles cut to at most SPLIT_EDGE_MM (the same
    surface): slivers that span a part (fans of a holed face) overlap every box on their way
    and made each query visit most of the tree (seconds to minutes on large parts)."""
    import igl
    sv, sf, parent = split_long_edges(v, f)
    d2, tri, _ = igl.point_mesh_squared_distance(np.ascontiguousarray(p, dtype=np.float64),
                                                 np.ascontiguousarray(sv, dtype=np.float64),
                                                 np.ascontiguousarray(sf, dtype=np.int64))
    return np.sqrt(np.maximum(d2, 0.0)), parent[tri]


def mesh_hausdorff(va, fa, vb, fb, dense: bool = True) -> float:
    """Symmetric Hausdorff distance between two meshes, sampled at the vertices (and with
    `dense`, the edge midpoints and centroids) of each, distances to the other mesh exact."""
    pa = samples(va, fa) if dense else va[np.unique(fa)]
    pb = samples(vb, fb) if dense else vb[np.unique(fb)]
    da, _ = point_mesh_distance(pa, vb, fb)
    db, _ = point_mesh_distance(pb, va, fa)
    return float(max(da.max(initial=0.0), db.max(initial=0.0)))


def bbox_dev(lo_a, hi_a, lo_b, hi_b) -> float:
    return float(max(np.abs(np.asarray(lo_a) - lo_b).max(), np.abs(np.asarray(hi_a) - hi_b).max()))


def load_stl(path):
    import trimesh
    m = trimesh.load(str(path), process=False, force="mesh")
    v, f = weld(np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64))
    return v, f


# ------------------------------------------------------------------------------------------
# The exact (OCCT) side


def occt_mesh(shape, lin_defl: float, ang_defl: float = 0.25):
    """Per-face triangulation of an OCCT shape: (vertices, faces, face index per triangle, faces)
    with outward winding, vertices of shared edges merged."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    from OCP.BRepTools import BRepTools
    BRepTools.Clean_s(shape.wrapped)  # no mesh left from another use of shared geometry
    BRepMesh_IncrementalMesh(shape.wrapped, lin_defl, False, ang_defl, True)
    verts, tris, fid, faces = [], [], [], []
    off = 0
    exp = TopExp_Explorer(shape.wrapped, TopAbs_FACE)
    while exp.More():
        face = TopoDS.Face_s(exp.Current())
        loc = TopLoc_Location()
        tri = BRep_Tool.Triangulation_s(face, loc)
        exp.Next()
        if tri is None:
            continue
        trsf = loc.Transformation()
        n = tri.NbNodes()
        pts = np.empty((n, 3))
        for i in range(1, n + 1):
            p = tri.Node(i).Transformed(trsf)
            pts[i - 1] = (p.X(), p.Y(), p.Z())
        t = np.empty((tri.NbTriangles(), 3), dtype=np.int64)
        for i in range(1, tri.NbTriangles() + 1):
            t[i - 1] = tri.Triangle(i).Get()
        t -= 1
        if face.Orientation() == TopAbs_REVERSED:
            t = t[:, [0, 2, 1]]
        verts.append(pts)
        tris.append(t + off)
        fid.append(np.full(len(t), len(faces)))
        faces.append(face)
        off += n
    v = np.concatenate(verts)
    f = np.concatenate(tris)
    v, f = weld_close(v, f, 1e-9)
    return v, f, np.concatenate(fid), faces


def weld_close(v, f, eps: float):
    """Vertices closer than `eps` merged (OCCT evaluates a shared edge's nodes on each face
    separately; they agree to ~1e-15 mm, not bit for bit)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree
    pairs = cKDTree(v).query_pairs(eps, output_type="ndarray")
    n = len(v)
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(g, directed=False)
    first = np.full(label.max() + 1, -1)
    first[label[::-1]] = np.arange(n)[::-1]
    return v[first], label[f].astype(np.int64)


class _ExactDistance:
    """Exact distance from a point to a face of an OCCT shape (projection on its surface when
    the foot lies in the face, else OCCT's extrema on the face; the whole shape when unsure)."""

    def __init__(self, shape, faces):
        self.shape, self.faces = shape, faces
        self.cache = {}

    def __call__(self, p, face_index: int) -> float:
        from OCP.BRep import BRep_Tool
        from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
        from OCP.BRepExtrema import BRepExtrema_DistShapeShape
        from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
        from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
        from OCP.gp import gp_Pnt, gp_Pnt2d
        from OCP.TopAbs import TopAbs_IN, TopAbs_ON

        face = self.faces[face_index]
        if face_index not in self.cache:
            self.cache[face_index] = (BRep_Tool.Surface_s(face), BRepTopAdaptor_FClass2d(face, 1e-9))
        surf, cls = self.cache[face_index]
        q = gp_Pnt(float(p[0]), float(p[1]), float(p[2]))
        pr = GeomAPI_ProjectPointOnSurf(q, surf)
        if pr.NbPoints() > 0:
            u, v = pr.LowerDistanceParameters()
            state = cls.Perform(gp_Pnt2d(u, v))
            if state == TopAbs_IN:
                return pr.LowerDistance(), False
            if state == TopAbs_ON:  # the foot is on the face's boundary: an edge of the solid
                return pr.LowerDistance(), True
        # The foot lies outside this face: OCCT's extrema to the trimmed face (its edges), an
        # upper bound of the distance to the solid's boundary; counted as a seam sample.
        vert = BRepBuilderAPI_MakeVertex(q).Vertex()
        d = BRepExtrema_DistShapeShape(vert, face)
        return d.Value(), True


# Candidates refined exactly whatever their bound (the report's figure: the largest distances
# measured, not only bounded).
EXACT_TOP = 200


def compare_exact(fv, ff, shape, tol: float, max_refine: int = 5000) -> dict:
    """fabkit's mesh (fv, ff) against the exact solid `shape` (both in print orientation).

    fabkit -> exact: each sample's distance to the twin's mesh, plus the mesh's deflection, bounds
    its distance to the exact surface. The samples are refined with exact point-to-face distances
    from the farthest: the first EXACT_TOP of them, then every one whose bound exceeds the
    Hausdorff bound (tol + 1 um), at most `max_refine`. The distance reported is the largest
    refined one or, where samples were left unrefined, the largest bound among them: an upper
    bound that the check holds to (a sample beyond the Hausdorff bound is always refined)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from .cq_common import exact_volume
    v_exact = exact_volume(shape)
    bb = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape.wrapped, bb, False, False)
    xmin, ymin, zmin, xmax, ymax, zmax = bb.Get()

    defl = tol / 4.0
    tv, tf, fid, faces = occt_mesh(shape, defl)
    tf_ok, dropped = drop_degenerate(tv, tf)
    watertight, n_edges = closed_edges(tf_ok)
    g_exact = (genus_from(len(np.unique(tf_ok)), n_edges, len(tf_ok), _solids(shape))
               if watertight else None)

    v_f = mesh_volume(fv, ff)
    a_f = mesh_area(fv, ff)
    # exact surface -> fabkit: the twin's mesh vertices lie on the exact surface
    used = np.unique(tf_ok)
    d_tf, _ = point_mesh_distance(tv[used], fv, ff)
    # twin vertices shared by two faces lie on the exact solid's edges (seams)
    seam_v = _seam_vertices(tv, tf_ok, fid[~_degenerate_mask(tv, tf)])[used]
    h_tf = float(d_tf[~seam_v].max(initial=0.0))
    h_tf_seam = float(d_tf[seam_v].max(initial=0.0))
    # fabkit -> exact surface: candidates from the twin's mesh (within its deflection), the
    # farthest ones refined with exact point-to-face distances
    s = samples(fv, ff)
    d_approx, tri = point_mesh_distance(s, tv, tf_ok if len(tf_ok) else tf)
    face_of = fid  # triangle -> face (degenerate ones dropped keep order of the rest)
    keep = ~_degenerate_mask(tv, tf)
    face_of = fid[keep]
    order = np.argsort(-d_approx)
    exact = _ExactDistance(shape, faces)
    best, best_seam = 0.0, 0.0
    refined = 0
    bound_rest = 0.0
    hb = hausdorff_bound(tol)
    for k in order:
        bound_k = float(d_approx[k] + defl)
        if bound_k <= best:
            break
        if (refined >= EXACT_TOP and bound_k <= hb) or refined >= max_refine:
            bound_rest = bound_k
            break
        d, seam = exact(s[k], int(face_of[tri[k]]))
        if seam:
            best_seam = max(best_seam, d)
        else:
            best = max(best, d)
        refined += 1
    h_ft = max(best, bound_rest)
    h_ft_seam = max(best_seam, bound_rest)
    return {
        "volume_exact_mm3": v_exact,
        "volume_fabkit_mm3": v_f,
        "volume_diff_mm3": v_f - v_exact,
        "volume_bound_mm3": a_f * tol + 1e-6 * abs(v_exact),
        "hausdorff_mm": max(h_tf, h_ft),
        "hausdorff_seam_mm": max(h_tf_seam, h_ft_seam),
        "hausdorff_fabkit_to_exact_mm": h_ft,
        "hausdorff_exact_to_fabkit_mm": h_tf,
        "hausdorff_refined_samples": refined,
        "bbox_exact_mm": {"min": [xmin, ymin, zmin], "max": [xmax, ymax, zmax]},
        "bbox_dev_mm": bbox_dev(fv.min(axis=0), fv.max(axis=0), [xmin, ymin, zmin],
                                [xmax, ymax, zmax]),
        "genus_exact": g_exact,
        "exact_mesh_watertight": watertight,
        "exact_mesh_pole_facets_dropped": dropped,
    }


def _degenerate_mask(v, f):
    rep = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 0] == f[:, 2])
    a = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    return rep | (a <= 1e-18)


def _solids(shape) -> int:
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    n = 0
    exp = TopExp_Explorer(shape.wrapped, TopAbs_SOLID)
    while exp.More():
        n += 1
        exp.Next()
    return n


def _seam_vertices(v, f, fid) -> np.ndarray:
    """Vertices used by triangles of two or more faces (on the exact solid's edges)."""
    pairs = np.unique(np.stack([f.reshape(-1), np.repeat(fid, 3)], axis=1), axis=0)
    count = np.bincount(pairs[:, 0], minlength=len(v))
    return count >= 2
