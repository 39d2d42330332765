"""fabkit.Design against the `fabkit` command line: loading (library name, YAML file, YAML text,
dict), parameters by path, presets, validation.

Needs FABKIT_BIN (the CLI binary; see conftest.py) and the built extension on PYTHONPATH.
"""

import json
import math
import os
import re
import sys
from pathlib import Path

import numpy as np
import pytest

# `python -m pytest` run from python/ puts that folder first on sys.path, where the package's
# sources lack the built extension (fabkit._fabkit): import the built package (PYTHONPATH) instead.
_SOURCES = Path(__file__).resolve().parents[1]
sys.path[:] = [p for p in sys.path if Path(p or os.curdir).resolve() != _SOURCES]

import fabkit
from conftest import cli_message

REPO = Path(__file__).resolve().parents[2]
LIBRARY = REPO / "designs" / "library"


def tree_bytes(root):
    """{relative path: bytes} of every file under root."""
    root = Path(root)
    return {
        p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()
    }


def assert_same_tree(a, b):
    ta, tb = tree_bytes(a), tree_bytes(b)
    assert sorted(ta) == sorted(tb)
    differ = [k for k in ta if ta[k] != tb[k]]
    assert not differ, f"files that differ between {a} and {b}: {differ}"


def cli_parameters(stdout):
    """{path: printed value} from `fabkit validate`'s parameter list."""
    out = {}
    lines = stdout.split("\n")
    start = next(i for i, l in enumerate(lines) if l.startswith("parameters of ")) + 1
    for l in lines[start:]:
        if not l.startswith("  "):
            break
        path, value = l[2:].split(" = ", 1)
        out[path] = value
    return out


def cli_stack(stdout):
    """The resolved layer stack `fabkit validate` prints (JSON)."""
    i = stdout.index("resolved layer stack")
    return json.loads(stdout[stdout.index("{", i):])


def assert_close_json(a, b, tol=1e-9, at=""):
    if isinstance(a, dict):
        assert isinstance(b, dict) and sorted(a) == sorted(b), at
        for k in a:
            assert_close_json(a[k], b[k], tol, f"{at}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), at
        for i, (x, y) in enumerate(zip(a, b)):
            assert_close_json(x, y, tol, f"{at}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert not isinstance(a, bool) and not isinstance(b, bool), at
        assert math.isclose(a, b, rel_tol=0, abs_tol=tol), f"{at}: {a} != {b}"
    else:
        assert a == b, f"{at}: {a!r} != {b!r}"


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    return tmp_path_factory.mktemp("designs")


@pytest.fixture(scope="module")
def rtac0_yaml(work, run_cli):
    """rtac0's YAML as `fabkit show rtac0 --out` writes it (absolute path)."""
    run_cli(work, "show", "rtac0", "--out", "rtac0_shown.yaml")
    return work / "rtac0_shown.yaml"


def meshes(kit):
    return {p.name: p.mesh() for p in kit.parts}


def assert_same_meshes(k1, k2):
    m1, m2 = meshes(k1), meshes(k2)
    assert list(m1) == list(m2)
    for name in m1:
        (v1, t1), (v2, t2) = m1[name], m2[name]
        assert np.array_equal(v1, v2), name
        assert np.array_equal(t1, t2), name


@pytest.fixture(scope="module")
def rtac0_kit():
    return fabkit.build_kit(fabkit.Design.load("rtac0"), chord_tolerance_mm=0.01)


# ---------------------------------------------------------------------------------------- loading


def test_library_designs_match_cli_listing(run_cli, work):
    """library_designs() and each design's presets are what `fabkit designs` lists."""
    out = run_cli(work, "designs").stdout.strip().split("\n")
    cli = {}
    for line in out:
        cols = line.split("\t")
        name = cols[0].replace(" (default)", "")
        presets = []
        for c in cols:
            if c.startswith("presets: "):
                presets = c[len("presets: "):].split(", ")
        cli[name] = (cols[1], presets)
    py = fabkit.library_designs()
    assert [n for n, _ in py] == list(cli)
    for name, description in py:
        assert description == cli[name][0]
        assert sorted(fabkit.Design.load(name).presets) == sorted(cli[name][1])
    assert out[0].startswith(fabkit.DEFAULT_DESIGN + " (default)")
    assert fabkit.Design.load().name == fabkit.DEFAULT_DESIGN


def test_load_library_name_matches_cli_manifest_provenance(work, run_cli):
    """Design.load('rtac0') has the source and sha256 that `fabkit export rtac0` records."""
    d = fabkit.Design.load("rtac0")
    assert d.name == "rtac0"
    run_cli(work, "export", "rtac0", "--out", "prov")
    m = json.loads((work / "prov" / "manifest.json").read_text())
    assert m["design"] == {"name": d.name, "source": d.source, "sha256": d.sha256}
    assert re.fullmatch("[0-9a-f]{64}", d.sha256)


def test_load_yaml_path_same_kit_as_library(rtac0_yaml, rtac0_kit):
    """A YAML file written by `fabkit show rtac0` loads to the same parameters and the same
    meshes as the library design; its source is the path and its sha256 that of the file."""
    import hashlib

    lib = fabkit.Design.load("rtac0")
    d = fabkit.Design.load(str(rtac0_yaml))
    assert d.source == str(rtac0_yaml)
    assert d.sha256 == hashlib.sha256(rtac0_yaml.read_bytes()).hexdigest()
    assert d.to_dict() == lib.to_dict()
    # a pathlib.Path works too
    assert fabkit.Design.load(rtac0_yaml).to_dict() == lib.to_dict()
    assert_same_meshes(fabkit.build_kit(d, chord_tolerance_mm=0.01), rtac0_kit)


@pytest.mark.parametrize("name", sorted(p.stem for p in LIBRARY.glob("*.yaml")))
def test_library_yaml_files_load_as_embedded(name):
    """designs/library/<name>.yaml (path and from_yaml text) is the embedded design <name>."""
    path = LIBRARY / f"{name}.yaml"
    emb = fabkit.Design.load(name)
    assert fabkit.Design.load(str(path)).to_dict() == emb.to_dict()
    t = fabkit.Design.from_yaml(path.read_text(), origin=str(path))
    assert t.to_dict() == emb.to_dict()
    assert t.source == str(path)


def test_from_dict_roundtrip_builds_same_kit(rtac0_kit):
    """from_dict(d.to_dict()) is the same design: same dict, same JSON and the same mesh
    arrays, part for part."""
    d = fabkit.Design.load("rtac0")
    d2 = fabkit.Design.from_dict(d.to_dict())
    assert d2.source == "<dict>"
    assert d2.to_dict() == d.to_dict()
    assert json.loads(d2.to_json()) == json.loads(d.to_json())
    assert_same_meshes(fabkit.build_kit(d2, chord_tolerance_mm=0.01), rtac0_kit)


def test_to_json_reads_back_with_from_yaml():
    """to_json() is YAML-compatible text that from_yaml reads back to the same design."""
    d = fabkit.Design.load("shadowtac")
    assert fabkit.Design.from_yaml(d.to_json()).to_dict() == d.to_dict()


# ------------------------------------------------------------------------------------- parameters


def test_parameter_paths_and_values_match_cli_validate(rtac0_yaml, run_cli, work):
    """parameter_paths() is the list `fabkit validate` prints, in its order, and d[path] reads
    the value it prints for every path."""
    out = run_cli(work, "validate", rtac0_yaml).stdout
    cli = cli_parameters(out)
    d = fabkit.Design.load(str(rtac0_yaml))
    assert d.parameter_paths() == list(cli)
    for path, shown in cli.items():
        v = d[path]
        if shown == "(not set)":
            assert v is None, path
        elif isinstance(v, float):
            assert math.isclose(v, float(shown), abs_tol=1e-9), path
        else:
            assert v == json.loads(shown), path


def test_validate_returns_cli_resolved_stack(rtac0_yaml, run_cli, work):
    """validate() returns the resolved layer stack `fabkit validate` prints (to its 1e-9
    rounding)."""
    out = run_cli(work, "validate", rtac0_yaml).stdout
    stack = fabkit.Design.load(str(rtac0_yaml)).validate()
    assert_close_json(stack, cli_stack(out))
    assert [l["name"] for l in stack["layers"]] == ["transparent_gel", "translucent_gel", "black_coating"]


def test_set_parameters_by_sweep_path_and_short_path():
    """d[path] = v sets exactly that parameter (full sweep path or a unique short path);
    with_values returns a copy and leaves the original alone."""
    d = fabkit.Design.load("rtac0")
    assert d["layers[1].outer_radius_mm"] == 14.9
    before = d.to_dict()
    d2 = d.with_values({"layers[1].outer_radius_mm": 14.7, "camera.bay_height_mm": 3.5})
    assert d.to_dict() == before
    assert d2["layers[1].outer_radius_mm"] == 14.7
    assert d2["housing.camera.bay_height_mm"] == 3.5
    after = d2.to_dict()
    assert after["layers"][1]["outer_radius_mm"] == 14.7
    assert after["housing"]["camera"]["bay_height_mm"] == 3.5
    # nothing else changed
    after["layers"][1]["outer_radius_mm"] = before["layers"][1]["outer_radius_mm"]
    after["housing"]["camera"]["bay_height_mm"] = before["housing"]["camera"]["bay_height_mm"]
    assert after == before
    # the change reaches the resolved stack: translucent gel 0.2 mm thinner
    s1, s2 = d.validate(), d2.validate()
    assert math.isclose(
        s1["layers"][1]["thickness_mm"] - s2["layers"][1]["thickness_mm"], 0.2, abs_tol=1e-9
    )
    # in place
    d["layers[1].outer_radius_mm"] = 14.8
    assert d.to_dict()["layers"][1]["outer_radius_mm"] == 14.8


def test_unknown_and_ambiguous_paths_raise_key_error():
    """An unknown path and a short path that names several parameters raise KeyError naming the
    candidates; the design is unchanged."""
    d = fabkit.Design.load("rtac0")
    before = d.to_dict()
    with pytest.raises(KeyError, match="layers\\[9\\]"):
        d["layers[9].outer_radius_mm"]
    with pytest.raises(KeyError, match="printers.fdm.bayonet.clearance_mm"):
        d["bayonet.clearance_mm"]
    with pytest.raises(KeyError):
        d["no_such_parameter"] = 1.0
    with pytest.raises(KeyError):
        d.with_values({"body.radius": 1.0})
    assert d.to_dict() == before


def test_setting_a_wrong_type_raises_design_error_with_path():
    """A value of the wrong type at a path raises DesignError naming path, value and rule."""
    d = fabkit.Design.load("rtac0")
    with pytest.raises(fabkit.DesignError) as e:
        d["body.radius_mm"] = "fifteen"
    (item,) = e.value.errors
    assert item.path == "body.radius_mm"
    assert item.value == "'fifteen'"
    assert item.rule
    assert str(e.value) == f"{item.path} = {item.value}: {item.rule}"
    assert d["body.radius_mm"] == 15.0


# ---------------------------------------------------------------------------------------- presets


def test_preset_export_matches_cli(work, run_cli):
    """`fabkit export rtac0 --preset square_split` and Design.with_preset('square_split') built
    and exported with the same command_line give the same files, byte for byte."""
    d = fabkit.Design.load("rtac0")
    assert "square_split" in d.presets
    run_cli(work, "export", "rtac0", "--preset", "square_split", "--out", "preset_cli")
    cli = work / "preset_cli"
    argv = json.loads((cli / "manifest.json").read_text())["command_line"]
    p = d.with_preset("square_split")
    assert p.name == "rtac0_square_split"
    assert p["housing.style"] == "square_split"
    assert p["housing.camera.board_width_mm"] == 25.0
    assert d["housing.style"] == "round_tube"  # the original is unchanged
    kit = fabkit.build_kit(p, chord_tolerance_mm=0.01)
    assert kit.name == "rtac0_square_split"
    m = kit.export(work / "preset_py", command_line=argv)
    assert m["design"]["name"] == "rtac0_square_split"
    assert_same_tree(cli, work / "preset_py")


def test_preset_values_match_cli_validate(run_cli, work):
    """A preset applied in Python gives the parameters `fabkit validate NAME --preset P` prints
    (a design whose preset sets a nested list path)."""
    out = run_cli(work, "validate", "tactip_dualmodal", "--preset", "tip_d").stdout
    cli = cli_parameters(out)
    d = fabkit.Design.load("tactip_dualmodal").with_preset("tip_d")
    assert d["layers[0].markers[0].pattern.spacing_mm"] == 4.5
    assert d["layers[0].markers[0].feature.diameter_mm"] == 1.7
    assert d.parameter_paths() == list(cli)
    for path, shown in cli.items():
        v = d[path]
        if isinstance(v, float):
            assert math.isclose(v, float(shown), abs_tol=1e-9), path


def test_unknown_preset_message_matches_cli(run_cli, work):
    """with_preset of a preset the design lacks raises DesignError with the CLI's message."""
    p = run_cli(work, "validate", "rtac0", "--preset", "nope", ok=False)
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.Design.load("rtac0").with_preset("nope")
    assert str(e.value) == cli_message(p.stderr)


# ------------------------------------------------------------------------------------- validation


def _bad_yaml(src, dst, replacements):
    text = src.read_text()
    lines = text.split("\n")
    for prefix, new in replacements.items():
        idx = [i for i, l in enumerate(lines) if l.startswith(prefix)]
        assert idx, prefix
        lines[idx[0]] = new
    dst.write_text("\n".join(lines))
    return dst


def test_validate_reports_every_violation_like_cli(rtac0_yaml, work, run_cli):
    """Two bad values give one DesignError listing both (path, value, rule), with the message
    `fabkit validate` prints for the same YAML; setting the same values in Python gives the same
    items."""
    bad = _bad_yaml(
        rtac0_yaml,
        work / "two_bad.yaml",
        {"  wall_thickness_mm: 1.0": "  wall_thickness_mm: -1.0", "  draft_angle_deg:": "  draft_angle_deg: 95"},
    )
    p = run_cli(work, "validate", bad, ok=False)
    d = fabkit.Design.load(str(bad))  # loads: the rules are checked by validate() and builds
    with pytest.raises(fabkit.DesignError) as e:
        d.validate()
    assert str(e.value) == cli_message(p.stderr)
    items = [(x.path, x.value, x.rule) for x in e.value.errors]
    assert [i[0] for i in items] == ["core.wall_thickness_mm", "mold.draft_angle_deg"]
    assert [i[1] for i in items] == ["-1", "95"]
    assert all(i[2] for i in items)
    for x in e.value.errors:
        assert isinstance(x, fabkit.ParamError)
        assert f"  {x.path} = {x.value}: {x.rule}" in str(e.value).split("\n")
    # the same values set in Python
    d2 = fabkit.Design.load("rtac0").with_values({"core.wall_thickness_mm": -1.0, "mold.draft_angle_deg": 95})
    with pytest.raises(fabkit.DesignError) as e2:
        d2.validate()
    assert [(x.path, x.value, x.rule) for x in e2.value.errors] == items
    assert str(e2.value) == str(e.value)
    # a build checks the same rules first
    with pytest.raises(fabkit.DesignError) as e3:
        fabkit.build_kit(d2, chord_tolerance_mm=0.01)
    assert [(x.path, x.value, x.rule) for x in e3.value.errors] == items
