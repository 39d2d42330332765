"""Overhead of the Python call against the library call for one kit build.

    PYTHONPATH=$(scripts/build-python) .venv-oracles/bin/python python/benches/build_overhead.py [DESIGN] [ROUNDS]

Builds DESIGN's kit (default rtac0, 0.01 mm chord tolerance) ROUNDS times (default 30) each way,
interleaved so that both see the same machine state: `fabkit.build_kit(design)` timed around the
Python call (argument conversion, GIL release, the result wrapped as a Kit), and the same library
call (`fabkit_designs::build_kit_bounded`) timed inside Rust (`fabkit._fabkit._library_build_seconds`).
Prints the median and interquartile range of each and the overhead of the medians. Use a release
build (`maturin build --release`) for figures to publish; the quick profile of scripts/build-python
differs only in debug information.
"""

import statistics
import sys
import time

import fabkit
from fabkit import _fabkit


def quartiles(xs):
    q = statistics.quantiles(xs, n=4)
    return q[0], q[2]


def main():
    name = sys.argv[1] if len(sys.argv) > 1 else "rtac0"
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 30
    design = fabkit.Design.load(name)
    fabkit.build_kit(design)  # warm-up: materials table, allocator, caches
    python_s, library_s = [], []
    for _ in range(rounds):
        t0 = time.perf_counter()
        kit = fabkit.build_kit(design)
        python_s.append(time.perf_counter() - t0)
        del kit
        library_s.extend(_fabkit._library_build_seconds(design, 1))
    mp, ml = statistics.median(python_s), statistics.median(library_s)
    (p1, p3), (l1, l3) = quartiles(python_s), quartiles(library_s)
    print(f"{name}: {rounds} builds each way")
    print(f"  python call   median {mp * 1e3:8.2f} ms  (IQR {p1 * 1e3:.2f} .. {p3 * 1e3:.2f})")
    print(f"  library call  median {ml * 1e3:8.2f} ms  (IQR {l1 * 1e3:.2f} .. {l3 * 1e3:.2f})")
    print(f"  overhead of the python call: {(mp / ml - 1) * 100:+.2f} % of the library call")


if __name__ == "__main__":
    main()
