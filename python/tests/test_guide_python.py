"""The user guide's first "From Python" example (arrays, docs/src/guide/python.md) runs as written, on inputs the CLI makes: a camera file
(cam.yaml), a calibration (calib/extrinsics.json), the R-Tac0 fixtures (out/rtac0_fixtures) and
a ground-truth folder (gt), in a fresh folder; so does the second (a board press and a ball
press's ground truth), on 9DTact's captures and the folders the CLI makes of them; and the third
(a sweep on a local Dask cluster), saved as a file and run with python as the guide says."""

import contextlib
import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

from test_groundtruth_render import CAMERA_YAML, pose

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "src" / "guide" / "python.md"


def guide_blocks():
    blocks = re.findall(r"```python\n(.*?)```", GUIDE.read_text(), re.S)
    assert len(blocks) == 3, "the chapter has three Python examples: arrays, a board press, a sweep"
    return blocks


def guide_example():
    return guide_blocks()[0]


def test_guide_example_runs(tmp_path, run_cli, monkeypatch):
    (tmp_path / "cam.yaml").write_text(CAMERA_YAML)
    (tmp_path / "calib").mkdir()
    (tmp_path / "calib" / "extrinsics.json").write_text(
        json.dumps({"T_cam_sensor": pose().tolist()})
    )
    run_cli(tmp_path, "fixtures", "rtac0", "--semidomes", "2", "--seed", "3", "--format", "stl",
            "--out", "out/rtac0_fixtures")
    run_cli(tmp_path, "groundtruth", "rtac0", "--camera", "cam.yaml", "--extrinsics",
            "calib/extrinsics.json", "--fixtures", "out/rtac0_fixtures", "--out", "gt")
    monkeypatch.chdir(tmp_path)
    printed = io.StringIO()
    scope = {}
    with contextlib.redirect_stdout(printed):
        exec(compile(guide_example(), str(GUIDE), "exec"), scope)
    # what the example made is what it says
    lines = printed.getvalue().splitlines()
    assert (tmp_path / "out" / "rtac0_py" / "manifest.json").is_file()
    manifest = json.loads((tmp_path / "out" / "rtac0_py" / "manifest.json").read_text())
    assert manifest["parts"][0]["volume_mm3"] == scope["kit"].parts[0].numbers()["volume_mm3"]
    # one line per configuration (2 patterns x 2 orientations), each pushed in somewhere
    frames = [l for l in lines if l.split()[0] in {p.name for p in scope["fabkit"].read_protrusions(
        "out/rtac0_fixtures", scope["design"])}]
    assert len(frames) == 4
    assert all(float(l.split()[1]) < 0 and int(l.split()[2]) > 0 for l in frames)
    # the pin dome's captures, named by their pins; the first rendered as a capture
    captures = scope["captures"]
    assert captures and all(c.name == "_".join("%02d" % int(i) for i in c.pins) for c in captures)
    assert scope["capture_image"].shape == scope["image"].shape
    # the loop visited the 2 x 2 stitched pairs, each with a finite depth and a push somewhere
    assert len(scope["gt"]) == 4
    assert scope["pair"].index == 3
    assert np.isfinite(scope["depth"]).any() and np.nanmin(scope["target"]) < 0


def test_guide_board_example_runs(tmp_path, run_cli, monkeypatch):
    """The board press example: 63 bumps, the RMS under 1.3 px, the board/ folder the CLI's; the
    ball press's fit and arrays read from the folder the CLI wrote."""
    repo = GUIDE.parents[3]
    (tmp_path / "tests").symlink_to(repo / "tests")
    data = "tests/data/9dtact_sensor1/"
    run_cli(tmp_path, "fixtures", "ninedtact", "--out", "fx")
    run_cli(tmp_path, "calibrate", "board", "--points", "fx/points/board_table.csv",
            "--reference", data + "camera_calibration/ref.png",
            "--image", data + "camera_calibration/sample.png", "--out", "board")
    run_cli(tmp_path, "groundtruth", "ninedtact", "--camera", "board/camera.yaml",
            "--extrinsics", "board/extrinsics.json",
            "--press-image", data + "depth_calibration/sample.png",
            "--press-reference", data + "depth_calibration/ref.png",
            "--sphere-radius-mm", "4", "--out", "gt_press")
    cli_report = json.loads((tmp_path / "board" / "extrinsics.json").read_text())
    monkeypatch.chdir(tmp_path)
    printed = io.StringIO()
    scope = {}
    with contextlib.redirect_stdout(printed):
        exec(compile(guide_blocks()[1], str(GUIDE), "exec"), scope)
    found, rms = printed.getvalue().splitlines()[0].split()
    assert int(found) == 63 and float(rms) < 1.3
    report = json.loads((tmp_path / "board" / "extrinsics.json").read_text())
    del report["command_line"], cli_report["command_line"]
    assert report == cli_report
    assert scope["camera"].shape == (480, 640) and scope["T_cam_sensor"].shape == (4, 4)
    press = scope["press"]
    assert 1.5 < press.depth_mm < 1.8
    assert abs(np.nanmin(scope["target"]) + press.depth_mm) < 0.01
    assert scope["normals"].shape == (480, 640, 3) and scope["capture"].shape == (480, 640, 3)


def test_guide_sweep_example_runs_as_a_script(tmp_path):
    """Issue 102: the sweep example returned 20 infeasible variants (the default layout ignores
    the spacing) and its process pool crashed without a __main__ guard. Saved as sweep.py and
    run with python (two Dask worker processes), it prints a progress line per variant and the
    table; called again, its variants build (the spacing moves the dimple count)."""
    pytest = __import__("pytest")
    pytest.importorskip("distributed")
    script = tmp_path / "sweep.py"
    script.write_text(guide_blocks()[2])
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                         text=True, env=dict(os.environ), timeout=600)
    assert run.returncode == 0, run.stderr
    assert "status" in run.stdout and "min_wall_mm" in run.stdout, run.stdout
    scope = {"__name__": "guide_sweep"}
    exec(compile(guide_blocks()[2], str(GUIDE), "exec"), scope)
    with contextlib.redirect_stdout(io.StringIO()):
        table = scope["main"]()
    assert len(table) == 20
    ok = table[table["status"] == "ok"]
    assert len(ok) >= 15, table["status"].value_counts()
    counts = [c for c in table.columns if c.startswith("markers.") and c.endswith(".count")]
    spacing = "layers[0].markers[0].pattern.spacing_mm"
    assert counts and ok.groupby(spacing)[counts[0]].first().nunique() > 1, ok
