r"""Coulomb's problem beside its associated (dilatant, convex) relaxation.

Coulomb's sliding rule (1.5) has no normal slip: the sliding potential is :math:`g = |T|`, not
the limit function :math:`f = |T| - \mu N`. The associated rule (1.6), :math:`g = f`, would make
the block separate from the surface at :math:`V_z = \mu|V_t|` while it slides, and then the
contact dissipates nothing: the friction work :math:`T\cdot V_t` is spent lifting the normal
force. With that rule the many-contact problem is a convex cone complementarity problem (the
optimality conditions of a quadratic program over the cones when W is symmetric), the problem
convex solvers and most physics engines actually solve. :func:`compare_relaxation` solves
both and says how far apart they are; ``docs/relaxation.md`` discusses it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .problem import FrictionContactProblem, Solution

__all__ = ["compare_relaxation", "RelaxationComparison"]


@dataclass(frozen=True)
class RelaxationComparison:
    r"""Coulomb's answer, the associated relaxation's, and their distance.

    Attributes
    ----------
    coulomb, associated : Solution
        Both problems solved from zero.
    coulomb_error_of_associated : float
        Siconos' error of the associated answer for Coulomb's problem: how wrong the convex
        relaxation is as an answer to the real one.
    dissipation_coulomb, dissipation_associated : float
        :math:`D = \sum_a T\cdot v_t - N v_n = -\sum_a r_a\cdot u_a` (the power (1.7) with the
        normal term, ``docs/conventions.md``). Coulomb's is :math:`\sum \mu r_N|u_T| \ge 0`;
        the associated one is zero at its solution (:math:`r \perp u`).
    friction_work_associated : float
        :math:`-\sum_a r_{aT}\cdot u_{aT}`, the tangential work of the associated answer,
        returned as lifting work :math:`\sum r_N u_N`.
    normal_velocity_coulomb, normal_velocity_associated : float
        Largest normal velocity :math:`u_N` at a loaded contact (:math:`r_N > 10^{-6}\max r_N`): zero for
        Coulomb, :math:`\mu|u_T|` at the sliding contacts of the associated answer.
    sliding_coulomb, sliding_associated : int
        Loaded contacts that slide: on the cone's boundary, :math:`|u_T|` above :math:`10^{-6}`
        of the velocity scale :math:`\max(|q|_\infty, |u|_\infty)`.
    warm_started : Solution
        Coulomb's problem solved from the associated answer.
    """

    coulomb: Solution
    associated: Solution
    coulomb_error_of_associated: float
    dissipation_coulomb: float
    dissipation_associated: float
    friction_work_associated: float
    normal_velocity_coulomb: float
    normal_velocity_associated: float
    sliding_coulomb: int
    sliding_associated: int
    warm_started: Solution


def _loaded_stats(problem: FrictionContactProblem, s: Solution):
    """Largest u_N at a loaded contact, and the loaded contacts that slide: on the cone's
    boundary, with |u_T| above 1e-6 of the velocity scale max(|q|, |u|) (max norms)."""
    r, u = s.r.reshape(-1, 3), s.u.reshape(-1, 3)
    loaded = r[:, 0] > 1e-6 * max(float(np.max(r[:, 0], initial=0.0)), np.finfo(float).tiny)
    ut, rt = np.linalg.norm(u[:, 1:], axis=1), np.linalg.norm(r[:, 1:], axis=1)
    scale = max(float(np.max(np.abs(problem.q), initial=0.0)), float(np.max(np.abs(u), initial=0.0)))
    on_cone = rt >= problem.mu_bar * r[:, 0] * (1.0 - 1e-6)
    un = float(np.max(u[loaded, 0])) if loaded.any() else 0.0
    return un, int(np.sum(loaded & on_cone & (ut > 1e-6 * scale)))


def compare_relaxation(problem: FrictionContactProblem, method: str = "auto", tol: float = 1e-8,
                       **solve_kwargs) -> RelaxationComparison:
    """Solve ``problem`` and its associated relaxation (:meth:`FrictionContactProblem.associated`)
    with :func:`~frictionrules.solve` (same ``method``, ``tol`` and keyword arguments), and
    Coulomb's again from the associated answer; see :class:`RelaxationComparison`."""
    from ._solve import solve
    from .error import fc3d_error
    coulomb = solve(problem, method=method, tol=tol, **solve_kwargs)
    relaxed = problem.associated()
    assoc = solve(relaxed, method=method, tol=tol, **solve_kwargs)
    warm = solve(problem, method=method, tol=tol, r0=assoc.r, **solve_kwargs)
    un_c, sl_c = _loaded_stats(problem, coulomb)
    un_a, sl_a = _loaded_stats(problem, assoc)
    ra, ua = assoc.r.reshape(-1, 3), assoc.u.reshape(-1, 3)
    return RelaxationComparison(
        coulomb=coulomb, associated=assoc,
        coulomb_error_of_associated=fc3d_error(problem, assoc.r),
        dissipation_coulomb=float(-coulomb.r @ coulomb.u),
        dissipation_associated=float(-assoc.r @ assoc.u),
        friction_work_associated=float(-np.sum(ra[:, 1:] * ua[:, 1:])),
        normal_velocity_coulomb=un_c, normal_velocity_associated=un_a,
        sliding_coulomb=sl_c, sliding_associated=sl_a, warm_started=warm)
