#!/usr/bin/env python3
"""Self-test of check_parts.py on small outputs made here (no fabkit needed).

Usage: python tests/oracles/test_check_parts.py   (with the oracle venv's python)

Builds a fake fabkit output directory (a box and a 64-sided cylinder as binary STL written by our
own writer, a kit 3MF written by trimesh, a manifest with analytic volumes, areas and bounding
boxes), checks that it passes, then that each mutation fails with the named reason. Further cases:
a part made of two disjoint boxes (genus 0 as fabkit counts it: shells - chi/2), and kit 3MFs laid
out as fabkit writes them by a small writer here: a PolyJet group as one object with one volume per
part in PrusaSlicer's Metadata/Slic3r_PE_model.config (passes), a group split over two objects,
ungrouped parts sharing an object, a volume moved in its object, volume ranges that do not split
the mesh and manifest objects that differ from the 3MF (each fails).
Prints one line per test and a last line `N passed, M failed`; exits 1 on any failure.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import traceback
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import trimesh

HERE = Path(__file__).resolve().parent
CHECK = HERE / "check_parts.py"

N_SIDES = 64
BOX_EXTENTS = (10.0, 20.0, 30.0)
BOX_CENTER = (1.0, 2.0, 3.0)
CYL_RADIUS, CYL_HEIGHT = 5.0, 8.0
CYL_CENTER = (20.0, 0.0, 4.0)


def write_stl(path: Path, vertices: np.ndarray, faces: np.ndarray) -> None:
    """Binary STL, float32, normals from the (float64) geometry."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    rec = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["n"] = n
    rec["v"] = tri
    with open(path, "wb") as f:
        f.write(b"fabkit check_parts self-test".ljust(80, b" "))
        f.write(struct.pack("<I", len(faces)))
        f.write(rec.tobytes())


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def box_mesh() -> trimesh.Trimesh:
    return trimesh.creation.box(extents=BOX_EXTENTS,
                                transform=trimesh.transformations.translation_matrix(BOX_CENTER))


def cyl_mesh() -> trimesh.Trimesh:
    return trimesh.creation.cylinder(
        radius=CYL_RADIUS, height=CYL_HEIGHT, sections=N_SIDES,
        transform=trimesh.transformations.translation_matrix(CYL_CENTER))


def analytic() -> dict:
    """Expected values from formulas, not from a mesh reader."""
    a, b, c = BOX_EXTENTS
    poly_area = 0.5 * N_SIDES * CYL_RADIUS**2 * math.sin(2 * math.pi / N_SIDES)
    side = 2 * CYL_RADIUS * math.sin(math.pi / N_SIDES)
    bx = {"volume_mm3": a * b * c, "surface_area_mm2": 2 * (a * b + b * c + c * a),
          "bbox_mm": {"min": [BOX_CENTER[i] - BOX_EXTENTS[i] / 2 for i in range(3)],
                      "max": [BOX_CENTER[i] + BOX_EXTENTS[i] / 2 for i in range(3)]},
          "triangles": 12, "genus": 0}
    half = (CYL_RADIUS, CYL_RADIUS, CYL_HEIGHT / 2)
    cy = {"volume_mm3": poly_area * CYL_HEIGHT,
          "surface_area_mm2": 2 * poly_area + N_SIDES * side * CYL_HEIGHT,
          "bbox_mm": {"min": [CYL_CENTER[i] - half[i] for i in range(3)],
                      "max": [CYL_CENTER[i] + half[i] for i in range(3)]},
          "triangles": 4 * N_SIDES, "genus": 0}
    return {"box": bx, "cylinder": cy}


def make_output(out: Path, stl_meshes: dict | None = None, kit_names=("box", "cylinder"),
                with_kit: bool = True, meshes: dict | None = None, expected: dict | None = None,
                techs: dict | None = None, groups: dict | None = None,
                kit_translations: dict | None = None) -> dict:
    """Write parts, kit and manifest; returns the manifest (already written).

    meshes/expected replace a part's geometry (STL and 3MF) and its manifest numbers;
    stl_meshes replaces the STL only; techs and groups set print_technology and group per part;
    kit_translations places a part's 3MF object by a translation (default: none)."""
    meshes = {"box": box_mesh(), "cylinder": cyl_mesh(), **(meshes or {})}
    stl = {name: (m.vertices, m.faces) for name, m in meshes.items()}
    stl.update(stl_meshes or {})
    exp = {**analytic(), **(expected or {})}
    techs = {"box": "FDM", "cylinder": "SLA", **(techs or {})}
    groups = groups or {}
    (out / "parts").mkdir(parents=True, exist_ok=True)
    parts = []
    for name in ("box", "cylinder"):
        rel = f"parts/{name}.stl"
        v, f = stl[name]
        write_stl(out / rel, np.asarray(v, dtype=np.float64), np.asarray(f))
        parts.append({"name": name, "file": rel, "role": "test", "material": "PLA",
                      "print_technology": techs[name], "group": groups.get(name),
                      **exp[name], "sha256": sha256(out / rel), "params": {}})
    manifest = {"fabkit_version": "0.0.0-selftest",
                "design": {"name": "selftest", "source": "test_check_parts.py", "sha256": "0" * 64},
                "chord_tolerance_mm": 0.01, "command_line": ["test_check_parts.py"],
                "parts": parts, "casts": []}
    if with_kit:
        scene = trimesh.Scene()
        translations = kit_translations or {}
        for name in kit_names:
            t = translations.get(name, (0.0, 0.0, 0.0))
            scene.add_geometry(meshes[name], geom_name=name, node_name=name,
                               transform=trimesh.transformations.translation_matrix(t))
        (out / "kit.3mf").write_bytes(scene.export(file_type="3mf"))
        manifest["kit_3mf"] = {"file": "kit.3mf", "sha256": sha256(out / "kit.3mf"),
                               "objects": len(kit_names)}
    write_manifest(out, manifest)
    return manifest


def write_manifest(out: Path, manifest: dict) -> None:
    (out / "manifest.json").write_text(json.dumps(manifest, indent=1), encoding="utf-8")


def write_kit_3mf(path: Path, objects: list) -> list[dict]:
    """A 3MF laid out as fabkit writes it, by our own small writer (trimesh cannot write
    PrusaSlicer's config): objects is [(name, group, [(part, mesh), ...], translation)]; each
    object's mesh is its parts' meshes one after the other; objects with a group get volumes in
    Metadata/Slic3r_PE_model.config. Returns the manifest's ``kit_3mf.objects``."""
    ns = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
    model = [f'<?xml version="1.0" encoding="UTF-8"?>\n<model unit="millimeter" xmlns="{ns}">'
             "<resources>"]
    config = ['<?xml version="1.0" encoding="UTF-8"?>\n<config>']
    build, listed = [], []
    for oid, (name, group, volumes, t) in enumerate(objects, start=1):
        verts, tris, ranges, base = [], [], [], 0
        for part, mesh in volumes:
            v = np.asarray(mesh.vertices, dtype=np.float64)
            f = np.asarray(mesh.faces, dtype=np.int64)
            verts += [f'<vertex x="{x!r}" y="{y!r}" z="{z!r}"/>' for x, y, z in v.tolist()]
            first = len(tris)
            tris += [f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in (f + base).tolist()]
            ranges.append((part, first, len(tris) - 1))
            base += len(v)
        model.append(f'<object id="{oid}" name="{name}" type="model"><mesh><vertices>'
                     + "".join(verts) + "</vertices><triangles>" + "".join(tris)
                     + "</triangles></mesh></object>")
        build.append(f'<item objectid="{oid}" transform="1 0 0 0 1 0 0 0 1 '
                     f'{t[0]!r} {t[1]!r} {t[2]!r}"/>')
        if group is not None:
            config.append(f'<object id="{oid}"><metadata type="object" key="name" '
                          f'value="{name}"/>')
            for k, (part, first, last) in enumerate(ranges, start=1):
                config.append(f'<volume firstid="{first}" lastid="{last}">'
                              f'<metadata type="volume" key="name" value="{part}"/>'
                              f'<metadata type="volume" key="extruder" value="{k}"/></volume>')
            config.append("</object>")
        listed.append({"id": oid, "name": name, "group": group, "translation_mm": list(t),
                       "volumes": [{"part": part, "first_triangle": first,
                                    "last_triangle": last, "extruder": k}
                                   for k, (part, first, last) in enumerate(ranges, start=1)]})
    model.append("</resources><build>" + "".join(build) + "</build></model>\n")
    config.append("</config>\n")
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("[Content_Types].xml",
                   '<?xml version="1.0" encoding="UTF-8"?>\n<Types xmlns="http://schemas.'
                   'openxmlformats.org/package/2006/content-types"><Default Extension="rels" '
                   'ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
                   '<Default Extension="model" ContentType="application/vnd.ms-package.'
                   '3dmanufacturing-3dmodel+xml"/></Types>\n')
        z.writestr("_rels/.rels",
                   '<?xml version="1.0" encoding="UTF-8"?>\n<Relationships xmlns="http://'
                   'schemas.openxmlformats.org/package/2006/relationships"><Relationship '
                   'Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/'
                   '3dmanufacturing/2013/01/3dmodel"/></Relationships>\n')
        z.writestr("3D/3dmodel.model", "".join(model))
        if any(o[1] is not None for o in objects):
            z.writestr("Metadata/Slic3r_PE_model.config", "".join(config))
    return listed


def make_group_output(out: Path, objects: list, groups: dict) -> dict:
    """make_output with PolyJet parts in `groups` and a kit 3MF from write_kit_3mf(objects)."""
    manifest = make_output(out, techs={"box": "PolyJet", "cylinder": "PolyJet"}, groups=groups)
    listed = write_kit_3mf(out / "kit.3mf", objects)
    manifest["kit_3mf"] = {"file": "kit.3mf", "sha256": sha256(out / "kit.3mf"),
                           "objects": listed}
    write_manifest(out, manifest)
    return manifest


GROUP_T = (40.0, 7.5, 0.0)


def run_check(out: Path, *extra: str) -> tuple[int, dict | None, str]:
    p = subprocess.run([sys.executable, str(CHECK), str(out), "--json", *extra],
                       capture_output=True, text=True, timeout=300)
    try:
        result = json.loads(p.stdout) if p.stdout.strip() else None
    except ValueError:
        result = None
    return p.returncode, result, p.stderr


def items_by_name(result: dict) -> dict:
    return {i["name"]: i for i in result["items"]}


def expect(cond: bool, what: str) -> None:
    if not cond:
        raise AssertionError(what)


def expect_only_failure(result: dict, name: str, reason_substrings: list[str]) -> None:
    """Exactly `name` fails, and each of its reasons contains one of reason_substrings."""
    items = items_by_name(result)
    failed = sorted(n for n, i in items.items() if not i["ok"])
    expect(failed == [name], f"failed items {failed}, expected [{name!r}]")
    reasons = items[name]["reasons"]
    for r in reasons:
        expect(any(s in r for s in reason_substrings), f"unexpected reason {r!r}")
    for s in reason_substrings[:1]:
        expect(any(s in r for r in reasons), f"no reason with {s!r} in {reasons}")


# ---- tests -------------------------------------------------------------------------------------

def test_valid_output_passes(tmp: Path) -> None:
    make_output(tmp)
    rc, res, err = run_check(tmp)
    expect(rc == 0, f"exit {rc}\n{err}")
    expect(res["passed"] == 3 and res["failed"] == 0, f"{res['passed']} passed {res['failed']} failed")
    expect(err.strip().splitlines()[-1] == "3 passed, 0 failed", f"last line: {err!r}")
    items = items_by_name(res)
    expect(items["cylinder"]["measured"]["manifold3d_status"] == "NoError", "status")
    expect(items["box"]["measured"]["genus"] == 0, "genus")


def test_plain_output_lines(tmp: Path) -> None:
    make_output(tmp)
    p = subprocess.run([sys.executable, str(CHECK), str(tmp)], capture_output=True, text=True,
                       timeout=300)
    lines = p.stdout.strip().splitlines()
    expect(p.returncode == 0, f"exit {p.returncode}: {p.stdout}{p.stderr}")
    expect([ln.split()[0] for ln in lines[:-1]] == ["PASS"] * 3, f"lines: {lines}")
    expect(lines[-1] == "3 passed, 0 failed", f"last line: {lines[-1]!r}")


def test_deleted_face_fails(tmp: Path) -> None:
    m = cyl_mesh()
    faces = np.delete(m.faces, 5, axis=0)
    manifest = make_output(tmp, {"cylinder": (m.vertices, faces)})
    # The STL and its count/hash agree with the manifest; only the geometry is broken.
    manifest["parts"][1]["triangles"] = len(faces)
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect(res["failed"] == 1, f"failed {res['failed']}")
    expect_only_failure(res, "cylinder", ["not watertight", "manifold3d: status NotManifold",
                                          "volume", "surface area"])
    reasons = items_by_name(res)["cylinder"]["reasons"]
    expect(any("manifold3d: status NotManifold" in r for r in reasons), f"{reasons}")


def test_flipped_face_fails(tmp: Path) -> None:
    m = cyl_mesh()
    faces = m.faces.copy()
    faces[7] = faces[7][::-1]
    make_output(tmp, {"cylinder": (m.vertices, faces)})
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "cylinder", ["winding not consistent", "manifold3d: status",
                                          "volume", "not watertight"])


def test_one_ulp_gap_fails(tmp: Path) -> None:
    """A vertex copy moved by one float32 ulp opens the mesh: the oracle must not weld it."""
    m = box_mesh()
    v = m.vertices[m.faces].reshape(-1, 3).astype(np.float32)
    v[0, 0] = np.nextafter(v[0, 0], np.float32(np.inf))
    faces = np.arange(len(v)).reshape(-1, 3)
    manifest = make_output(tmp, {"box": (v.astype(np.float64), faces)})
    manifest["parts"][0]["bbox_mm"]["max"][0] = float(v[:, 0].max())
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "box", ["not watertight", "manifold3d: status", "volume",
                                     "surface area"])


def test_wrong_volume_fails(tmp: Path) -> None:
    manifest = make_output(tmp)
    manifest["parts"][0]["volume_mm3"] *= 1 + 1e-5
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp, "--kit-vol-rel-tol", "1e-4")
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "box", ["trimesh volume", "manifold3d volume"])
    expect(len(items_by_name(res)["box"]["reasons"]) == 2, "two volume reasons")


def test_volume_within_tolerance_passes(tmp: Path) -> None:
    manifest = make_output(tmp)
    manifest["parts"][0]["volume_mm3"] *= 1 + 5e-7
    write_manifest(tmp, manifest)
    rc, res, err = run_check(tmp)
    expect(rc == 0, f"exit {rc}\n{err}")


def test_wrong_sha256_fails(tmp: Path) -> None:
    manifest = make_output(tmp)
    manifest["parts"][1]["sha256"] = "f" * 64
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "cylinder", ["sha256"])


def test_wrong_bbox_fails(tmp: Path) -> None:
    manifest = make_output(tmp)
    manifest["parts"][0]["bbox_mm"]["min"][2] += 2e-5
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "box", ["bbox"])


def test_wrong_triangle_count_fails(tmp: Path) -> None:
    manifest = make_output(tmp)
    manifest["parts"][1]["triangles"] += 1
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "cylinder", ["triangles"])


def test_wrong_genus_fails(tmp: Path) -> None:
    manifest = make_output(tmp)
    manifest["parts"][1]["genus"] = 1
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "cylinder", ["genus"])


def two_boxes_mesh() -> tuple[trimesh.Trimesh, dict]:
    """Two disjoint boxes in one mesh, and their manifest numbers (genus 0: two balls)."""
    other = box_mesh()
    other.apply_translation((0.0, 0.0, BOX_EXTENTS[2] + 5.0))
    mesh = trimesh.util.concatenate([box_mesh(), other])
    one = analytic()["box"]
    exp = {"volume_mm3": 2 * one["volume_mm3"], "surface_area_mm2": 2 * one["surface_area_mm2"],
           "bbox_mm": {"min": one["bbox_mm"]["min"],
                       "max": [*one["bbox_mm"]["max"][:2],
                               one["bbox_mm"]["max"][2] + BOX_EXTENTS[2] + 5.0]},
           "triangles": 24, "genus": 0}
    return mesh, exp


def test_two_disjoint_boxes_have_genus_0(tmp: Path) -> None:
    """fabkit's genus sums the shells' genera (manifold3d's whole-mesh genus() is -1 here)."""
    mesh, exp = two_boxes_mesh()
    make_output(tmp, meshes={"box": mesh}, expected={"box": exp})
    rc, res, err = run_check(tmp)
    expect(rc == 0, f"exit {rc}\n{err}")
    m = items_by_name(res)["box"]["measured"]
    expect(m["genus"] == 0 and m["shells"] == 2 and m["euler_characteristic"] == 4, f"{m}")
    expect(m["manifold3d_genus"] == -1, f"{m}")


def test_two_disjoint_boxes_with_whole_mesh_genus_fail(tmp: Path) -> None:
    mesh, exp = two_boxes_mesh()
    make_output(tmp, meshes={"box": mesh}, expected={"box": {**exp, "genus": -1}})
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "box", ["genus 0 (2 shells, chi 4) != manifest -1"])


def test_group_as_one_object_with_volumes_passes(tmp: Path) -> None:
    """A PolyJet group as fabkit writes it: one object `box+cylinder`, one volume per part."""
    make_group_output(tmp, [("box+cylinder", "g", [("box", box_mesh()), ("cylinder", cyl_mesh())],
                             GROUP_T)], groups={"box": "g", "cylinder": "g"})
    rc, res, err = run_check(tmp)
    expect(rc == 0, f"exit {rc}\n{err}")
    m = items_by_name(res)["kit_3mf"]["measured"]
    expect(m["parts"] == ["box", "cylinder"] and m["objects"] == {"1": ["box", "cylinder"]},
           f"{m}")


def test_objects_of_fabkit_layout_without_groups_pass(tmp: Path) -> None:
    """Our writer without groups: two objects, no PrusaSlicer config, moved by build items."""
    manifest = make_output(tmp)
    listed = write_kit_3mf(tmp / "kit.3mf", [("box", None, [("box", box_mesh())], (15.0, 1.0, 2.0)),
                                             ("cylinder", None, [("cylinder", cyl_mesh())],
                                              GROUP_T)])
    manifest["kit_3mf"] = {"file": "kit.3mf", "sha256": sha256(tmp / "kit.3mf"), "objects": listed}
    write_manifest(tmp, manifest)
    rc, res, err = run_check(tmp)
    expect(rc == 0, f"exit {rc}\n{err}")


def test_objects_moved_by_trimesh_build_items_pass(tmp: Path) -> None:
    """A 3MF written by trimesh with build transforms: parts stay in object coordinates."""
    make_output(tmp, kit_translations={"box": (40.0, 7.5, 0.0), "cylinder": (0.0, 60.0, 1.0)})
    rc, res, err = run_check(tmp)
    expect(rc == 0, f"exit {rc}\n{err}")


def test_group_split_over_two_objects_fails(tmp: Path) -> None:
    """Two objects, even placed by one translation, are sliced as two objects."""
    make_group_output(tmp, [("box", None, [("box", box_mesh())], GROUP_T),
                            ("cylinder", None, [("cylinder", cyl_mesh())], GROUP_T)],
                      groups={"box": "g", "cylinder": "g"})
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "kit_3mf", ["group 'g': its parts are in 2 objects"])


def test_ungrouped_parts_in_one_object_fail(tmp: Path) -> None:
    make_group_output(tmp, [("box+cylinder", "g", [("box", box_mesh()), ("cylinder", cyl_mesh())],
                             GROUP_T)], groups={})
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "kit_3mf", ["object box+cylinder: holds parts ['box', 'cylinder']"])


def test_group_volume_moved_in_its_object_fails(tmp: Path) -> None:
    """The cylinder volume is shifted by 1e-3 mm against the box: registration lost."""
    moved = cyl_mesh()
    moved.apply_translation((0.0, 0.0, 1e-3))
    make_group_output(tmp, [("box+cylinder", "g", [("box", box_mesh()), ("cylinder", moved)],
                             GROUP_T)], groups={"box": "g", "cylinder": "g"})
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "kit_3mf", ["cylinder: box in its object"])


def test_volume_ranges_that_do_not_split_the_mesh_fail(tmp: Path) -> None:
    make_group_output(tmp, [("box+cylinder", "g", [("box", box_mesh()), ("cylinder", cyl_mesh())],
                             GROUP_T)], groups={"box": "g", "cylinder": "g"})
    kit = tmp / "kit.3mf"
    with zipfile.ZipFile(kit) as z:
        files = {n: z.read(n) for n in z.namelist()}
    cfg = files["Metadata/Slic3r_PE_model.config"].decode()
    files["Metadata/Slic3r_PE_model.config"] = cfg.replace('lastid="11"', 'lastid="10"').encode()
    with zipfile.ZipFile(kit, "w", zipfile.ZIP_DEFLATED) as z:
        for n, b in files.items():
            z.writestr(n, b)
    manifest = json.loads((tmp / "manifest.json").read_text())
    manifest["kit_3mf"]["sha256"] = sha256(kit)
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "kit_3mf", ["object box+cylinder: volume triangle ranges",
                                         "no geometry named", "parts in the 3MF",
                                         "manifest volumes"])


def test_manifest_volumes_that_differ_from_the_3mf_fail(tmp: Path) -> None:
    manifest = make_group_output(
        tmp, [("box+cylinder", "g", [("box", box_mesh()), ("cylinder", cyl_mesh())], GROUP_T)],
        groups={"box": "g", "cylinder": "g"})
    manifest["kit_3mf"]["objects"][0]["volumes"][1]["first_triangle"] = 13
    manifest["kit_3mf"]["objects"][0]["translation_mm"][2] = 1e-3
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "kit_3mf", ["object box+cylinder: manifest volumes",
                                         "object box+cylinder: manifest translation"])
    expect(len(items_by_name(res)["kit_3mf"]["reasons"]) == 2, "two reasons")


def test_unknown_print_technology_and_bad_group_fail(tmp: Path) -> None:
    make_output(tmp, techs={"cylinder": "SLS"}, groups={"cylinder": ""})
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "cylinder", ["print_technology = 'SLS'", "group = ''"])
    expect(len(items_by_name(res)["cylinder"]["reasons"]) == 2, "two reasons")


def test_kit_missing_part_fails(tmp: Path) -> None:
    make_output(tmp, kit_names=("box",))
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "kit_3mf", ["no geometry named", "parts in the 3MF",
                                         "manifest objects"])


def test_kit_wrong_volume_fails(tmp: Path) -> None:
    """The 3MF holds a cylinder of a coarser tessellation than the STL part."""
    make_output(tmp)
    scene = trimesh.Scene()
    scene.add_geometry(box_mesh(), geom_name="box", node_name="box")
    coarse = trimesh.creation.cylinder(
        radius=CYL_RADIUS, height=CYL_HEIGHT, sections=32,
        transform=trimesh.transformations.translation_matrix(CYL_CENTER))
    scene.add_geometry(coarse, geom_name="cylinder", node_name="cylinder")
    (tmp / "kit.3mf").write_bytes(scene.export(file_type="3mf"))
    manifest = json.loads((tmp / "manifest.json").read_text())
    manifest["kit_3mf"]["sha256"] = sha256(tmp / "kit.3mf")
    write_manifest(tmp, manifest)
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "kit_3mf", ["cylinder: volume"])


def test_without_kit_passes(tmp: Path) -> None:
    make_output(tmp, with_kit=False)
    rc, res, err = run_check(tmp)
    expect(rc == 0, f"exit {rc}\n{err}")
    expect(res["passed"] == 2 and res["failed"] == 0, "2 passed")


def test_missing_stl_fails(tmp: Path) -> None:
    make_output(tmp)
    (tmp / "parts" / "box.stl").unlink()
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "box", ["not found"])


def test_unreadable_manifest_exits_2(tmp: Path) -> None:
    (tmp / "manifest.json").write_text("{not json", encoding="utf-8")
    rc, res, err = run_check(tmp)
    expect(rc == 2, f"exit {rc}")
    expect("manifest.json" in err, f"stderr: {err!r}")


def run_one(name: str, fn) -> tuple[bool, list[str]]:
    """One test in its own temporary folder: (passed, traceback lines)."""
    with tempfile.TemporaryDirectory(prefix="fabkit-check-parts-") as d:
        try:
            fn(Path(d))
        except Exception:
            return False, traceback.format_exc().splitlines()
    return True, []


def main() -> int:
    tests = [(n, f) for n, f in globals().items() if n.startswith("test_") and callable(f)]
    passed = failed = 0
    # Each test waits on its check_parts.py subprocess: one test per CPU at a time; the lines
    # keep the tests' order.
    jobs = max(1, min(len(tests), os.cpu_count() or 1))
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        for (name, _), (ok, tb) in zip(tests, pool.map(lambda t: run_one(*t), tests)):
            if ok:
                passed += 1
                print(f"ok   {name}")
            else:
                failed += 1
                print(f"FAIL {name}")
                for line in tb:
                    print(f"  | {line}")
    print(f"{passed} passed, {failed} failed")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
