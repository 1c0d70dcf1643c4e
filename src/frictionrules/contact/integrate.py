r"""Integration of the elastic-plastic contact law (4.1)–(4.7): the implicit return mapping,
its consistent tangent, and the explicit rate form (4.10)–(4.11).

Everything works on batches: forces ``sigma = (T1, T2, N)`` of shape ``(n, 3)`` and hardening
variables ``q = (kappa, beta)`` of shape ``(n, 2)``. The elastic law (4.2), written in the
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

with :math:`h = (|g_{,T}|,\; B(\beta) g_{,N})` from (4.5), by Newton's method with a
backtracking line search. The consistent tangent is the σ-block of the inverse Newton
Jacobian times ``E``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..laws.base import safe_ratio

#: Newton tolerance on the scaled residual, and the iteration limits.
_TOL = 1e-13
_MAX_ITER = 60
_MAX_HALVINGS = 12


@dataclass(frozen=True)
class Local:
    """Everything the return mapping needs at one batch of points ``(sigma, q)``.

    ``f`` (n,), ``df`` (n, 3) and ``dfq`` (n, 2) the gradients of f in sigma and q, ``dg``
    (n, 3), ``hgg`` (n, 3, 3) and ``hgq`` (n, 3, 2) the gradient and Hessian blocks of g, ``h``
    (n, 2) the hardening rates per unit λ, ``dhs`` (n, 2, 3) and ``dhq`` (n, 2, 2) their
    derivatives.
    """

    f: np.ndarray
    df: np.ndarray
    dfq: np.ndarray
    dg: np.ndarray
    hgg: np.ndarray
    hgq: np.ndarray
    h: np.ndarray
    dhs: np.ndarray
    dhq: np.ndarray


def _hardening_rates(dg, hgg, hgq, B, dB, g_n):
    r"""(4.5): :math:`h = (|g_{,T}|, B g_{,N})` and its derivatives in sigma and q."""
    n = dg.shape[0]
    norm = np.hypot(dg[:, 0], dg[:, 1])
    e = np.stack((safe_ratio(dg[:, 0], norm), safe_ratio(dg[:, 1], norm)), axis=-1)
    h = np.stack((norm, B * g_n), axis=-1)
    dhs = np.empty((n, 2, 3))
    dhs[:, 0] = np.einsum("ni,nij->nj", e, hgg[:, :2, :])
    dhs[:, 1] = B[:, None] * hgg[:, 2, :]
    dhq = np.empty((n, 2, 2))
    dhq[:, 0] = np.einsum("ni,nij->nj", e, hgq[:, :2, :])
    dhq[:, 1] = B[:, None] * hgq[:, 2, :]
    dhq[:, 1, 1] += dB * g_n
    return h, dhs, dhq


class LawSurface:
    r"""A protocol law, optionally with the slip hardening ``s(κ)`` of :class:`SlipHardening`.

    :math:`\hat f(T, N, \kappa) = f(T, s(\kappa) N)`, :math:`\hat g = g(T, s(\kappa) N)`: the
    law's gradients and its SymPy-derived Hessians are used through the chain rule. At the
    apex ``T = 0`` of a cone the Hessian of ``|T|`` is unbounded; where it is not finite its
    entries are set to 0, the Hessian of the minimal-norm subgradient used by the gradients.

    Laws are defined for ``N >= 0``; Newton iterates with ``N < 0`` are evaluated at ``N = 0``.
    Returns that end at the apex of a cone are recognized by :meth:`apex_region`.
    """

    def __init__(self, law, hardening=None):
        self.law = law
        self.hardening = hardening

    def scale(self, kappa):
        if self.hardening is None:
            return np.ones_like(kappa), np.zeros_like(kappa)
        return self.hardening.scale(kappa), self.hardening.scale_derivative(kappa)

    def limit(self, sigma, q):
        s, _ = self.scale(q[:, 0])
        return self.law.limit(sigma[:, :2], s * np.maximum(sigma[:, 2], 0.0))

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

    def evaluate(self, sigma, q) -> Local:
        T, N = sigma[:, :2], np.maximum(sigma[:, 2], 0.0)
        s, ds = self.scale(q[:, 0])
        Ns = s * N
        f = self.law.limit(T, Ns)
        gf = self.law.limit_gradient(T, Ns)
        gg = self.law.potential_gradient(T, Ns)
        with np.errstate(invalid="ignore", divide="ignore"):
            H = self.law.potential_hessian(T, Ns)
        # |T| -> 0 at the apex of a cone: the Hessian of |T| is unbounded (inf or nan); use
        # that of the minimal-norm subgradient, 0, as the gradients do.
        H = np.where(np.isfinite(H), H, 0.0)
        S = np.stack((np.ones_like(s), np.ones_like(s), s), axis=-1)
        df = gf * S
        dfq = np.stack((gf[:, 2] * N * ds, np.zeros_like(s)), axis=-1)
        dg = gg * S
        hgg = S[:, :, None] * H * S[:, None, :]
        hgq = np.zeros((len(s), 3, 2))
        hgq[:, 0, 0] = H[:, 0, 2] * N * ds
        hgq[:, 1, 0] = H[:, 1, 2] * N * ds
        hgq[:, 2, 0] = ds * gg[:, 2] + s * H[:, 2, 2] * N * ds
        zero = np.zeros_like(s)
        h, dhs, dhq = _hardening_rates(dg, hgg, hgq, zero, zero, dg[:, 2])
        return Local(f, df, dfq, dg, hgg, hgq, h, dhs, dhq)


class CapSurface:
    """The :class:`EllipsoidCap` with its own hardening A(κ, β), B(β)."""

    def __init__(self, cap):
        from .cap import _compiled_cap
        self.cap = cap
        self.fun = _compiled_cap(cap)

    def limit(self, sigma, q):
        return self.fun.f(sigma[:, 0], sigma[:, 1], sigma[:, 2], q[:, 0], q[:, 1])

    def evaluate(self, sigma, q) -> Local:
        args = (sigma[:, 0], sigma[:, 1], sigma[:, 2], q[:, 0], q[:, 1])
        f = self.fun.f(*args)
        gf = self.fun.grad_f(*args)
        gg = self.fun.grad_g(*args)
        H = self.fun.hess_g(*args)
        dg, hgg, hgq = gg[:, :3], H[:, :3, :3], H[:, :3, 3:]
        beta = q[:, 1]
        h, dhs, dhq = _hardening_rates(dg, hgg, hgq, self.cap.B(beta), self.cap.B.derivative(beta),
                                       dg[:, 2])
        return Local(f, gf[:, :3], gf[:, 3:], dg, hgg, hgq, h, dhs, dhq)


def surface_for(law, hardening=None):
    from .cap import EllipsoidCap
    if isinstance(law, EllipsoidCap):
        return CapSurface(law)
    return LawSurface(law, hardening)


def _jacobian(loc: Local, dlam, Dv):
    """Newton Jacobian of the backward-Euler residual in ``x = (sigma, q, Δλ)``, shape (n, 6, 6)."""
    n = len(dlam)
    J = np.zeros((n, 6, 6))
    lam = dlam[:, None, None]
    J[:, :3, :3] = np.eye(3) + lam * Dv[None, :, None] * loc.hgg
    J[:, :3, 3:5] = lam * Dv[None, :, None] * loc.hgq
    J[:, :3, 5] = Dv * loc.dg
    J[:, 3:5, :3] = -lam * loc.dhs
    J[:, 3:5, 3:5] = np.eye(2) - lam * loc.dhq
    J[:, 3:5, 5] = -loc.h
    J[:, 5, :3] = loc.df
    J[:, 5, 3:5] = loc.dfq
    return J


def _residual(loc: Local, sigma, q, dlam, sigma_tr, q_n, Dv):
    R = np.empty((len(dlam), 6))
    R[:, :3] = sigma - sigma_tr + dlam[:, None] * Dv * loc.dg
    R[:, 3:5] = q - q_n - dlam[:, None] * loc.h
    R[:, 5] = loc.f
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
    """Row and column scales that make the Newton system dimensionless."""
    F = np.maximum(np.linalg.norm(sigma_tr, axis=-1), 1e-300)
    ell = F / Dv.min()
    loc = surface.evaluate(sigma_tr, q_n)
    fs = np.maximum(np.linalg.norm(loc.df, axis=-1) * F, 1e-300)
    gs = np.maximum(np.linalg.norm(Dv * loc.dg, axis=-1), 1e-300)
    one = np.ones_like(F)
    rows = np.stack((1 / F, 1 / F, 1 / F, 1 / ell, one, 1 / fs), axis=-1)
    cols = np.stack((F, F, F, ell, one, F / gs), axis=-1)
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
    for _ in range(_MAX_ITER):
        active &= ~(merit <= _TOL)
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        sub = _take(loc, idx)
        J = _jacobian(sub, dlam[idx], Dv) * rows[idx, :, None] * cols[idx, None, :]
        ok = np.isfinite(J).all(axis=(1, 2))
        J[~ok] = np.eye(6)
        step = -np.linalg.solve(J, R[idx][..., None])[..., 0] * cols[idx]
        step[~ok] = 0.0
        alpha = np.ones(idx.size)
        pending = np.ones(idx.size, dtype=bool)
        for _ in range(_MAX_HALVINGS):
            k = idx[pending]
            s_k = step[pending] * alpha[pending, None]
            sig_k, q_k = sigma[k] + s_k[:, :3], q[k] + s_k[:, 3:5]
            lam_k = dlam[k] + s_k[:, 5]
            loc_k = surface.evaluate(sig_k, q_k)
            R_k = _residual(loc_k, sig_k, q_k, lam_k, sigma_tr[k], q_n[k], Dv) * rows[k]
            m_k = np.linalg.norm(R_k, axis=-1)
            accept = np.isfinite(m_k) & (m_k <= (1 - 1e-4 * alpha[pending]) * merit[k])
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
    converged = (merit <= _TOL) & (dlam >= 0)
    J = _jacobian(loc, dlam, Dv)
    good = np.isfinite(J).all(axis=(1, 2)) & converged
    dsig = np.zeros((n, 3, 3))
    if good.any():
        dsig[good] = np.linalg.inv(J[good])[:, :3, :3]
    return ReturnResult(sigma, q, dlam, converged & good, dsig)


def _take(loc: Local, idx) -> Local:
    return Local(*(getattr(loc, k)[idx] for k in Local.__dataclass_fields__))


def _put(loc: Local, idx, new: Local) -> Local:
    if len(idx) == 0:
        return loc
    out = {}
    for k in Local.__dataclass_fields__:
        a = getattr(loc, k).copy()
        a[idx] = getattr(new, k)
        out[k] = a
    return Local(**out)


def tangent_at(surface, sigma, q, dlam, Dv) -> np.ndarray:
    """``d sigma / d sigma_trial`` at a converged return ``(sigma, q, Δλ)``, shape (n, 3, 3)."""
    J = _jacobian(surface.evaluate(sigma, q), dlam, Dv)
    return np.linalg.inv(J)[:, :3, :3]


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
