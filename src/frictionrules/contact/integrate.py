r"""Integration of the elastic-plastic contact law (4.1)–(4.7): the implicit return mapping,
its consistent tangent, and the explicit rate form (4.10)–(4.11).

Everything works on batches: forces ``sigma = (T1, T2, N)`` of shape ``(n, 3)`` and the law's
internal variables ``q`` of shape ``(n, nq)`` (none for a perfectly plastic law; ``(kappa,)``
with slip hardening; ``(kappa, beta)`` for the cap (4.9)). The elastic law (4.2), written in the
frictionrules convention (``δn`` positive on opening, ``N > 0`` compression), is

.. math:: T = k_t(\delta_t - \delta_t^p), \qquad N = -k_n(\delta_n - \delta_n^p),

and the sliding rule (4.3) :math:`\dot\delta^p = \dot\lambda\,(g_{,T_1}, g_{,T_2}, -g_{,N})`.
Both together give, in the force space ``(T1, T2, N)``, the familiar

.. math:: \dot\sigma = E\dot\delta - \dot\lambda\, D\,\nabla g, \qquad
          E = \mathrm{diag}(k_t, k_t, -k_n),\; D = \mathrm{diag}(k_t, k_t, k_n).

Backward Euler (closest-point projection in the energy metric when g = f) solves for
``(sigma, q, Δλ)``

.. math:: \sigma - \sigma^{tr} + \Delta\lambda D\nabla g(\sigma, q) = 0,\quad
          q - q_n - \Delta\lambda\, h(\sigma, q) = 0,\quad f(\sigma, q) = 0,

with the law's evolution :math:`h = \dot q/\dot\lambda` (4.5), e.g.
:math:`h = (|g_{,T}|,\; B(\beta) g_{,N})` for the cap, by Newton's method with a
backtracking line search. The consistent tangent is the σ-block of the inverse Newton
Jacobian times ``E``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._returnspec import KINK_POINTS, MAX_HALVINGS, MAX_ITER, TOL, kink_circle, sufficient_decrease
from ..laws import LocalDerivatives
from ..laws.base import safe_ratio

class Surface:
    r"""A law of the protocol seen by the return mapping: forces ``sigma = (T1, T2, N)`` and the
    law's internal variables ``q`` as rows of arrays ``(n, 3)`` and ``(n, nq)``.

    Everything comes from the law's symbolic form (:meth:`FrictionLaw.local`). Derivatives that
    are not finite at a kink (the apex ``T = 0`` of a cone: 0/0 in the gradient of ``|T|``, an
    unbounded Hessian) are replaced by 0, the minimal-norm subgradient and its derivative.
    Laws defined for ``N >= 0`` only are evaluated at ``max(N, 0)`` along Newton iterates with
    ``N < 0``. Returns that end at the apex of a cone are recognized by :meth:`apex_region`.
    """

    def __init__(self, law):
        self.law = law
        self.nq = len(law.state_names)
        self._clip = not law.defined_in_tension

    def _N(self, sigma):
        return np.maximum(sigma[:, 2], 0.0) if self._clip else sigma[:, 2]

    def limit(self, sigma, q):
        """f at ``(sigma, q)`` from the law's symbolic form, by the kink rule where it is not
        finite (:mod:`frictionrules._returnspec`)."""
        return self.evaluate(sigma, q).f

    def _kink(self, sigma, q):
        """The kink rule: the largest f on a small circle around T (every path uses it)."""
        t1, t2 = kink_circle(sigma[:, 0], sigma[:, 1], self._N(sigma))
        n = len(sigma)
        ring = np.repeat(sigma[None], KINK_POINTS, axis=0)
        ring[..., 0], ring[..., 1] = t1, t2
        ring = ring.reshape(-1, 3)
        f = self.law.local_derivatives(ring[:, :2], self._N(ring), np.tile(q, (KINK_POINTS, 1))).f
        return np.max(np.reshape(f, (KINK_POINTS, n)), axis=0)

    def evaluate(self, sigma, q) -> LocalDerivatives:
        loc = self.law.local_derivatives(sigma[:, :2], self._N(sigma), q)
        parts = {k: getattr(loc, k) for k in LocalDerivatives.__dataclass_fields__}
        bad = ~np.isfinite(parts["f"])
        if bad.any():
            parts["f"] = parts["f"].copy()
            parts["f"][bad] = self._kink(sigma[bad], q[bad])
        for k, a in parts.items():
            if k != "f":
                parts[k] = np.where(np.isfinite(a), a, 0.0)
        return LocalDerivatives(**parts)

    def apex_region(self, sigma_tr, q, Dv):
        r"""Trial forces whose backward-Euler return ends at the apex ``σ = 0`` of a cone.

        Near the apex of a positively homogeneous law the flow direction ∇g depends on the
        direction only; approaching along the trial's tangential direction it is
        :math:`\nabla g(T^{tr}, 0)`. Returning along it, N reaches 0 no later than T when
        :math:`g_{,N} > 0` (compaction) and
        :math:`N^{tr}/(k_n g_{,N}) \le |T^{tr}|/(k_t |g_{,T}|)`: then the return ends at the
        apex. Only laws with ``f(0, 0) = 0`` (cones) have such an apex.
        """
        zero = np.zeros((1, 3))
        if not np.all(self.limit(zero, q[:1]) == 0.0):
            return np.zeros(len(sigma_tr), dtype=bool)
        at_plane = sigma_tr.copy()
        at_plane[:, 2] = 0.0
        dg = self.evaluate(at_plane, q).dg
        gt = np.hypot(dg[:, 0], dg[:, 1])
        Tt = np.hypot(sigma_tr[:, 0], sigma_tr[:, 1])
        return (dg[:, 2] > 0) & (sigma_tr[:, 2] * Dv[0] * gt <= Tt * Dv[2] * dg[:, 2])


def _jacobian(loc: LocalDerivatives, dlam, Dv):
    """Newton Jacobian of the backward-Euler residual in ``x = (sigma, q, Δλ)``, shape
    ``(n, 4 + nq, 4 + nq)``."""
    n, nq = len(dlam), loc.h.shape[-1]
    m = 3 + nq
    J = np.zeros((n, m + 1, m + 1))
    lam = dlam[:, None, None]
    J[:, :3, :3] = np.eye(3) + lam * Dv[None, :, None] * loc.hgg
    J[:, :3, 3:m] = lam * Dv[None, :, None] * loc.hgq
    J[:, :3, m] = Dv * loc.dg
    J[:, 3:m, :3] = -lam * loc.dhs
    J[:, 3:m, 3:m] = np.eye(nq) - lam * loc.dhq
    J[:, 3:m, m] = -loc.h
    J[:, m, :3] = loc.df
    J[:, m, 3:m] = loc.dfq
    return J


def _residual(loc: LocalDerivatives, sigma, q, dlam, sigma_tr, q_n, Dv):
    nq = q.shape[-1]
    R = np.empty((len(dlam), 4 + nq))
    R[:, :3] = sigma - sigma_tr + dlam[:, None] * Dv * loc.dg
    R[:, 3:3 + nq] = q - q_n - dlam[:, None] * loc.h
    R[:, 3 + nq] = loc.f
    return R


@dataclass(frozen=True)
class ReturnResult:
    """Outcome of :func:`return_map` per row: the converged point and the tangent block."""

    sigma: np.ndarray
    q: np.ndarray
    dlam: np.ndarray
    converged: np.ndarray
    dsigma_dtrial: np.ndarray


def _scales(surface, sigma_tr, q_n, Dv):
    r"""Row and column scales that make the Newton system dimensionless.

    Forces scale with :math:`F = |\sigma^{tr}|`, the multiplier with :math:`F/|D\nabla g|`
    (the return of a step of size F), and each internal variable with the change that
    multiplier gives it, :math:`|h_i| F/|D\nabla g|`, or its own size if that is larger.
    """
    F = np.maximum(np.linalg.norm(sigma_tr, axis=-1), 1e-300)
    loc = surface.evaluate(sigma_tr, q_n)
    fs = np.maximum(np.linalg.norm(loc.df, axis=-1) * F, 1e-300)
    gs = np.maximum(np.linalg.norm(Dv * loc.dg, axis=-1), 1e-300)
    lam = F / gs
    qs = np.maximum(np.maximum(np.abs(loc.h) * lam[:, None], np.abs(q_n)), 1e-300)
    F3 = np.repeat(F[:, None], 3, axis=1)
    rows = np.concatenate((1 / F3, 1 / qs, (1 / fs)[:, None]), axis=-1)
    cols = np.concatenate((F3, qs, lam[:, None]), axis=-1)
    return rows, cols


def return_map(surface, sigma_tr, q_n, Dv) -> ReturnResult:
    """Backward-Euler return of the trial forces ``sigma_tr`` (n, 3) onto ``f = 0``.

    Newton's method on the dimensionless residual with a backtracking line search on its
    norm; a row converges when the scaled residual is below 1e-13 and ``Δλ >= 0``. Rows that
    do not converge are flagged (the caller substeps them).
    """
    n = len(sigma_tr)
    sigma, q, dlam = sigma_tr.copy(), q_n.copy(), np.zeros(n)
    rows, cols = _scales(surface, sigma_tr, q_n, Dv)
    loc = surface.evaluate(sigma, q)
    R = _residual(loc, sigma, q, dlam, sigma_tr, q_n, Dv) * rows
    merit = np.linalg.norm(R, axis=-1)
    active = np.ones(n, dtype=bool)
    for _ in range(MAX_ITER):
        active &= ~(merit <= TOL)
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        sub = _take(loc, idx)
        J = _jacobian(sub, dlam[idx], Dv) * rows[idx, :, None] * cols[idx, None, :]
        ok = np.isfinite(J).all(axis=(1, 2))
        J[~ok] = np.eye(J.shape[-1])
        step = -np.linalg.solve(J, R[idx][..., None])[..., 0] * cols[idx]
        step[~ok] = 0.0
        alpha = np.ones(idx.size)
        pending = np.ones(idx.size, dtype=bool)
        for _ in range(MAX_HALVINGS):
            k = idx[pending]
            s_k = step[pending] * alpha[pending, None]
            sig_k, q_k = sigma[k] + s_k[:, :3], q[k] + s_k[:, 3:-1]
            lam_k = dlam[k] + s_k[:, -1]
            loc_k = surface.evaluate(sig_k, q_k)
            R_k = _residual(loc_k, sig_k, q_k, lam_k, sigma_tr[k], q_n[k], Dv) * rows[k]
            m_k = np.linalg.norm(R_k, axis=-1)
            accept = sufficient_decrease(m_k, merit[k], alpha[pending])
            acc = k[accept]
            sigma[acc], q[acc], dlam[acc] = sig_k[accept], q_k[accept], lam_k[accept]
            R[acc], merit[acc] = R_k[accept], m_k[accept]
            loc = _put(loc, acc, _take(loc_k, np.flatnonzero(accept)))
            pos = np.flatnonzero(pending)
            pending[pos[accept]] = False
            alpha[pending] *= 0.5
            if not pending.any():
                break
        stuck = idx[pending]
        active[stuck] = False
        merit[stuck] = np.inf
    converged = (merit <= TOL) & (dlam >= 0)
    J = _jacobian(loc, dlam, Dv)
    good = np.isfinite(J).all(axis=(1, 2)) & converged
    dsig = np.zeros((n, 3, 3))
    if good.any():
        dsig[good] = np.linalg.inv(J[good])[:, :3, :3]
    return ReturnResult(sigma, q, dlam, converged & good, dsig)


def _take(loc: LocalDerivatives, idx) -> LocalDerivatives:
    return LocalDerivatives(*(getattr(loc, k)[idx] for k in LocalDerivatives.__dataclass_fields__))


def _put(loc: LocalDerivatives, idx, new: LocalDerivatives) -> LocalDerivatives:
    if len(idx) == 0:
        return loc
    out = {}
    for k in LocalDerivatives.__dataclass_fields__:
        a = getattr(loc, k).copy()
        a[idx] = getattr(new, k)
        out[k] = a
    return LocalDerivatives(**out)


def tangent_at(surface, sigma, q, dlam, Dv) -> np.ndarray:
    """``d sigma / d sigma_trial`` at a converged return ``(sigma, q, Δλ)``, shape (n, 3, 3).

    At a vertex of f where the return lands on ``T = 0`` with a vanishing gradient (the
    frictionless cone ``|T| <= 0``) the system is singular: there the tangential force is pinned
    at zero and the normal force elastic, ``diag(0, 0, 1)``.
    """
    J = _jacobian(surface.evaluate(sigma, q), dlam, Dv)
    out = np.zeros((len(J), 3, 3))
    finite = np.isfinite(J).all(axis=(1, 2))
    Jf = np.where(finite[:, None, None], J, 0.0)
    # Hadamard's bound |det J| <= Π |rows|: relative to it the determinant measures singularity
    bound = np.prod(np.linalg.norm(Jf, axis=2), axis=1)
    regular = finite & (np.abs(np.linalg.det(Jf)) > 1e-12 * bound)
    if regular.any():
        out[regular] = np.linalg.inv(J[regular])[:, :3, :3]
    out[~regular] = np.diag([0.0, 0.0, 1.0])
    return out


def rate_step(surface, sigma, q, dsigma_e, Dv):
    r"""One explicit (forward-Euler) step of the rate form (4.7), (4.10)–(4.11).

    With the elastic predictor rate :math:`\dot\sigma^e = E\dot\delta`, the plastic multiplier
    is :math:`\dot\lambda = \nabla f\cdot\dot\sigma^e / (H + \nabla f\cdot D\nabla g)`,
    :math:`H = -\nabla_q f\cdot h` ((4.7); (4.11) for the cap), and
    :math:`\dot\sigma = \dot\sigma^e - \dot\lambda D\nabla g`, :math:`\dot q = \dot\lambda h`.
    The elastic part of a step that crosses the surface is found by bisection first. No drift
    correction: this is the verification scheme, not the production one.

    Returns ``(sigma, q, dlam)`` after the step.
    """
    f0 = surface.limit(sigma, q)
    f1 = surface.limit(sigma + dsigma_e, q)
    frac = np.where(f1 <= 0, 1.0, 0.0)
    crossing = (f0 < 0) & (f1 > 0)
    lo, hi = np.zeros(len(f0)), np.ones(len(f0))
    if crossing.any():
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            fm = surface.limit(sigma + mid[:, None] * dsigma_e, q)
            inside = fm <= 0
            lo = np.where(crossing & inside, mid, lo)
            hi = np.where(crossing & ~inside, mid, hi)
        frac = np.where(crossing, lo, frac)
    s0 = sigma + frac[:, None] * dsigma_e
    rest = (1.0 - frac)[:, None] * dsigma_e
    loc = surface.evaluate(s0, q)
    H = -np.sum(loc.dfq * loc.h, axis=-1)
    den = H + np.sum(loc.df * Dv * loc.dg, axis=-1)
    load = np.sum(loc.df * rest, axis=-1)
    dlam = np.where((frac < 1.0) & (load > 0), safe_ratio(load, den), 0.0)
    sig = s0 + rest - dlam[:, None] * Dv * loc.dg
    return sig, q + dlam[:, None] * loc.h, dlam
