"""Design sweeps from Python: ``fabkit.sweep(design, variants, executor=...)``.

The same variants give the same results table as ``fabkit sweep``: the checks, the variant ids,
the build and measurement of each variant and the table are fabkit's sweep code; only where each
variant runs is Python's choice. Without an executor the variants are built on threads in this
process (the GIL released); with one, each variant is a task of
``executor.submit(fn, *args)``: a ``concurrent.futures.ProcessPoolExecutor`` on one machine, a
``dask.distributed.Client`` on a cluster (the same futures interface), or any other
``concurrent.futures.Executor``. A task carries only text (the base design's JSON form and the
variant's values) and returns text (its results.jsonl line), so it pickles anywhere fabkit is
installed.
"""

from __future__ import annotations

import csv
import io
import os
import queue
import sys
from concurrent.futures import ProcessPoolExecutor
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional

from . import _fabkit

__all__ = ["sweep", "SweepTables"]

Progress = Callable[[int, int, str], Any]


class SweepTables:
    """The results of a sweep as ``fabkit sweep`` writes them: ``csv`` (results.csv) and
    ``jsonl`` (results.jsonl), text; ``parameters``, the varied paths (the table's parameter
    columns)."""

    def __init__(self, parameters: List[str], csv_text: str, jsonl_text: str):
        self.parameters = parameters
        self.csv = csv_text
        self.jsonl = jsonl_text

    def records(self) -> List[Dict[str, Any]]:
        """One dict per variant in variant order, keyed by results.csv's header: numbers as int
        or float, empty cells as None, the rest as text."""
        return [{k: _cell(v) for k, v in row.items()} for row in csv.DictReader(io.StringIO(self.csv))]

    def dataframe(self):
        """results.csv as a pandas DataFrame (``pandas.read_csv`` of the same text)."""
        import pandas

        return pandas.read_csv(io.StringIO(self.csv))


def _cell(text: str):
    if text == "":
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def _evaluate(base_json: str, chord_tolerance_mm: float, max_triangles: int, index: int,
              variant_id: str, params_json: str, files: Optional[dict] = None) -> str:
    """One variant, in whatever process runs it: its results.jsonl line (and its files, when
    ``files`` holds outputs, out, source and command_line)."""
    return _fabkit._sweep_evaluate(base_json, chord_tolerance_mm, max_triangles, index,
                                   variant_id, params_json, **(files or {}))


def _check_start_method(executor) -> None:
    """A ProcessPoolExecutor that forks its workers would hang: refused before any task."""
    if not isinstance(executor, ProcessPoolExecutor):
        return
    context = getattr(executor, "_mp_context", None)
    method = context.get_start_method() if context is not None else None
    if method == "fork":
        raise ValueError(
            "executor: a ProcessPoolExecutor that starts its workers with 'fork' would hang "
            "(a forked child inherits fabkit's thread pool without its threads); use "
            "ProcessPoolExecutor(n, mp_context=multiprocessing.get_context(\"spawn\")) "
            "or \"forkserver\"")


def sweep(
    design,
    variants: Iterable[Mapping[str, Any]],
    *,
    executor=None,
    jobs: Optional[int] = None,
    chord_tolerance_mm: float = 0.01,
    max_triangles: int = 4_000_000,
    build_time: bool = True,
    progress: Optional[Progress] = None,
    table: str = "auto",
    outputs: Iterable[str] = ("metrics",),
    out=None,
):
    """Builds and measures every variant of ``design`` and returns the results table of
    ``fabkit sweep``.

    ``variants``: any iterable of dicts ``{parameter path: value}`` (the paths of sweep files
    and presets, short paths included; values as a sweep file's: numbers, text, booleans,
    lists). Variant ``i`` is the design with its values set; variants may set different
    parameters (a cell is empty where a variant does not set its column).

    ``executor``: None builds the variants on ``jobs`` threads here (default: one per CPU);
    otherwise a ``concurrent.futures.Executor`` or anything with its ``submit`` (a
    ``dask.distributed.Client``), one task per variant. A ProcessPoolExecutor must start its
    workers with ``spawn`` or ``forkserver``
    (``mp_context=multiprocessing.get_context("spawn")``): a child forked from a process whose
    fabkit threads have run inherits their pool without its threads and would wait forever, so
    one that forks (Linux's default before Python 3.14) raises ValueError.
    ``progress(done, total, variant_id)`` is called as variants finish. ``build_time``: False leaves the build_time_s cells empty,
    as ``fabkit sweep --no-build-time`` (tables equal on any machine and executor).

    ``table``: ``"auto"`` returns a pandas DataFrame if pandas is installed, else
    ``"records"``: a list of dicts (one per variant, keyed by results.csv's header: index, id,
    the parameters, status, part/cast/marker metrics, min_wall_mm, triangles,
    printable.<printer>, build_time_s, errors); ``"pandas"``; ``"tables"``: a SweepTables with
    the exact text of results.csv and results.jsonl.

    ``outputs``: as a sweep file's: ``["metrics"]``, or ``["metrics", "files"]`` (``stl`` or
    ``3mf`` for one format) to also write each ok variant's files of ``fabkit export`` into
    ``out/<id>/`` (``out`` a folder path, created if missing; an earlier export of the same
    variant there is replaced, anything else refused and the variant recorded as an error).
    The files are written by whichever process builds the variant: with an executor on
    other machines, ``out`` must be a shared folder.

    A variant that breaks the design's rules is a row with status ``infeasible`` and its
    violations; a failed build, status ``error``. Raises DesignError with the message of
    ``fabkit sweep`` for an unknown path or a value of the wrong type (``variants[3]:
    vary.<path> = <value>: <rule>``) or a non-finite number, before anything is built;
    ValueError for a bad option or a ProcessPoolExecutor that forks.
    """
    if table not in ("auto", "records", "pandas", "tables"):
        raise ValueError(f"table: '{table}' is not one of auto, records, pandas, tables")
    outputs = [outputs] if isinstance(outputs, str) else list(outputs)
    out = None if out is None else os.fspath(out)
    _fabkit._sweep_check_outputs(outputs, out)
    files = None
    if outputs != ["metrics"]:
        files = {"outputs": outputs, "out": out, "source": design.source,
                 "command_line": list(sys.argv)}
    _check_start_method(executor)
    parameters, planned = _fabkit._sweep_plan(design, variants, chord_tolerance_mm)
    base = _fabkit._sweep_base(design)
    total = len(planned)
    if executor is None:
        n = jobs if jobs is not None else (os.cpu_count() or 1)
        if not (isinstance(n, int) and 1 <= n <= 4 * (os.cpu_count() or 1)):
            raise ValueError(
                f"jobs = {n}: must be from 1 to {4 * (os.cpu_count() or 1)} "
                f"(4 x the {os.cpu_count() or 1} CPUs of this machine)")
        results = _fabkit._sweep_run_threads(base, chord_tolerance_mm, max_triangles, planned,
                                             n, progress, **(files or {}))
    else:
        # completion through add_done_callback, which concurrent.futures and dask.distributed
        # futures both have (their as_completed functions take only their own futures)
        finished: "queue.Queue[int]" = queue.Queue()
        futures = []
        for index, variant_id, params in planned:
            f = executor.submit(_evaluate, base, chord_tolerance_mm, max_triangles, index,
                                variant_id, params, files)
            f.add_done_callback(lambda _, i=index: finished.put(i))
            futures.append(f)
        for done in range(1, total + 1):
            index = finished.get()
            if progress is not None:
                progress(done, total, planned[index][1])
        results = [f.result() for f in futures]
    csv_text, jsonl_text = _fabkit._sweep_tables(parameters, results, build_time)
    tables = SweepTables(parameters, csv_text, jsonl_text)
    if table == "tables":
        return tables
    if table == "pandas":
        return tables.dataframe()
    if table == "auto":
        try:
            import pandas  # noqa: F401
        except ImportError:
            return tables.records()
        return tables.dataframe()
    return tables.records()
