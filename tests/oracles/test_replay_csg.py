#!/usr/bin/env python3
"""Self-test of replay_csg.py on the hand-made tree csg_selftest.json.

Usage: python tests/oracles/test_replay_csg.py   (with the oracle venv's python)

csg_selftest.json: leaf boxes A = [0,10]^3 and B = [5,15]x[5,15]x[-1,11]; its recorded volumes were
worked out by hand (A-B = 750, A^B = 250, A+B = 1950, ...). rotated_split (500) only comes out
right if the 3x4 matrix is read as p' = R p + t with R row-major and split_keep keeps the side the
normal points to. Prints one line per test and a last line `N passed, M failed`; exits 1 on failure.
"""

from __future__ import annotations

import copy
import json
import subprocess
import sys
import tempfile
import traceback
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPLAY = HERE / "replay_csg.py"
SELFTEST = HERE / "csg_selftest.json"


def run(path: Path, *extra: str) -> tuple[int, dict | None, str]:
    p = subprocess.run([sys.executable, str(REPLAY), str(path), "--json", *extra],
                       capture_output=True, text=True, timeout=300)
    try:
        res = json.loads(p.stdout) if p.stdout.strip() else None
    except ValueError:
        res = None
    return p.returncode, res, p.stderr


def expect(cond: bool, what: str) -> None:
    if not cond:
        raise AssertionError(what)


def mutated(tmp: Path, change) -> Path:
    doc = json.loads(SELFTEST.read_text())
    doc = copy.deepcopy(doc)
    change(doc)
    out = tmp / "csg.json"
    out.write_text(json.dumps(doc))
    return out


def test_selftest_file_is_small(_: Path) -> None:
    expect(SELFTEST.stat().st_size < 20_000, "csg_selftest.json must stay < 20 kB")


def test_selftest_passes(_: Path) -> None:
    rc, res, err = run(SELFTEST, "--repeat", "2")
    expect(rc == 0, f"exit {rc}: {err}")
    expect(len(res["seconds_runs"]) == 2 and res["seconds_best"] == min(res["seconds_runs"]),
           "timing")
    parts = {p["name"]: p for p in res["parts"]}
    for name, p in parts.items():
        expect(p["ok"] and p["status"] == "NoError", f"{name}: {p}")
        expect(p["volume_rel_diff"] < 1e-12, f"{name}: rel diff {p['volume_rel_diff']}")
    rot = parts["rotated"]["bbox_mm"]
    expect(rot["min"] == [20.0, 0.0, 0.0] and rot["max"] == [30.0, 10.0, 10.0], f"rotated {rot}")
    bottom = parts["bottom"]["bbox_mm"]
    expect(bottom["max"][2] == 4.0, f"bottom keeps the negative side: {bottom}")
    expect(parts["compose"]["genus"] == -1, "compose: two disjoint bodies (genus 1 - chi/2)")


def test_plain_output(_: Path) -> None:
    p = subprocess.run([sys.executable, str(REPLAY), str(SELFTEST), "--repeat", "1"],
                       capture_output=True, text=True, timeout=300)
    expect(p.returncode == 0, f"exit {p.returncode}: {p.stdout}{p.stderr}")
    lines = p.stdout.strip().splitlines()
    expect(lines[-1].startswith("seconds_best "), f"last line {lines[-1]!r}")
    expect(sum(ln.startswith("PASS ") for ln in lines) == 8, f"{lines}")


def test_wrong_recorded_volume_fails(tmp: Path) -> None:
    def change(doc):
        doc["parts"][2]["volume_mm3"] = 750.0  # rotated_split is 500: wrong matrix convention
    rc, res, _ = run(mutated(tmp, change), "--repeat", "1")
    expect(rc == 1, f"exit {rc}")
    failed = [p["name"] for p in res["parts"] if not p["ok"]]
    expect(failed == ["rotated_split"], f"failed {failed}")


def test_open_leaf_fails(tmp: Path) -> None:
    def change(doc):
        del doc["nodes"][1]["triangles"][3]
    rc, res, _ = run(mutated(tmp, change), "--repeat", "1")
    expect(rc == 1, f"exit {rc}")
    expect(res["bad_leaves"] == {"1": "NotManifold"}, f"bad leaves {res['bad_leaves']}")


def test_forward_child_reference_is_rejected(tmp: Path) -> None:
    def change(doc):
        doc["nodes"][2]["children"] = [0, 5]
    rc, _, err = run(mutated(tmp, change))
    expect(rc == 2, f"exit {rc}")
    expect("nodes[2].children" in err, f"stderr {err!r}")


def test_wrong_format_is_rejected(tmp: Path) -> None:
    def change(doc):
        doc["format"] = "fabkit-csg/2"
    rc, _, err = run(mutated(tmp, change))
    expect(rc == 2 and "format" in err, f"exit {rc}: {err!r}")


def main() -> int:
    tests = [(n, f) for n, f in globals().items() if n.startswith("test_") and callable(f)]
    passed = failed = 0
    for name, fn in tests:
        with tempfile.TemporaryDirectory(prefix="fabkit-replay-csg-") as d:
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
