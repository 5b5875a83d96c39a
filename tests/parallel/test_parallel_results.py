"""A parallel run gives the serial run's table, bit for bit (issue 13): compare, generalize,
select and pl-search on two forked worker processes (the default local executor) and on a real
two-process Dask cluster, and ``--scheduler`` and ``--workers 2`` on the CLI.

Only the fits' own wall times (``fit_seconds``, ``seconds``) may differ.
"""

from __future__ import annotations

import json

from hystkit.cli._main import main
from hystkit.compensation import DEFAULT_CENTER
from hystkit.models.pl import structural_search
from hystkit.parallel import open_executor
from hystkit.studies import (
    Candidate,
    compare_models,
    generalization_matrix,
    select_model,
)

TIMES = {"fit_seconds", "seconds"}


def _untimed(tree):
    """`tree` without its wall-clock entries; everything else exactly as it was."""
    if isinstance(tree, dict):
        return {k: _untimed(v) for k, v in tree.items() if k not in TIMES}
    if isinstance(tree, list | tuple):
        return [_untimed(v) for v in tree]
    return tree




def test_compare_in_parallel_equals_the_serial_run(parallel_executor, short_pair):
    models, sizes = ["mpl", "pi", "bobbio"], {"mpl": 1}
    serial = compare_models(*short_pair, models, sizes)
    parallel = compare_models(*short_pair, models, sizes, executor=parallel_executor)
    assert list(parallel) == models
    assert _untimed(parallel) == _untimed(serial)
    assert all("error" not in row for row in serial.values())


def test_generalize_in_parallel_equals_the_serial_run(parallel_executor, short_pair):
    fit, val = short_pair
    train, test = {"a": fit, "b": val}, {"b": val, "a": fit}
    serial = generalization_matrix(train, test, ["mpl", "pi"], {"mpl": 1})
    parallel = generalization_matrix(train, test, ["mpl", "pi"], {"mpl": 1},
                                     executor=parallel_executor)
    assert json.dumps(parallel) == json.dumps(serial)  # values and the order of every key
    assert serial["mpl"]["r2"]["a"]["b"] is not None


def test_select_in_parallel_equals_the_serial_run(parallel_executor, short_pair):
    # fast candidates; an mPL of 0 cells fails in every fold: an error row
    cands = [Candidate("mpl", 1, mode, DEFAULT_CENTER) for mode in ("direct", "inverse")]
    cands += [Candidate("bobbio", 10, "direct", DEFAULT_CENTER),
              Candidate("mpl", 0, "direct", DEFAULT_CENTER)]
    serial = select_model([short_pair[0]], cands)
    parallel = select_model([short_pair[0]], cands, executor=parallel_executor)
    assert _untimed(parallel["ranking"]) == _untimed(serial["ranking"])
    assert parallel["winner"]["candidate"] == serial["winner"]["candidate"]
    assert parallel["compensator"].params == serial["compensator"].params
    assert len(serial["ranking"]) == len(cands)
    assert [r["candidate"] for r in serial["ranking"] if "error" in r] == ["mpl:0:direct:fit"]


def test_pl_search_in_parallel_equals_the_serial_run(parallel_executor, short_pair):
    rec = short_pair[0]
    grid = {"n": (1, 2), "p": (5.0,), "m": (1, 2), "s": (0.001,)}
    serial = structural_search(rec.position, rec.sensor, rec.dt, grid)
    parallel = structural_search(rec.position, rec.sensor, rec.dt, grid,
                                 executor=parallel_executor)
    assert [(r["n_cells"], r["n_basis"]) for r in parallel] == [(1, 1), (1, 2), (2, 1), (2, 2)]
    assert _untimed(parallel) == _untimed(serial)


def test_compare_cli_with_scheduler_writes_the_serial_table(cluster_address, short_pair,
                                                            tmp_path, capsys):
    from hystkit.io import write_recording

    paths = [write_recording(rec, tmp_path / f"{k}.csv") for k, rec in zip("fv", short_pair)]
    args = ["compare", *map(str, paths), "--models", "pi,mpl", "--size", "mpl=1"]
    assert main([*args, "--workers", "1", "--out", str(tmp_path / "serial")]) == 0
    assert main([*args, "--scheduler", cluster_address, "--out", str(tmp_path / "dask")]) == 0
    assert f"4 pieces of work on 2 Dask workers ({cluster_address})" in capsys.readouterr().out
    tables = [json.loads((tmp_path / name / "compare.json").read_text())
              for name in ("serial", "dask")]
    assert list(tables[1]) == ["pi", "mpl"]
    assert _untimed(tables[1]) == _untimed(tables[0])
    assert main([*args, "--workers", "2", "--out", str(tmp_path / "forked")]) == 0
    assert "4 pieces of work on 2 Dask workers (local, forked processes)" in \
        capsys.readouterr().out
    forked = json.loads((tmp_path / "forked" / "compare.json").read_text())
    assert _untimed(forked) == _untimed(tables[0])


def test_workers_and_scheduler_exclude_each_other(capsys):
    assert main(["compare", "a.csv", "b.csv", "--workers", "2", "--scheduler", "x"]) == 2
    assert "not allowed with argument" in capsys.readouterr().err


def test_batch_on_the_cluster_equals_the_serial_run(cluster_address, short_pair, tmp_path):
    from hystkit.batch import read_manifest, run_batch
    from hystkit.io import write_recording

    for name, rec in zip(("a", "b"), short_pair):
        write_recording(rec, tmp_path / f"{name}.csv")
    (tmp_path / "m.csv").write_text("sensor,fit,validate,size\nab,a.csv,b.csv,1\n"
                                    "ba,b.csv,a.csv,1\nbroken,missing.csv,a.csv,1\n")
    jobs = read_manifest(tmp_path / "m.csv", {})
    serial = run_batch(jobs, tmp_path / "serial")
    with open_executor(scheduler=cluster_address) as executor:
        parallel = run_batch(jobs, tmp_path / "dask", executor=executor)
    assert [r["status"] for r in parallel] == ["ok", "ok", "failed"]
    assert _untimed(parallel) == _untimed(serial)
