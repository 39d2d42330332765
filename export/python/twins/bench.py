#!/usr/bin/env python3
"""Time the CadQuery twin of a whole export: build every part's exact solid from the manifest
and write its STEP file (the work `fabkit export --format step` adds), best of N runs.

Usage: python export/python/twins/bench.py EXPORT_DIR [--repeat N]   (from any directory); prints JSON
{"design", "parts", "build_s_best", "step_s_best", "total_s_best", "runs": [...]}.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("export", type=Path)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    from twins import cq_common, cq_twin
    from twins.step_export import write_step
    cq_common.PARALLEL = True  # as the STEP export runs them
    man = json.loads((args.export / "manifest.json").read_text())
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeat):
            cq_common._SPLINES.clear()
            t0 = time.perf_counter()
            shapes = [(p["name"], cq_twin.build(p)) for p in man["parts"]]
            t1 = time.perf_counter()
            for name, s in shapes:
                write_step(s, Path(tmp) / f"{name}.step", name)
            t2 = time.perf_counter()
            runs.append({"build_s": t1 - t0, "step_s": t2 - t1, "total_s": t2 - t0})
    best = min(runs, key=lambda r: r["total_s"])
    json.dump({"design": man["design"]["name"], "parts": len(man["parts"]),
               "build_s_best": best["build_s"], "step_s_best": best["step_s"],
               "total_s_best": best["total_s"], "runs": runs}, sys.stdout)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
