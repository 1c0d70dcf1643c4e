"""The first call of a command: compiled kernels cached between processes, compiled once per
signature, shown on a terminal while they compile; the time limit and the start-up."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("numba")
pytest.importorskip("scipy")

SRC = Path(__file__).resolve().parents[1] / "src"


def _python(code: str, cache: Path, **env) -> str:
    """Run ``code`` in a fresh interpreter with Numba's cache in ``cache``; its stdout."""
    environ = dict(os.environ, PYTHONPATH=str(SRC), NUMBA_CACHE_DIR=str(cache / "numba"),
                   FRICTIONRULES_CACHE_DIR=str(cache / "kernels"), **env)
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=environ, capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout


_SMALL_BATCH = """
    import json
    import numpy as np
    from numba.core.registry import CPUDispatcher
    from frictionrules import FrictionContactProblem, solve_batch
    from frictionrules.multicontact import _kernels, _lapack, _small

    W = np.array([[1.0, 0.1, 0.0], [0.1, 1.0, 0.0], [0.0, 0.0, 1.0]])
    sol = solve_batch([FrictionContactProblem(W, np.array([-1.0, 0.5, 0.1]), [0.5])])[0]
    stats = {f"{m.__name__}.{k}": (sum(f.stats.cache_hits.values()), sum(f.stats.cache_misses.values()),
                                   [str(s) for s in f.signatures])
             for m in (_small, _kernels, _lapack) for k, f in vars(m).items() if isinstance(f, CPUDispatcher)}
    print(json.dumps({"converged": sol.converged, "stats": stats}))
"""


def test_a_second_process_loads_the_small_path_from_numbas_cache(tmp_path):
    """A fresh interpreter with an empty ``NUMBA_CACHE_DIR`` compiles the small-problem path
    of :func:`~frictionrules.solve_batch` (Numba's ``cache_misses``) and writes it to the cache;
    a second interpreter with the same folder loads it (``cache_hits``) and compiles nothing.
    A problem the sweeps solve (one contact: one exact local solve) compiles the sweeps alone,
    never the polish (``small_solve_many``, ``natural_map``, ``min_norm_solve``: no signature)."""
    first = json.loads(_python(_SMALL_BATCH, tmp_path))
    second = json.loads(_python(_SMALL_BATCH, tmp_path))
    assert first["converged"] and second["converged"]
    assert first["stats"]["frictionrules.multicontact._small.sweeps_many"][1] == 1
    entry = second["stats"]["frictionrules.multicontact._small.sweeps_many"]
    assert entry[0] == 1 and entry[1] == 0
    assert all(misses == 0 for _hits, misses, _sigs in second["stats"].values())
    for name in ("_small.small_solve_many", "_kernels.natural_map", "_lapack.min_norm_solve"):
        assert first["stats"][f"frictionrules.multicontact.{name}"][2] == []
    # one signature for the entry point, and no literal specialisation anywhere it was compiled
    assert len(entry[2]) == 1
    assert not any("Literal" in s for _h, _m, sigs in first["stats"].values() for s in sigs)


def test_min_norm_solve_is_numpys_lstsq():
    """:func:`_lapack.min_norm_solve` is ``np.linalg.lstsq(J, b, rcond=-1)[0]`` (the same LAPACK
    routine, dgelsd, with the same arguments: equal to the bit), also for a singular J (the
    minimum-norm solution) and a zero J; NaN for a J that is not finite."""
    from frictionrules.multicontact._lapack import min_norm_solve
    rng = np.random.default_rng(3)
    for n in (1, 3, 9, 24):
        J, b = rng.standard_normal((n, n)), rng.standard_normal(n)
        assert np.array_equal(min_norm_solve(J, b), np.linalg.lstsq(J, b, -1.0)[0])
    J = rng.standard_normal((6, 2)) @ rng.standard_normal((2, 6))          # rank 2
    b = rng.standard_normal(6)
    x = min_norm_solve(J, b)
    assert np.array_equal(x, np.linalg.lstsq(J, b, -1.0)[0])
    # minimum norm: no component in the null space of J (the span of J's rows)
    assert np.allclose(x, np.linalg.pinv(J) @ b, atol=1e-10)
    assert np.array_equal(min_norm_solve(np.zeros((3, 3)), np.ones(3)), np.zeros(3))
    J[0, 0] = np.inf
    assert np.isnan(min_norm_solve(J, b)).all()


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def _compile_a_kernel():
    """Compile a new Numba function (a new closure: never in the cache)."""
    from numba import njit
    offset = float(np.random.default_rng().integers(1 << 30))

    @njit
    def kernel(x):
        return np.sin(x) + offset
    return kernel(np.ones(3))


def test_compile_notice_draws_one_line_on_a_terminal_only():
    """While Numba compiles, :class:`CompileNotice` draws ``compiling kernels (first run): … s``
    on a terminal, one line (redrawn in place with ``\\r``, ended once); elsewhere (a pipe, a
    log file) nothing, and disabled nothing."""
    from frictionrules._progress import COMPILING, CompileNotice
    tty = _Terminal()
    with CompileNotice(stream=tty, interval=0.01, after=0.0) as notice:
        _compile_a_kernel()
    text = tty.getvalue()
    assert text.startswith("\r" + COMPILING + ": ") and text.endswith(" s\n") and text.count("\n") == 1
    assert notice.seconds > 0.0
    pipe = io.StringIO()
    with CompileNotice(stream=pipe, interval=0.01, after=0.0):
        _compile_a_kernel()
    quiet = _Terminal()
    with CompileNotice(stream=quiet, enabled=False, interval=0.01, after=0.0):
        _compile_a_kernel()
    assert pipe.getvalue() == "" and quiet.getvalue() == ""


def test_a_progress_line_ends_the_compile_notice_line():
    """A :class:`Progress` line drawn after a compilation starts on its own line: the notice's
    line is ended first (no progress text appended to it)."""
    from frictionrules._progress import COMPILING, CompileNotice, Progress
    tty = _Terminal()
    with CompileNotice(stream=tty, interval=0.01, after=0.0, idle=60.0):
        _compile_a_kernel()
        with Progress("solve", 1, stream=tty, interval=0.0) as bar:
            bar(1)
    lines = tty.getvalue().split("\n")
    assert lines[0].split("\r")[-1].startswith(COMPILING)
    assert lines[1].split("\r")[-1].startswith("solve: 1/1 steps in")


def test_compile_notice_draws_nothing_where_nothing_compiles():
    """No line where nothing compiles (a command whose kernels are loaded from the cache, or
    that needs none): the notice reacts to Numba's compile events only; its thread ends with
    it."""
    from frictionrules._progress import CompileNotice
    tty = _Terminal()
    with CompileNotice(stream=tty, interval=0.01, after=0.0):
        np.ones(3).sum()
    assert tty.getvalue() == ""
    assert not any(t.name == "frictionrules-compile-notice" for t in threading.enumerate())


def test_start_up_loads_only_the_paths_the_problems_take():
    """``solve_many``'s start-up loads what the task's problems need (:data:`batch.PATHS`): a
    one-contact problem without time limit the compiled batch alone; with a time limit or a
    callback the general path (where :func:`~frictionrules.solve` takes them); a problem of
    more than ``SMALL_MAX`` contacts the general path."""
    from frictionrules import FrictionContactProblem
    from frictionrules.batch import _paths
    one = FrictionContactProblem(np.eye(3), np.array([-1.0, 0.0, 0.0]), [0.5])
    big = FrictionContactProblem(np.eye(3 * 17), np.tile([-1.0, 0.0, 0.0], 17), [0.5] * 17)
    assert _paths([one], "auto", True, [True]) == ["small batch"]
    assert _paths([one], "auto", False, [True]) == ["small"]
    assert _paths([one], "auto", False, [False]) == ["general"]
    assert _paths([one, big], "auto", True, [True, True]) == ["small batch", "general"]
    assert _paths([one], "prox", True, [True]) == ["general"]


def test_the_time_limit_excludes_the_start_up(monkeypatch, tmp_path):
    """``--time-limit`` (``solve_many(time_limit=)``) bounds each problem's solve; the start-up
    of the process (loading or, on a first run, compiling the kernels) runs before it, is timed
    apart (``startup_seconds``), and does not shorten the limit given to the solve
    (docs/multicontact.md, "The first call")."""
    from frictionrules import FrictionContactProblem, batch
    calls = []
    monkeypatch.setattr(batch, "_started", set())
    monkeypatch.setattr(batch, "_start_up", lambda method, path: calls.append(("start-up", path)) or 2.5)
    real_solve = batch.solve

    def solve(problem, **kwargs):
        calls.append(("solve", kwargs["time_limit"]))
        return real_solve(problem, **kwargs)
    monkeypatch.setattr(batch, "solve", solve)
    problem = FrictionContactProblem(np.eye(3), np.array([-1.0, 0.2, 0.0]), [0.5])
    records = batch.solve_many([problem, problem], method="nsgs", time_limit=0.75)
    assert calls == [("start-up", "general"), ("solve", 0.75), ("solve", 0.75)]
    assert records[0].startup_seconds == 2.5 and records[1].startup_seconds == 0.0
    assert all(r.converged for r in records)



@pytest.mark.parametrize("compiling", (True, False))
def test_solve_time_limit_does_not_count_compiling(compiling):
    """``solve(time_limit=)`` bounds the solver's work: seconds inside Numba compilations (the
    ``"numba:compile"`` events a first call emits) are subtracted. A callback spends 1.5 s
    once, inside such an event or outside it; with a limit of 1 s the run then reaches
    ``max_iter`` or stops at the limit (the rest of the run is microseconds)."""
    import time
    from numba.core import event
    from frictionrules import FrictionContactProblem, solve
    problem = FrictionContactProblem(np.eye(3), np.array([-1.0, 0.2, 0.0]), [0.5])

    def callback(info):
        if info.iteration == 1:
            if compiling:
                event.start_event("numba:compile")
            time.sleep(1.5)
            if compiling:
                event.end_event("numba:compile")
        return False
    s = solve(problem, method="admm", tol=0.0, max_iter=5, time_limit=1.0, callback=callback)
    assert s.reason == ("max_iter" if compiling else "time_limit")


_GENERATED = """
    import json
    import numpy as np
    from frictionrules import Coulomb
    from frictionrules.contact._generated import generated_step, generated_kernel

    law = Coulomb(mu=0.4)
    n = 4
    du = np.array([[0.1, 0.0, -0.1], [0.0, 0.0, 0.1], [0.5, 0.2, -0.1], [0.0, 0.0, -0.2]])
    step, failed, _ = generated_step(law, 1.0, 1.0, np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 0)), du,
                                     tangent=False)
    m = generated_kernel(law).module
    print(json.dumps({"force": step.force.tolist(), "failed": failed.tolist(),
                      "plain": [sum(m._batch_plain.stats.cache_hits.values()),
                                sum(m._batch_plain.stats.cache_misses.values())],
                      "tangent_signatures": len(m._batch_tangent.signatures)}))
"""


def test_a_laws_generated_kernel_is_cached_between_processes_and_compiled_per_use(tmp_path):
    """A law's generated module (written to ``FRICTIONRULES_CACHE_DIR``, imported from there)
    keeps its machine code in Numba's cache: a second interpreter loads the batch loop
    (``cache_hits``, no miss). A caller that never asks for the tangent never compiles the
    loop with the tangent (two entries, each compiled when first called). The forces are
    Coulomb's (4.2): ``|T| <= mu N`` after the return."""
    first = json.loads(_python(_GENERATED, tmp_path))
    second = json.loads(_python(_GENERATED, tmp_path))
    assert first["plain"] == [0, 1] and second["plain"] == [1, 0]
    assert first["tangent_signatures"] == 0 and second["tangent_signatures"] == 0
    force = np.array(second["force"])
    assert np.array_equal(force, np.array(first["force"])) and not any(second["failed"])
    assert np.all(np.hypot(force[:, 0], force[:, 1]) <= 0.4 * np.maximum(force[:, 2], 0.0) * (1 + 1e-12))


def test_the_commands_that_need_numba_show_the_compile_notice():
    """The command line draws the notice for the commands that may compile (those needing Numba:
    solve, drive, assembly, paper), not for the others (law) nor with ``--quiet``."""
    from frictionrules.cli import _compiles, build_parser
    parse = build_parser().parse_args
    assert _compiles(parse(["solve", "x.hdf5"])) and _compiles(parse(["drive", "x.toml"]))
    assert _compiles(parse(["paper"])) and _compiles(parse(["assembly", "x.toml", "--out", "run.h5"]))
    assert not _compiles(parse(["law", "coulomb", "--mu", "0.5", "--force", "0", "0", "--normal", "1"]))
    assert not _compiles(parse(["drive", "x.toml", "--quiet"]))
