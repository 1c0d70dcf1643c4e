r"""The error Siconos reports for a 3-D frictional contact problem (``fc3d_compute_error``).

For :math:`u = W r + q` and per contact the modified velocity
:math:`\hat u_a = u_a + \mu_a |u_{aT}|\, e_N` (De Saxcé), the error is the normalized norm of
the natural map

.. math::

    e(r) = \frac{\sqrt{\sum_a |r_a - P_{K_a}(r_a - \hat u_a)|^2}}
                {\max(|q|, |r|, |u|)} ,

the division being skipped when the scale is at most the machine epsilon. ``P_K`` is the
projection on the Coulomb cone :math:`K_\mu = \{|r_T| \le \mu r_N\}`: with :math:`t = |z_T|`,

* :math:`P_K(z) = 0` if :math:`\mu t \le -z_N` (polar cone),
* :math:`P_K(z) = z` if :math:`t \le \mu z_N` (inside),
* otherwise :math:`s = (z_N + \mu t)/(1 + \mu^2)`, :math:`P_K(z) = (s, \mu s z_T/t)`.

:math:`e = 0` exactly at a solution of :math:`K \ni r \perp \hat u \in K^*`. For a contact
with another law of this library the same formula is evaluated in its circular frame with the
generalized modified velocity :math:`\hat u_N = u_N + \bar\mu(1 - d)|\tilde u_T|` (see
:mod:`frictionrules.multicontact.problem`), the norms of the scale included; for plain Coulomb
contacts the frame is the identity and the value is Siconos' to rounding.
"""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError, check_finite

__all__ = ["fc3d_error", "project_cone"]


def project_cone(z, mu) -> np.ndarray:
    r"""Projection of ``z`` (``(..., 3)``, ordered ``(N, T1, T2)``) on the cone :math:`K_\mu`."""
    z = np.asarray(z, dtype=float)
    mu = np.asarray(mu, dtype=float)
    zn, zt = z[..., 0], z[..., 1:]
    t = np.linalg.norm(zt, axis=-1)
    polar = mu * t <= -zn
    inside = t <= mu * zn
    s = (zn + mu * t) / (1.0 + mu * mu)
    with np.errstate(divide="ignore", invalid="ignore"):
        et = np.where(t[..., None] > 0, zt / np.where(t > 0, t, 1.0)[..., None], 0.0)
    out = np.concatenate((s[..., None], (mu * s)[..., None] * et), axis=-1)
    out = np.where(inside[..., None], z, out)
    return np.where(polar[..., None], 0.0, out)


def fc3d_error(problem, r, u=None) -> float:
    r"""Siconos' normalized natural-map error of ``r`` for ``problem`` (see the module docstring).

    Parameters
    ----------
    problem : FrictionContactProblem
    r : (3 nc,) array
        Reactions in the problem's own (contact) frame.
    u : (3 nc,) array, optional
        Velocities; :math:`W r + q` when omitted (Siconos recomputes it too).

    Returns
    -------
    float
    """
    if problem.path != "cone":
        raise FrictionRulesError("problem = the law path (a law that is not an elliptic cone) "
                                 "violates: fc3d_error needs every contact's law to declare the "
                                 "capability 'cone'; use law_error")
    r, u = checked_vectors(problem, r, u)
    rr, uu, qq = r.reshape(-1, 3).copy(), u.reshape(-1, 3).copy(), problem.q.reshape(-1, 3).copy()
    if problem.frames is not None:  # to the circular frame: r~_T = A^-1 r_T, u~_T = A^T u_T
        rr[:, 1:] = np.linalg.solve(problem.frames, rr[:, 1:, None])[..., 0]
        uu[:, 1:] = np.einsum("aji,aj->ai", problem.frames, uu[:, 1:])
        qq[:, 1:] = np.einsum("aji,aj->ai", problem.frames, qq[:, 1:])
    scale = max(np.linalg.norm(qq), np.linalg.norm(rr), np.linalg.norm(uu))
    mu, d = problem.mu_bar, problem.dilatancy
    uhat = uu.copy()
    uhat[:, 0] += mu * (1.0 - d) * np.linalg.norm(uu[:, 1:], axis=-1)
    res = rr - project_cone(rr - uhat, mu[:, None][..., 0])
    err = float(np.sqrt(np.sum(res * res)))
    return err / scale if scale > np.finfo(float).eps else err


def checked_vectors(problem, r, u):
    """``r`` and ``u`` (``problem.velocity(r)`` where None) as contiguous float vectors of
    ``3 nc`` finite entries, checked where they enter."""
    n = 3 * problem.nc
    r = check_finite("r", r).ravel()
    if r.size != n:
        raise FrictionRulesError(f"r has {r.size} entries; constraint: 3 nc = {n}")
    u = problem.velocity(r) if u is None else check_finite("u", u).ravel()
    if u.size != n:
        raise FrictionRulesError(f"u has {u.size} entries; constraint: 3 nc = {n}")
    return np.ascontiguousarray(r, dtype=float), np.ascontiguousarray(u, dtype=float)
