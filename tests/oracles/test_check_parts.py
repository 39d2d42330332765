#!/usr/bin/env python3
"""Self-test of check_parts.py on small outputs made here (no fabkit needed).

Usage: python tests/oracles/test_check_parts.py   (with the oracle venv's python)

Builds a fake fabkit output directory (a box and a 64-sided cylinder as binary STL written by our
own writer, a kit 3MF written by trimesh, a manifest with analytic volumes, areas and bounding
boxes), checks that it passes, then that each mutation fails with the named reason. Further cases:
a part made of two disjoint boxes (genus 0 as fabkit counts it: shells - chi/2), a PolyJet group
placed by one translation (passes) or by two (fails).
Prints one line per test and a last line `N passed, M failed`; exits 1 on any failure.
"""

from __future__ import annotations

import hashlib
import json
import math
import struct
import subprocess
import sys
import tempfile
import traceback
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


def test_group_with_one_placement_passes(tmp: Path) -> None:
    """A PolyJet group of two parts placed by the same translation, as fabkit lays it out."""
    make_output(tmp, techs={"box": "PolyJet", "cylinder": "PolyJet"},
                groups={"box": "g", "cylinder": "g"},
                kit_translations={"box": (40.0, 7.5, 0.0), "cylinder": (40.0, 7.5, 0.0)})
    rc, res, err = run_check(tmp)
    expect(rc == 0, f"exit {rc}\n{err}")


def test_group_with_two_placements_fails(tmp: Path) -> None:
    make_output(tmp, groups={"box": "g", "cylinder": "g"},
                kit_translations={"box": (40.0, 7.5, 0.0), "cylinder": (40.0, 7.5, 1e-3)})
    rc, res, _ = run_check(tmp)
    expect(rc == 1, f"exit {rc}")
    expect_only_failure(res, "kit_3mf", ["group 'g': cylinder is placed by"])


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
    expect_only_failure(res, "kit_3mf", ["no geometry named", "geometries"])


def test_kit_wrong_volume_fails(tmp: Path) -> None:
    """The 3MF holds a cylinder of a coarser tessellation than the STL part."""
    make_output(tmp)
    scene = trimesh.Scene()
    scene.add_geometry(box_mesh(), geom_name="box", node_name="box")
    coarse = trimesh.creation.cylinder(radius=CYL_RADIUS, height=CYL_HEIGHT, sections=32)
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


def main() -> int:
    tests = [(n, f) for n, f in globals().items() if n.startswith("test_") and callable(f)]
    passed = failed = 0
    for name, fn in tests:
        with tempfile.TemporaryDirectory(prefix="fabkit-check-parts-") as d:
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
