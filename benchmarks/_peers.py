"""The peers of ``benchmarks/fclib.py``: Siconos and Pinocchio, each run in a subprocess of its
own Python on the same W, q, mu, its answer read back and measured with our error.

* Siconos 4.4 (Debian ``python3-siconos python3-scipy`` for ``/usr/bin/python3``): NSGS,
  NSN_AC, PROX and ADMM of ``fc3d_driver``, fed W as ``SBM_from_csparse(3, W_csc)``. The time
  of a run is that of the ``fc3d_driver`` call (its options and arrays made before); on
  problems of at most ``CALL_MAX_UNKNOWNS`` unknowns the whole Python call (making the
  options and the arrays, the driver, reading the results: what ``solve`` does in one call)
  is also timed, as ``times_call``.
* Pinocchio 4.1 (``pip install pin scipy`` in a separate venv, named by ``--pinocchio-python``
  or ``$PINOCCHIO_PYTHON``): ``ADMMConstraintSolver`` on ``DelassusOperatorSparse`` (``ADMM``;
  ``ADMM_DENSE`` on ``DelassusOperatorDense`` can be named, and was slower on KaplasTower, 4.9 s
  of CPU against 2.0 s) and ``PGSConstraintSolver`` on ``DelassusOperatorDense`` (PGS takes a
  dense Delassus only), the dense ones up to ``PGS_MAX_UNKNOWNS`` unknowns; with
  ``solve_ncp=True`` (De Saxcé's correction: the exact Coulomb problem), one
  ``PointContactConstraintModel`` per contact carrying its mu; components reordered to
  Pinocchio's ``(T1, T2, N)``. ADMM's Lanczos decomposition is of size ``LANCZOS_SIZE``, not
  Pinocchio 4.1's default (the whole problem), which costs 50x the solve on KaplasTower.
  Pinocchio 4.1's PGS crashes (a segmentation fault in ``enforceSymmetry``) on KaplasTower's
  1,710 unknowns; it runs on Capsules' 858.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
from pathlib import Path

import numpy as np

SYSTEM_PYTHON = "/usr/bin/python3"
#: Every peer runs on one thread, as ours do (``blas_threads=1``): the same CPU for everybody.
SINGLE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}

#: (solver, iteration limit) of each peer; Pinocchio's PGS only up to this many unknowns (its
#: dense Delassus needs 8 n^2 bytes).
SICONOS = (("NSGS", 100000), ("NSN_AC", 2000), ("PROX", 1000), ("ADMM", 20000))
PINOCCHIO = (("ADMM", 20000), ("PGS", 100000))
PGS_MAX_UNKNOWNS = 6000
#: Pinocchio's ADMM estimates W's largest eigenvalue by a Lanczos decomposition of this size.
#: Pinocchio 4.1's default is the whole problem size: on KaplasTower (1,710 unknowns) that
#: decomposition is 98 % of the solve (1.27 s against 0.025 s with 3, the same 16-17 iterations).
#: 3 is the default of the ADMM contact solver of Pinocchio 3 (``ADMMContactSolver``).
LANCZOS_SIZE = 3

#: Repetitions of a run: until its CPU time adds up to REPEAT_SECONDS, at most REPEATS_MAX
#: (the median is reported with the spread); a run of a tiny problem is repeated hundreds of times.
REPEAT_PREAMBLE = "REPEAT_SECONDS, REPEATS_MAX, CALL_MAX_UNKNOWNS = 0.3, 400, 48\n"

SICONOS_RUNNER = REPEAT_PREAMBLE + r"""
import json, resource, sys, time
import numpy as np
import scipy.sparse as sp
import siconos.numerics as sn
data = np.load(sys.argv[1])
solver, max_iter, tol = sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
n = int(data["n"])
W = sp.csc_matrix((data["x"], data["i"].astype(np.int64), data["p"].astype(np.int64)), shape=(n, n))
q, mu = data["q"], data["mu"]
status, sbm = sn.SBM_from_csparse(3, W)
problem = sn.FrictionContactProblem(3, sbm, q, mu)
times, spent, last = [], 0.0, None
while len(times) < REPEATS_MAX and (not times or spent < REPEAT_SECONDS):
    options = sn.SolverOptions(getattr(sn, "SICONOS_FRICTION_3D_" + solver))
    options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter
    options.dparam[sn.SICONOS_DPARAM_TOL] = tol
    r, u = np.zeros(q.size), np.zeros(q.size)
    t0 = time.thread_time()
    info = sn.fc3d_driver(problem, r, u, options)
    times.append(time.thread_time() - t0)
    spent += times[-1]
    last = (info, int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]), float(options.dparam[sn.SICONOS_DPARAM_RESIDU]), r)
calls, spent = [], 0.0
while q.size <= CALL_MAX_UNKNOWNS and len(calls) < REPEATS_MAX and (not calls or spent < REPEAT_SECONDS):
    t0 = time.thread_time()           # the whole Python call: options, arrays, driver, results
    options = sn.SolverOptions(getattr(sn, "SICONOS_FRICTION_3D_" + solver))
    options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter
    options.dparam[sn.SICONOS_DPARAM_TOL] = tol
    r, u = np.zeros(q.size), np.zeros(q.size)
    info = sn.fc3d_driver(problem, r, u, options)
    result = (info, int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]), float(options.dparam[sn.SICONOS_DPARAM_RESIDU]), r, u)
    calls.append(time.thread_time() - t0)
    spent += calls[-1]
np.save(sys.argv[5], last[3])
print(json.dumps({"info": int(last[0]), "iterations": last[1], "own_error": last[2], "times": times,
                  "times_call": calls, "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""

PINOCCHIO_RUNNER = REPEAT_PREAMBLE + f"LANCZOS_SIZE = {LANCZOS_SIZE}\n" + r"""
import json, resource, sys, time
import numpy as np
import scipy.sparse as sp
import pinocchio as pin
data = np.load(sys.argv[1])
solver, tol = sys.argv[2], float(sys.argv[4])
budgets = [int(k) for k in sys.argv[3].split(",")]      # several: run in turn, in pairs
n = int(data["n"]); nc = n // 3
W = sp.csc_matrix((data["x"], data["i"].astype(np.int64), data["p"].astype(np.int64)), shape=(n, n))
q, mu = data["q"], data["mu"]
perm = np.array([[3 * a + 1, 3 * a + 2, 3 * a] for a in range(nc)]).ravel()   # (T1, T2, N)
Wp = sp.csc_matrix(W.tocsr()[perm][:, perm])
model = pin.Model()
model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "body")
models, datas = pin.StdVec_ConstraintModel(), pin.StdVec_ConstraintData()
for a in range(nc):
    cm = pin.PointContactConstraintModel(model, 1)
    cm.setFriction(float(mu[a]))
    c = pin.ConstraintModel(cm)
    models.append(c)
    datas.append(c.createData())
times, spent, last = [], 0.0, None
while len(times) % len(budgets) or (len(times) < REPEATS_MAX and (not times or spent < REPEAT_SECONDS)):
    max_iter = budgets[len(times) % len(budgets)]
    if solver.startswith("ADMM"):
        G = pin.DelassusOperatorSparse(Wp) if solver == "ADMM" else pin.DelassusOperatorDense(Wp.toarray())
        s, st, res = pin.ADMMConstraintSolver(n), pin.ADMMSolverSettings(), pin.ADMMSolverResult()
    else:
        D = np.asfortranarray(Wp.toarray())     # kept alive: the operator holds a view of it
        G = pin.DelassusOperatorDense(D)
        s, st, res = pin.PGSConstraintSolver(n), pin.PGSSolverSettings(), pin.PGSSolverResult()
    st.max_iterations = max_iter
    st.absolute_feasibility_tol = st.relative_feasibility_tol = tol
    st.absolute_complementarity_tol = st.relative_complementarity_tol = tol
    st.solve_ncp = True
    if solver.startswith("ADMM"):
        st.lanczos_size = LANCZOS_SIZE
    g = q[perm].copy()
    t0 = time.thread_time()
    ok = s.solve(G, g, models, datas, st, res)
    times.append(time.thread_time() - t0)
    spent += times[-1]
    lam = np.asarray(res.retrieveConstraintImpulses()).ravel()
    r = np.empty(n)
    r[perm] = lam
    last = (bool(ok), int(res.iterations), r)
np.save(sys.argv[5], last[2])
print(json.dumps({"info": 0 if last[0] else 1, "iterations": last[1], "own_error": float("nan"),
                  "times": times, "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def pinocchio_python(arg=None):
    """The Python that imports pinocchio (argument, ``$PINOCCHIO_PYTHON``), or None."""
    candidate = arg or os.environ.get("PINOCCHIO_PYTHON")
    if candidate and Path(candidate).exists() and _imports(candidate, "pinocchio, scipy.sparse"):
        return candidate
    return None


def siconos_python():
    return SYSTEM_PYTHON if Path(SYSTEM_PYTHON).exists() and _imports(SYSTEM_PYTHON, "siconos.numerics, scipy.sparse") \
        else None


def _imports(python: str, modules: str) -> bool:
    return subprocess.run([python, "-c", f"import {modules}"], capture_output=True).returncode == 0


def save_problem(problem, path: Path) -> Path:
    import scipy.sparse as sp
    W = sp.csc_matrix(problem.W)
    W.sort_indices()
    np.savez(path, x=W.data, i=W.indices.astype(np.int32), p=W.indptr.astype(np.int32), n=W.shape[0],
             q=problem.q, mu=problem.mu_bar)
    return path


def run_peer(python: str, runner: str, data: Path, solver: str, max_iter: int | str, tol: float, tmp: Path,
             timeout: float) -> dict:
    """One peer run in a subprocess: ``{info, iterations, times, peak_mb, r}`` (``times``: the
    CPU seconds of each repetition of the solver call); ``r`` is None (and ``info`` says why)
    when it crashed or ran out of time. Pinocchio's runner also takes budgets as ``"K1,K2"``:
    repetitions with each in turn (``times`` in that order, whole pairs)."""
    rfile = tmp / "r.npy"
    rfile.unlink(missing_ok=True)
    env = dict(os.environ, **SINGLE_THREAD)

    def cpu_limit():                        # CPU seconds, not the wall clock of a loaded machine
        resource.setrlimit(resource.RLIMIT_CPU, (int(timeout) + 1, int(timeout) + 2))
    try:
        out = subprocess.run([python, "-c", runner, str(data), solver, str(max_iter), str(tol), str(rfile)],
                             capture_output=True, text=True, timeout=20 * timeout + 60, env=env,
                             preexec_fn=cpu_limit)
    except subprocess.TimeoutExpired:
        return {"info": "timeout", "iterations": 0, "times": [float("inf")], "peak_mb": float("nan"), "r": None}
    if out.returncode in (-24, 128 + 24):   # SIGXCPU: the CPU limit
        return {"info": "timeout", "iterations": 0, "times": [float("inf")], "peak_mb": float("nan"), "r": None}
    if out.returncode != 0 or not out.stdout.strip():
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        return {"info": "crash", "iterations": 0, "times": [float("inf")], "peak_mb": peak, "r": None,
                "message": (out.stderr.strip().splitlines() or ["?"])[-1]}
    res = json.loads(out.stdout.strip().splitlines()[-1])
    res["r"] = np.load(rfile)
    return res
