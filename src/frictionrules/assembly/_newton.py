r"""The pieces of the implicit increment's Newton iteration that handle mechanisms, changes of
a contact's status and rattlers (:func:`frictionrules.assembly._solver.solve_increment`).

**Mechanisms.** A sliding contact's consistent tangent has no stiffness along its flow
direction (it stays on the limit surface as long as it keeps sliding within the increment).
Where the sliding contacts of a sample form a mechanism — a motion of the grains that moves
each of them along its flow direction — the Jacobian ``J`` is singular, and at the plateau of
a test it is close to singular in ever more directions (the residual tangential stiffness of
a sliding contact decays with its slip). Newton's step along such a mode is the residual's
component on it over a stiffness that is zero or round-off: its amplitude is not fixed by the
linearized equations. Such modes are kept out of the Newton step (:func:`newton_direction`);
the part of the residual on them (the load on the mechanism) is balanced only once a contact
changes status, so where it dominates the residual the mechanism is moved to its next change
of status (:func:`along_mechanism`): a contact stops sliding, starts sliding, opens or closes.

**Changes of status.** Every change of a contact's status is a kink of the residual; a Newton
step that crosses one is tried at the first change along it before it is halved
(:func:`line_search`).

**Rattlers.** Grains held by fewer than two contacts (:func:`rattlers`) carry no force in
equilibrium: a single force cannot be balanced. They are left out of the unknowns (they move
with the cell) instead of being held by a regularization.
"""

from __future__ import annotations

import numpy as np

from .._returnspec import backtrack, sufficient_decrease

__all__ = ["MECHANISM", "newton_direction", "line_search", "along_mechanism", "rattlers",
           "PERMC_SPEC", "PIVOT_THRESHOLD"]

#: A mode of the Jacobian that keeps less than this fraction of its elastic stiffness is a
#: mechanism (:func:`newton_direction`).
MECHANISM = 1e-6
#: The identity's share (relative to the mean diagonal of the elastic Jacobian) in the metric
#: of the mechanisms: it holds the spins and grains no closed contact holds.
FREE_SHIFT = 1e-8
#: Halvings of the line search.
HALVINGS = 11
#: Bisections locating the first change of a contact's status along a step (the change is
#: then located to 2⁻³⁰ of the step: a contact that stops sliding there keeps its force).
EVENT_BISECTIONS = 30
#: Column ordering and partial-pivoting threshold of the sparse LU (SuperLU): minimum degree on
#: the pattern of ``J + Jᵀ`` (the grain graph: ``J`` is symmetric in pattern) with the
#: diagonal preferred as pivot (``J`` is nearly symmetric, its diagonal strong).
#: ``benchmarks/assembly.py`` measures it against SciPy's default (COLAMD, threshold 1).
PERMC_SPEC = "MMD_AT_PLUS_A"
PIVOT_THRESHOLD = 0.01


def jacobian(B, S, dense: bool):
    """``Bᵀ S B`` for the block-diagonal ``S`` (m, 3, 3): dense, or sparse CSC."""
    m = S.shape[0]
    if dense:
        return B.T @ (S @ B.reshape(m, 3, -1)).reshape(3 * m, -1)
    from .._optional import require
    sparse = require("scipy.sparse")
    Sm = sparse.bsr_matrix((S, np.arange(m), np.arange(m + 1)), shape=(3 * m, 3 * m))
    return (B.T @ (Sm @ B)).tocsc()


def newton_direction(B, S, S_elastic, R, dense: bool, *, permc_spec: str = PERMC_SPEC,
                     pivot_threshold: float = PIVOT_THRESHOLD):
    r"""Newton's step for ``J dx = -R`` (``J = Bᵀ S B``, the consistent tangents ``S``) without
    its part on the mechanisms.

    A mechanism is a mode that keeps less than ``ε =`` :data:`MECHANISM` of its elastic
    stiffness: ``J v = λ M v`` with ``λ ≪ ε``, ``M = E + η I`` (``E = Bᵀ S_elastic B`` the
    elastic Jacobian, ``η`` a small multiple of its mean diagonal for what no closed contact
    holds). With ``A = J + ε M``, ``y = -A⁻¹R``, ``z₁ = ε A⁻¹ M y`` and ``z₂ = ε A⁻¹ M z₁`` have
    on a mode the factors ``-(1 - q)/λ``, ``-q(1 - q)/λ`` and ``-q²(1 - q)/λ`` with
    ``q = ε/(λ + ε)``; the step ``dx = y + z₁ - 2 z₂`` has ``-(1 - q)²(1 + 2q)/λ``: Newton's
    ``-1/λ`` to within ``3q² ≈ 3(ε/λ)²`` on the stiff modes, and ``-3λ/ε²`` (nothing) on the
    mechanisms, whose amplitude the linearized equations do not fix. It leaves the residual
    ``R + J dx`` (``(3q² - 2q³)`` of each mode's): the load on the mechanisms, which no
    neighbouring configuration with the same statuses balances.

    Returns ``(dx, y - dx, R + J dx)`` — the step, its part on the mechanisms (where the load
    drives them, :func:`along_mechanism`) and that load — or None where the factorization
    fails.
    """
    J = jacobian(B, S, dense)
    E = jacobian(B, S_elastic, dense)
    diag = np.abs(E.diagonal())
    scale = float(diag.mean()) if diag.size and diag.max() > 0 else 1.0
    n = J.shape[0]
    if dense:
        M = E + FREE_SHIFT * scale * np.eye(n)
        try:
            solve = np.linalg.inv(J + MECHANISM * M).__matmul__
        except np.linalg.LinAlgError:
            return None
    else:
        from .._optional import require
        sparse = require("scipy.sparse")
        spla = require("scipy.sparse.linalg")
        M = (E + sparse.identity(n, format="csc") * (FREE_SHIFT * scale)).tocsc()
        try:
            solve = spla.splu((J + MECHANISM * M).tocsc(), permc_spec=permc_spec,
                              diag_pivot_thresh=pivot_threshold).solve
        except RuntimeError:
            return None
    y = solve(-R)
    z1 = MECHANISM * solve(M @ y)
    z2 = MECHANISM * solve(M @ z1)
    dx = y + z1 - 2 * z2
    if not np.all(np.isfinite(dx)):
        return None
    return dx, y - dx, R + J @ dx


def accepts(trial, ev, t: float, rtol: float) -> bool:
    """Armijo's sufficient decrease of the merit (:func:`frictionrules._returnspec.
    sufficient_decrease`) or convergence at step length ``t``."""
    return trial.residual <= rtol or bool(sufficient_decrease(trial.merit, ev.merit, t))


def first_change(evaluate, x, d, status, lo: float, hi: tuple) -> tuple:
    """Bisect ``(lo, hi[0]]`` for the first point of ``x + t d`` where a contact's status
    differs from ``status`` (it does at ``hi = (t, evaluation)``); returns ``(t, evaluation)``
    just past it."""
    for _ in range(EVENT_BISECTIONS):
        mid = 0.5 * (lo + hi[0])
        trial = evaluate(x + mid * d)
        if np.any(trial.status != status):
            hi = (mid, trial)
        else:
            lo = mid
    return hi


def line_search(evaluate, x, dx, ev, rtol: float):
    """Backtracking along Newton's step ``dx`` from ``x`` (evaluation ``ev``); returns
    ``(x, evaluation, t)`` (``t`` the fraction of the step taken) or None.

    The full step, else the first of the halved steps that decreases the merit enough
    (Armijo). A step that changes the status of a contact (sticking, sliding, open) crosses a
    kink of the residual beyond which the linearization does not hold: there the point just
    past the first change is tried too, and the better of the two is taken.
    """
    trial = evaluate(x + dx)
    if accepts(trial, ev, 1.0, rtol):
        return x + dx, trial, 1.0
    best = None
    if np.any(trial.status != ev.status):
        t, first = first_change(evaluate, x, dx, ev.status, 0.0, (1.0, trial))
        if accepts(first, ev, t, rtol):
            best = (x + t * dx, first, t)
    t, trial, ok = backtrack(lambda t: evaluate(x + t * dx),
                             lambda trial, t: accepts(trial, ev, t, rtol), 0.5, HALVINGS)
    if ok and (best is None or trial.merit < best[1].merit):
        best = (x + t * dx, trial, t)
    return best


def along_mechanism(evaluate, B, x, ev, z, max_move: float, rtol: float):
    """Move along the mechanism ``z`` (the part of Newton's step on the mechanisms) to the
    first change of a contact's status; returns ``(x, evaluation, t)``, or None where none
    comes within ``max_move`` (the mechanism runs away: no equilibrium near ``x``).

    Along a mechanism of the sliding contacts their forces do not change: the load on it is
    balanced only once a contact stops sliding, starts sliding, opens or closes.
    ``z ≈ -Σ (vᵀR/ε) v`` points where that load drives the mechanism; the distance is found
    by doubling from ``2⁻³⁰`` of the increment's largest contact displacement, then bisection.
    """
    dz = np.abs(B @ z)
    if not dz.size or not dz.max() > 0:
        return None
    d = z / dz.max()                      # unit largest contact displacement
    scale = float(np.abs(ev.u).max())
    t, lo = (scale if scale > 0 else max_move) * 2.0 ** -30, 0.0
    while t <= max_move:
        trial = evaluate(x + t * d)
        if trial.residual <= rtol:
            return x + t * d, trial, t
        if np.any(trial.status != ev.status):
            t, first = first_change(evaluate, x, d, ev.status, lo, (t, trial))
            return x + t * d, first, t
        lo, t = t, 2 * t
    return None


def rattlers(n: int, i: np.ndarray, j: np.ndarray, holding: np.ndarray) -> np.ndarray:
    """The grains held by fewer than two contacts, found by pruning: ``(n,)`` bool.

    ``holding`` (m,) marks the contacts that can carry a force (closed, or open by less than
    the tolerance). A grain with one such contact cannot balance its force, so it carries none
    in equilibrium; it is removed with its contact, which may leave a neighbour with fewer
    than two, and so on (the grains that remain are the 2-core of the contact graph). A
    contact of a grain with its own image counts twice (two points of contact). This is
    Thornton's criterion for the grains that take part in the stress (grains with 0 or 1
    contacts, "rattlers"); in a frictional packing two contacts can hold a grain (the forces
    opposite along the line through both contact points, within both friction cones), so the
    frictionless criterion (d + 1 contacts) would remove grains that carry load.
    """
    alive = np.ones(n, dtype=bool)
    hold = np.asarray(holding, dtype=bool).copy()
    while True:
        count = np.bincount(i[hold], minlength=n) + np.bincount(j[hold], minlength=n)
        out = alive & (count < 2)
        if not out.any():
            return ~alive
        alive &= ~out
        hold &= alive[i] & alive[j]
