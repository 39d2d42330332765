"""Exact building blocks of the CadQuery twins: body profiles and their true offsets, solids of
revolution, marker features, primitives, booleans and the print placement.

Everything here is written from the parameters alone (docs/conventions.md: sensor frame, mm,
z along the sensor axis through the pole, origin at the centre of the tip curvature), not from
fabkit's code paths: surfaces are exact (circles, lines, and for the half ellipsoid an
B-spline approximating exact points of the offset curve, within 1e-6 mm of it).
"""

from __future__ import annotations

import math

import cadquery as cq
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.gp import gp_Trsf
from OCP.TopTools import TopTools_ListOfShape

# Booleans on several threads (OCCT's parallel mode): the same B-rep as single-threaded, so STEP
# export keeps it on (step_export.py's docstring says which files vary from run to run anyway).
PARALLEL = True

# Geometric resolution of the exact twins (B-spline fit of ellipse offsets), mm.
SPLINE_TOL_MM = 1e-6


class TwinError(Exception):
    """A twin cannot be built from the parameters it was given."""


def vec(r: float, z: float) -> cq.Vector:
    """A point of the (r, z) half-plane as the 3D point (r, 0, z) (the XZ plane, y = 0)."""
    return cq.Vector(float(r), 0.0, float(z))


# ------------------------------------------------------------------------------------------
# Body profiles (designs/src/profile.rs documents the same shapes; see docs/conventions.md)


_SPLINES: dict = {}


class Body:
    """The outer surface of the sensor skin and its normal offsets, in the (r, z) half-plane."""

    def __init__(self, p: dict):
        self.kind = p["profile"]
        if self.kind == "hemisphere_on_cylinder":
            self.R = float(p["radius_mm"])
            self.L = float(p["cylinder_length_mm"])
        elif self.kind == "spherical_cap":
            b, h = float(p["base_diameter_mm"]) / 2.0, float(p["height_mm"])
            self.R = (b * b + h * h) / (2.0 * h)
            self.zb = self.R - h
        elif self.kind == "half_ellipsoid":
            self.a = float(p["diameter_mm"]) / 2.0
            self.c = float(p["height_mm"])
        else:
            raise TwinError(f"body.profile = {self.kind!r}: no twin for this profile")

    # --- scalar geometry
    def base_z(self) -> float:
        return {"hemisphere_on_cylinder": lambda: -self.L, "spherical_cap": lambda: self.zb,
                "half_ellipsoid": lambda: 0.0}[self.kind]()

    def is_sphere(self) -> bool:
        return self.kind != "half_ellipsoid"

    def pole_z(self, d: float) -> float:
        return self.c + d if self.kind == "half_ellipsoid" else self.R + d

    def rim_radius(self, d: float) -> float:
        if self.kind == "hemisphere_on_cylinder":
            return self.R + d
        if self.kind == "spherical_cap":
            return math.sqrt((self.R + d) ** 2 - self.zb ** 2)
        return self.a + d

    def ellipse_offset(self, d: float, th: float) -> tuple[float, float, float, float]:
        """(r, z, nr, nz) of the offset curve at ellipse angle th (pi/2 = pole, 0 = rim)."""
        a, c = self.a, self.c
        nr, nz = c * math.cos(th), a * math.sin(th)
        n = math.hypot(nr, nz)
        nr, nz = nr / n, nz / n
        return a * math.cos(th) + d * nr, c * math.sin(th) + d * nz, nr, nz

    def surface_point(self, d: float, polar_deg: float) -> tuple[float, float, float, float]:
        """(r, z, nr, nz): the point of the offset surface at `d` seen from the origin at
        `polar_deg` from +z, with its outward unit normal."""
        th = math.radians(polar_deg)
        if self.is_sphere():
            rho = self.R + d
            if self.kind == "hemisphere_on_cylinder" and th > math.pi / 2:
                # on the cylinder below the equator: r = rho, z = rho / tan(polar)
                return rho, rho * math.cos(th) / math.sin(th), 1.0, 0.0
            return rho * math.sin(th), rho * math.cos(th), math.sin(th), math.cos(th)
        if polar_deg == 0.0:
            return 0.0, self.c + d, 0.0, 1.0
        lo, hi = 0.0, math.pi / 2  # ellipse angle; polar grows as th falls
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            r, z, _, _ = self.ellipse_offset(d, mid)
            if math.atan2(r, z) > th:
                lo = mid
            else:
                hi = mid
        return self.ellipse_offset(d, 0.5 * (lo + hi))

    # --- edges of the offset curve, from the pole (r = 0) to the rim on the base plane
    def curve_edges(self, d: float) -> list:
        zb = self.base_z()
        if self.is_sphere():
            rho = self.R + d
            if self.kind == "hemisphere_on_cylinder":
                a_end = 0.0
            else:
                a_end = math.asin(max(-1.0, min(1.0, zb / rho)))
            a_mid = 0.5 * (math.pi / 2 + a_end)
            end = vec(rho * math.cos(a_end), rho * math.sin(a_end))
            if self.kind == "spherical_cap":
                end = vec(self.rim_radius(d), zb)
            edges = [cq.Edge.makeThreePointArc(vec(0.0, rho),
                                               vec(rho * math.cos(a_mid), rho * math.sin(a_mid)),
                                               end)]
            if self.kind == "hemisphere_on_cylinder" and self.L > 0:
                edges.append(cq.Edge.makeLine(vec(rho, 0.0), vec(rho, zb)))
            return edges
        return [self._ellipse_offset_spline(d)]

    def _ellipse_offset_spline(self, d: float):
        # The fitted curve is cached, never the edge: parts must not share topology (OCCT keeps
        # a mesh on the edge, which would then belong to two parts' faces).
        from OCP.BRep import BRep_Tool
        from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
        key = (self.a, self.c, d)
        if key not in _SPLINES:
            _SPLINES[key] = BRep_Tool.Curve_s(self._fit_ellipse_offset(d).wrapped, 0.0, 1.0)
        return cq.Edge(BRepBuilderAPI_MakeEdge(_SPLINES[key]).Edge())

    def _fit_ellipse_offset(self, d: float):
        # A B-spline (degree <= 8) approximating 2001 exact points of the offset curve, uniform
        # in the ellipse angle, within SPLINE_TOL_MM / 10 of them; then checked against 4000
        # exact points in between. Few poles keep OCCT's booleans on it fast.
        from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
        from OCP.GeomAbs import GeomAbs_C2
        from OCP.GeomAPI import GeomAPI_PointsToBSpline
        from OCP.gp import gp_Pnt
        from OCP.TColgp import TColgp_Array1OfPnt
        n = 2000
        arr = TColgp_Array1OfPnt(1, n + 1)
        for i in range(n + 1):
            r, z, _, _ = self.ellipse_offset(d, math.pi / 2 * (1.0 - i / n))
            arr.SetValue(i + 1, gp_Pnt(0.0 if i == 0 else r, 0.0, 0.0 if i == n else z))
        curve = GeomAPI_PointsToBSpline(arr, 3, 8, GeomAbs_C2, SPLINE_TOL_MM / 10).Curve()
        e = cq.Edge(BRepBuilderAPI_MakeEdge(curve).Edge())
        worst = 0.0
        for i in range(0, 4000, 7):
            r, z, _, _ = self.ellipse_offset(d, math.pi / 2 * (1.0 - (i + 0.5) / 4000))
            worst = max(worst, _edge_distance(e, vec(r, z)))
        if worst > SPLINE_TOL_MM:
            raise TwinError(f"ellipse offset {d} mm: B-spline fit {worst:.2e} mm")
        return e


def _edge_distance(edge, p: cq.Vector) -> float:
    from OCP.BRep import BRep_Tool
    from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve
    from OCP.gp import gp_Pnt
    curve = BRep_Tool.Curve_s(edge.wrapped, 0.0, 1.0)
    pr = GeomAPI_ProjectPointOnCurve(gp_Pnt(p.x, p.y, p.z), curve)
    return pr.LowerDistance() if pr.NbPoints() else math.inf


# ------------------------------------------------------------------------------------------
# Solids


def revolve(curve_edges: list, points: list[tuple[float, float]], start=None) -> cq.Solid:
    """The solid of revolution about z of the closed (r, z) profile: `curve_edges` (in order),
    then straight lines through `points`, then back to the start of the first edge (or `start`
    when there are no edges)."""
    edges = list(curve_edges)
    if edges:
        first = edges[0].startPoint()
        cur = edges[-1].endPoint()
    else:
        first = vec(*start)
        cur = first
    for (r, z) in points:
        p = vec(r, z)
        if (p - cur).Length > 1e-12:
            edges.append(cq.Edge.makeLine(cur, p))
            cur = p
    if (first - cur).Length > 1e-12:
        edges.append(cq.Edge.makeLine(cur, first))
    wire = cq.Wire.assembleEdges(edges)
    face = cq.Face.makeFromWires(wire)
    return _solid(cq.Solid.revolve(face, 360.0, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1)))


def revolve_polyline(points: list[tuple[float, float]]) -> cq.Solid:
    return revolve([], points[1:], start=points[0])


def _solid(s):
    """The single solid of a shape (revolve returns a Solid; booleans may return a compound)."""
    return s


def box(lo, hi) -> cq.Solid:
    lo = [float(x) for x in lo]
    hi = [float(x) for x in hi]
    return cq.Solid.makeBox(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], cq.Vector(*lo))


def cylinder_between(p0, p1, radius: float) -> cq.Solid:
    a, b = cq.Vector(*p0), cq.Vector(*p1)
    ax = b - a
    return cq.Solid.makeCylinder(float(radius), ax.Length, a, ax.normalized())


def cylinder_z(radius: float, z0: float, z1: float, x: float = 0.0, y: float = 0.0):
    return cq.Solid.makeCylinder(float(radius), float(z1 - z0), cq.Vector(x, y, z0),
                                 cq.Vector(0, 0, 1))


def place_along(shape, origin, direction):
    """`shape` (built about its local +z axis at the origin) moved so that its origin is at
    `origin` and its +z along the unit `direction`."""
    n = cq.Vector(*direction).normalized()
    helper = cq.Vector(0, 0, 1) if abs(n.z) < 0.9 else cq.Vector(1, 0, 0)
    x = helper.cross(n).normalized()
    return shape.moved(cq.Location(cq.Plane(origin=cq.Vector(*origin), xDir=x, normal=n)))


def feature(diameter_mm: float, height_mm: float, embed_mm: float,
            dilation_mm: float = 0.0) -> cq.Solid:
    """A marker feature in its own frame: a cylinder from `embed_mm` behind the surface
    (z = -embed) ending in a hemisphere whose top is at z = height (axis +z). With
    `dilation_mm`, the feature grown by it all round and seen from the surface that far beyond
    (designs/src/markers.rs, local_feature_dilated): radius r + t, the hemisphere's centre t
    closer to the surface, the same height; negative for a recessed feature."""
    r = diameter_mm / 2.0 + dilation_mm
    hc = height_mm - diameter_mm / 2.0 - dilation_mm
    embed_mm = max(embed_mm, -hc + 0.01)
    arc = cq.Edge.makeThreePointArc(vec(r, hc), vec(r * math.cos(math.pi / 4),
                                                    hc + r * math.sin(math.pi / 4)), vec(0.0, height_mm))
    return revolve([cq.Edge.makeLine(vec(0.0, -embed_mm), vec(r, -embed_mm)),
                    cq.Edge.makeLine(vec(r, -embed_mm), vec(r, hc)), arc], [])


def stem(diameter_mm: float, height_mm: float, embed_mm: float) -> cq.Solid:
    """The cylinder of a feature only (no hemisphere), from -embed to height - radius."""
    r = diameter_mm / 2.0
    return cylinder_z(r, -embed_mm, height_mm - r)


def hemisphere_tip(diameter_mm: float) -> cq.Solid:
    """The hemisphere of a feature: flat face on z = 0, dome towards +z."""
    r = diameter_mm / 2.0
    arc = cq.Edge.makeThreePointArc(vec(r, 0.0), vec(r * math.cos(math.pi / 4),
                                                    r * math.sin(math.pi / 4)), vec(0.0, r))
    return revolve([cq.Edge.makeLine(vec(0.0, 0.0), vec(r, 0.0)), arc], [])


def _lists(shapes):
    lst = TopTools_ListOfShape()
    for s in shapes:
        lst.Append(s.wrapped)
    return lst


def _boolean(op, base, tools):
    if not tools:
        return base
    op.SetArguments(_lists([base]))
    op.SetTools(_lists(tools))
    op.SetRunParallel(PARALLEL)
    op.Build()
    if not op.IsDone():
        raise TwinError(f"OCCT boolean {type(op).__name__} failed")
    return cq.Shape.cast(op.Shape())


def fuse(base, tools):
    return _boolean(BRepAlgoAPI_Fuse(), base, list(tools))


def cut(base, tools):
    return _boolean(BRepAlgoAPI_Cut(), base, list(tools))


def common(base, tool):
    return _boolean(BRepAlgoAPI_Common(), base, [tool])


def transformed(shape, m):
    """`shape` under the 3x4 row-major affine map `m` (p' = R p + t)."""
    t = gp_Trsf()
    t.SetValues(*[float(x) for row in m for x in row])
    return cq.Shape.cast(BRepBuilderAPI_Transform(shape.wrapped, t, True).Shape())


def rotation_deg(x: float, y: float, z: float):
    """Rotation about x, then y, then z (degrees) as a 3x4 map."""
    def sc(d):
        r = d % 360.0
        if r % 90.0 == 0.0:
            return {0: (0.0, 1.0), 1: (1.0, 0.0), 2: (0.0, -1.0), 3: (-1.0, 0.0)}[int(r // 90)]
        return math.sin(math.radians(d)), math.cos(math.radians(d))
    (sx, cx), (sy, cy), (sz, cz) = sc(x), sc(y), sc(z)
    rx = [[1, 0, 0], [0, cx, -sx], [0, sx, cx]]
    ry = [[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]]
    rz = [[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]
    mul = lambda a, b: [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)]
                        for i in range(3)]
    m = mul(rz, mul(ry, rx))
    return [m[0] + [0.0], m[1] + [0.0], m[2] + [0.0]]


# ------------------------------------------------------------------------------------------
# Primitives (fixtures/src/primitives.rs JSON form)


def primitive(p: dict):
    t = p["type"]
    if t == "sphere":
        return cq.Solid.makeSphere(float(p["radius_mm"]), cq.Vector(*p["centre_mm"]),
                                   angleDegrees1=-90, angleDegrees2=90)
    if t == "cylinder":
        return cylinder_between(p["base_mm"], p["top_mm"], p["radius_mm"])
    if t == "cone":
        a, b = cq.Vector(*p["apex_mm"]), cq.Vector(*p["base_mm"])
        ax = a - b
        return cq.Solid.makeCone(float(p["base_radius_mm"]), 0.0, ax.Length, b, ax.normalized())
    if t == "capsule":
        a, b = cq.Vector(*p["p0_mm"]), cq.Vector(*p["p1_mm"])
        r = float(p["radius_mm"])
        h = (b - a).Length
        arc0 = cq.Edge.makeThreePointArc(vec(0.0, -r), vec(r * math.cos(-math.pi / 4),
                                                          r * math.sin(-math.pi / 4)), vec(r, 0.0))
        arc1 = cq.Edge.makeThreePointArc(vec(r, h), vec(r * math.cos(math.pi / 4),
                                                       h + r * math.sin(math.pi / 4)), vec(0.0, h + r))
        local = revolve([arc0, cq.Edge.makeLine(vec(r, 0.0), vec(r, h)), arc1], [])
        return place_along(local, p["p0_mm"], (b - a).normalized().toTuple())
    if t == "box":
        e = p["half_extents_mm"]
        ax = p["axes"]
        local = box([-e[0], -e[1], -e[2]], [e[0], e[1], e[2]])
        c = p["centre_mm"]
        m = [[ax[0][0], ax[1][0], ax[2][0], c[0]], [ax[0][1], ax[1][1], ax[2][1], c[1]],
             [ax[0][2], ax[1][2], ax[2][2], c[2]]]
        return transformed(local, m)
    raise TwinError(f"primitive type {t!r}: no exact twin")


def place(shape, params: dict, key: str = "T_print_sensor"):
    """The solid in print orientation: `params[key]` applied (sensor or own frame -> print)."""
    if key not in params:
        raise TwinError(f"params.{key} is missing: the manifest must carry the print placement")
    return transformed(shape, params[key])


def exact_volume(shape) -> float:
    """Volume of an OCCT shape by adaptive integration to a relative error of 1e-9 (OCCT's
    default integration is off by up to ~3e-5 relative on parts with many features)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    g = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape.wrapped, g, 1e-9)
    return g.Mass()
