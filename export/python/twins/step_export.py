"""STEP files of fabkit parts through the CadQuery twins (`fabkit export --format step`).

Usage: python -m twins.step_export PARTS.json OUT_DIR

PARTS.json: {"chord_tolerance_mm": tol, "parts": [manifest part, ...]} (name, role, params,
volume_mm3, surface_area_mm2, bbox_mm as in manifest.json). Writes OUT_DIR/<name>.step per part,
in print orientation, mm. Before writing, the exact solid's volume must be within the chord
bound of fabkit's (|dV| <= area x tol + 1e-6 V) and its bounding box within tol + 1 um: a twin
that disagrees with fabkit's part would write a wrong STEP file.

The STEP header carries no time stamp (fixed fields), and booleans run single-threaded, so the
same parts give the same bytes. Progress goes to stderr, one line as each part starts:
`step_export: I/N NAME` (part I of N, in the input's order). Exit status: 0 written; 2 unreadable
input; 3 a twin failed or disagreed (the last stderr line names the part:
`step_export: part NAME: ...`); 4 no CadQuery.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def write_step(shape, path: Path, name: str) -> None:
    from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TCollection import TCollection_HAsciiString

    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    Interface_Static.SetCVal_s("write.step.product.name", name)
    w = STEPControl_Writer()
    w.Transfer(shape.wrapped, STEPControl_AsIs)
    h = APIHeaderSection_MakeHeader(w.Model())
    h.SetName(TCollection_HAsciiString(name))
    h.SetTimeStamp(TCollection_HAsciiString("1970-01-01T00:00:00"))
    h.SetAuthorValue(1, TCollection_HAsciiString("fabkit"))
    h.SetOrganizationValue(1, TCollection_HAsciiString("fabkit"))
    h.SetOriginatingSystem(TCollection_HAsciiString("fabkit CadQuery twin (OpenCASCADE)"))
    h.SetPreprocessorVersion(TCollection_HAsciiString("fabkit"))
    h.SetAuthorisation(TCollection_HAsciiString(""))
    if w.Write(str(path)) != IFSelect_RetDone:
        raise RuntimeError(f"OCCT could not write {path}")


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    try:
        import cadquery  # noqa: F401
    except ImportError as e:
        print(f"step_export: cadquery is not installed ({e})", file=sys.stderr)
        return 4
    from . import cq_common
    from . import cq_twin
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    cq_common.PARALLEL = False  # same bytes whatever the machine
    try:
        doc = json.loads(Path(argv[0]).read_text())
        tol = float(doc["chord_tolerance_mm"])
        parts = doc["parts"]
    except (OSError, ValueError, KeyError, TypeError) as e:
        print(f"step_export: {argv[0]}: {e}", file=sys.stderr)
        return 2
    out = Path(argv[1])
    out.mkdir(parents=True, exist_ok=True)
    for i, part in enumerate(parts, start=1):
        name = part["name"]
        print(f"step_export: {i}/{len(parts)} {name}", file=sys.stderr, flush=True)
        try:
            shape = cq_twin.build(part)
            v = cq_common.exact_volume(shape)
            bound = part["surface_area_mm2"] * tol + 1e-6 * abs(v)
            if not abs(v - part["volume_mm3"]) <= bound:
                raise ValueError(f"the exact twin's volume {v:.4f} mm3 differs from fabkit's "
                                 f"{part['volume_mm3']:.4f} mm3 by more than {bound:.4f} mm3")
            bb = Bnd_Box()
            BRepBndLib.AddOptimal_s(shape.wrapped, bb, False, False)
            lo, hi = bb.Get()[:3], bb.Get()[3:]
            dev = max(max(abs(a - b) for a, b in zip(lo, part["bbox_mm"]["min"])),
                      max(abs(a - b) for a, b in zip(hi, part["bbox_mm"]["max"])))
            if not dev <= tol + 1e-3:
                raise ValueError(f"the exact twin's bounding box is {dev:.4f} mm off fabkit's")
            write_step(shape, out / f"{name}.step", name)
        except Exception as e:  # reported with the part's name, exit 3
            print(f"step_export: part {name}: {type(e).__name__}: {e}", file=sys.stderr)
            return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
