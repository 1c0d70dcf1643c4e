r"""The return-map specification: every number and rule of the implicit return of a contact,
with its reason, in one place.

Read by every return of the package: the NumPy return (:mod:`frictionrules.contact.integrate`,
:mod:`frictionrules.contact._step`), the Numba kernel
(:mod:`frictionrules.contact._return_kernel`) and the C and Fortran printers of
:func:`frictionrules.export`, which print these values (:func:`placeholders`) instead of
literals of their own.

**The kink rule.** Where a law's symbolic limit condition is not finite (0/0 at the apex
``T = 0`` of a law written through the direction of T, e.g. the Huber ellipse
``|T| - N μ(θ)``), f is its largest value on the circle of radius
:math:`r = 10^{-9}(|T| + |N|) + 10^{-300}` around T in the tangential plane, sampled at
:data:`KINK_POINTS` points. Reason: it needs the symbolic form only, so a built-in law and a
user law written alike get the same answer on every path; the largest value (the upper
envelope) makes a point elastic only when its whole neighbourhood is, so a return is never
skipped. A derivative that is not finite there is 0 (the minimal-norm subgradient).

**The line search.** Every Newton iteration of the package that backtracks — the NumPy and
compiled returns, the force-controlled driver (:func:`frictionrules.drive`) and the grain
assembly's solver — takes a step of length α when :func:`sufficient_decrease` holds (Armijo's
rule on the norm of the residual) and halves α otherwise (:func:`backtrack` for the scalar
iterations; the returns' loops over many contacts apply the same rule elementwise).
"""

from __future__ import annotations

import math

__all__ = ["TOL", "MAX_ITER", "MAX_HALVINGS", "SUFFICIENT_DECREASE", "MAX_SUBSTEP_DEPTH",
           "KINK_RADIUS", "KINK_POINTS", "SCALAR_TOL", "SCALAR_MAX_ITER", "ELASTIC", "PLASTIC",
           "OPEN", "APEX", "FAILED", "GENERAL", "RETURN_GENERIC", "RETURN_RADIAL",
           "RETURN_ELLIPTIC", "RETURN_AFFINE", "RETURN_SIZE", "kink_circle", "placeholders",
           "sufficient_decrease", "backtrack"]

#: Newton tolerance on the dimensionless residual: a few hundred ulps of the force scale, far
#: below any physical tolerance and reached in one or two quadratic steps from 1e-7.
TOL = 1e-13
#: Newton iterations before a contact is substepped (quadratic convergence needs < 10).
MAX_ITER = 60
#: Step halvings of the backtracking line search (down to 2^-12 of a Newton step): a step that
#: needs more is a bad Newton direction, and a substep is cheaper than more halvings.
MAX_HALVINGS = 12
#: Armijo's constant of the line search: a step of length α is taken when the residual's norm
#: falls to ``(1 - SUFFICIENT_DECREASE α)`` of its value (Dennis & Schnabel's 1e-4: any real
#: decrease, yet enough to rule out stagnation).
SUFFICIENT_DECREASE = 1e-4
#: Halvings of a step whose return does not converge, before giving up (2^10 = 1024 substeps:
#: a step that needs more is not a step of the loading history but a jump).
MAX_SUBSTEP_DEPTH = 10
#: Relative radius of the circle of the kink rule: far below any physical force, far above
#: round-off of the force scale.
KINK_RADIUS = 1e-9
#: Points on that circle (every 45°: both axes and both diagonals, enough for a law whose f
#: depends on the direction of T through squares of its components).
KINK_POINTS = 8
#: Relative tolerance of a return reduced to one scalar equation (a few ulps: Newton's
#: iteration on a convex function converges monotonically, to round-off).
SCALAR_TOL = 1e-15
#: Iterations of such a scalar Newton iteration (halvings of a step included).
SCALAR_MAX_ITER = 200

#: How a law's return is solved (:func:`frictionrules.codegen.return_structure`, recognised from
#: its symbolic form): Newton's method on the whole system (any law); the radial return along a
#: flow direction that does not turn (one scalar equation, closed form where f is linear along
#: it); the elliptic section's one scalar equation; Newton's method on the system reduced to
#: (Δλ, q) where the forces follow from them in closed form (a flow direction affine in the
#: forces). The special ones fall back to the general return where their assumptions fail at a
#: contact (a path through the apex, N < 0, no convergence).
RETURN_GENERIC, RETURN_RADIAL, RETURN_ELLIPTIC, RETURN_AFFINE = 0, 1, 2, 3
#: Numbers of a law's return block: kind, linear flag, cos and sin of the principal frame and
#: the eigenvalues of A, and the ratio c of the elliptic return.
RETURN_SIZE = 7

#: Status codes of an update, per contact (``frictionrules.contact.state``).
ELASTIC, PLASTIC, OPEN = 0, 1, 2
#: Outcomes of one return inside the compiled and exported updates: a return that ends at the
#: apex of a cone (reported as OPEN), and a Newton iteration that failed (the step is halved).
APEX, FAILED = 3, -1
#: What a law's generated step returns for a contact it leaves to the general return (a limit
#: condition that is not finite at the trial, a return through the apex, N <= 0 on the way).
GENERAL = -2


def sufficient_decrease(trial, merit, alpha):
    r"""Armijo's rule: a step of length ``alpha`` (a fraction of Newton's step) is taken when
    the merit (the norm of the residual, >= 0) falls to
    :math:`\|R(x + \alpha d)\| \le (1 - c\,\alpha)\,\|R(x)\|`, ``c`` =
    :data:`SUFFICIENT_DECREASE`, and is finite.

    Plain arithmetic and comparisons: the same function for scalars, NumPy arrays (elementwise)
    and compiled code (Numba compiles it where a kernel calls it).
    """
    return (trial < math.inf) & (trial <= (1.0 - SUFFICIENT_DECREASE * alpha) * merit)


def backtrack(evaluate, accept, alpha: float, tries: int):
    """The backtracking line search of a scalar Newton iteration: ``evaluate(α)`` at
    ``α = alpha, alpha/2, ...`` (``tries`` values) until ``accept(value, α)`` (usually
    :func:`sufficient_decrease` of the value's merit). Returns ``(α, value, accepted)``: the
    first accepted step, else the last one tried with ``accepted`` false."""
    for k in range(tries):
        if k:
            alpha *= 0.5
        value = evaluate(alpha)
        if accept(value, alpha):
            return alpha, value, True
    return alpha, value, False


def kink_circle(T1, T2, N):
    """Points of the kink rule's circle around ``(T1, T2)`` at ``N`` (arrays broadcast):
    ``(t1, t2)`` each of shape ``(KINK_POINTS, ...)``."""
    import numpy as np
    r = KINK_RADIUS * (np.hypot(T1, T2) + np.abs(N)) + 1e-300
    a = (2.0 * np.pi / KINK_POINTS) * np.arange(KINK_POINTS).reshape((-1,) + (1,) * np.ndim(r))
    return T1 + r * np.cos(a), T2 + r * np.sin(a)


def placeholders(real) -> dict[str, str]:
    """The ``@NAME@`` placeholders of the C and Fortran templates and their values, floats
    printed by ``real`` (``repr`` for C, ``1.0D-13`` for Fortran)."""
    return {"@TOL@": real(TOL), "@MAX_ITER@": str(MAX_ITER), "@MAX_HALVINGS@": str(MAX_HALVINGS),
            "@SUFFICIENT_DECREASE@": real(SUFFICIENT_DECREASE),
            "@MAX_DEPTH@": str(MAX_SUBSTEP_DEPTH), "@FULL@": str(2 ** MAX_SUBSTEP_DEPTH),
            "@KINK_RADIUS@": real(KINK_RADIUS), "@KINK_POINTS@": str(KINK_POINTS),
            "@KINK_LAST@": str(KINK_POINTS - 1), "@KINK_ANGLE@": real(6.283185307179586 / KINK_POINTS),
            "@SCALAR_TOL@": real(SCALAR_TOL), "@SCALAR_MAX_ITER@": str(SCALAR_MAX_ITER),
            "@ELASTIC@": str(ELASTIC), "@PLASTIC@": str(PLASTIC), "@OPEN@": str(OPEN),
            "@APEX@": str(APEX), "@FAILED@": str(FAILED)}
