"""Type stubs of fabkit.sweep (see python/fabkit/sweep.py for the docstrings)."""

from concurrent.futures import Executor
from typing import Any, Callable, Dict, Iterable, List, Literal, Mapping, Optional, Union

from ._fabkit import Design

Progress = Callable[[int, int, str], Any]

class SweepTables:
    parameters: List[str]
    csv: str
    jsonl: str
    def records(self) -> List[Dict[str, Any]]: ...
    def dataframe(self) -> Any: ...

def sweep(
    design: Design,
    variants: Iterable[Mapping[str, Any]],
    *,
    executor: Optional[Union[Executor, Any]] = None,
    jobs: Optional[int] = None,
    chord_tolerance_mm: float = 0.01,
    max_triangles: int = 4_000_000,
    build_time: bool = True,
    progress: Optional[Progress] = None,
    table: Literal["auto", "records", "pandas", "tables"] = "auto",
) -> Union[List[Dict[str, Any]], Any, SweepTables]:
    """Variants: dicts {parameter path: value}. Returns results.csv's rows (pandas DataFrame
    when installed with table="auto", list of dicts with "records", SweepTables with "tables").
    Raises DesignError (the CLI's message for an unknown path, a wrong-typed or non-finite
    value), TypeError (a variant that is not a dict), ValueError (bad jobs or table, a
    ProcessPoolExecutor that forks its workers: use spawn or forkserver)."""
