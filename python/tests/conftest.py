"""Shared fixtures of the `fabkit` Python package's tests.

The tests compare the package with the `fabkit` command line: FABKIT_BIN names the CLI binary
(scripts/test sets it to the one `cargo test` built). Without it the tests that need it are
skipped, unless FABKIT_REQUIRE_ORACLES=1 (scripts/test), where they fail.
"""

import os
import subprocess

import pytest

# MuJoCo's off-screen renderer without a display: EGL (Mesa's llvmpipe on the CPU), chosen when
# mujoco is first imported
os.environ.setdefault("MUJOCO_GL", "egl")


def _require():
    return os.environ.get("FABKIT_REQUIRE_ORACLES") == "1"


@pytest.fixture(scope="session")
def fabkit_bin():
    """Path of the `fabkit` CLI binary (FABKIT_BIN)."""
    binary = os.environ.get("FABKIT_BIN")
    why = None
    if not binary:
        why = "FABKIT_BIN is not set (path of a built `fabkit` CLI binary)"
    elif not (os.path.isfile(binary) and os.access(binary, os.X_OK)):
        why = f"FABKIT_BIN = {binary}: not an executable file"
    if why:
        if _require():
            pytest.fail(why)
        pytest.skip(why)
    return binary


@pytest.fixture(scope="session")
def run_cli(fabkit_bin):
    """run_cli(cwd, *args, ok=True) -> CompletedProcess of `fabkit args...` in cwd (text)."""

    def run(cwd, *args, ok=True):
        p = subprocess.run(
            [fabkit_bin, *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=600
        )
        if ok:
            assert p.returncode == 0, f"fabkit {' '.join(map(str, args))} failed:\n{p.stderr}"
        else:
            assert p.returncode != 0, f"fabkit {' '.join(map(str, args))} succeeded"
        return p

    return run


def cli_message(stderr):
    """The message the CLI printed after `error: ` (with its `caused by:` lines), as the Python
    exception carries it."""
    lines = stderr.rstrip("\n").split("\n")
    start = next(i for i, l in enumerate(lines) if l.startswith("error: "))
    lines = lines[start:]
    lines[0] = lines[0][len("error: "):]
    return "\n".join(lines)


# The test camera of the Python tests: the benchmark lens of fabkit's tests (f = 215 px at
# 640 x 480, Kannala-Brandt) scaled to 160 x 120, as a ROS camera_info YAML.
W, H = 160, 120
FX, FY, CX, CY = 53.75, 53.75, 79.5, 59.5
KB = [-0.02, 0.004, -0.0015, 0.0002]
CAMERA_YAML = f"""image_width: {W}
image_height: {H}
camera_name: fabkit
camera_matrix:
  rows: 3
  cols: 3
  data: [{FX}, 0.0, {CX}, 0.0, {FY}, {CY}, 0.0, 0.0, 1.0]
distortion_model: equidistant
distortion_coefficients:
  rows: 1
  cols: 4
  data: [{', '.join(map(str, KB))}]
"""


def ran_during(call):
    """(call's result, whether this thread ran Python while call() ran in another thread),
    decided without a clock. With the interpreter's switch interval set to an hour, a thread
    that holds the GIL keeps it until it blocks or releases it, as a Rust call does around its
    work (`allow_threads`): this thread, woken as the call starts, then runs before the call
    returns only if the call released the GIL. A fast or slow machine gives the same answer."""
    import sys
    import threading

    started, finished = threading.Event(), threading.Event()
    box = {}

    def worker():
        started.set()
        box["out"] = call()
        finished.set()

    old = sys.getswitchinterval()
    sys.setswitchinterval(3600.0)
    try:
        th = threading.Thread(target=worker)
        th.start()
        started.wait()
        during = not finished.is_set()
        th.join()
    finally:
        sys.setswitchinterval(old)
    return box.get("out"), during
