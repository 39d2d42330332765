"""fabkit.build_fixtures against `fabkit fixtures`: the same folder byte for byte, the point table
and capture plan as numpy arrays equal to the CSV files, progress from the worker threads.

Needs FABKIT_BIN (the CLI binary; see conftest.py) and the built extension on PYTHONPATH.
"""

import csv
import io
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from test_designs import fabkit  # noqa: E402 (imports the built package)
from conftest import cli_message
from test_designs import assert_same_tree, tree_bytes

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def pair(tmp_path_factory, run_cli):
    """(CLI folder F, Python folder G, Fixtures, progress calls) of rtac0 with 2 generated
    semi-domes, seed 3."""
    work = tmp_path_factory.mktemp("fixtures")
    run_cli(work, "fixtures", "rtac0", "--semidomes", "2", "--seed", "3", "--out", "F")
    f = work / "F"
    argv = json.loads((f / "manifest.json").read_text())["command_line"]
    calls = []
    fx = fabkit.build_fixtures(
        fabkit.Design.load("rtac0"),
        semidomes=2,
        seed=3,
        chord_tolerance_mm=0.01,
        progress=lambda d, t, m: calls.append((d, t, m)),
    )
    fx.kit.export(work / "G", command_line=argv)
    return f, work / "G", fx, calls


def test_fixtures_export_same_bytes_as_cli(pair):
    """Fixtures.kit.export with the CLI's argv writes the same files as `fabkit fixtures`."""
    f, g, fx, _ = pair
    assert (f / "points" / "point_table.csv").is_file()
    assert_same_tree(f, g)
    assert fx.kit.name == json.loads((f / "manifest.json").read_text())["design"]["name"]


def test_files_equal_cli_data_files(pair):
    """Fixtures.files holds every data file the CLI writes (points/, protrusions/,
    indenters/), byte for byte; the two generated semi-domes are there."""
    f, _, fx, _ = pair
    files = fx.files
    cli = tree_bytes(f)
    assert "points/point_table.csv" in files
    assert {"protrusions/p001.json", "protrusions/p002.json"} <= set(files)
    assert "protrusions/p003.json" not in files
    for name, data in files.items():
        assert cli[name] == data, name
    data_dirs = ("points/", "protrusions/", "indenters/")
    assert {k for k in cli if k.startswith(data_dirs)} == set(files)


def test_point_table_equals_csv(pair):
    """point_table's arrays are the columns of points/point_table.csv (9 decimals) and of
    points/point_table.json; unit axes; the tip lies depth below the contact along the axis."""
    f, _, fx, _ = pair
    pt = fx.point_table
    df = pd.read_csv(f / "points" / "point_table.csv")
    n = len(df)
    assert n > 0
    assert pt["id"].dtype == np.uint32 and pt["ring"].dtype == np.uint32
    assert np.array_equal(pt["id"], df["id"].to_numpy())
    assert np.array_equal(pt["ring"], df["ring"].to_numpy())
    for key, prefix in (("tip_mm", "tip"), ("contact_mm", "contact"), ("axis", "axis")):
        a = pt[key]
        assert a.shape == (n, 3) and a.dtype == np.float64
        unit = "_mm" if key != "axis" else ""
        cols = [f"{prefix}_{c}{unit}" for c in "xyz"]
        assert np.allclose(a, df[cols].to_numpy(), rtol=0, atol=5e-10), key
    assert pt["indentation_depth_mm"].shape == (n,)
    assert np.allclose(pt["indentation_depth_mm"], df["indentation_depth_mm"], rtol=0, atol=5e-10)
    assert np.allclose(np.linalg.norm(pt["axis"], axis=1), 1.0, atol=1e-9)
    # the CSV text is exactly the arrays printed to 9 decimals
    text = fx.files["points/point_table.csv"].decode()
    rows = list(csv.reader(io.StringIO(text)))[1:]
    assert len(rows) == n
    for i, r in enumerate(rows):
        assert r[2:5] == [f"{x + 0.0:.9f}".replace("-0.000000000", "0.000000000") for x in pt["tip_mm"][i]]


def test_capture_plan_equals_csv(pair):
    """capture_plan lists, per capture, the pin ids of points/capture_plan.csv; every pin once."""
    f, _, fx, _ = pair
    df = pd.read_csv(f / "points" / "capture_plan.csv")
    expected = [list(g["id"]) for _, g in df.groupby("capture", sort=True)]
    assert fx.capture_plan == expected
    pt = fx.point_table
    assert {i for c in fx.capture_plan for i in c} == set(pt["id"].tolist())
    ring = dict(zip(pt["id"].tolist(), pt["ring"].tolist()))
    rings = sorted(set(ring.values()))
    for c in fx.capture_plan:  # one pin per ring, inner to outer
        assert [ring[i] for i in c] == rings


def test_fixtures_progress_called(pair):
    """progress(done, total, message) is called with (0, parts) first, then as parts finish
    (from worker threads, so in any order): distinct counts up to all the parts."""
    _, _, fx, calls = pair
    assert calls, "progress was never called"
    total = len(fx.kit.parts)
    assert total == 8  # the paper's dome and its ring, pin, holder, empty half, 2 patterns, indenter
    assert calls[0][:2] == (0, total)
    assert all(t == total for _, t, _ in calls)
    dones = [d for d, _, _ in calls[1:]]
    assert dones and len(set(dones)) == len(dones)
    assert max(dones) == total and min(dones) >= 1


def test_fixture_params_dict_path_and_preset_agree(tmp_path, run_cli):
    """The published pin dome as a params YAML path, as the same dict, and as pins_preset='rtac0'
    gives the same point table; it is the one `fabkit fixtures --params FILE` writes."""
    import yaml

    path = REPO / "fixtures" / "presets" / "rtac0_pins.yaml"
    d = fabkit.Design.load("rtac0")
    by_path = fabkit.build_fixtures(d, params=str(path), semidomes=0)
    by_dict = fabkit.build_fixtures(d, params=yaml.safe_load(path.read_text()), semidomes=0)
    by_preset = fabkit.build_fixtures(d, pins_preset="rtac0", semidomes=0)
    assert len(by_path.point_table["id"]) == 29  # the pole and 4 + 8 + 8 + 8 holes
    for other in (by_dict, by_preset):
        for k, v in by_path.point_table.items():
            assert np.array_equal(v, other.point_table[k]), k
        assert other.capture_plan == by_path.capture_plan
    run_cli(tmp_path, "fixtures", "rtac0", "--params", path, "--semidomes", "0", "--out", "P")
    cli = (tmp_path / "P" / "points" / "point_table.csv").read_bytes()
    assert by_path.files["points/point_table.csv"] == cli


def test_rtac0s_default_fixtures_are_its_papers():
    """R-Tac0's default fixtures are its paper's, as `fabkit fixtures rtac0` builds them: the
    published dome (29 holes) and 100 semi-domes; fabkit's own dome (13 holes) with
    pins_preset='default'; a params dict's own dome and count win over the paper's."""
    d = fabkit.Design.load("rtac0")
    patterns = lambda fx: sum(re.fullmatch(r"protrusions/p\d{3}\.json", f) is not None
                              for f in fx.files)
    paper = fabkit.build_fixtures(d)
    assert len(paper.point_table["id"]) == 29 and patterns(paper) == 100
    published = fabkit.build_fixtures(d, pins_preset="rtac0", semidomes=0)
    assert np.array_equal(paper.point_table["tip_mm"], published.point_table["tip_mm"])
    assert patterns(published) == 0
    own = fabkit.build_fixtures(d, pins_preset="default", semidomes=0)
    assert len(own.point_table["id"]) == 13
    given = fabkit.build_fixtures(
        d, params={"pin_dome": {"engrave_numbers": True}, "semidomes": {"generate": 1}})
    assert len(given.point_table["id"]) == 13 and patterns(given) == 1


def test_seed_makes_protrusions_deterministic():
    """The same seed gives the same files; another seed other protrusions and the same pins."""
    d = fabkit.Design.load("rtac0")
    a = fabkit.build_fixtures(d, semidomes=1, seed=7)
    b = fabkit.build_fixtures(d, semidomes=1, seed=7)
    assert a.files == b.files
    c = fabkit.build_fixtures(d, semidomes=1, seed=8)
    assert c.files["protrusions/p001.json"] != a.files["protrusions/p001.json"]
    assert np.array_equal(c.point_table["tip_mm"], a.point_table["tip_mm"])


def test_bad_fixture_params_message_matches_cli(tmp_path, run_cli):
    """A params YAML with an unknown key: DesignError with the message `fabkit fixtures
    --params` prints for the same file."""
    bad = tmp_path / "params.yaml"
    bad.write_text("pin_dome:\n  no_such_key: 1\n")
    p = run_cli(tmp_path, "fixtures", "rtac0", "--params", bad, "--out", "X", ok=False)
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.build_fixtures(fabkit.Design.load("rtac0"), params=str(bad))
    assert str(e.value) == cli_message(p.stderr)
    assert not (tmp_path / "X").exists()


def test_an_export_never_replaces_fixtures(pair):
    """Kit.export into the folder of a fixtures kit is refused, even with force=True (a command
    replaces only its own kind of output), naming the command, and the folder is unchanged."""
    _, g, _, _ = pair
    before = {p.relative_to(g): p.read_bytes() for p in sorted(g.rglob("*")) if p.is_file()}
    kit = fabkit.build_kit(fabkit.Design.load("rtac0"))
    for force in (False, True):
        with pytest.raises(fabkit.ExportError, match="holds the output of `fabkit fixtures`"):
            kit.export(g, force=force)
    after = {p.relative_to(g): p.read_bytes() for p in sorted(g.rglob("*")) if p.is_file()}
    assert after == before
