"""STEP files of fabkit parts through the CadQuery twins (`fabkit export --format step`).

Usage: python -m twins.step_export PARTS.json OUT_DIR [ASSEMBLY.step]

PARTS.json: {"chord_tolerance_mm": tol, "parts": [manifest part, ...]} (name, role, params,
volume_mm3, surface_area_mm2, bbox_mm as in manifest.json). Writes OUT_DIR/<name>.step per part
(its one PRODUCT named <name>), in print orientation, mm. Before writing, the exact solid's volume must be within the chord
bound of fabkit's (|dV| <= area x tol + 1e-6 V) and its bounding box within tol + 1 um: a twin
that disagrees with fabkit's part would write a wrong STEP file.

With ASSEMBLY.step, PARTS.json also holds "design" (the assembly's name) and "assembly": one
entry per assembly member (name, kind, volume_mm3, surface_area_mm2, bbox_mm and shells of
fabkit's mesh in the sensor frame, and what to build it from: "part", the printed part's name, whose twin above is
moved back by the inverse of its params.T_print_sensor; or "exact", an ExactShape of
designs/src/assembly.rs; or "mesh", {"vertices": [[x, y, z], ...], "triangles": [[i, j, k],
...]}, whose triangles are joined at their shared edges into closed shells). The file holds one STEP assembly named
after the design with one named solid per member (a compound of solids for a member made of
separate pieces, such as marker tips), in the sensor frame, mm; each member passes the same
volume and box checks, must be valid (BRepCheck) with closed shells, and must have as many
shells as fabkit's mesh.

PARTS.json's "machined" (may be absent): parts made to order by a shop, each as an assembly
member with "exact"; each is written to OUT_DIR/<name>.step in the sensor frame, after the
member checks below.

The STEP header carries no time stamp (fixed fields), so the same parts give the same bytes.
OCCT's booleans run on its thread pool (SetRunParallel): they give the same B-rep, and so the
same bytes, as single-threaded ones with pools of 1, 2, 3 and 8 threads (every part of UVDtact
and ShadowTac), and every library design's STEP files on 2 threads hash as
tests/e2e/output_hashes_step.txt lists them but for the files OCCT writes differently from run
to run single-threaded too (a compound of many holes or tips: the pin domes, DIGIT Pinki's
semi-dome, the TacTip's skin tips). On 2 cores they take about half the time (UVDtact's parts
11.3 -> 6.4 s; `fabkit export uvdtact --format step` 31 -> 19 s).

Progress goes to stderr, one line as each part starts: `step_export: I/N NAME` (part I of N, in the input's order), then `step_export: member NAME`
per assembly member. Exit status: 0 written; 2 unreadable input; 3 a twin failed or disagreed
(the last stderr line names the part, `step_export: part NAME: ...`, or the assembly member,
`step_export: member NAME: ...`); 4 no CadQuery.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def write_step(shape, path: Path, name: str) -> None:
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    w = STEPControl_Writer()
    w.Transfer(shape.wrapped, STEPControl_AsIs)
    name_products(w.Model(), name)
    write_header(w.Model(), name)
    if w.Write(str(path)) != IFSelect_RetDone:
        raise RuntimeError(f"OCCT could not write {path}")


def name_products(model, name: str) -> None:
    """Names the file's PRODUCT (id and name) `name`, the part's name. OCCT 7.9 names it
    "Open CASCADE STEP translator 7.9 1" and ignores `write.step.product.name` set before the
    writer is made (set after, it gives "name 1"), so the transferred entity is renamed."""
    from OCP.StepBasic import StepBasic_Product
    from OCP.TCollection import TCollection_HAsciiString

    for i in range(1, model.NbEntities() + 1):
        e = model.Value(i)
        if isinstance(e, StepBasic_Product):
            e.SetId(TCollection_HAsciiString(name))
            e.SetName(TCollection_HAsciiString(name))


def write_header(model, name: str) -> None:
    """Fixed STEP header fields (no time stamp, so the same shapes give the same bytes)."""
    from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
    from OCP.TCollection import TCollection_HAsciiString

    h = APIHeaderSection_MakeHeader(model)
    h.SetName(TCollection_HAsciiString(name))
    h.SetTimeStamp(TCollection_HAsciiString("1970-01-01T00:00:00"))
    h.SetAuthorValue(1, TCollection_HAsciiString("fabkit"))
    h.SetOrganizationValue(1, TCollection_HAsciiString("fabkit"))
    h.SetOriginatingSystem(TCollection_HAsciiString("fabkit CadQuery twin (OpenCASCADE)"))
    h.SetPreprocessorVersion(TCollection_HAsciiString("fabkit"))
    h.SetAuthorisation(TCollection_HAsciiString(""))


def check_against(shape, ref: dict, tol: float, planar: bool = False) -> None:
    """Raises ValueError unless `shape`'s exact volume is within the chord bound of `ref`'s
    (volume_mm3, surface_area_mm2) and its bounding box within tol + 1 um of `ref`'s bbox_mm.
    `planar`: every face of `shape` is a plane (a sewn mesh), whose volume OCCT's default Gauss
    integration gives exactly (the integrand is a polynomial of degree 2 over straight-edged
    faces; 59,256 triangles: the same volume to the last digit in 1.2 s, against 13.6 s for the
    adaptive integration to 1e-9 the curved twins need)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from . import cq_common

    v = planar_volume(shape) if planar else cq_common.exact_volume(shape)
    bound = ref["surface_area_mm2"] * tol + 1e-6 * abs(v)
    if not abs(v - ref["volume_mm3"]) <= bound:
        raise ValueError(f"the exact twin's volume {v:.4f} mm3 differs from fabkit's "
                         f"{ref['volume_mm3']:.4f} mm3 by more than {bound:.4f} mm3")
    bb = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape.wrapped, bb, False, False)
    lo, hi = bb.Get()[:3], bb.Get()[3:]
    dev = max(max(abs(a - b) for a, b in zip(lo, ref["bbox_mm"]["min"])),
              max(abs(a - b) for a, b in zip(hi, ref["bbox_mm"]["max"])))
    if not dev <= tol + 1e-3:
        raise ValueError(f"the exact twin's bounding box is {dev:.4f} mm off fabkit's")


def planar_volume(shape) -> float:
    """Volume of an OCCT shape whose faces are all planes, by OCCT's default integration."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    g = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape.wrapped, g)
    return g.Mass()


def rigid_inverse(t: list) -> list:
    """The inverse of a rigid 3x4 row-major map (p' = R p + t): R^T and -R^T t."""
    return [[t[j][i] for j in range(3)] + [-sum(t[k][i] * t[k][3] for k in range(3))]
            for i in range(3)]


def exact_member(e: dict):
    """The solid of an ExactShape (designs/src/assembly.rs) in the sensor frame."""
    from . import cq_common as C
    from . import cq_layers

    shape = e["shape"]
    if shape == "layer":
        return cq_layers.printed_skin(e["params"], tips=False)
    if shape == "revolved":
        return C.revolve_polyline([tuple(p) for p in e["profile_rz_mm"]])
    if shape == "cylinder":
        return C.cylinder_z(e["radius_mm"], e["z0_mm"], e["z1_mm"])
    if shape == "ring":
        z0, z1 = e["z0_mm"], e["z1_mm"]
        return C.cut(C.cylinder_z(e["outer_radius_mm"], z0, z1),
                     [C.cylinder_z(e["inner_radius_mm"], z0 - 1.0, z1 + 1.0)])
    if shape == "box":
        return C.box(e["min_mm"], e["max_mm"])
    if shape == "core_shell":
        return cq_layers.core_shell(e["params"])
    if shape == "inner_cavity":
        return cq_layers.inner_cavity(e["params"], e["opening_radius_mm"], e["opening_z0_mm"],
                                      e["opening_z1_mm"])
    raise C.TwinError(f"exact shape {shape!r}: no twin")


def sewn_mesh(mesh: dict):
    """A solid from an indexed triangle mesh (a closed 2-manifold, fabkit's written mesh): one
    planar face per triangle, its wire running a -> b -> c about the triangle's normal, every
    mesh edge one OCCT edge shared by its two faces, one shell per connected piece (in the
    order of their first triangles), oriented outward. The mesh's indices give the sharing, so
    no sewing tolerance search is needed (OCCT's BRepBuilderAPI_Sewing took about a minute for
    60,000 triangles). Raises ValueError for a triangle without area."""
    import cadquery as cq
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace,
                                    BRepBuilderAPI_MakeSolid, BRepBuilderAPI_MakeVertex)
    from OCP.BRepLib import BRepLib
    from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
    from OCP.TopoDS import TopoDS_Shell, TopoDS_Wire

    xyz = [tuple(map(float, v)) for v in mesh["vertices"]]
    pts = [gp_Pnt(*v) for v in xyz]
    vertices = [BRepBuilderAPI_MakeVertex(p).Vertex() for p in pts]
    edges = {}

    def edge(i: int, j: int):
        """The edge i -> j, made once per pair (from the lower index), reversed as needed."""
        key = (i, j) if i < j else (j, i)
        e = edges.get(key)
        if e is None:
            e = edges[key] = BRepBuilderAPI_MakeEdge(vertices[key[0]], vertices[key[1]]).Edge()
        return e if i < j else e.Reversed()

    triangles = [tuple(map(int, t)) for t in mesh["triangles"]]
    # connected pieces: union-find over the triangles' vertices
    parent = list(range(len(xyz)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b, c in triangles:
        ra = root(a)
        parent[root(b)] = ra
        parent[root(c)] = ra
    builder = BRep_Builder()
    shells = {}
    for a, b, c in triangles:
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = xyz[a], xyz[b], xyz[c]
        u, v = (bx - ax, by - ay, bz - az), (cx - ax, cy - ay, cz - az)
        n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        if n == (0.0, 0.0, 0.0):
            raise ValueError(f"triangle ({a}, {b}, {c}) of the mesh has no area")
        wire = TopoDS_Wire()
        builder.MakeWire(wire)
        for e in (edge(a, b), edge(b, c), edge(c, a)):
            builder.Add(wire, e)
        wire.Closed(True)
        face = BRepBuilderAPI_MakeFace(gp_Pln(pts[a], gp_Dir(*n)), wire, True).Face()
        shell = shells.get(root(a))
        if shell is None:
            shell = shells[root(a)] = TopoDS_Shell()
            builder.MakeShell(shell)
        builder.Add(shell, face)
    if not shells:
        raise ValueError("the mesh has no triangles")
    maker = BRepBuilderAPI_MakeSolid()
    for shell in shells.values():
        shell.Closed(True)
        maker.Add(shell)
    solid = maker.Solid()
    BRepLib.OrientClosedSolid_s(solid)
    return cq.Solid(solid)


def member_solids(shape, shells: int):
    """The solid of `shape` (a boolean may return a compound holding it), or for a member made
    of separate pieces (marker tips) the compound of its solids; their shells must number
    `shells`, as fabkit's mesh of the member."""
    import cadquery as cq

    solids = shape.Solids()
    found = sum(len(s.Shells()) for s in solids)
    if not solids or found != shells:
        raise ValueError(f"{len(solids)} solid(s) with {found} shell(s) where fabkit's mesh "
                         f"has {shells} shell(s)")
    if len(solids) == 1:
        return cq.Solid(solids[0].wrapped)
    return cq.Compound.makeCompound(solids)


def check_closed_valid(shape) -> None:
    """Raises ValueError unless `shape` passes BRepCheck and every shell of it is closed."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepCheck import BRepCheck_Analyzer

    # geometric controls on, faces checked in parallel (a check: the bytes written do not
    # depend on it)
    if not BRepCheck_Analyzer(shape.wrapped, True, True).IsValid():
        raise ValueError("the solid is not valid (BRepCheck)")
    if not all(BRep_Tool.IsClosed_s(s.wrapped) for s in shape.Shells()):
        raise ValueError("a shell of the solid is open")


def write_assembly_step(members: list, path: Path, name: str) -> None:
    """One STEP file: an assembly `name` with one component per (member name, solid), each
    component and its product named after the member, at the identity placement."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_AsIs
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    app = XCAFApp_Application.GetApplication_s()
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    app.InitDocument(doc)
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    root = tool.NewShape()
    TDataStd_Name.Set_s(root, TCollection_ExtendedString(name))
    for member, shape in members:
        label = tool.AddShape(shape.wrapped, False, False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(member))
        component = tool.AddComponent(root, label, TopLoc_Location())
        TDataStd_Name.Set_s(component, TCollection_ExtendedString(member))
    tool.UpdateAssemblies()
    w = STEPCAFControl_Writer()
    w.SetNameMode(True)
    if not w.Transfer(doc, STEPControl_AsIs):
        raise RuntimeError(f"OCCT could not transfer the assembly {name}")
    write_header(w.ChangeWriter().Model(), name)
    if w.Write(str(path)) != IFSelect_RetDone:
        raise RuntimeError(f"OCCT could not write {path}")


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    try:
        import cadquery  # noqa: F401
    except ImportError as e:
        print(f"step_export: cadquery is not installed ({e})", file=sys.stderr)
        return 4
    from . import cq_common
    from . import cq_twin

    cq_common.PARALLEL = True  # the same bytes as single-threaded (see above)
    try:
        doc = json.loads(Path(argv[0]).read_text())
        tol = float(doc["chord_tolerance_mm"])
        parts = doc["parts"]
        assembly = doc["assembly"] if len(argv) == 3 else None
        design = str(doc["design"]) if len(argv) == 3 else None
    except (OSError, ValueError, KeyError, TypeError) as e:
        print(f"step_export: {argv[0]}: {e}", file=sys.stderr)
        return 2
    out = Path(argv[1])
    out.mkdir(parents=True, exist_ok=True)
    shapes = {}
    for i, part in enumerate(parts, start=1):
        name = part["name"]
        print(f"step_export: {i}/{len(parts)} {name}", file=sys.stderr, flush=True)
        try:
            shape = cq_twin.build(part)
            check_against(shape, part, tol)
            write_step(shape, out / f"{name}.step", name)
            shapes[name] = (shape, part["params"])
        except Exception as e:  # reported with the part's name, exit 3
            print(f"step_export: part {name}: {type(e).__name__}: {e}", file=sys.stderr)
            return 3
    for m in doc.get("machined", []):
        name = m["name"]
        print(f"step_export: member {name}", file=sys.stderr, flush=True)
        try:
            shape = member_solids(exact_member(m["exact"]), m["shells"])
            check_against(shape, m, tol)
            check_closed_valid(shape)
            write_step(shape, out / f"{name}.step", name)
        except Exception as e:  # reported with the member's name, exit 3
            print(f"step_export: member {name}: {type(e).__name__}: {e}", file=sys.stderr)
            return 3
    if assembly is None:
        return 0
    built = []
    for m in assembly:
        name = m["name"]
        print(f"step_export: member {name}", file=sys.stderr, flush=True)
        try:
            planar = False  # a sewn mesh's faces are all planes
            if m.get("part") is not None:
                shape, params = shapes[m["part"]]
                shape = cq_common.transformed(shape, rigid_inverse(params["T_print_sensor"]))
            elif m.get("exact") is not None:
                shape = exact_member(m["exact"])
            else:
                shape = sewn_mesh(m["mesh"])
                planar = True
            shape = member_solids(shape, int(m["shells"]))
            check_closed_valid(shape)
            check_against(shape, m, tol, planar=planar)
            built.append((name, shape))
        except Exception as e:  # reported with the member's name, exit 3
            print(f"step_export: member {name}: {type(e).__name__}: {e}", file=sys.stderr)
            return 3
    try:
        write_assembly_step(built, Path(argv[2]), design)
    except Exception as e:
        print(f"step_export: member (all): {type(e).__name__}: {e}", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
