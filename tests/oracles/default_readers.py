"""fabkit's outputs in their users' default readers, with default arguments.

Usage: python default_readers.py SPEC.json

SPEC.json: {"csv": [{"path", "columns", "rows"}], "ply": [{"path", "range_npy"}],
"export": EXPORT_DIR or null}.

- CSV: pandas.read_csv(path), csv.DictReader and numpy.genfromtxt(path, names=True,
  delimiter=",", dtype=None, encoding=None) give the same header names and row count, equal to
  the expected ones (a leading `#` line makes genfromtxt take its names from the comment and
  pandas read the comment as the header).
- PLY: open3d.t.io.read_point_cloud keeps u, v (and contact) as point attributes, one per
  finite pixel of `range_npy` in row-major order, u the column and v the row.
- EXPORT_DIR (manifest.json): each STL's 80-byte header starts with `fabkit ` and ends in the
  unit word `mm`, naming the part (or a prefix of it cut with `~`); each STEP file's PRODUCT
  names are its part's name; assembly.step's are the design's and its members' names.

Prints one JSON line {"checked": n, "failures": [...]} and `default_readers: N checked, F
failed`; exits 1 on any failure.
"""

import csv
import json
import re
import sys
from pathlib import Path


def check_csv(spec: dict, fail) -> None:
    import numpy as np
    import pandas as pd

    path, columns, rows = spec["path"], spec["columns"], spec.get("rows")
    df = pd.read_csv(path)
    with open(path, newline="", encoding="utf-8") as f:
        r = csv.DictReader(f)
        dict_rows = list(r)
        dict_names = list(r.fieldnames or [])
    arr = np.genfromtxt(path, names=True, delimiter=",", dtype=None, encoding=None)
    np_names = list(arr.dtype.names or [])
    np_rows = 1 if arr.ndim == 0 else len(arr)
    if list(df.columns) != columns:
        fail(f"{path}: pandas columns {list(df.columns)} != {columns}")
    if dict_names != columns:
        fail(f"{path}: csv.DictReader columns {dict_names} != {columns}")
    if np_names != columns:
        fail(f"{path}: numpy.genfromtxt names {np_names} != {columns}")
    counts = {"pandas": len(df), "csv": len(dict_rows), "numpy": np_rows}
    if len(set(counts.values())) != 1:
        fail(f"{path}: row counts differ {counts}")
    if rows is not None and len(df) != rows:
        fail(f"{path}: {len(df)} rows, expected {rows}")
    if any(None in row or None in row.values() for row in dict_rows):
        fail(f"{path}: a row with more or fewer cells than the header")


def check_ply(spec: dict, fail) -> None:
    import numpy as np
    import open3d as o3d

    path = spec["path"]
    pc = o3d.t.io.read_point_cloud(path)
    r = np.load(spec["range_npy"])
    idx = np.flatnonzero(np.isfinite(r))
    w = r.shape[1]
    n = len(pc.point["positions"])
    if n != len(idx):
        fail(f"{path}: {n} points, {len(idx)} finite pixels")
        return
    for k, want in (("u", idx % w), ("v", idx // w)):
        if k not in pc.point:
            fail(f"{path}: open3d.t.io.read_point_cloud dropped {k}")
            continue
        got = pc.point[k].numpy().ravel()
        if not np.array_equal(got.astype(np.int64), want):
            fail(f"{path}: {k} differs from the pixel index")
    if "contact" not in pc.point:
        fail(f"{path}: open3d.t.io.read_point_cloud dropped contact")


def walk(v):
    if isinstance(v, dict):
        yield v
        for x in v.values():
            yield from walk(x)
    elif isinstance(v, list):
        for x in v:
            yield from walk(x)


def step_products(path: Path) -> list:
    text = path.read_text(encoding="latin-1")
    return re.findall(r"=\s*PRODUCT\s*\(\s*'((?:[^']|'')*)'", text)


def check_export(d: Path, fail) -> int:
    m = json.loads((d / "manifest.json").read_text())
    n = 0
    for e in walk(m):
        name = e.get("name")
        f = e.get("file")
        if isinstance(name, str) and isinstance(f, str) and f.endswith(".stl"):
            n += 1
            head = (d / f).read_bytes()[:80].decode("ascii").rstrip(" ")
            if not head.startswith("fabkit ") or not head.endswith(" mm"):
                fail(f"{f}: STL header {head!r} lacks fabkit ... mm")
            words = head.split(" ")
            cut = len(words) >= 4 and words[-3].endswith("~") and name.startswith(words[-3][:-1])
            if name not in words and not cut:
                fail(f"{f}: STL header {head!r} does not name {name}")
        sf = e.get("step_file")
        if isinstance(name, str) and isinstance(sf, str):
            n += 1
            got = step_products(d / sf)
            if got != [name]:
                fail(f"{sf}: STEP products {got} != [{name!r}]")
    a = m.get("assembly_step")
    if isinstance(a, dict):
        n += 1
        got = sorted(set(step_products(d / a["file"])))
        want = sorted({m["design"] if isinstance(m["design"], str) else m["design"]["name"]}
                      | {x["name"] for x in a["members"]})
        if got != want:
            fail(f"{a['file']}: STEP products {got} != {want}")
    return n


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    spec = json.loads(Path(argv[0]).read_text())
    failures = []
    checked = 0
    for c in spec.get("csv", []):
        try:
            check_csv(c, failures.append)
        except Exception as e:  # a reader refusing the file is a failure, not a crash
            failures.append(f"{c['path']}: {type(e).__name__}: {e}")
        checked += 1
    for p in spec.get("ply", []):
        try:
            check_ply(p, failures.append)
        except Exception as e:
            failures.append(f"{p['path']}: {type(e).__name__}: {e}")
        checked += 1
    if spec.get("export"):
        checked += check_export(Path(spec["export"]), failures.append)
    print(json.dumps({"checked": checked, "failures": failures}))
    print(f"default_readers: {checked} checked, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
