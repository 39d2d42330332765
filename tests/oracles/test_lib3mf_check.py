#!/usr/bin/env python3
"""Self-test of lib3mf_check.py on small 3MF packages written here (no fabkit needed).

Usage: python tests/oracles/test_lib3mf_check.py   (with the oracle venv's python)

Each package holds one tetrahedron with vertices (0,0,0), (10,0,0), (0,20,0), (0,0,30). Object
metadata in the form fabkit writes (a <metadatagroup> before <mesh>, prefix declared on <model>)
passes and is reported under its namespace URI; an undeclared prefix, a <metadata> straight under
<object> and an unknown name without a namespace each fail with lib3mf's strict-mode message. The
build item's transform "0 1 0 -1 0 0 0 0 1 5 6 7" maps [x y z 1] to (5 - y, 6 + x, 7 + z) (row
vector times the 4x3 matrix), so its bbox is [[-15, 6, 7], [5, 16, 37]]; reading the matrix as
columns would give [[5, -4, 7], [25, 6, 37]]. Also: a components object, unit="centimeter" (bbox_mm
scaled by 10), several files with one bad, a missing file, a usage error.
Prints one line per test and a last line `N passed, M failed`; exits 1 on any failure.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import traceback
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
CHECK = HERE / "lib3mf_check.py"

FABKIT_NS = "http://schemas.fabkit.org/3mf/2026"
ROLE = f"{{{FABKIT_NS}}}role"
CONTENT_TYPES = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
    '<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
    '<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
    '</Types>')
RELS = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    '<Relationship Target="/3D/3dmodel.model" Id="rel0" '
    'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>')
MESH = (
    '<mesh><vertices><vertex x="0" y="0" z="0"/><vertex x="10" y="0" z="0"/>'
    '<vertex x="0" y="20" z="0"/><vertex x="0" y="0" z="30"/></vertices><triangles>'
    '<triangle v1="0" v2="2" v3="1"/><triangle v1="0" v2="1" v3="3"/>'
    '<triangle v1="1" v2="2" v3="3"/><triangle v1="0" v2="3" v3="2"/></triangles></mesh>')
GROUP = ('<metadatagroup><metadata name="fabkit:role" preserve="1">mold</metadata>'
         '<metadata name="fabkit:part" preserve="1">transparent_gel_mold_box</metadata>'
         '</metadatagroup>')
ROTATE_Z90 = "0 1 0 -1 0 0 0 0 1 5 6 7"


def model_xml(object_inner: str = GROUP + MESH, declare: bool = True, unit: str = "millimeter",
              extra_resources: str = "", items: str = f'<item objectid="1" transform="{ROTATE_Z90}"/>'
              ) -> str:
    ns = f' xmlns:fabkit="{FABKIT_NS}"' if declare else ""
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<model unit="{unit}" xml:lang="en-US" '
            f'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02"{ns}>'
            '<metadata name="Title">lib3mf_check self-test</metadata><resources>'
            f'<object id="1" name="tet" type="model">{object_inner}</object>{extra_resources}'
            f'</resources><build>{items}</build></model>')


def write_3mf(path: Path, xml: str) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("[Content_Types].xml", CONTENT_TYPES)
        z.writestr("_rels/.rels", RELS)
        z.writestr("3D/3dmodel.model", xml)
    return path


def run(*paths: Path | str) -> tuple[int, dict | None, str]:
    p = subprocess.run([sys.executable, str(CHECK), *map(str, paths)],
                       capture_output=True, text=True, timeout=120)
    try:
        res = json.loads(p.stdout) if p.stdout.strip() else None
    except ValueError:
        res = None
    return p.returncode, res, p.stderr


def expect(cond: bool, what: str) -> None:
    if not cond:
        raise AssertionError(what)


def expect_strict_failure(tmp: Path, xml: str, message: str) -> None:
    rc, res, err = run(write_3mf(tmp / "bad.3mf", xml))
    expect(rc == 1, f"exit {rc}: {err}")
    f = res["files"][0]
    expect(not f["ok"] and message in f["error"], f"error {f['error']!r}")
    expect(f["objects"] == [] and f["build_items"] == [], "no model reported after a failed read")


def test_fabkit_metadata_form_passes(tmp: Path) -> None:
    rc, res, err = run(write_3mf(tmp / "ok.3mf", model_xml()))
    expect(rc == 0, f"exit {rc}: {err}")
    expect(res["lib3mf_version"] == "2.5.0", f"version {res['lib3mf_version']}")
    f = res["files"][0]
    expect(f["ok"] and f["error"] is None and f["warnings"] == [], f"{f}")
    expect(f["unit"] == "millimeter", f"unit {f['unit']}")
    expect(f["model_metadata"] == {"Title": "lib3mf_check self-test"}, f"{f['model_metadata']}")
    (obj,) = f["objects"]
    expect(obj["name"] == "tet" and obj["triangles"] == 4 and obj["vertices"] == 4, f"{obj}")
    expect(obj["metadata"] == {ROLE: "mold", f"{{{FABKIT_NS}}}part": "transparent_gel_mold_box"},
           f"metadata {obj['metadata']}")
    expect(obj["bbox_mm"] == [[0, 0, 0], [10, 20, 30]], f"object bbox {obj['bbox_mm']}")
    (item,) = f["build_items"]
    expect(item["object_name"] == "tet", f"{item}")
    expect(item["transform"] == [float(x) for x in ROTATE_Z90.split()], f"{item['transform']}")
    expect(item["bbox_mm"] == [[-15, 6, 7], [5, 16, 37]], f"item bbox {item['bbox_mm']}")


def test_metadata_after_mesh_and_prefix_on_object_pass(tmp: Path) -> None:
    xml = model_xml(MESH + GROUP)
    rc, res, _ = run(write_3mf(tmp / "after.3mf", xml))
    expect(rc == 0 and res["files"][0]["objects"][0]["metadata"][ROLE] == "mold", "after <mesh>")
    xml = model_xml(declare=False).replace(
        '<object id="1"', f'<object xmlns:fabkit="{FABKIT_NS}" id="1"')
    rc, res, _ = run(write_3mf(tmp / "on_object.3mf", xml))
    expect(rc == 0 and res["files"][0]["objects"][0]["metadata"][ROLE] == "mold", "on <object>")


def test_other_prefix_same_uri_gives_same_key(tmp: Path) -> None:
    xml = model_xml().replace("fabkit:", "fk:").replace("xmlns:fabkit=", "xmlns:fk=")
    rc, res, err = run(write_3mf(tmp / "fk.3mf", xml))
    expect(rc == 0, f"exit {rc}: {err}")
    expect(res["files"][0]["objects"][0]["metadata"][ROLE] == "mold", "key is by URI")


def test_undeclared_prefix_fails(tmp: Path) -> None:
    expect_strict_failure(tmp, model_xml(declare=False),
                          "Could not get XML Namespace for a metadatum.")


def test_metadata_directly_under_object_fails(tmp: Path) -> None:
    expect_strict_failure(tmp, model_xml('<metadata name="fabkit:role">mold</metadata>' + MESH),
                          "Invalid Element in namespace.")


def test_unknown_name_without_namespace_fails(tmp: Path) -> None:
    group = '<metadatagroup><metadata name="role">mold</metadata></metadatagroup>'
    expect_strict_failure(tmp, model_xml(group + MESH), "Unknown Model Metadata.")


def test_components_object(tmp: Path) -> None:
    comp = ('<object id="2" name="pair" type="model"><components>'
            '<component objectid="1"/><component objectid="1" transform="1 0 0 0 1 0 0 0 1 100 0 0"/>'
            '</components></object>')
    xml = model_xml(MESH, extra_resources=comp,
                    items='<item objectid="2" transform="1 0 0 0 1 0 0 0 1 0 0 1"/>')
    rc, res, err = run(write_3mf(tmp / "comp.3mf", xml))
    expect(rc == 0, f"exit {rc}: {err}")
    f = res["files"][0]
    pair = [o for o in f["objects"] if o["name"] == "pair"][0]
    expect(pair["components"] == 2 and pair["triangles"] is None, f"{pair}")
    expect(pair["bbox_mm"] == [[0, 0, 0], [110, 20, 30]], f"object bbox {pair['bbox_mm']}")
    expect(f["build_items"][0]["bbox_mm"] == [[0, 0, 1], [110, 20, 31]],
           f"item bbox {f['build_items'][0]['bbox_mm']}")


def test_centimeter_unit_scales_bbox(tmp: Path) -> None:
    rc, res, _ = run(write_3mf(tmp / "cm.3mf", model_xml(unit="centimeter")))
    f = res["files"][0]
    expect(rc == 0 and f["unit"] == "centimeter", f"exit {rc}, unit {f['unit']}")
    expect(f["objects"][0]["bbox_mm"] == [[0, 0, 0], [100, 200, 300]], f"{f['objects'][0]}")


def test_one_bad_file_among_several(tmp: Path) -> None:
    good = write_3mf(tmp / "good.3mf", model_xml())
    bad = write_3mf(tmp / "bad.3mf", model_xml(declare=False))
    rc, res, _ = run(good, bad, tmp / "missing.3mf")
    expect(rc == 1, f"exit {rc}")
    expect([f["ok"] for f in res["files"]] == [True, False, False], f"{res['files']}")
    expect(res["files"][1]["warnings"][0]["message"]
           == "Could not get XML Namespace for a metadatum.", f"{res['files'][1]['warnings']}")


def test_usage_error(_: Path) -> None:
    rc, res, err = run()
    expect(rc == 2 and res is None and "usage" in err, f"exit {rc}: {err!r}")
    rc, _, _ = run("--strict")
    expect(rc == 2, f"exit {rc}")


def main() -> int:
    tests = [(n, f) for n, f in globals().items() if n.startswith("test_") and callable(f)]
    passed = failed = 0
    for name, fn in tests:
        with tempfile.TemporaryDirectory(prefix="fabkit-lib3mf-check-") as d:
            try:
                fn(Path(d))
            except Exception:
                failed += 1
                print(f"FAIL {name}")
                for line in traceback.format_exc().splitlines():
                    print(f"  | {line}")
            else:
                passed += 1
                print(f"ok   {name}")
    print(f"{passed} passed, {failed} failed")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
