#!/usr/bin/env python3
"""Read back the STEP files of a `fabkit export --format step` (CadQuery import) and check each
against the exact solid (issue 7).

Usage: python export/python/twins/check_step.py EXPORT_DIR [EXPORT_DIR ...]
       [--exact-json TWINS.json]   (from any directory; one CadQuery start for every export folder)

Per part with a `step_file` in manifest.json (and per machined part, against its `exact`
shape): the file imports into CadQuery as a valid shape
with as many solids as the exact twin, and its volume equals the exact twin's within 1e-6
relative (the same B-rep written and read back). The exact volumes come from `--exact-json`
(the rows check_twins.py wrote in the same run) or, without it, from the twins built here.
Prints a line per part and, per folder, `check_step: DIR: N passed, M failed`.
Exit status 0 when every part of every folder passes, 1 otherwise, 2 on unreadable input.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("exports", type=Path, nargs="+")
    ap.add_argument("--exact-json", type=Path)
    args = ap.parse_args(argv)
    rows = json.loads(args.exact_json.read_text()) if args.exact_json else []
    status = 0
    for export in args.exports:
        status = max(status, check_export(export, rows))
    return status


def check_export(export: Path, rows: list[dict]) -> int:
    import cadquery as cq
    from twins import compare as K
    from twins import cq_common, cq_twin
    try:
        man = json.loads((export / "manifest.json").read_text())
    except (OSError, ValueError) as e:
        print(f"check_step: {e}", file=sys.stderr)
        return 2
    exact = {}
    for r in rows:
        if r.get("volume_exact_mm3") is not None and r["design"] == export.name:
            exact[r["part"]] = r["volume_exact_mm3"]
    bad = 0
    for part in man["parts"]:
        name = part["name"]
        if not part.get("step_file"):
            print(f"FAIL {name}: no step_file in the manifest")
            bad += 1
            continue
        shape = cq.importers.importStep(str(export / part["step_file"])).val()
        ok_shape = shape.isValid()
        v_step = cq_common.exact_volume(shape)
        if name in exact:
            v_exact, n_exact = exact[name], None
        else:
            twin = cq_twin.build(part)
            v_exact, n_exact = cq_common.exact_volume(twin), K._solids(twin)
        n_step = K._solids(shape)
        rel = abs(v_step - v_exact) / abs(v_exact)
        ok = ok_shape and rel <= 1e-6 and n_step >= 1 and (n_exact is None or n_step == n_exact)
        bad += not ok
        print(f"{'PASS' if ok else 'FAIL'} {name}: STEP volume {v_step:.6f} mm3 vs exact "
              f"{v_exact:.6f} (rel {rel:.1e}), {n_step} solid(s), valid {ok_shape}", flush=True)
    from twins import step_export
    machined = man.get("machined_parts", [])
    for mp in machined:
        # a part made to order: its STEP file against the exact shape the manifest gives
        name = mp["name"]
        if not mp.get("step_file"):
            print(f"FAIL {name}: no step_file in the manifest")
            bad += 1
            continue
        shape = cq.importers.importStep(str(export / mp["step_file"])).val()
        ok_shape = shape.isValid()
        v_step = cq_common.exact_volume(shape)
        v_exact = cq_common.exact_volume(step_export.exact_member(mp["exact"]))
        rel = abs(v_step - v_exact) / abs(v_exact)
        ok = ok_shape and rel <= 1e-6 and K._solids(shape) == 1
        bad += not ok
        print(f"{'PASS' if ok else 'FAIL'} {name} (machined): STEP volume {v_step:.6f} mm3 vs "
              f"exact {v_exact:.6f} (rel {rel:.1e}), valid {ok_shape}", flush=True)
    total = len(man["parts"]) + len(machined)
    print(f"check_step: {export.name}: {total - bad} passed, {bad} failed")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
