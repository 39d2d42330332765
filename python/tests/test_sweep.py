"""fabkit.sweep against `fabkit sweep`: the same variants give the same results.csv, byte for
byte, on threads, on a process pool and on a Dask LocalCluster with 2 worker processes; bad
variants raise the CLI's message (parameter path, value, rule)."""

import csv
import io
import multiprocessing
from concurrent.futures import ProcessPoolExecutor

import pytest

import fabkit
from conftest import cli_message

SWEEP = """base: rtac0
vary:
  mold.wall_thickness_mm: [3.0, 4.0]
  core.wall_thickness_mm: [1.0, 1.2, -0.5]
"""


@pytest.fixture(scope="module")
def cli_sweep(tmp_path_factory, run_cli):
    d = tmp_path_factory.mktemp("sweep")
    (d / "s.yaml").write_text(SWEEP)
    run_cli(d, "sweep", "s.yaml", "--out", "out", "--no-build-time", "--jobs", "2")
    text = (d / "out" / "results.csv").read_text()
    rows = list(csv.DictReader(io.StringIO(text)))
    params = ["mold.wall_thickness_mm", "core.wall_thickness_mm"]
    variants = [{p: float(r[p]) for p in params} for r in rows]
    return {"csv": text, "jsonl": (d / "out" / "results.jsonl").read_text(), "rows": rows,
            "variants": variants, "dir": d}


def test_the_cli_sweep_has_ok_and_infeasible_rows(cli_sweep):
    statuses = [r["status"] for r in cli_sweep["rows"]]
    assert len(statuses) == 6 and "ok" in statuses and "infeasible" in statuses


def test_threads_give_the_cli_tables(cli_sweep):
    seen = []
    t = fabkit.sweep(fabkit.Design.load("rtac0"), cli_sweep["variants"], jobs=2, build_time=False,
                     table="tables", progress=lambda d, n, i: seen.append((d, n, i)))
    assert t.csv == cli_sweep["csv"]
    assert t.jsonl == cli_sweep["jsonl"]
    assert sorted(d for d, _, _ in seen) == list(range(1, 7)) and {n for _, n, _ in seen} == {6}
    assert {i for _, _, i in seen} == {r["id"] for r in cli_sweep["rows"]}


def test_records_and_dataframe_are_the_cli_rows(cli_sweep):
    import pandas

    design = fabkit.Design.load("rtac0")
    records = fabkit.sweep(design, cli_sweep["variants"], build_time=False, table="records")
    assert len(records) == len(cli_sweep["rows"])
    for got, want in zip(records, cli_sweep["rows"]):
        assert list(got) == list(want)
        for k, v in want.items():
            assert got[k] == (None if v == "" else type(got[k])(v)), k
    frame = fabkit.sweep(design, cli_sweep["variants"], build_time=False)
    pandas.testing.assert_frame_equal(
        frame, pandas.read_csv(cli_sweep["dir"] / "out" / "results.csv"))


def test_a_process_pool_gives_the_cli_tables(cli_sweep):
    # spawn: a forked child of a process whose fabkit threads already ran would wait forever
    # on the thread pool it inherited without its threads
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        t = fabkit.sweep(fabkit.Design.load("rtac0"), iter(cli_sweep["variants"]),
                         executor=pool, build_time=False, table="tables")
    assert t.csv == cli_sweep["csv"]
    assert t.jsonl == cli_sweep["jsonl"]


def test_a_dask_local_cluster_gives_the_cli_tables(cli_sweep):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        seen = []
        t = fabkit.sweep(fabkit.Design.load("rtac0"), cli_sweep["variants"], executor=client,
                         build_time=False, table="tables",
                         progress=lambda d, n, i: seen.append(d))
        workers = client.run(lambda: __import__("os").getpid())
    assert len(workers) == 2
    assert t.csv == cli_sweep["csv"]
    assert seen == list(range(1, 7))


@pytest.mark.parametrize("vary, variant", [
    ("core.wall_thicknes_mm: [1.0, 1.2]", {"core.wall_thicknes_mm": 1.0}),
    ('core.wall_thickness_mm: [1.0, "thick"]', {"core.wall_thickness_mm": "thick"}),
])
def test_a_bad_variant_raises_the_cli_message(tmp_path, run_cli, vary, variant):
    (tmp_path / "bad.yaml").write_text(f"base: rtac0\nvary:\n  {vary}\n")
    cli = cli_message(run_cli(tmp_path, "sweep", "bad.yaml", "--out", "o", ok=False).stderr)
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.sweep(fabkit.Design.load("rtac0"), [{"core.wall_thickness_mm": 1.1}, variant])
    got = str(e.value)
    # the same message after the location: bad.yaml:L:C in the file, variants[1] here
    assert got.startswith("variants[1]: ")
    assert got.split(": ", 1)[1] == cli.split(": ", 1)[1]
    assert not (tmp_path / "o" / "results.csv").exists()


def test_a_nan_names_the_path_value_and_rule():
    with pytest.raises(fabkit.DesignError) as e:
        fabkit.sweep(fabkit.Design.load("rtac0"), [{"core.wall_thickness_mm": float("nan")}])
    assert str(e.value) == "variants[0]: vary.core.wall_thickness_mm = nan: must be a finite number"


def test_bad_calls():
    d = fabkit.Design.load("rtac0")
    with pytest.raises(TypeError, match=r"variants\[0\]: a variant is a dict"):
        fabkit.sweep(d, [3])
    with pytest.raises(fabkit.DesignError, match="no variants"):
        fabkit.sweep(d, [])
    with pytest.raises(fabkit.DesignError, match="resolve to the same design"):
        fabkit.sweep(d, [{"core.wall_thickness_mm": 1.1}, {"core.wall_thickness_mm": 1.1}])
    with pytest.raises(ValueError, match="jobs = 0"):
        fabkit.sweep(d, [{"core.wall_thickness_mm": 1.1}], jobs=0)
    with pytest.raises(ValueError, match="table"):
        fabkit.sweep(d, [{"core.wall_thickness_mm": 1.1}], table="xlsx")


def test_a_forking_process_pool_is_refused_before_any_task():
    # a forked worker would inherit fabkit's thread pool without its threads and hang
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as pool:
        with pytest.raises(ValueError, match="'fork' would hang.*spawn"):
            fabkit.sweep(fabkit.Design.load("rtac0"), [{"core.wall_thickness_mm": 1.1}],
                         executor=pool)
        assert not pool._processes  # no worker was started


def test_files_are_the_cli_variant_exports(tmp_path, run_cli):
    """outputs with files write each ok variant's export as `fabkit sweep` does
    (variants/<id>/ there, out/<id>/ here): the same STL bytes, the same design hash, and the
    same results table; a variant the rules refuse writes nothing."""
    (tmp_path / "s.yaml").write_text(
        "base: rtac0\nvary:\n  core.wall_thickness_mm: [1.1, -0.5]\noutputs: [metrics, stl]\n")
    run_cli(tmp_path, "sweep", "s.yaml", "--out", "cli", "--no-build-time", "--jobs", "1")
    cli_csv = (tmp_path / "cli" / "results.csv").read_text()
    t = fabkit.sweep(fabkit.Design.load("rtac0"), [{"core.wall_thickness_mm": 1.1},
                                                  {"core.wall_thickness_mm": -0.5}],
                     build_time=False, table="tables", outputs=["metrics", "stl"],
                     out=tmp_path / "py")
    assert t.csv == cli_csv
    rows = list(csv.DictReader(io.StringIO(cli_csv)))
    ok = [r["id"] for r in rows if r["status"] == "ok"]
    assert len(ok) == 1 and len(rows) == 2
    assert sorted(p.name for p in (tmp_path / "py").iterdir()) == ok
    cli_dir, py_dir = tmp_path / "cli" / "variants" / ok[0], tmp_path / "py" / ok[0]
    stls = sorted(p.relative_to(cli_dir) for p in cli_dir.rglob("*.stl"))
    assert stls and stls == sorted(p.relative_to(py_dir) for p in py_dir.rglob("*.stl"))
    assert not list(py_dir.rglob("*.3mf"))
    for rel in stls:
        assert (py_dir / rel).read_bytes() == (cli_dir / rel).read_bytes(), rel
    import json
    m_cli = json.loads((cli_dir / "manifest.json").read_text())
    m_py = json.loads((py_dir / "manifest.json").read_text())
    assert m_py["design"]["sha256"] == m_cli["design"]["sha256"]
    assert "of fabkit.sweep" in m_py["design"]["source"]


def test_bad_outputs_are_refused_before_anything_is_built(tmp_path):
    d = fabkit.Design.load("rtac0")
    with pytest.raises(ValueError, match="needed for outputs"):
        fabkit.sweep(d, [{"core.wall_thickness_mm": 1.1}], outputs=["metrics", "files"])
    with pytest.raises(ValueError, match="'step' is not one of"):
        fabkit.sweep(d, [{"core.wall_thickness_mm": 1.1}], outputs=["metrics", "step"],
                     out=tmp_path)
    with pytest.raises(ValueError, match="must include metrics"):
        fabkit.sweep(d, [{"core.wall_thickness_mm": 1.1}], outputs=["files"], out=tmp_path)
    assert not list(tmp_path.iterdir())
