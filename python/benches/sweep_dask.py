"""A Dask sweep against `fabkit sweep --jobs 2`: 100 ShadowTac variants on 2 workers.

    PYTHONPATH=$(scripts/build-python) .venv-oracles/bin/python python/benches/sweep_dask.py \
        [FABKIT_BIN] [ROUNDS]

The variants are those of scripts/bench-sweep: the ShadowTac dimple mold (library design
shadowtac, preset paper_text) at the default 0.01 mm chord tolerance, metrics only, spacing_mm
1.3..2.2 step 0.1 x dimple height_mm 0.30..0.75 step 0.05 (10 x 10).

- CLI: `FABKIT_BIN sweep sweep.yaml --jobs 2 --no-build-time --out <fresh folder>`, the whole
  process timed (start, design checks, 100 variants, tables, variants/<id>.json files).
- Dask: `fabkit.sweep(design, variants, executor=client, build_time=False, table="tables")` on
  a `dask.distributed.LocalCluster(n_workers=2, threads_per_worker=1)`, the call timed (the
  variant checks, 100 tasks, the tables). The cluster is started once, before the rounds, and
  each worker imports fabkit first: a cluster is started once for many sweeps. Its start-up
  time is printed on its own.

The two are run ROUNDS times (default 3) interleaved, so that both see the same machine state;
prints each round, the median of each, their ratio, and whether both gave the same results.csv.
FABKIT_BIN (default target/quick/fabkit) should be built in the same profile as the package
(scripts/build-python builds `quick`, the release code without debug information).
"""

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import fabkit

SPACING_PATH = "layers[0].markers[0].pattern.spacing_mm"
HEIGHT_PATH = "layers[0].markers[0].feature.height_mm"
SPACINGS = [round(1.3 + 0.1 * i, 1) for i in range(10)]
HEIGHTS = [round(0.30 + 0.05 * j, 2) for j in range(10)]


def sweep_file(folder: Path) -> Path:
    path = folder / "sweep.yaml"
    path.write_text(
        "base: shadowtac\n"
        "preset: paper_text\n"
        "vary:\n"
        f"  {SPACING_PATH}: {{range: [1.3, 2.2, 0.1]}}\n"
        f"  {HEIGHT_PATH}: {{range: [0.30, 0.75, 0.05]}}\n"
        "mode: grid\n"
        "outputs: [metrics]\n")
    return path


def run_cli(fabkit_bin: str, sweep: Path, out: Path) -> float:
    t0 = time.perf_counter()
    subprocess.run([fabkit_bin, "sweep", str(sweep), "--jobs", "2", "--no-build-time",
                    "--out", str(out)], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main():
    repo = Path(__file__).resolve().parents[2]
    fabkit_bin = sys.argv[1] if len(sys.argv) > 1 else str(repo / "target/quick/fabkit")
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    from dask.distributed import Client, LocalCluster

    design = fabkit.Design.load("shadowtac").with_preset("paper_text")
    # grid order: the first parameter varies slowest, as in the sweep file
    variants = [{SPACING_PATH: s, HEIGHT_PATH: h} for s in SPACINGS for h in HEIGHTS]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sweep = sweep_file(tmp)
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
        client.run(lambda: __import__("fabkit") and None)
        start_s = time.perf_counter() - t0
        cli_s, dask_s, same = [], [], True
        try:
            for r in range(rounds):
                out = tmp / f"cli_{r}"
                cli_s.append(run_cli(fabkit_bin, sweep, out))
                t0 = time.perf_counter()
                tables = fabkit.sweep(design, variants, executor=client, build_time=False,
                                      table="tables")
                dask_s.append(time.perf_counter() - t0)
                same &= tables.csv == (out / "results.csv").read_text()
                print(f"round {r + 1}: fabkit sweep --jobs 2 {cli_s[-1]:6.1f} s, "
                      f"Dask (2 workers) {dask_s[-1]:6.1f} s", flush=True)
        finally:
            client.close()
            cluster.close()
    mc, md = statistics.median(cli_s), statistics.median(dask_s)
    print(f"machine: {os.cpu_count()} CPUs, load average after: "
          f"{' '.join(Path('/proc/loadavg').read_text().split()[:3])}")
    print(f"LocalCluster start (2 worker processes, fabkit imported): {start_s:.1f} s")
    print(f"median of {rounds}: fabkit sweep --jobs 2 {mc:.1f} s ({100 / mc:.2f} variants/s), "
          f"Dask {md:.1f} s ({100 / md:.2f} variants/s); Dask / CLI = {md / mc:.2f}")
    print(f"results.csv of both: {'identical' if same else 'DIFFERENT'}")
    sys.exit(0 if same else 1)


if __name__ == "__main__":
    main()
