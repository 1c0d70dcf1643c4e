"""Many problems at once: solve_many on executors (serial, threads, a two-worker local Dask
cluster) gives the serial loop's answers, writes its table as results arrive and resumes from
it; sweep over a parameter grid."""

from __future__ import annotations

import concurrent.futures as cf
import os

import numpy as np
import pytest

from frictionrules import (FrictionContactProblem, FrictionRulesError, SolveRecord, SweepPoint, solve,
                           solve_many, sweep, write_fclib)


def random_problem(seed: int, nc: int = 4) -> FrictionContactProblem:
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(3 * nc, 3 * nc))
    return FrictionContactProblem(A @ A.T + np.eye(3 * nc), rng.normal(size=3 * nc),
                                  rng.uniform(0.1, 0.9, nc), title=f"random{seed}")


@pytest.fixture
def folder(tmp_path):
    for k in range(5):
        write_fclib(tmp_path / f"p{k}.hdf5", random_problem(k, nc=3 + k))
    return tmp_path


def assert_same(records, serial):
    assert [r.name for r in records] == [r.name for r in serial]
    for a, b in zip(records, serial):
        np.testing.assert_array_equal(a.solution.r, b.solution.r)
        assert a.error == b.error and a.iterations == b.iterations and a.reason == b.reason


def test_serial_solve_many_is_the_loop_of_solve(folder):
    records = solve_many(folder, method="nsgs", tol=1e-10)
    assert all(isinstance(r, SolveRecord) and r.converged for r in records)
    from frictionrules import read_fclib
    for rec, path in zip(records, sorted(folder.glob("*.hdf5"))):
        s = solve(read_fclib(path), method="nsgs", tol=1e-10)
        np.testing.assert_array_equal(rec.solution.r, s.r)


def test_thread_pool_and_batches_give_the_serial_answers(folder):
    serial = solve_many(folder, method="admm", tol=1e-10)
    with cf.ThreadPoolExecutor(2) as ex:
        for batch_bytes in (0, 10**9):      # one problem per task, and all in one task
            assert_same(solve_many(folder, method="admm", tol=1e-10, executor=ex,
                                   batch_bytes=batch_bytes), serial)


def test_two_worker_local_dask_cluster_gives_the_serial_answers(folder):
    """The documented engine: a local Dask cluster of two worker processes."""
    from frictionrules.parallel import local_cluster
    paths = sorted(folder.glob("*.hdf5"))
    problems = [random_problem(10 + k) for k in range(3)]
    serial = solve_many([*paths, *problems], method="prox", tol=1e-10)
    with local_cluster(2) as client:
        parallel = solve_many([*paths, *problems], method="prox", tol=1e-10, executor=client, batch_bytes=0)
        assert_same(parallel, serial)
        points = sweep(_scaled_solve, {"scale": [1.0, 2.0], "seed": [3]}, executor=client)
    assert [p.parameters for p in points] == [{"scale": 1.0, "seed": 3}, {"scale": 2.0, "seed": 3}]
    assert points[1].value == pytest.approx(2.0 * points[0].value, rel=1e-8)


def _scaled_solve(scale, seed):
    """|r| of a random problem with q scaled: r scales with q (the law is homogeneous)."""
    p = random_problem(seed)
    return float(np.linalg.norm(solve(FrictionContactProblem(p.W, scale * p.q, p.mu_bar), tol=1e-12).r))


def test_table_written_as_results_arrive_and_resumed(folder, tmp_path):
    out = tmp_path / "table" / "t.csv"
    seen = []
    first = solve_many(sorted(folder.glob("*.hdf5"))[:3], method="nsgs", out=out, on_result=seen.append)
    assert len(seen) == 3 and len(data_lines(out)) == 4
    assert "# units: " in out.read_text() and "frictionrules" in out.read_text()   # provenance
    assert (out.stat().st_mode & 0o777) == 0o666 & ~_umask()
    again = solve_many(folder, method="nsgs", out=out)
    assert [r.resumed for r in again] == [True] * 3 + [False] * 2
    assert [r.error for r in again[:3]] == pytest.approx([r.error for r in first], rel=1e-6)
    assert len(data_lines(out)) == 6
    other = solve_many(folder, method="admm", out=tmp_path / "t2.csv")  # another method: solved
    assert not any(r.resumed for r in other)


def data_lines(path):
    return [line for line in path.read_text().splitlines() if not line.startswith("#")]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_bad_file_is_a_record_and_bad_arguments_raise(folder, tmp_path):
    (folder / "zz.hdf5").write_bytes(b"not hdf5")
    records = solve_many(folder, method="nsgs")
    assert records[-1].reason == "bad input" and records[-1].error is None and records[-1].message
    assert not records[-1].converged
    with pytest.raises(FrictionRulesError, match="method"):
        solve_many(folder, method="cg")
    with pytest.raises(FrictionRulesError, match="paths_or_problems"):
        solve_many([3.0])
    with pytest.raises(FrictionRulesError, match="executor"):
        solve_many(folder, executor="dask")
    (tmp_path / "empty").mkdir()
    with pytest.raises(FrictionRulesError, match="no \\*.hdf5"):
        solve_many(tmp_path / "empty")


def test_saved_solutions_warm_start_the_next_run(folder, tmp_path):
    first = solve_many(folder, method="nsgs", tol=1e-12, save_solutions=tmp_path / "sols")
    again = solve_many(folder, method="nsgs", tol=1e-12, warm_start=tmp_path / "sols")
    assert all(b.iterations <= 1 for b in again)
    assert [b.error <= 1e-12 for b in again] == [a.converged for a in first]


def test_sweep_grid_order_and_executor():
    grid = {"a": [1, 2], "b": [10, 20, 30]}
    serial = sweep(_product, grid)
    assert [p.parameters for p in serial][:2] == [{"a": 1, "b": 10}, {"a": 1, "b": 20}]
    assert [p.value for p in serial] == [10, 20, 30, 20, 40, 60]
    with cf.ThreadPoolExecutor(2) as ex:
        assert sweep(_product, grid, executor=ex) == serial
    assert sweep(_product, [{"a": 3, "b": 4}]) == [SweepPoint({"a": 3, "b": 4}, 12)]
    with pytest.raises(FrictionRulesError, match="parameter_grid"):
        sweep(_product, 3)


def _product(a, b):
    return a * b


def test_missing_dask_names_the_extra(monkeypatch):
    import sys

    from frictionrules.parallel import local_cluster
    # None in sys.modules makes every import of the package fail, already imported or not
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(FrictionRulesError, match=r"frictionrules\[dask\]"):
        with local_cluster(2):
            pass
