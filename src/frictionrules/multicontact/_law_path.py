r"""The law path: many-contact problems whose laws are cones in (T, N) but not elliptic cones
with an associated sliding rule in the plane (the paper's non-associated rules).

A contact's law enters through its symbolic form: f and g homogeneous of degree one in
``(T, N)`` (the traits :attr:`~frictionrules.laws.LawTraits.degree` and
:attr:`~frictionrules.laws.LawTraits.slip_degree`, derived from the symbolic form), no
internal variables. In FCLIB's variables (``r = (r_N, r_T)``, ``u = (u_N, u_T)``,
:math:`F(r) = f(-r_T, r_N)`, :math:`G(r) = g(-r_T, r_N)`) the contact law reads

* separated: :math:`r = 0`, :math:`u_N \ge 0`;
* stick: :math:`F(r) < 0`, :math:`u = 0`;
* sliding: :math:`F(r) = 0`, :math:`r \ne 0`, :math:`u = -\dot\lambda\nabla G(r)`,
  :math:`\dot\lambda \ge 0` (the sliding rule (1.1)–(1.2), (1.18) in the contact's
  variables);

that is :math:`u \in \mathcal N_g(r)`, and for any diagonal positive ``K`` its solutions are
the fixed points of the law's projection along its potential,
:math:`r = P_K(r - K u)` (the oblique projection of a non-associated return map, e.g.
Simo & Hughes, *Computational Inelasticity*, §3.3; De Saxcé & Feng's bipotential gives the
same law as one variational inequality, Hjiaj, Feng, de Saxcé & Mróz 2004). :math:`P_K` is
the contact layer's compiled return map of the law with stiffness ``K`` (one concept, one
place: :mod:`._law_kernels`).

The solver is non-smooth Gauss–Seidel with the contact's diagonal block of W as metric in
the local fixed point (``K = diag(1/W_NN, 2/(W_T1T1 + W_T2T2), same)``). Its error measure is
the law's natural map with the identity metric, normalised as FCLIB's,

.. math:: e(r) = |r - P_I(r - \rho u)| / \max(|q|, |r|, |u|),

zero exactly at a solution (:func:`law_error`: ρ = 1 but where a dilatant contact opens faster
than :math:`r_N/2`). For a dilatant law the local fixed point is retried with the trial
:math:`r - \omega K u`, ω divided by 4, where it does not converge (a tensile trial opens the
contact in the return map, so a solution with :math:`k_n u_N \ge r_N` is no fixed point).
``method="polish"`` is semismooth Newton on the global map (:mod:`._law_polish`); ``"auto"``
alternates sweeps and Newton steps.

The separation rule is the contact layer's (a contact whose trial force is tensile opens): for
a dilatant law it admits :math:`r = 0` with any :math:`u_N \ge 0`, where the cone path's De
Saxcé condition asks :math:`u_N \ge \bar\mu d|\tilde u_T|`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError
from ._frame import UNBOUNDED, _Monitor
from ._law_check import LAW_METHODS, check_law, short
from .error import checked_vectors
from .problem import Solution

__all__ = ["LAW_METHODS", "check_law", "law_error", "contact_dissipation", "solve_law"]

#: Newton iterations of a contact's local problem per sweep, and their tolerance on the local
#: natural map relative to the contact's reactions (a few tens of ulps; where a contact does
#: not get there, the sweeps continue it; where neither Newton's step nor the fixed point
#: lowers a map already within the return's tolerance, :func:`._law_kernels._newton` stops).
LOCAL_ITER, LOCAL_TOL = 30, 1e-14
#: ``"auto"`` on the law path: the first stage's sweeps (doubled at each round) and the Newton
#: steps of each polish between them.
AUTO_SWEEPS, AUTO_POLISH_STEPS = 100, 20


@dataclass(frozen=True, eq=False)
class LawSet:
    """The contacts' laws as the kernels take them: ``fn`` (nc, 4) addresses of each law's
    generated functions, ``rows`` (nc, L) its row with unit stiffnesses (padded with zeros),
    ``dilatant`` (nc,) the laws with normal slip (the trait ``normal_slip``), ``kernels``
    keeping the generated modules alive, ``ell`` (nc, 8) the numbers of the projection of
    two coaxial elliptic cones (:func:`frictionrules.codegen.elliptic_cones`; flag 0: the
    law's general update)."""

    fn: np.ndarray
    rows: np.ndarray
    dilatant: np.ndarray
    kernels: tuple
    ell: np.ndarray


def _as_law(law):
    if isinstance(law, float):
        from ..laws import Coulomb
        return Coulomb(law)
    return law


def law_set(problem) -> LawSet:
    """The problem's :class:`LawSet` (built once per problem)."""
    cached = problem.__dict__.get("_law_set")
    if cached is not None:
        return cached
    from ..codegen import elliptic_cones
    from ..contact import compiled_law
    from ..laws import form_of
    # each distinct law object once (its compiled law cached by value), spread by index
    seen, keys, index = {}, [], np.empty(problem.nc, dtype=np.intp)
    for a, law in enumerate(problem.laws):
        k = ("mu", law) if isinstance(law, float) else id(law)     # a coefficient by its value
        j = seen.get(k)
        if j is None:
            j = seen[k] = len(keys)
            key = _as_law(law)
            check_law(key, a)
            keys.append(key)
        index[a] = j
    compiled = [compiled_law(key, 1.0, 1.0) for key in keys]
    width = max(c.row.size for c in compiled)
    fn_u = np.array([c.fn for c in compiled], dtype=np.int64).reshape(len(keys), 4)
    rows_u = np.zeros((len(keys), width))
    for j, c in enumerate(compiled):
        rows_u[j, :c.row.size] = c.row
    fn, rows = fn_u[index], rows_u[index]
    dilatant = np.array([key.traits.normal_slip for key in keys], dtype=np.bool_)[index]
    ell = np.ascontiguousarray(np.array([elliptic_cones(form_of(key)) for key in keys])[index])
    out = LawSet(fn, rows, dilatant, tuple(c.kernel for c in compiled), ell)
    problem.__dict__["_law_set"] = out
    return out


def _kernels():
    from . import _law_kernels
    return _law_kernels


def law_error(problem, r, u=None) -> float:
    r"""The natural-map error of ``r`` for the laws of ``problem``, zero exactly at a solution.

    .. math:: e(r) = \frac{\sqrt{\sum_a |r_a - P_a(r_a - \rho_a u_a)|^2}}{\max(|q|, |r|, |u|)}

    with :math:`P_a` the return map of contact a's law along its potential (identity metric:
    :math:`P(x) = x - \Delta\lambda\nabla G(P(x))` on the limit surface, ``x`` inside, 0 for
    a tensile ``x_N <= 0``), in FCLIB's variables, and :math:`\rho_a = 1` except at a
    compressed contact opening faster than :math:`r_N/2` (a dilatant law sliding), where
    :math:`\rho_a = r_N/(2u_N)` keeps the trial compressed: the contact layer's return opens a
    contact whose trial is tensile, so with :math:`\rho = 1` such a solution would not be a
    zero. The division is skipped when the scale is at most the machine epsilon. FCLIB's
    measure (:func:`fc3d_error`) projects on the cone with De Saxcé's modified velocity
    instead; the two vanish together for isotropic Coulomb without normal slip.

    Parameters
    ----------
    problem : FrictionContactProblem
        Every contact's law a cone in (T, N) without internal variables.
    r : (3 nc,) array
        Reactions ``(r_N, r_T1, r_T2)`` per contact.
    u : (3 nc,) array, optional
        Velocities; :math:`W r + q` when omitted.
    """
    r, u = checked_vectors(problem, r, u)
    ls = law_set(problem)
    K = _kernels()
    from ..contact import workspace
    res = np.empty(r.size)
    K.natural_residual(ls.fn, ls.rows, ls.ell, r, u, workspace(0), res)
    err = float(np.sqrt(res @ res))
    scale = max(float(np.linalg.norm(problem.q)), float(np.linalg.norm(r)), float(np.linalg.norm(u)))
    return err / scale if scale > np.finfo(float).eps else err


def contact_dissipation(problem, r, u=None) -> np.ndarray:
    r"""Power dissipated at each contact, :math:`D_a = -r_a\cdot u_a`, shape ``(nc,)``.

    In the laws' variables (``T = -r_T``, ``N = r_N``, ``v = u``) this is
    :math:`D = T\cdot v_t - N v_n` ((1.7), (1.12)). At a solution it is 0 for a separated or
    sticking contact and :math:`\dot\lambda\,g(T, N)` for a sliding one (Euler's identity for a
    potential homogeneous of degree one): non-negative wherever g is on the limit surface,
    e.g. for every law of the paper without normal slip.
    """
    r, u = checked_vectors(problem, r, u)
    return -np.einsum("ai,ai->a", r.reshape(-1, 3), u.reshape(-1, 3))


class _LawFrame:
    """What :class:`._frame._Monitor` reads of a run: the bound of the reactions."""

    def __init__(self, problem):
        W = problem.W
        diag = np.abs(W.diagonal())
        mean_diag = float(np.mean(diag[diag > 0])) if np.any(diag > 0) else 1.0
        self.nc = problem.nc
        self.norm_q = float(np.linalg.norm(problem.q))
        self.r_bound = UNBOUNDED * max(self.norm_q, np.finfo(float).tiny) / mean_diag


def check_method(problem, method: str) -> None:
    """Refuse a method that cannot take the problem's laws, in one line."""
    if method in LAW_METHODS:
        return
    a, law = next((a, law) for a, law in enumerate(problem.laws)
                  if not isinstance(law, float) and "cone" not in law.capabilities)
    raise FrictionRulesError(
        f"method = {method!r} violates: one of {list(LAW_METHODS)} for contact {a}'s law "
        f"{short(law)}: {method} needs every law to be an elliptic cone with a constant "
        "dilatancy ratio (capability 'cone')")


def metric_rows(problem, ls: LawSet, D) -> np.ndarray:
    """The laws' rows with each contact's ``kt, kn`` from its diagonal block ``D`` of W
    (:func:`._law_kernels.metric_rows`)."""
    return _kernels().metric_rows(ls.rows, np.ascontiguousarray(D, dtype=float))


def solve_law(problem, method, tol, max_iter, r0, opts, callback, time_limit, t0, c0) -> Solution:
    """:func:`~frictionrules.solve` on the law path (arguments checked by the caller; ``opts``
    the method's options record or None). ``"nsgs"``: sweeps; ``"polish"``: Newton steps
    (:mod:`._law_polish`) from ``r0``; ``"auto"``: :data:`AUTO_SWEEPS` sweeps, then the
    polish, then twice as many sweeps, and so on."""
    from ..contact import workspace
    from ._kernels import diagonal_blocks
    from ._law_polish import polish
    from ._options import NSGSOptions
    check_method(problem, method)
    nsgs_opts = opts if isinstance(opts, NSGSOptions) else NSGSOptions()
    ls = law_set(problem)
    K = _kernels()
    W = problem.W
    csr = (W.indptr.astype(np.int32, copy=False), W.indices.astype(np.int32, copy=False), W.data)
    D = diagonal_blocks(*csr, problem.nc)
    rows_k = metric_rows(problem, ls, D)
    fr = _LawFrame(problem)
    mon = _Monitor(fr, tol, time_limit, callback)
    n = 3 * problem.nc
    if r0 is None:
        r = np.zeros(n)
    else:
        from ._frame import initial_reactions
        r = initial_reactions(r0, n)
    ws = workspace(0)
    done, ran = 0, []

    def sweeps(budget):
        """NSGS sweeps on ``r`` (in place); True when the monitor stops the run."""
        nonlocal done
        chunk, end = 1, done + budget
        while done < end:
            m = min(chunk, end - done)
            hist_err, hist_it = np.full(m, np.nan), np.zeros(m, dtype=np.int64)
            t = time.perf_counter()
            it, err, nh = K.law_nsgs(*csr, D, problem.q, ls.fn, rows_k, ls.rows, ls.ell, ls.dilatant, r, tol, m,
                                     hist_err, hist_it, fr.norm_q, nsgs_opts.max_check_interval,
                                     LOCAL_ITER, LOCAL_TOL, ws)
            per_sweep = (time.perf_counter() - t) / max(it, 1)
            for k in range(nh - 1):
                mon.errors.append(float(hist_err[k]))
                mon.iterations.append(done + int(hist_it[k]))
            done += it
            if mon.record("nsgs", done, r, err):
                return True
            chunk = int(max(1, min(10 * chunk + 10, nsgs_opts.chunk_seconds / max(per_sweep, 1e-9))))
        return False

    def newton(steps):
        nonlocal r

        def record(rr, err):
            nonlocal done
            done += 1
            return mon.record("polish", done, rr, err)

        r, _err, _k, stop = polish(problem, ls, rows_k, r, tol, steps, lambda x: law_error(problem, x),
                                   record, ws)
        return stop or _err <= tol

    if method == "nsgs":
        ran.append("nsgs")
        sweeps(max_iter)
    elif method == "polish":
        ran.append("polish")
        newton(max_iter)
    else:
        budget = AUTO_SWEEPS
        while done < max_iter:
            ran.append("nsgs")
            if sweeps(min(budget, max_iter - done)) or done >= max_iter:
                break
            ran.append("polish")
            if newton(min(AUTO_POLISH_STEPS, max_iter - done)):
                break
            budget *= 2
    u = problem.velocity(r)
    err = law_error(problem, r, u)
    bounded = bool(np.linalg.norm(r) <= fr.r_bound)
    reason = mon.reason or "max_iter"
    if err <= tol and bounded:
        reason = "converged"
    elif reason == "converged":
        reason = "max_iter" if bounded else "unbounded"
    stages = "+".join(dict.fromkeys(ran)) if ran else method
    return Solution(r=r, u=u, error=err, iterations=int(done), converged=reason == "converged",
                    history=np.array(mon.errors), history_iterations=np.array(mon.iterations, dtype=int),
                    method=stages, seconds=time.perf_counter() - t0, reason=reason,
                    cpu_seconds=time.thread_time() - c0, error_measure="law")
