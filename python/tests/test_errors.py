"""Bad input: the Python package raises the error the `fabkit` command line reports for the same
input (same message), of a class that says what failed, and never panics or crashes the
interpreter.

Needs FABKIT_BIN (the CLI binary; see conftest.py) and the built extension on PYTHONPATH.
"""

import math
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

# `python -m pytest` run from python/ puts that folder first on sys.path, where the package's
# sources lack the built extension (fabkit._fabkit): import the built package (PYTHONPATH) instead.
_SOURCES = Path(__file__).resolve().parents[1]
sys.path[:] = [p for p in sys.path if Path(p or os.curdir).resolve() != _SOURCES]

import fabkit
from conftest import cli_message


@pytest.fixture(scope="module")
def work(tmp_path_factory, run_cli):
    w = tmp_path_factory.mktemp("errors")
    run_cli(w, "show", "rtac0", "--out", "rtac0.yaml")
    return w


def variant(work, name, replacements):
    """rtac0's YAML with lines starting with each key replaced; absolute path."""
    lines = (work / "rtac0.yaml").read_text().split("\n")
    for prefix, new in replacements.items():
        i = next(i for i, l in enumerate(lines) if l.startswith(prefix))
        lines[i] = new
    path = work / name
    path.write_text("\n".join(lines))
    return path


def test_wrong_type_argument_is_type_error():
    """A source that is not text or a path, a kit of something that is not a Design, a key that
    is not text: TypeError, not a fabkit error."""
    with pytest.raises(TypeError):
        fabkit.Design.load(42)
    with pytest.raises(TypeError):
        fabkit.build_kit("rtac0")
    with pytest.raises(TypeError):
        fabkit.Design.load("rtac0")[1]
    with pytest.raises(TypeError, match="body.radius_mm"):
        fabkit.Design.load("rtac0")["body.radius_mm"] = object()


def test_wrong_type_in_dict_is_design_error():
    """A dict whose value has the wrong type: DesignError naming the parameter path, the
    offending value and the expected type (`<dict>: path = value: rule`); a dict missing a
    required field: DesignError naming it."""
    d = fabkit.Design.load("rtac0").to_dict()
    d["layers"][1]["thickness_mm"] = "fifteen"
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.Design.from_dict(d)
    assert str(e.value).startswith('<dict>: layers[1].thickness_mm = "fifteen": ')
    assert "f64" in str(e.value)
    [item] = e.value.errors
    assert (item.path, item.value) == ("layers[1].thickness_mm", '"fifteen"')
    assert str(e.value) == f"<dict>: {item}"
    with pytest.raises(fabkit.DesignError, match="name"):
        fabkit.Design.from_dict({})
    with pytest.raises(TypeError, match="key must be text"):
        fabkit.Design.from_dict({1: 2})


def test_wrong_type_in_yaml_file_message_matches_cli(work, run_cli):
    """A YAML file with a wrong-typed value: Design.load raises DesignError with the message
    `fabkit validate` prints for that file (file:line:column)."""
    bad = variant(work, "wrong_type.yaml", {"  radius_mm: 15.0": "  radius_mm: fifteen"})
    p = run_cli(work, "validate", bad, ok=False)
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.Design.load(str(bad))
    assert str(e.value) == cli_message(p.stderr)
    assert str(e.value).startswith(f"{bad}:")
    # the same text through from_yaml, named alike
    with pytest.raises(fabkit.DesignError) as e2:
        fabkit.Design.from_yaml(bad.read_text(), origin=str(bad))
    assert str(e2.value) == str(e.value)


def test_missing_file_message_matches_cli(work, run_cli):
    """A missing design file: DesignError with the CLI's message for the same path."""
    p = run_cli(work, "validate", "/nonexistent/x.yaml", ok=False)
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.Design.load("/nonexistent/x.yaml")
    assert str(e.value) == cli_message(p.stderr)
    assert "/nonexistent/x.yaml" in str(e.value)


@pytest.mark.parametrize("arg", ["no_such_design", "/tmp"])
def test_unknown_name_or_folder_message_matches_cli(work, run_cli, arg):
    """An unknown library name and a folder given as a design: the CLI's message."""
    p = run_cli(work, "validate", arg, ok=False)
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.Design.load(arg)
    assert str(e.value) == cli_message(p.stderr)


def test_nan_parameter_message_matches_cli(work, run_cli):
    """A parameter set to NaN in Python, and a YAML file with `.nan` there: validate() and
    build_kit raise DesignError with the message `fabkit validate` prints for that file, and an
    item (path, 'NaN', rule)."""
    bad = variant(work, "nan.yaml", {"  radius_mm: 15.0": "  radius_mm: .nan"})
    p = run_cli(work, "validate", bad, ok=False)
    expected = cli_message(p.stderr)
    from_file = fabkit.Design.load(str(bad))
    in_python = fabkit.Design.load("rtac0")
    in_python["body.radius_mm"] = float("nan")
    assert math.isnan(in_python["body.radius_mm"])
    for d in (from_file, in_python):
        for call in (d.validate, lambda: fabkit.build_kit(d), lambda: fabkit.build_fixtures(d)):
            with pytest.raises(fabkit.DesignError) as e:
                call()
            assert str(e.value) == expected
            [(path, value)] = [(x.path, x.value) for x in e.value.errors]
            assert (path, value) == ("body.radius_mm", "NaN")
            assert e.value.errors[0].rule in expected


@pytest.mark.parametrize("value", ["0", "NaN", "-1", "inf"])
def test_bad_chord_tolerance_rule_matches_cli(work, run_cli, value):
    """chord_tolerance_mm = 0, NaN, -1, inf: ValueError naming the argument, with the rule text
    of the CLI's --chord-tolerance-mm error; nothing is built or written."""
    p = run_cli(work, "export", "rtac0", f"--chord-tolerance-mm={value}", "--out", "never", ok=False)
    msg = cli_message(p.stderr)
    assert msg.startswith("--chord-tolerance-mm: ")
    rule = msg[len("--chord-tolerance-mm: "):]
    d = fabkit.Design.load("rtac0")
    x = float(value)
    for call in (
        lambda: fabkit.build_kit(d, chord_tolerance_mm=x),
        lambda: d.validate(chord_tolerance_mm=x),
        lambda: fabkit.build_fixtures(d, chord_tolerance_mm=x),
    ):
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value) == f"chord_tolerance_mm: {rule}"
    assert not (work / "never").exists()


def test_bad_max_triangles_rule_matches_cli(work, run_cli):
    """max_triangles 0: ValueError with the CLI's --max-triangles rule; a kit over the limit:
    DesignError with the CLI's message."""
    p = run_cli(work, "export", "rtac0", "--max-triangles", "0", "--out", "never", ok=False)
    rule = cli_message(p.stderr).split("\n")[0].split(": ", 1)[1]
    for n in (0, -5, 100_000_001):
        with pytest.raises(ValueError) as e:
            fabkit.build_kit(fabkit.Design.load("rtac0"), max_triangles=n)
        assert str(e.value) == f"max_triangles: {rule}"
    p = run_cli(work, "export", "rtac0", "--max-triangles", "1000", "--out", "never", ok=False)
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.build_kit(fabkit.Design.load("rtac0"), max_triangles=1000)
    assert str(e.value) == cli_message(p.stderr)


def test_unknown_pins_preset_and_params_file(work, run_cli):
    """build_fixtures with an unknown pins preset or a missing params file: DesignError with the
    CLI's message."""
    p = run_cli(work, "fixtures", "rtac0", "--pins-preset", "nope", "--out", "never", ok=False)
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.build_fixtures(fabkit.Design.load("rtac0"), pins_preset="nope")
    assert str(e.value) == cli_message(p.stderr)
    p = run_cli(work, "fixtures", "rtac0", "--params", "/nonexistent/p.yaml", "--out", "never", ok=False)
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.build_fixtures(fabkit.Design.load("rtac0"), params="/nonexistent/p.yaml")
    assert str(e.value) == cli_message(p.stderr)


def test_export_into_a_file_is_export_error(tmp_path):
    """Exporting into a path that is a file: ExportError, and the file is untouched."""
    f = tmp_path / "file"
    f.write_text("keep")
    kit = fabkit.build_kit(fabkit.Design.load("rtac0"))
    with pytest.raises(fabkit.ExportError):
        kit.export(f)
    assert f.read_text() == "keep"
    assert issubclass(fabkit.ExportError, fabkit.FabkitError)
    assert issubclass(fabkit.DesignError, fabkit.FabkitError)
    assert issubclass(fabkit.InternalError, fabkit.FabkitError)


BATCH = r'''
import math, sys, fabkit

D = lambda: fabkit.Design.load("rtac0")
deep_list = []
for _ in range(100000):
    deep_list = [deep_list]
deep_dict = {}
for _ in range(100000):
    deep_dict = {"a": deep_dict}

def setting(path, value):
    d = D()
    d[path] = value
    return d

cases = [
    ("TypeError", lambda: fabkit.Design.load(42)),
    ("TypeError", lambda: fabkit.Design.load(b"\xff\xfe" * 3 + b"\0")),
    ("DesignError", lambda: fabkit.Design.load("")),
    ("DesignError", lambda: fabkit.Design.load("/")),
    ("DesignError", lambda: fabkit.Design.load("/nonexistent/x.yaml")),
    ("ValueError", lambda: fabkit.Design.load("rtac0", max_data_file_bytes=0)),
    ("OverflowError", lambda: fabkit.Design.load("rtac0", max_data_file_bytes=-1)),
    ("ValueError", lambda: fabkit.Design.load("rtac0", allow_data_dirs=["/nonexistent"])),
    ("DesignError", lambda: fabkit.Design.from_dict(42)),
    ("DesignError", lambda: fabkit.Design.from_dict({})),
    ("TypeError", lambda: fabkit.Design.from_dict({1: 2})),
    ("TypeError", lambda: fabkit.Design.from_dict({"name": object()})),
    ("ValueError", lambda: fabkit.Design.from_dict({"name": deep_list})),
    ("DesignError", lambda: fabkit.Design.from_yaml("{{{")),
    ("DesignError", lambda: fabkit.Design.from_yaml("")),
    ("DesignError", lambda: fabkit.Design.from_yaml("\x00")),
    ("DesignError", lambda: fabkit.Design.from_yaml("[" * 100000)),
    ("TypeError", lambda: D()[1]),
    ("KeyError", lambda: D()["nope"]),
    ("KeyError", lambda: D()["layers[99999999999999999999].outer_radius_mm"]),
    ("KeyError", lambda: D()["layers[-1].outer_radius_mm"]),
    ("KeyError", lambda: D()[""]),
    ("TypeError", lambda: setting("body.radius_mm", object())),
    ("DesignError", lambda: setting("body.radius_mm", [1, 2])),
    ("DesignError", lambda: setting("layers", None)),
    ("DesignError", lambda: setting("mold.vent.count", -1)),
    ("DesignError", lambda: setting("layers[0].markers", [{"x": 1}])),
    ("OverflowError", lambda: setting("body.radius_mm", 10**400)),
    ("DesignError", lambda: setting("body.radius_mm", 10**300).validate()),
    ("DesignError", lambda: setting("body.radius_mm", math.inf).validate()),
    ("DesignError", lambda: setting("body.radius_mm", -math.inf).validate()),
    ("TypeError", lambda: D().with_values({1: 2})),
    ("TypeError", lambda: D().with_preset(None)),
    ("DesignError", lambda: D().with_preset("")),
    ("TypeError", lambda: fabkit.build_kit("rtac0")),
    ("TypeError", lambda: fabkit.build_kit(D(), chord_tolerance_mm="x")),
    ("ValueError", lambda: fabkit.build_kit(D(), chord_tolerance_mm=0)),
    ("ValueError", lambda: fabkit.build_kit(D(), chord_tolerance_mm=math.nan)),
    ("ValueError", lambda: fabkit.build_kit(D(), chord_tolerance_mm=-math.inf)),
    ("ValueError", lambda: fabkit.build_kit(D(), max_triangles=0)),
    ("ValueError", lambda: fabkit.build_kit(D(), max_triangles=10**30)),
    ("OverflowError", lambda: fabkit.build_kit(D(), max_triangles=10**50)),
    ("DesignError", lambda: fabkit.build_kit(D(), max_triangles=1)),
    ("DesignError", lambda: fabkit.build_kit(setting("body.radius_mm", 1e6))),
    ("DesignError", lambda: fabkit.build_kit(setting("body.radius_mm", 1e-6))),
    ("DesignError", lambda: fabkit.build_kit(setting("body.radius_mm", 0))),
    ("DesignError", lambda: fabkit.build_kit(setting("layers[0].outer_radius_mm", 0.0))),
    ("DesignError", lambda: fabkit.build_kit(setting("mold.vent.count", 10**9))),
    ("DesignError", lambda: fabkit.build_kit(setting("layers", []))),
    ("TypeError", lambda: fabkit.build_fixtures(D(), params=42)),
    ("DesignError", lambda: fabkit.build_fixtures(D(), params={"pin_dome": 5})),
    ("ValueError", lambda: fabkit.build_fixtures(D(), params={"pin_dome": deep_dict})),
    ("DesignError", lambda: fabkit.build_fixtures(D(), params="/nonexistent.yaml")),
    ("DesignError", lambda: fabkit.build_fixtures(D(), params="/")),
    ("DesignError", lambda: fabkit.build_fixtures(D(), pins_preset="nope")),
    ("OverflowError", lambda: fabkit.build_fixtures(D(), semidomes=-1)),
    ("DesignError", lambda: fabkit.build_fixtures(D(), semidomes=10**6)),
    ("OverflowError", lambda: fabkit.build_fixtures(D(), seed=-1)),
    ("ValueError", lambda: fabkit.build_fixtures(D(), chord_tolerance_mm=0)),
    ("DesignError", lambda: fabkit.build_fixtures(D(), params={"pin_dome": {"rings": [{"polar_angle_deg": 179, "count": 100000}]}})),
    ("DesignError", lambda: fabkit.build_fixtures(D(), params={"pin_dome": {"rings": [{"polar_angle_deg": math.nan, "count": 3}]}})),
    ("ValueError", lambda: fabkit.build_kit(D()).export("/tmp/never", formats=["obj"])),
    ("TypeError", lambda: fabkit.build_kit(D()).export("/tmp/never", formats=[1])),
    ("ExportError", lambda: fabkit.build_kit(D()).export("/proc/version")),
    ("KeyError", lambda: fabkit.build_kit(D()).part("nope")),
    # a progress callback that is not callable or raises is reported, the build goes on
    (None, lambda: fabkit.build_kit(D(), progress=5)),
    (None, lambda: fabkit.build_kit(D(), progress=lambda *a: 1 / 0)),
    (None, lambda: fabkit.build_fixtures(D(), progress=lambda *a: 1 / 0)),
]
failures = []
for i, (expected, call) in enumerate(cases):
    try:
        call()
    except BaseException as e:  # PanicException derives from BaseException
        got = type(e).__name__
        if got != expected or type(e).__module__ == "pyo3_runtime" or isinstance(e, fabkit.InternalError):
            failures.append(f"case {i}: expected {expected}, got {type(e).__module__}.{got}: {e}"[:300])
    else:
        if expected is not None:
            failures.append(f"case {i}: expected {expected}, nothing raised")
print(f"{len(cases)} cases")
for f in failures:
    print("FAIL", f)
sys.exit(0)
'''


def test_bad_calls_never_panic_or_crash(tmp_path):
    """A batch of bad calls in a fresh interpreter: each raises the expected Python exception
    (never pyo3_runtime.PanicException or fabkit.InternalError), and the interpreter exits
    normally (no signal, no abort)."""
    env = dict(os.environ)
    p = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(BATCH)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
        env=env,
    )
    assert p.returncode == 0, f"interpreter died (returncode {p.returncode}):\n{p.stdout}\n{p.stderr[-3000:]}"
    fails = [l for l in p.stdout.split("\n") if l.startswith("FAIL")]
    assert not fails, "\n".join(fails)
    assert " cases" in p.stdout
    assert "PanicException" not in p.stderr
    # the raising callbacks were reported as unraisable, not swallowed silently
    assert "ZeroDivisionError" in p.stderr
