"""The export guide's Simulators section (docs/src/guide/export.md) runs as written, in a fresh
folder: its `sh` block (`fabkit export rtac0 --format stl,3mf,mjcf`, fabkit on the PATH) and
then its Python block, which loads the MJCF in MuJoCo; the numbers it reads are the manifest's."""

import contextlib
import io
import json
import os
import re
import subprocess
import tempfile
from pathlib import Path

import pytest

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "src" / "guide" / "export.md"


def test_the_simulators_section_runs(tmp_path, fabkit_bin, monkeypatch):
    pytest.importorskip("mujoco")
    section = GUIDE.read_text().split("## Simulators", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```(sh|python)\n(.*?)```", section, re.S)
    assert [lang for lang, _ in blocks] == ["sh", "python"]
    bindir = Path(tempfile.mkdtemp())
    (bindir / "fabkit").symlink_to(Path(fabkit_bin).resolve())
    env = dict(os.environ, PATH=f"{bindir}:{os.environ.get('PATH', '')}")
    run = subprocess.run(["bash", "-euo", "pipefail", "-c", blocks[0][1]], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    monkeypatch.chdir(tmp_path)
    printed, scope = io.StringIO(), {}
    with contextlib.redirect_stdout(printed):
        exec(compile(blocks[1][1], str(GUIDE), "exec"), scope)
    mass = json.loads((tmp_path / "out" / "rtac0" / "manifest.json").read_text())[
        "assembly_3mf"]["mass"]
    first = printed.getvalue().splitlines()[0].split(maxsplit=1)
    assert abs(float(first[0]) - mass["mass_g"] * 1e-3) < 1e-9
    assert abs(float(printed.getvalue().splitlines()[1]) - 108.78) < 0.01
