#!/usr/bin/env python3
"""read_assembly_step.py - reads an assembly STEP file back with OpenCASCADE (XDE) and prints
what it holds, for tests/e2e/assembly_step.rs.

Usage: read_assembly_step.py ASSEMBLY.step   (run by a Python with CadQuery/OCP)

Prints one JSON object: `roots` (names of the file's top-level products) and `members`, one per
component of the first root, in file order: `component` and `product` (their STEP names),
`solids` (number of solids), `valid` (BRepCheck), `closed` (every shell closed), `volume_mm3`
(adaptive integration, 1e-9 relative), `bbox_mm` ([xmin, ymin, zmin, xmax, ymax, zmax], the
located shape, i.e. in the assembly's frame), and `up_faces_z_mm` (z of every planar face whose
outward normal is +z, ascending). Also `sewn_octahedron`: the volume, validity and closedness
of a unit octahedron (|x| + |y| + |z| <= 1, volume 4/3) sewn by fabkit's
`twins.step_export.sewn_mesh`, the path STEP export takes for a member without an exact shape.
Exit status 0, or 2 when the file cannot be read.
"""

import json
import sys
from pathlib import Path


def main() -> int:
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.BRepLProp import BRepLProp_SLProps
    from OCP.Bnd import Bnd_Box
    from OCP.GeomAbs import GeomAbs_Plane
    from OCP.GProp import GProp_GProps
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDF import TDF_Label, TDF_LabelSequence
    from OCP.TDocStd import TDocStd_Document
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED, TopAbs_SHELL, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    def name(label):
        n = TDataStd_Name()
        return n.Get().ToExtString() if label.FindAttribute(TDataStd_Name.GetID_s(), n) else None

    def subs(shape, kind):
        out, e = [], TopExp_Explorer(shape, kind)
        while e.More():
            out.append(e.Current())
            e.Next()
        return out

    def volume(shape):
        g = GProp_GProps()
        BRepGProp.VolumeProperties_s(shape, g, 1e-9)
        return g.Mass()

    def valid_closed(shape):
        return (BRepCheck_Analyzer(shape).IsValid(),
                all(BRep_Tool.IsClosed_s(s) for s in subs(shape, TopAbs_SHELL)))

    def up_faces_z(shape):
        zs = []
        for f in subs(shape, TopAbs_FACE):
            face = TopoDS.Face_s(f)
            s = BRepAdaptor_Surface(face)
            if s.GetType() != GeomAbs_Plane:
                continue
            u, v = s.FirstUParameter(), s.FirstVParameter()
            props = BRepLProp_SLProps(s, u, v, 1, 1e-9)
            n = props.Normal()
            if face.Orientation() == TopAbs_REVERSED:
                n.Reverse()
            if n.Z() > 1.0 - 1e-9:
                zs.append(props.Value().Z())
        return sorted(zs)

    app = XCAFApp_Application.GetApplication_s()
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    app.InitDocument(doc)
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    if reader.ReadFile(sys.argv[1]) != IFSelect_RetDone or not reader.Transfer(doc):
        print(f"read_assembly_step: cannot read {sys.argv[1]}", file=sys.stderr)
        return 2
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    roots = TDF_LabelSequence()
    tool.GetFreeShapes(roots)
    out = {"roots": [name(roots.Value(i + 1)) for i in range(roots.Length())], "members": []}
    comps = TDF_LabelSequence()
    if roots.Length():
        tool.GetComponents_s(roots.Value(1), comps, False)
    for i in range(comps.Length()):
        c = comps.Value(i + 1)
        shape = tool.GetShape_s(c)
        ref = TDF_Label()
        tool.GetReferredShape_s(c, ref)
        bb = Bnd_Box()
        BRepBndLib.AddOptimal_s(shape, bb, False, False)
        valid, closed = valid_closed(shape)
        out["members"].append({
            "component": name(c), "product": name(ref),
            "solids": len(subs(shape, TopAbs_SOLID)), "valid": valid, "closed": closed,
            "volume_mm3": volume(shape), "bbox_mm": list(bb.Get()),
            "up_faces_z_mm": up_faces_z(shape),
        })
    # fabkit's sewing path on a mesh with a known volume
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "export" / "python"))
    from twins.step_export import sewn_mesh
    v = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
    t = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    octa = sewn_mesh({"vertices": v, "triangles": t}).wrapped
    valid, closed = valid_closed(octa)
    out["sewn_octahedron"] = {"volume_mm3": volume(octa), "valid": valid, "closed": closed,
                              "solids": len(subs(octa, TopAbs_SOLID))}
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
