#!/usr/bin/env python3
"""Strict 3MF reader oracle: reads each file with lib3mf (the 3MF Consortium's library) in strict mode.

Usage: python tests/oracles/lib3mf_check.py FILE.3mf [FILE.3mf ...]   (with the oracle venv's python)

In strict mode lib3mf turns every reader warning into an error, so a file is `ok` only when the
whole model part was read. Prints ONE JSON document on stdout:

  {"lib3mf_version": "2.5.0",
   "files": [{"file": PATH, "ok": bool, "error": null | "NAME: message",
              "warnings": [{"code": int, "message": str}, ...],
              "unit": "millimeter" | "micron" | "centimeter" | "inch" | "foot" | "meter" | null,
              "model_metadata": {KEY: value},
              "objects": [{"id": int, "name": str, "type": "model" | ..., "metadata": {KEY: value},
                           "triangles": N | null, "vertices": N | null, "components": N | null,
                           "bbox_mm": [[minx, miny, minz], [maxx, maxy, maxz]] | null}],
              "build_items": [{"object_id": int, "object_name": str, "transform": [12 numbers],
                               "metadata": {KEY: value}, "bbox_mm": [[...], [...]] | null}],
              "thumbnail": null | {"path": "/Metadata/thumbnail.png", "bytes": N}}]}

- Metadata keys: lib3mf gives a metadatum's namespace URI and local name, never the prefix the file
  used, so a namespaced key is written in Clark notation, "{URI}name" (the fabkit role is
  "{http://schemas.fabkit.org/3mf/2026}role", whatever prefix the file declared), and a key without
  a namespace (the 3MF core's well-known names: Title, Application, ...) as its bare name. A prefix
  bound to the wrong URI therefore shows up as a different key.
- `transform`: the 3MF attribute's order, row-major 4x3 (m00 m01 m02 m10 m11 m12 m20 m21 m22 m30
  m31 m32), as lib3mf holds it (float32); the identity when the item has no transform.
- Objects' `bbox_mm`: the mesh's vertices in object coordinates (a components object: its
  components' vertices through their transforms). Items' `bbox_mm`: the object's vertices as row
  vectors [x y z 1] times the item's 4x3 matrix (the 3MF convention). Both are scaled from the
  model's unit to mm. `triangles`/`vertices` are null for a components object, `components` is null
  for a mesh object.
- `thumbnail`: the package thumbnail lib3mf found (the root relationship of type .../metadata/
  thumbnail), its part name and size; null when the package has none.
Exit status: 0 when every file is ok with no warnings, 1 otherwise (the JSON is printed either
way), 2 on a usage error.
"""

from __future__ import annotations

import json
import sys

import lib3mf
import numpy as np

# 3MF core spec, the model's unit attribute, and its size in mm.
UNITS = {
    lib3mf.ModelUnit.MicroMeter: ("micron", 0.001),
    lib3mf.ModelUnit.MilliMeter: ("millimeter", 1.0),
    lib3mf.ModelUnit.CentiMeter: ("centimeter", 10.0),
    lib3mf.ModelUnit.Inch: ("inch", 25.4),
    lib3mf.ModelUnit.Foot: ("foot", 304.8),
    lib3mf.ModelUnit.Meter: ("meter", 1000.0),
}
OBJECT_TYPES = {
    lib3mf.ObjectType.Model: "model",
    lib3mf.ObjectType.Other: "other",
    lib3mf.ObjectType.Support: "support",
    lib3mf.ObjectType.SolidSupport: "solidsupport",
    lib3mf.ObjectType.Surface: "surface",
}


def metadata(group) -> dict:
    out = {}
    for i in range(group.GetMetaDataCount()):
        md = group.GetMetaData(i)
        ns, name = md.GetNameSpace(), md.GetName()
        out[f"{{{ns}}}{name}" if ns else name] = md.GetValue()
    return out


def matrix(transform) -> np.ndarray:
    """(4, 3) float64 from a lib3mf Transform (Fields[row][col], rows 0..2 linear, row 3 offset)."""
    return np.array([[float(transform.Fields[r][c]) for c in range(3)] for r in range(4)])


def apply(points: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Row vectors [x y z 1] times the 4x3 matrix."""
    return points @ m[:3] + m[3]


def bbox(points: np.ndarray, scale_mm: float) -> list | None:
    if len(points) == 0:
        return None
    p = points * scale_mm
    return [p.min(axis=0).tolist(), p.max(axis=0).tolist()]


def object_points(model, obj, cache: dict, depth: int = 0) -> np.ndarray:
    """(N, 3) float64 vertices of an object in its own coordinates, in model units."""
    rid = obj.GetResourceID()
    if rid in cache:
        return cache[rid]
    if depth > 64:
        raise RecursionError(f"components nested deeper than 64 levels at object {rid}")
    if obj.IsMeshObject():
        mesh = model.GetMeshObjectByID(rid)
        pts = np.array([v.Coordinates[:] for v in mesh.GetVertices()],
                       dtype=np.float64).reshape(-1, 3)
    elif obj.IsComponentsObject():
        comps = model.GetComponentsObjectByID(rid)
        parts = []
        for i in range(comps.GetComponentCount()):
            c = comps.GetComponent(i)
            child = object_points(model, c.GetObjectResource(), cache, depth + 1)
            parts.append(apply(child, matrix(c.GetTransform())) if c.HasTransform() else child)
        pts = np.concatenate(parts) if parts else np.zeros((0, 3))
    else:
        pts = np.zeros((0, 3))
    cache[rid] = pts
    return pts


def check(wrapper, path: str) -> dict:
    res = {"file": path, "ok": False, "error": None, "warnings": [], "unit": None,
           "model_metadata": {}, "objects": [], "build_items": [], "thumbnail": None}
    model = wrapper.CreateModel()
    reader = model.QueryReader("3mf")
    reader.SetStrictModeActive(True)
    try:
        reader.ReadFromFile(path)
    except lib3mf.ELib3MFException as e:
        res["error"] = f"{e.error_name}: {e.error_message or e.error_description}"
    for i in range(reader.GetWarningCount()):
        code, message = reader.GetWarning(i)
        res["warnings"].append({"code": code, "message": message})
    if res["error"] is not None:
        return res
    try:
        unit, scale_mm = UNITS[model.GetUnit()]
        res["unit"] = unit
        res["model_metadata"] = metadata(model.GetMetaDataGroup())
        cache: dict = {}
        names = {}
        it = model.GetObjects()
        while it.MoveNext():
            obj = it.GetCurrentObject()
            rid = obj.GetResourceID()
            names[rid] = obj.GetName()
            entry = {"id": rid, "name": obj.GetName(),
                     "type": OBJECT_TYPES.get(obj.GetType(), str(obj.GetType())),
                     "metadata": metadata(obj.GetMetaDataGroup()),
                     "triangles": None, "vertices": None, "components": None}
            if obj.IsMeshObject():
                mesh = model.GetMeshObjectByID(rid)
                entry["triangles"] = mesh.GetTriangleCount()
                entry["vertices"] = mesh.GetVertexCount()
            elif obj.IsComponentsObject():
                entry["components"] = model.GetComponentsObjectByID(rid).GetComponentCount()
            entry["bbox_mm"] = bbox(object_points(model, obj, cache), scale_mm)
            res["objects"].append(entry)
        items = model.GetBuildItems()
        while items.MoveNext():
            item = items.GetCurrent()
            obj = item.GetObjectResource()
            m = matrix(item.GetObjectTransform()) if item.HasObjectTransform() \
                else np.vstack([np.eye(3), np.zeros(3)])
            res["build_items"].append({
                "object_id": item.GetObjectResourceID(),
                "object_name": obj.GetName(),
                "transform": m.reshape(-1).tolist(),
                "metadata": metadata(item.GetMetaDataGroup()),
                "bbox_mm": bbox(apply(object_points(model, obj, cache), m), scale_mm),
            })
        if model.HasPackageThumbnailAttachment():
            a = model.GetPackageThumbnailAttachment()
            res["thumbnail"] = {"path": a.GetPath(), "bytes": a.GetStreamSize()}
    except (lib3mf.ELib3MFException, RecursionError) as e:
        name = getattr(e, "error_name", type(e).__name__)
        res["error"] = f"{name}: {getattr(e, 'error_message', None) or e}"
        return res
    res["ok"] = True
    return res


def main(argv: list[str]) -> int:
    if not argv or any(a.startswith("-") for a in argv):
        print("usage: lib3mf_check.py FILE.3mf [FILE.3mf ...]", file=sys.stderr)
        return 2
    wrapper = lib3mf.get_wrapper()
    doc = {"lib3mf_version": ".".join(map(str, wrapper.GetLibraryVersion())),
           "files": [check(wrapper, p) for p in argv]}
    print(json.dumps(doc, indent=1))
    return 0 if all(f["ok"] and not f["warnings"] for f in doc["files"]) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
