"""The polish stage and what surrounds it: semismooth Newton on De Saxcé's natural map from a
settled active set (hand-made problems with a known active set, the small shared files), the
answer of ``auto`` never called converged above the tolerance, the compiled small-problem
path, the table of methods, thread limits over the whole solve, and the times and columns of
``solve_many``'s table."""

from __future__ import annotations

import concurrent.futures as cf
import csv
import multiprocessing

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frictionrules import (ADMMOptions, FrictionContactProblem, PolishOptions, read_fclib, solve, solve_many,
                           write_fclib)
from frictionrules.batch import CSV_HEADER
from frictionrules.multicontact import METHODS, fc3d_error
from frictionrules.multicontact._frame import REASONS
from test_io import FCLIB, needs_fclib
from test_multicontact import cone_violation
from test_threads import PARALLEL_TOTAL, run_probe


def known_active_set(seed: int, pieces=("stick", "slip", "open", "slip", "stick", "open")):
    r"""A coupled problem built around a chosen solution: per contact ``r*``, ``u*`` obey
    Coulomb's law in the chosen regime (stick: :math:`u = 0`, :math:`|r_T| < \mu r_N`; slip:
    :math:`r = r_N(1, -\mu e)`, :math:`u = (0, s e)`; open: :math:`r = 0`, :math:`u_N > 0`),
    W is symmetric positive definite and :math:`q = u^* - W r^*`. Returns the problem and r*."""
    rng = np.random.default_rng(seed)
    nc = len(pieces)
    mu = rng.uniform(0.2, 0.8, nc)
    r, u = np.zeros((nc, 3)), np.zeros((nc, 3))
    for a, kind in enumerate(pieces):
        e = rng.normal(size=2)
        e /= np.linalg.norm(e)
        if kind == "stick":
            r[a] = [rng.uniform(0.5, 2.0), *(0.5 * mu[a] * e)]
            r[a, 1:] *= r[a, 0]
        elif kind == "slip":
            rn = rng.uniform(0.5, 2.0)
            r[a] = [rn, *(-mu[a] * rn * e)]
            u[a, 1:] = rng.uniform(0.2, 1.0) * e
        else:
            u[a] = [rng.uniform(0.2, 1.0), *rng.normal(size=2)]
    A = rng.normal(size=(3 * nc, 3 * nc))
    W = A @ A.T / (3 * nc) + np.eye(3 * nc)
    q = u.ravel() - W @ r.ravel()
    return FrictionContactProblem(W, q, mu), r.ravel()


@pytest.mark.parametrize("seed", range(4))
def test_polish_recovers_a_known_active_set_quadratically(seed):
    """From a perturbation of the built solution r*, the polish returns r* to rounding, and its
    errors fall quadratically (e_{k+1} <= C e_k^2 once e_k < 1e-3)."""
    p, r_star = known_active_set(seed)
    start = r_star + 1e-3 * np.random.default_rng(seed + 10).normal(size=r_star.size)
    s = solve(p, method="polish", r0=start, tol=1e-14)
    assert s.converged and s.error <= 1e-14 and s.method == "polish"
    np.testing.assert_allclose(s.r, r_star, atol=1e-12)
    e = s.history
    assert s.iterations <= 6
    for a, b in zip(e[:-1], e[1:]):
        if 1e-12 < a < 1e-3:
            assert b <= 10.0 * a * a


def test_polish_pieces_are_the_regimes_of_the_solution():
    from frictionrules.multicontact import _kernels as K
    kinds = ("stick", "slip", "open", "slip", "stick", "open")
    p, r_star = known_active_set(7, kinds)
    u = p.W @ r_star + p.q
    phi, _B1, _B2, pieces = K.natural_map(r_star, u, p.mu_bar, p.dilatancy, np.ones(p.nc))
    assert [("open", "stick", "slip")[k] for k in pieces] == list(kinds)
    np.testing.assert_allclose(phi, 0.0, atol=1e-14)


def test_polish_jacobian_matches_finite_differences():
    """J = B1 + B2 W of the natural map against central differences at a point where every
    contact is strictly inside its piece."""
    from frictionrules.multicontact import _kernels as K
    p, r_star = known_active_set(3)
    r = r_star + 1e-4 * np.random.default_rng(0).normal(size=r_star.size)
    rho = np.full(p.nc, 0.7)
    W = p.W.toarray()

    def phi(x):
        return K.natural_map(x, W @ x + p.q, p.mu_bar, p.dilatancy, rho)[0]

    _phi, B1, B2, _ = K.natural_map(r, W @ r + p.q, p.mu_bar, p.dilatancy, rho)
    n = r.size
    J = np.zeros((n, n))
    for a in range(p.nc):
        J[3 * a:3 * a + 3, 3 * a:3 * a + 3] += B1[a]
        J[3 * a:3 * a + 3] += B2[a] @ W[3 * a:3 * a + 3]
    h = 1e-7
    fd = np.column_stack([(phi(r + h * np.eye(n)[j]) - phi(r - h * np.eye(n)[j])) / (2 * h) for j in range(n)])
    np.testing.assert_allclose(J, fd, atol=1e-6)


def test_polish_on_more_than_sixteen_contacts_uses_the_sparse_path():
    kinds = ("stick", "slip", "open") * 7
    p, r_star = known_active_set(11, kinds)
    start = r_star + 1e-4 * np.random.default_rng(1).normal(size=r_star.size)
    s = solve(p, method="polish", r0=start, tol=1e-13, options=PolishOptions(dense_max=0))
    assert s.converged
    np.testing.assert_allclose(s.r, r_star, atol=1e-11)


def test_polish_stalls_honestly_far_from_the_solution():
    """From zero on a problem whose active set is far away the polish may not converge; it then
    says so (``stalled`` or ``max_iter``), with an error above the tolerance."""
    p, _ = known_active_set(5)
    s = solve(p, method="polish", tol=1e-14, max_iter=2)
    assert s.converged == (s.error <= 1e-14)
    if not s.converged:
        assert s.reason in ("stalled", "max_iter")


@needs_fclib
@pytest.mark.parametrize("name, admm_tol", [("Box_Stacks-i0122-82-5.hdf5", 1e-5), ("local_problem_test.hdf5", 1e-6),
                                            ("Spheres-i099-356-679.hdf5", 1e-5), ("KaplasTower-i1061-4.hdf5", 1e-5)])
def test_polish_finishes_an_admm_iterate_on_shared_files(name, admm_tol):
    """ADMM to ``admm_tol``, then the polish to 1e-10; the cone conditions checked directly on
    (r, u) at the error's scale, independently of the solver and of the error measure. (On
    local_problem_test, under the all-stick penalty, ADMM reaches 1e-5 in 36 iterations before
    its active set has settled: from there the polish halves its error a step and stops; from
    1e-6, 93 iterations, it finishes in one step, on each of 16 draws of W and q perturbed by
    1e-15, as on the other three files from 1e-5.)"""
    p = read_fclib(FCLIB / name)
    first = solve(p, method="admm", tol=admm_tol)
    s = solve(p, method="polish", r0=first.r, tol=1e-10)
    assert s.converged and s.error <= 1e-10 and s.iterations <= 10
    assert fc3d_error(p, s.r) == pytest.approx(s.error, rel=1e-6, abs=1e-16)
    scale = max(np.linalg.norm(p.q), np.linalg.norm(s.r), np.linalg.norm(s.u))
    assert cone_violation(p.mu_bar, s.r, s.u, scale_r=scale, scale_u=scale) < 1e-9


@needs_fclib
@pytest.mark.parametrize("name", ["CubeH8.hdf5", "LMGC_GlobalFrictionContactProblem00046.hdf5",
                                  "local_problem_test.hdf5", "Box_Stacks-i0122-82-5.hdf5",
                                  "Spheres-i099-356-679.hdf5", "KaplasTower-i1061-4.hdf5"])
def test_auto_on_shared_files_converged_means_within_tol(name):
    p = read_fclib(FCLIB / name)
    s = solve(p, tol=1e-8)
    assert s.converged and fc3d_error(p, s.r) <= 1e-8


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10**6), nc=st.integers(1, 24), tol=st.sampled_from([1e-4, 1e-8, 1e-12, 1e-15]),
       max_iter=st.sampled_from([None, 1, 3, 60]))
def test_auto_never_calls_converged_above_tol(seed, nc, tol, max_iter):
    """Random problems (small path and general path, limited budgets): ``converged`` implies the
    error, recomputed independently, is within ``tol``; a stop for any other reason is not."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(3 * nc, 3 * nc))
    W = A @ A.T * rng.uniform(0.0, 1.0) + rng.uniform(0.0, 0.1) * np.eye(3 * nc)
    p = FrictionContactProblem(W, rng.normal(size=3 * nc), rng.uniform(0.0, 1.0, nc))
    s = solve(p, tol=tol, max_iter=max_iter)
    assert s.converged == (s.reason == "converged") and s.reason in REASONS
    if s.converged:
        assert fc3d_error(p, s.r) <= tol * (1 + 1e-9)
        np.testing.assert_allclose(s.u, p.W @ s.r + p.q, atol=1e-12 * max(1.0, np.abs(s.u).max()))


# ---- ADMM's penalty in the all-stick regime ---------------------------------------------------
@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("nc", [6, 150])
def test_admm_all_stick_regime_takes_the_small_penalty(seed, nc):
    """A problem whose solution sticks at every contact (u* = 0, |r*_T| < mu r*_N, built as in
    ``known_active_set``; dense and sparse factorizations): ADMM with the small penalty
    recovers r* in a few iterations, fewer than with the spectral penalty alone."""
    p, r_star = known_active_set(seed, pieces=("stick",) * nc)
    s = solve(p, method="admm", tol=1e-10)
    spectral = solve(p, method="admm", tol=1e-10, options=ADMMOptions(rho_stick=0.0))
    assert s.converged and spectral.converged
    np.testing.assert_allclose(s.r, r_star, atol=1e-8 * np.abs(r_star).max())
    assert s.iterations <= 10 and s.iterations < spectral.iterations


def test_auto_hands_over_from_admm_only_inside_its_stages():
    """A mixed problem (stick, slip, open) through ``auto``'s general path (``time_limit``):
    whatever stages ran, the reason is one of the public ones and the answer is r*."""
    p, r_star = known_active_set(3, pieces=("stick", "slip", "open") * 8)
    s = solve(p, tol=1e-12, time_limit=100.0)
    assert s.converged and s.reason == "converged"
    np.testing.assert_allclose(s.r, r_star, atol=1e-9 * np.abs(r_star).max())


# ---- the small-problem path -------------------------------------------------------------------
def test_solution_record_is_the_generated_init():
    """``Solution._record`` (the small path's constructor) gives the record ``Solution(...)``
    gives: the same fields, frozen."""
    import dataclasses
    p, _ = known_active_set(1)
    s = solve(p, method="nsgs", tol=1e-12)
    fields = [getattr(s, f.name) for f in dataclasses.fields(s)]
    fast = type(s)._record(*fields)
    for f in dataclasses.fields(s):
        np.testing.assert_array_equal(getattr(fast, f.name), getattr(s, f.name))
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.error = 0.0


@pytest.mark.parametrize("method", ["nsgs", "auto", "polish"])
def test_solve_batch_equals_solve_one_by_one(method):
    """``solve_batch`` (the small problems in one compiled call) returns what ``solve`` returns
    problem by problem: reactions, velocities, errors, iterations, histories, stages, reasons;
    a problem beyond the small path's 16 contacts and a dilatant one go through it too."""
    from frictionrules import Coulomb, solve_batch
    rng = np.random.default_rng(7)
    problems = []
    for nc in (1, 2, 5, 9, 16, 20):
        A = rng.normal(size=(3 * nc, 3 * nc))
        problems.append(FrictionContactProblem(A @ A.T / (3 * nc) + 0.3 * np.eye(3 * nc), rng.normal(size=3 * nc),
                                               rng.uniform(0.1, 0.9, nc)))
    problems.append(FrictionContactProblem(np.eye(3), [-1.0, 2.0, 0.0], [Coulomb(0.5, dilatant=True)]))
    batch = solve_batch(problems, method=method, tol=1e-10)
    for p, b in zip(problems, batch):
        s = solve(p, method=method, tol=1e-10)
        np.testing.assert_array_equal(b.r, s.r)
        np.testing.assert_array_equal(b.u, s.u)
        np.testing.assert_array_equal(b.history, s.history)
        np.testing.assert_array_equal(b.history_iterations, s.history_iterations)
        assert (b.error, b.iterations, b.method, b.reason, b.converged) == (s.error, s.iterations, s.method,
                                                                             s.reason, s.converged)
        assert b.cpu_seconds >= 0.0 and b.seconds >= 0.0
    assert solve_batch([], method=method) == []
@pytest.mark.parametrize("method", ["nsgs", "auto", "polish"])
def test_small_path_agrees_with_the_general_path(method):
    """``time_limit`` sends a problem of <= 16 contacts down the general path: both answers
    solve the problem."""
    p, r_star = known_active_set(2)
    r0 = r_star + 1e-3 if method == "polish" else None
    small = solve(p, method=method, tol=1e-12, r0=r0)
    general = solve(p, method=method, tol=1e-12, r0=r0, time_limit=100.0)
    assert small.converged and general.converged
    np.testing.assert_allclose(small.r, general.r, atol=1e-10)
    assert small.history.size and small.history[-1] == pytest.approx(small.error, rel=1e-9, abs=1e-300)


@pytest.mark.parametrize("warm", [False, True])
def test_small_path_keeps_a_history_longer_than_its_buffers(warm):
    """A small-path run whose history outgrows the buffers allocated per call (one chunk of
    sweeps) is run again with room for it, from the same start: the whole history,
    consistent with the answer, and the reactions of the general path (the same sweeps)."""
    from frictionrules.multicontact import _small
    rng = np.random.default_rng(3)
    nc = 12
    A = rng.normal(size=(3 * nc, 3 * nc - 6))
    p = FrictionContactProblem(A @ A.T / (3 * nc) + 1e-9 * np.eye(3 * nc), rng.normal(size=3 * nc),
                               rng.uniform(0.1, 0.9, nc))
    r0 = np.tile([0.1, 0.0, 0.0], nc) if warm else None
    s = solve(p, method="nsgs", tol=1e-300, max_iter=2000, r0=r0)
    general = solve(p, method="nsgs", tol=1e-300, max_iter=2000, r0=r0, time_limit=1e3)
    assert s.history.size > _small.HISTORY and s.iterations == 2000 and s.reason == "max_iter"
    assert np.all(np.diff(s.history_iterations) > 0) and s.history_iterations[-1] == s.iterations
    assert s.history[-1] == s.error
    np.testing.assert_allclose(s.r, general.r, rtol=0.0, atol=1e-12 * np.abs(general.r).max())


def test_small_path_history_is_kept_when_its_buffers_grew_but_it_fits():
    """A run of more than one chunk of sweeps (``_small.CHUNK``) grows the history buffers
    before each chunk that might outgrow them; a history that ends up fitting the caller's
    buffers is copied back from the grown ones: finite errors, strictly increasing iterations
    ending at the run's, and the last error the run's (NSGS runs of 2000 sweeps to a tolerance
    they do not reach)."""
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(16):
        nc = int(rng.integers(4, 9))
        A = rng.normal(size=(3 * nc, 3 * nc - 6))
        p = FrictionContactProblem(A @ A.T / (3 * nc) + 1e-9 * np.eye(3 * nc), rng.normal(size=3 * nc),
                                   rng.uniform(0.1, 0.9, nc))
        s = solve(p, method="nsgs", tol=1e-12, max_iter=2000)
        if s.iterations <= 256 or s.history.size > 256:
            continue
        checked += 1
        assert np.all(np.isfinite(s.history)) and np.all(np.diff(s.history_iterations) > 0)
        assert s.history_iterations[-1] == s.iterations and s.history[-1] == s.error
    assert checked >= 1


def test_small_path_goes_on_after_its_sweeps_as_one_run_from_the_start():
    """The small path runs the sweeps alone first (all of ``nsgs``, the probe of ``auto``) and
    compiles the polish only for a problem that goes on after them: ``auto`` resumed from the
    state the sweeps left (:func:`_small.solve_into` with ``ns = 1``) is the run from the start
    in one compiled call (``ns = 0``), to the bit: reactions, velocities, error, iterations,
    stages and history."""
    from frictionrules.multicontact import _small
    rng = np.random.default_rng(11)
    went_on = 0
    for _ in range(12):
        nc = int(rng.integers(4, 9))
        A = rng.normal(size=(3 * nc, 3 * nc - 6))                    # W singular but for 1e-9 I
        p = FrictionContactProblem(A @ A.T / (3 * nc) + 1e-9 * np.eye(3 * nc), rng.normal(size=3 * nc),
                                   rng.uniform(0.1, 0.9, nc))
        W, n, size, mode, tol, max_iter = p.W, 3 * p.nc, _small.HISTORY, _small.MODES["auto"], 1e-12, 2000
        common = (W.indptr, W.indices, W.data, p.q, p.mu_bar, p.dilatancy, np.empty(0))
        polish = _small.POLISH_DEFAULTS
        tail = (tol, max_iter, mode, polish.contraction, polish.patience, polish.max_halvings, _small.UNBOUNDED)
        whole, whole_it = np.empty(2 * n + size), np.empty(size, np.int64)
        a = _small.solve_into(*common, whole, whole_it, *tail, 0, 0, 0, np.inf)
        out, out_it = np.empty(2 * n + size), np.empty(size, np.int64)
        it, _err, _bounded, stage_err, nh = _small.sweeps_into(*common, out, out_it, tol,
                                                               min(_small.AUTO_PROBE, max_iter), _small.UNBOUNDED)
        if not _small.goes_on(mode, stage_err, tol, it, max_iter):
            continue
        went_on += 1
        b = _small.solve_into(*common, out, out_it, *tail, 1, it, nh, stage_err)
        assert a == b and a[3] >= 2
        np.testing.assert_array_equal(whole[:2 * n + a[4]], out[:2 * n + b[4]])
        np.testing.assert_array_equal(whole_it[:a[4]], out_it[:b[4]])
    assert went_on >= 3


def test_small_path_reads_the_initial_reactions_without_writing_them():
    """The small path copies ``r0`` into its compiled call's buffer: the caller's array is
    left as it was, and a read-only one gives the same answer without compiling another
    signature of the call."""
    from frictionrules.multicontact import _small
    p, r_star = known_active_set(2)
    r0 = r_star + 1e-3
    frozen = r0.copy()
    frozen.flags.writeable = False
    a = solve(p, method="polish", tol=1e-12, r0=r0)
    signatures = len(_small.solve_into.signatures)
    b = solve(p, method="polish", tol=1e-12, r0=frozen)
    assert len(_small.solve_into.signatures) == signatures
    np.testing.assert_array_equal(a.r, b.r)
    np.testing.assert_array_equal(r0, r_star + 1e-3)
    assert a.converged


def test_small_path_reports_its_wall_time_as_cpu_time():
    """The small path does not read the thread's CPU clock (a system call of a sixth of a tiny
    solve): its ``cpu_seconds`` is its wall time."""
    p, _ = known_active_set(1)
    s = solve(p, method="nsgs")
    assert s.cpu_seconds == s.seconds > 0.0


def test_solve_many_of_many_small_problems_is_the_loop():
    problems = [known_active_set(k % 3)[0] for k in range(50)]
    records = solve_many(problems, method="auto")
    assert all(r.converged for r in records)
    for p, rec in zip(problems[:3], records[:3]):
        np.testing.assert_array_equal(rec.solution.r, solve(p).r)


# ---- the table of methods and the CLI ----------------------------------------------------------
def test_one_table_of_methods_for_the_solver_and_the_cli():
    from frictionrules.cli import build_parser
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices["solve"]
    method = next(a for a in sub._actions if a.dest == "method")
    assert tuple(method.choices) == tuple(METHODS)
    p = FrictionContactProblem(np.eye(3), [-1.0, 2.0, 0.0], [0.5])
    for name, entry in METHODS.items():
        s = solve(p, method=name, tol=1e-10)
        assert s.converged and entry.max_iter >= 1
        np.testing.assert_allclose(s.r, [1.0, -0.5, 0.0], atol=1e-9)


# ---- thread limits, times, the table's columns -----------------------------------------------
def test_thread_limits_cover_every_blas_call_of_a_solve():
    """During a solve (here prox: SciPy's LU and NumPy's products), every BLAS and OpenMP
    library loaded in the process, SciPy's own included, runs on one thread."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    seen = []

    def look(info):
        seen.append([(lib["internal_api"], lib["filepath"], lib["num_threads"])
                     for lib in threadpoolctl.threadpool_info()])

    p, _ = known_active_set(4, ("stick", "slip", "open") * 8)
    solve(p, method="prox", tol=1e-10, callback=look)
    assert seen and all(threads == 1 for libs in seen for _api, _path, threads in libs)
    assert any("scipy" in path for _api, path, _t in seen[0])


_OPENMP_AFTER_A_SOLVE = """
import json, numpy as np, threadpoolctl
from frictionrules import FrictionContactProblem, solve
from frictionrules._threads import prefer_openmp
p = FrictionContactProblem(np.eye(3), [-1.0, 2.0, 0.0], [0.5])
solve(p, method="prox")                 # the controller is built before OpenMP is loaded
prefer_openmp()
""" + PARALLEL_TOTAL + """
total(10)                               # Numba's OpenMP layer loads the OpenMP runtime
seen = []
solve(p, method="prox", callback=lambda info: seen.append(
    [(lib["internal_api"], lib["num_threads"]) for lib in threadpoolctl.threadpool_info()]))
import numba
print(json.dumps({"layer": numba.threading_layer(), "libs": seen[0]}))
"""


def test_thread_limits_cover_an_openmp_runtime_loaded_after_an_earlier_solve():
    """The OpenMP runtime of Numba's threading layer, loaded after the first solve built the
    thread controller, is limited by the next solve too (in a fresh interpreter: the order of
    loading is the test)."""
    pytest.importorskip("threadpoolctl")
    got = run_probe(_OPENMP_AFTER_A_SOLVE)
    assert got["libs"] and all(threads == 1 for _api, threads in got["libs"])
    if got["layer"] == "omp":           # where GNU OpenMP loads, it is among the limited libraries
        assert "openmp" in {api for api, _t in got["libs"]}


def test_table_has_the_method_that_ran_and_the_parameters(tmp_path):
    for k in range(3):
        write_fclib(tmp_path / f"p{k}.hdf5", known_active_set(k, ("stick", "slip", "open") * (1 + 6 * k))[0])
    out = tmp_path / "t.csv"
    with cf.ThreadPoolExecutor(2) as ex:
        records = solve_many(tmp_path, method="auto", tol=1e-9, time_limit=30.0, out=out, executor=ex)
    text = out.read_text()
    comments = "\n".join(line for line in text.splitlines() if line.startswith("#"))
    assert "time_limit" in comments and "ThreadPoolExecutor (2 workers)" in comments
    rows = list(csv.DictReader(line for line in text.splitlines() if not line.startswith("#")))
    assert tuple(rows[0]) == CSV_HEADER
    for row, rec in zip(rows, records):
        assert row["method"] == rec.solution.method != "auto" and row["requested"] == "auto"
        assert float(row["tol"]) == 1e-9 and float(row["time_limit"]) == 30.0
        assert float(row["cpu_seconds"]) == pytest.approx(rec.cpu_seconds, abs=1e-6)
    again = solve_many(tmp_path, method="auto", tol=1e-9, time_limit=30.0, out=out)
    assert all(r.resumed for r in again)
    other = solve_many(tmp_path, method="auto", tol=1e-9, time_limit=10.0, out=out)   # another parameter
    assert not any(r.resumed for r in other)


def test_cli_csv_records_time_limit_and_the_method_that_ran(tmp_path):
    from frictionrules.cli import main
    write_fclib(tmp_path / "a.hdf5", known_active_set(1, ("stick", "slip", "open") * 8)[0])
    out = tmp_path / "t.csv"
    assert main(["solve", str(tmp_path), "--time-limit", "20", "--csv", str(out)]) == 0
    text = out.read_text()
    assert "--time-limit 20" in text
    row = next(csv.DictReader(line for line in text.splitlines() if not line.startswith("#")))
    assert row["requested"] == "auto" and row["method"].startswith("nsgs") and row["time_limit"] == "20"


def test_solve_times_exclude_the_start_up_of_a_fresh_worker(tmp_path):
    """In a fresh process (spawned: nothing loaded), loading the compiled kernels is done and
    timed before the first problem, and reported as ``startup_seconds`` apart: the first
    problem's solve time is that of a solve, not of a start-up (loading costs far more CPU
    than solving a few contacts), and later tasks in the same process report no start-up."""
    problems = [known_active_set(k)[0] for k in range(3)]
    context = multiprocessing.get_context("spawn")
    with cf.ProcessPoolExecutor(1, mp_context=context) as ex:
        records = solve_many(problems, method="nsgs", executor=ex, batch_bytes=0)
    assert all(r.converged for r in records)
    assert records[0].startup_seconds > 0 and all(r.startup_seconds == 0 for r in records[1:])
    assert records[0].cpu_seconds < 0.1 * records[0].startup_seconds


@pytest.mark.parametrize("dense_max", [400, 0])
def test_polish_direction_takes_a_second_shift_only_where_the_first_lu_fails(monkeypatch, dense_max):
    r""":func:`polish_direction` factorizes :math:`J + \sigma I`, :math:`\sigma = 10^{-9}
    \max|J_{ii}|`; a thousand times :math:`\sigma` only where that matrix is singular (here a
    row of J that is :math:`-\sigma` on the diagonal and zero elsewhere), not where the
    refinement stalls above the tolerance (an inconsistent singular system) or spends its
    steps, with the dense LU and the sparse one."""
    import scipy.sparse as sp

    from frictionrules.multicontact import _polish as P
    opts = PolishOptions(dense_max=dense_max)
    shifts = []
    lu = P._lu
    monkeypatch.setattr(P, "_lu", lambda J, sigma, dense, perm=None: (shifts.append(sigma),
                                                                        lu(J, sigma, dense, perm))[1])
    d = np.array([2.0, 1.0, 4.0, 3.0])
    sigma = 1e-9 * 4.0
    failing = sp.csr_matrix(np.diag([2.0, 1.0, 4.0, -sigma]) + np.diag([0.5, 0.5, 0.0], 1))
    x, res = P.polish_direction(failing, np.array([1.0, 2.0, 3.0, 0.0]), opts)
    assert shifts == [sigma, 1e3 * sigma] and res < 1e-12
    np.testing.assert_allclose(failing @ x, [1.0, 2.0, 3.0, 0.0], atol=1e-9)
    shifts.clear()
    stalled = sp.csr_matrix(np.diag(d * [1.0, 1.0, 1.0, 0.0]))     # b has a component out of J's range
    x, res = P.polish_direction(stalled, np.array([1.0, 1.0, 1.0, 1.0]), opts)
    assert shifts == [sigma] and res == pytest.approx(0.5, rel=1e-6)
    shifts.clear()
    one_step = PolishOptions(dense_max=dense_max, refinement_steps=0)   # sigma leaves 1e-9 of b
    x, res = P.polish_direction(sp.csr_matrix(np.diag(d)), np.ones(4), one_step, rtol=1e-14)
    assert shifts == [sigma] and 1e-14 < res < 1e-8
