"""The user guide's "From Python" chapter (docs/src/guide/python.md) runs as written, in a
fresh folder, block by block as the page shows them: the `sh` blocks that make an example's
inputs (with `fabkit` on the PATH), then its Python blocks in one scope. The first example
(arrays) reads the nominal camera, R-Tac0's fixtures and a ground truth the CLI makes; the
board example calibrates 9DTact's board press and reads a ball press's ground truth the CLI
makes through that camera; the sweep example (a local Dask cluster) is saved as a file and run
with python as the guide says."""

import contextlib
import io
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "src" / "guide" / "python.md"


def blocks():
    """The chapter's `sh` and `python` blocks, in order: (language, code)."""
    return re.findall(r"```(sh|python)\n(.*?)```", GUIDE.read_text(), re.S)


def guide_blocks():
    found = [code for lang, code in blocks() if lang == "python"]
    assert len(found) == 4, "four Python blocks: arrays, a board press and its ball press, a sweep"
    return found


def run_guide(first, last, cwd, fabkit_bin):
    """Runs the chapter's blocks from the `sh` blocks just before Python block `first` (the
    commands that make its inputs; not the install line) to Python block `last`, in `cwd`:
    `sh` with bash -euo pipefail and `fabkit` on the PATH, Python exec'd in one scope.
    Returns (scope, what the Python blocks printed)."""
    bl = blocks()
    at = [i for i, (lang, _) in enumerate(bl) if lang == "python"]
    start = at[first]
    while start > 0 and bl[start - 1][0] == "sh" and "pip install" not in bl[start - 1][1]:
        start -= 1
    assert bl[start][0] == "sh", "an example's inputs are made by the commands shown before it"
    bindir = Path(tempfile.mkdtemp())
    (bindir / "fabkit").symlink_to(Path(fabkit_bin).resolve())
    env = dict(os.environ, PATH=f"{bindir}:{os.environ.get('PATH', '')}")
    scope, printed = {}, io.StringIO()
    cwd_before = os.getcwd()
    os.chdir(cwd)
    try:
        for lang, code in bl[start:at[last] + 1]:
            if lang == "sh":
                run = subprocess.run(["bash", "-euo", "pipefail", "-c", code], cwd=cwd, env=env,
                                     capture_output=True, text=True, timeout=900)
                assert run.returncode == 0, f"{code}\n{run.stderr}"
            else:
                with contextlib.redirect_stdout(printed):
                    exec(compile(code, str(GUIDE), "exec"), scope)
    finally:
        os.chdir(cwd_before)
    return scope, printed.getvalue()


def test_guide_example_runs(tmp_path, fabkit_bin):
    scope, printed = run_guide(0, 0, tmp_path, fabkit_bin)
    # what the example made is what it says
    lines = printed.splitlines()
    assert (tmp_path / "out" / "rtac0_py" / "manifest.json").is_file()
    manifest = json.loads((tmp_path / "out" / "rtac0_py" / "manifest.json").read_text())
    assert manifest["parts"][0]["volume_mm3"] == scope["kit"].parts[0].numbers()["volume_mm3"]
    # one line per configuration (2 patterns x 2 orientations), each pushed in somewhere
    names = {p.name for p in scope["fabkit"].read_protrusions(
        tmp_path / "out" / "rtac0_fixtures", scope["design"])}
    frames = [l for l in lines if l.split()[0] in names]
    assert len(frames) == 4
    assert all(float(l.split()[1]) < 0 and int(l.split()[2]) > 0 for l in frames)
    # the pin dome's captures (the paper's dome, R-Tac0's default: 8 captures), named by their
    # pins; the first rendered as a capture
    captures = scope["captures"]
    assert len(captures) == 8
    assert all(c.name == "_".join("%02d" % int(i) for i in c.pins) for c in captures)
    assert scope["capture_image"].shape == scope["image"].shape
    # the loop visited the 2 x 2 stitched pairs, each with a finite depth and a push somewhere
    assert len(scope["gt"]) == 4
    assert scope["pair"].index == 3
    assert np.isfinite(scope["depth"]).any() and np.nanmin(scope["target"]) < 0


def test_guide_board_example_runs(tmp_path, run_cli, fabkit_bin):
    """The board press example: 63 bumps, the RMS under 1.3 px, the board/ folder the CLI's
    `calibrate board` writes; the ball press's fit and arrays read from the folder the CLI
    wrote through that camera."""
    repo = GUIDE.parents[3]
    (tmp_path / "tests").symlink_to(repo / "tests")
    scope, printed = run_guide(1, 2, tmp_path, fabkit_bin)
    found, rms = printed.splitlines()[0].split()
    assert int(found) == 63 and float(rms) < 1.3
    data = "tests/data/9dtact_sensor1/"
    run_cli(tmp_path, "calibrate", "board", "--points", "fx/points/board_table.csv",
            "--reference", data + "camera_calibration/ref.png",
            "--image", data + "camera_calibration/sample.png", "--out", "board_cli")
    report = json.loads((tmp_path / "board" / "extrinsics.json").read_text())
    cli_report = json.loads((tmp_path / "board_cli" / "extrinsics.json").read_text())
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
    script.write_text(guide_blocks()[3])
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                         text=True, env=dict(os.environ), timeout=600)
    assert run.returncode == 0, run.stderr
    assert "status" in run.stdout and "min_wall_mm" in run.stdout, run.stdout
    scope = {"__name__": "guide_sweep"}
    exec(compile(guide_blocks()[3], str(GUIDE), "exec"), scope)
    with contextlib.redirect_stdout(io.StringIO()):
        table = scope["main"]()
    assert len(table) == 20
    ok = table[table["status"] == "ok"]
    assert len(ok) >= 15, table["status"].value_counts()
    counts = [c for c in table.columns if c.startswith("markers.") and c.endswith(".count")]
    spacing = "layers[0].markers[0].pattern.spacing_mm"
    assert counts and ok.groupby(spacing)[counts[0]].first().nunique() > 1, ok
