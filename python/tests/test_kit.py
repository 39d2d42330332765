"""fabkit.build_kit and fabkit.Kit against `fabkit export`: the same files byte for byte, part
numbers as in the manifest, mesh arrays as in the STL files, the pour table, progress callbacks
and the GIL released during a build.

Needs FABKIT_BIN (the CLI binary; see conftest.py) and the built extension on PYTHONPATH.
"""

import json
from pathlib import Path

import numpy as np
import pytest

from test_designs import fabkit  # noqa: E402 (imports the built package)
from test_designs import assert_same_tree


def read_stl(path):
    """(triangle corners (m, 3, 3) float32, normals (m, 3) float32) of a binary STL."""
    data = Path(path).read_bytes()
    (count,) = np.frombuffer(data, dtype="<u4", count=1, offset=80)
    assert len(data) == 84 + 50 * count
    rec = np.dtype([("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    r = np.frombuffer(data, dtype=rec, count=count, offset=84)
    return r["v"].copy(), r["n"].copy()


def mesh_volume(vertices, triangles):
    """Volume enclosed by a closed, outward-oriented triangle mesh (divergence theorem)."""
    a, b, c = (vertices[triangles[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


@pytest.fixture(scope="module")
def export_pair(tmp_path_factory, run_cli):
    """(CLI export folder, Python export folder, CLI manifest, Python manifest, kit) for rtac0 at
    the default options; the Python export records the CLI's argv."""
    work = tmp_path_factory.mktemp("kit")
    run_cli(work, "export", "rtac0", "--out", "A")
    a = work / "A"
    manifest = json.loads((a / "manifest.json").read_text())
    kit = fabkit.build_kit(fabkit.Design.load("rtac0"), chord_tolerance_mm=0.01)
    py_manifest = kit.export(work / "B", command_line=manifest["command_line"])
    return a, work / "B", manifest, py_manifest, kit


def test_export_same_bytes_as_cli(export_pair):
    """Kit.export with the CLI's command_line writes the same files as `fabkit export rtac0`,
    byte for byte, and returns the manifest it wrote."""
    a, b, manifest, py_manifest, kit = export_pair
    assert manifest["command_line"][1:] == ["export", "rtac0", "--out", "A"]
    assert_same_tree(a, b)
    assert py_manifest == manifest
    assert json.loads((b / "manifest.json").read_text()) == py_manifest


def test_kit_identity(export_pair):
    """The kit's name, parts (names, roles, materials, technologies, order) and tolerance are the
    manifest's."""
    _, _, manifest, _, kit = export_pair
    assert kit.name == manifest["design"]["name"] == "rtac0"
    assert kit.chord_tolerance_mm == manifest["chord_tolerance_mm"] == 0.01
    assert len(kit) == len(kit.parts) == len(manifest["parts"])
    for part, entry in zip(kit.parts, manifest["parts"]):
        assert part.name == entry["name"]
        assert part.role == entry["role"]
        assert part.material == entry["material"]
        assert part.technology.upper() == entry["print_technology"].upper()
        assert kit.part(part.name).name == part.name
    with pytest.raises(KeyError, match="shell_base"):
        kit.part("no_such_part")


def test_part_numbers_equal_manifest_entries(export_pair):
    """Part.numbers() is the manifest's parts[] entry without the written files' fields (file,
    sha256, preview): volume_mm3, bbox_mm, triangles, vertices, genus, mass_g, params, ..."""
    _, _, manifest, _, kit = export_pair
    for part, entry in zip(kit.parts, manifest["parts"]):
        n = part.numbers()
        expected = {
            k: v for k, v in entry.items() if k not in ("file", "sha256", "preview", "preview_sha256")
        }
        assert n == expected, part.name
        assert n["volume_mm3"] > 0 and n["triangles"] > 0


def test_mesh_arrays_match_stl_and_volume(export_pair):
    """Part.mesh(): (n, 3) float64 vertices, (m, 3) uint32 triangles with valid indices; the
    divergence-theorem volume equals volume_mm3 to 1e-6, the counts and bbox are the manifest's,
    and the triangles are those of parts/<part>.stl, in order."""
    a, _, manifest, _, kit = export_pair
    for part, entry in zip(kit.parts, manifest["parts"]):
        v, t = part.mesh()
        assert v.dtype == np.float64 and v.ndim == 2 and v.shape[1] == 3
        assert t.dtype == np.uint32 and t.ndim == 2 and t.shape[1] == 3
        assert v.shape[0] == entry["vertices"] and t.shape[0] == entry["triangles"]
        assert t.max() < len(v)
        # the coordinates are float32 values (as written)
        assert np.array_equal(v.astype(np.float32).astype(np.float64), v)
        vol = mesh_volume(v, t)
        assert abs(vol - entry["volume_mm3"]) <= 1e-6 * abs(entry["volume_mm3"]), part.name
        assert np.allclose(v.min(axis=0), entry["bbox_mm"]["min"], atol=0, rtol=0)
        assert np.allclose(v.max(axis=0), entry["bbox_mm"]["max"], atol=0, rtol=0)
        corners, normals = read_stl(a / entry["file"])
        assert np.array_equal(corners, v[t].astype(np.float32)), part.name
        # the STL normals point the way the triangles' winding says (outward)
        n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
        big = np.linalg.norm(n, axis=1) > 1e-9
        # measured 1.0 (every triangle; the 0.1 % is for float32 slivers whose normal rounds away)
        assert (np.einsum("ij,ij->i", n[big], normals[big]) > 0).mean() > 0.999


def test_pour_table_equals_manifest_casts(export_pair):
    """Kit.casts() is manifest casts[]; Kit.summary() is manifest summary."""
    _, _, manifest, _, kit = export_pair
    casts = kit.casts()
    assert casts == manifest["casts"]
    assert [c["step"] for c in casts] == list(range(1, len(casts) + 1))
    assert kit.summary() == manifest["summary"]


def test_export_replaces_own_and_refuses_foreign_folder(export_pair, tmp_path):
    """Exporting again into an earlier export of the same kit replaces it (same bytes); a
    folder holding anything else is refused with ExportError and left untouched; a different
    kit needs force=True."""
    a, b, manifest, _, kit = export_pair
    kit.export(b, command_line=manifest["command_line"])
    assert_same_tree(a, b)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    with pytest.raises(fabkit.ExportError):
        kit.export(foreign)
    assert sorted(p.name for p in foreign.iterdir()) == ["notes.txt"]
    other = fabkit.build_kit(fabkit.Design.load("rtac0").with_preset("square_split"))
    c = tmp_path / "c"
    kit.export(c)
    with pytest.raises(fabkit.ExportError):
        other.export(c)
    assert json.loads((c / "manifest.json").read_text())["design"]["name"] == "rtac0"
    other.export(c, force=True)
    assert json.loads((c / "manifest.json").read_text())["design"]["name"] == "rtac0_square_split"


def test_export_formats(tmp_path):
    """formats=['stl'] writes STL parts and no 3MF; an unknown format is a ValueError before
    anything is written."""
    kit = fabkit.build_kit(fabkit.Design.load("rtac0"))
    with pytest.raises(ValueError, match="obj"):
        kit.export(tmp_path / "x", formats=["obj"])
    assert not (tmp_path / "x").exists()
    kit.export(tmp_path / "s", formats=["stl"])
    files = [p.name for p in (tmp_path / "s").rglob("*") if p.is_file()]
    assert "shell_base.stl" in files
    assert not any(f.endswith(".3mf") for f in files)


def test_build_kit_progress_called():
    """build_kit calls progress(done, total, message) at the start and at the end."""
    calls = []
    fabkit.build_kit(
        fabkit.Design.load("rtac0"), progress=lambda d, t, m: calls.append((d, t, m))
    )
    assert [(d, t) for d, t, _ in calls] == [(0, 1), (1, 1)]
    assert all(isinstance(m, str) and "rtac0" in m for _, _, m in calls)


def test_build_kit_releases_gil():
    """While build_kit runs in a thread, another Python thread runs (conftest.ran_during: no
    clock, the interpreter's switch interval set so that only a released GIL lets it in)."""
    from conftest import ran_during

    design = fabkit.Design.load("rtac0")
    kit, during = ran_during(lambda: fabkit.build_kit(design, chord_tolerance_mm=0.05))
    assert during, "no other thread ran while build_kit held the GIL"
    assert kit is not None
    # and a call that holds the GIL is told apart: a pure-Python loop of the same thread
    _, during = ran_during(lambda: sum(range(2_000_000)))
    assert not during


def test_simulator_formats_same_bytes_as_cli(tmp_path, run_cli):
    """formats=['mjcf', 'urdf', 'usd'] writes the simulators' files `fabkit export --format
    mjcf,urdf,usd` writes (the nominal camera, the lights, the meshes), byte for byte; the
    fixtures' export refuses them before anything is written (as `fabkit fixtures --format
    mjcf` does)."""
    run_cli(tmp_path, "export", "uvdtact", "--format", "mjcf,urdf,usd", "--out", "A")
    manifest = json.loads((tmp_path / "A" / "manifest.json").read_text())
    kit = fabkit.build_kit(fabkit.Design.load("uvdtact"))
    kit.export(tmp_path / "B", formats=["mjcf", "urdf", "usd"],
               command_line=manifest["command_line"])
    assert_same_tree(tmp_path / "A", tmp_path / "B")
    sim = sorted(p.relative_to(tmp_path / "B").as_posix()
                 for p in (tmp_path / "B" / "sim").rglob("*") if p.is_file())
    assert {"sim/uvdtact.xml", "sim/uvdtact.urdf", "sim/uvdtact.usda", "sim/camera.yaml"} <= set(sim)
    fixtures = fabkit.build_fixtures(fabkit.Design.load("uvdtact"), semidomes=1)
    with pytest.raises(ValueError, match="simulators"):
        fixtures.kit.export(tmp_path / "F", formats=["stl", "mjcf"])
    assert not (tmp_path / "F").exists()
    cli = run_cli(tmp_path, "fixtures", "uvdtact", "--semidomes", "1", "--format", "stl,mjcf",
                  "--out", "G", ok=False)
    assert "--format mjcf: the simulators' files are of the sensor" in cli.stderr
    assert not (tmp_path / "G").exists()
