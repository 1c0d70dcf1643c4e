r"""A facet's local law as the mechanism search uses it: limit, slip, inverse relation, dilatancy.

Forces and slips are in the facet's frame ``(t1, t2, n)`` (``._hull.facet_frames``): the force
the block exerts on the facet is :math:`(T_1, T_2, N)`, ``N > 0`` compression, and the block's
velocity relative to the facet is the slip :math:`(v_1, v_2, v_n)`, ``vn > 0`` opening — the
conventions of every law (``docs/conventions.md``).

What the search needs of a law, and where it comes from:

* the limit condition and the slip direction of the sliding rule (every law);
* that both scale with the normal force: f positively homogeneous in ``(T, N)`` and the slip
  direction of degree zero, so that the limit curve at ``N`` is ``N`` times the one at
  ``N = 1`` (the trait ``conical`` of :class:`frictionrules.LawTraits`), and a convex limit
  curve. A law with the capability ``"cone"`` is such a law and gives closed forms (a
  quadratic for a facet's limit load, the inverse relation (1.13), the dilatancy
  :math:`v_n = d\,\bar\mu\,|A^T v_t|` of :class:`frictionrules.laws.Cone`); any other law is
  checked by its traits and handled numerically (roots by bracketing to machine precision);
* no internal variables (the search is a limit analysis of the block at rest).

The *dilatancy* :math:`\psi(\theta) = v_n/|v_t|` of the slip that the law gives for the
tangential slip angle ``theta`` bounds the velocities a facet admits:
:math:`V\cdot n \ge |V_t|\,\psi(\theta)` (a facet in contact slides with that normal slip or
opens further). The *associated twin* of a law has the same limit condition and ``g = f``.
"""

from __future__ import annotations

import functools

import numpy as np

from ..errors import FrictionRulesError
from ..laws import Cone, require
from .._rotation import rotation
from .._roots import bracketed_root, golden_min

#: Samples of a law's limit curve (at N = 1) for brackets of its inverse relation.
CURVE_SAMPLES = 720
#: Samples along a facet's load path for brackets of its limit condition (non-cone laws).
PATH_SAMPLES = 128
#: Roots kept per load path.
MAX_ROOTS = 4
_TWO_PI = 2.0 * np.pi


def local_law(law, where: str):
    """The adaptor of ``law`` for the mechanism search; raises naming what is missing."""
    caps = getattr(law, "capabilities", None)
    if caps is None:
        raise FrictionRulesError(f"{where}: law = {law!r} violates: a number (local Coulomb mu) "
                                 "or a friction law of frictionrules (a FrictionLaw)")
    if getattr(law, "normal_name", "N") != "N":
        raise FrictionRulesError(
            f"{where}: law = {_short(law)} is a law in external loads ({law.normal_name} in the "
            "place of N); constraint: a local law in the facet's forces (T, N)")
    if law.state_names:
        raise FrictionRulesError(
            f"{where}: law = {_short(law)} has the internal variables {list(law.state_names)}; "
            "constraint: a local law without internal variables (the mechanism search is a "
            "limit analysis of the block at rest: pass the law at its state as a law without "
            "state)")
    if "cone" in caps:
        c = law.cone()
        return ConeLocal(law, c.mu_x, c.mu_y, c.angle, c.dilatancy)
    if "symbolic" not in caps:
        require(law, "cone", where)         # names the capability the search needs
    traits = law.traits
    if not traits.conical:
        what = ("f is not positively homogeneous in (T, N)" if traits.degree is None or
                traits.degree <= 0 else
                "the slip direction (the gradient of g) changes when (T, N) is scaled")
        raise FrictionRulesError(
            f"{where}: law = {_short(law)}: {what}; constraint: a cone-like local law (its limit "
            "curve at N is N times the one at N = 1), which the mechanism search needs for the "
            "equilibrium of two facets (a 3x3 linear system) and the scaling with Q")
    if not traits.convex:
        raise FrictionRulesError(
            f"{where}: law = {_short(law)}: its limit curve at N = 1 is not convex (e.g. Huber "
            "with a ratio of mu_1 to mu_2 beyond 1.5); constraint: a convex limit condition, on "
            "which the static maximum and the check that the facets carry Q rely (limit "
            "analysis)")
    return CurveLocal(law, traits.normal_slip, twin_of=False)


def _short(law) -> str:
    text = repr(law)
    return text if len(text) <= 120 else text[:117] + "..."


def wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % _TWO_PI - np.pi


def _slip_angle(s: np.ndarray) -> np.ndarray:
    return np.arctan2(s[..., 1], s[..., 0])


class _Local:
    """Shared parts: values of f and g from the law (g = f for a twin)."""

    law = None
    twin_of = False

    def limit_gradient(self, T, N):
        return self.law.limit_gradient(T, N)

    def potential(self, T, N):
        return self.law.limit(T, N) if self.twin_of else self.law.potential(T, N)

    def potential_gradient(self, T, N):
        return self.law.limit_gradient(T, N) if self.twin_of else self.law.potential_gradient(T, N)

    def boundary(self, p: np.ndarray) -> np.ndarray:
        """Unit slips ``(..., 3)`` of the boundary of the admissible cone, parameter ``p``."""
        raise NotImplementedError  # pragma: no cover

    def dilatancy(self, theta: np.ndarray) -> np.ndarray:
        raise NotImplementedError  # pragma: no cover


class ConeLocal(_Local):
    r"""An elliptic cone (capability ``"cone"``): :math:`f \propto \rho(T) - N`,
    :math:`g \propto \rho(T) - dN`, :math:`\rho = |\mathrm{diag}(1/\mu_x, 1/\mu_y)R(-a)T|`."""

    def __init__(self, law, mu_x, mu_y, angle, d, twin_of=False):
        self.law, self.twin_of = law, twin_of
        self.cone = Cone(float(mu_x), float(mu_y), float(angle), float(d))
        R = rotation(angle)
        self.M = R @ np.diag([1.0 / mu_x**2, 1.0 / mu_y**2]) @ R.T
        self.dilatant = d != 0.0
        self.associated = d == 1.0
        self.psi_range = (d * min(mu_x, mu_y), d * max(mu_x, mu_y))

    @property
    def coulomb(self) -> float | None:
        """``mu`` of an isotropic cone, ``None`` otherwise."""
        return self.cone.mu_x if self.cone.mu_x == self.cone.mu_y else None

    def twin(self) -> "ConeLocal":
        if self.associated:
            return self
        c = self.cone
        return ConeLocal(self.law, c.mu_x, c.mu_y, c.angle, 1.0, twin_of=True)

    def line_roots(self, T0, N0, T1, N1) -> np.ndarray:
        """``t >= 0`` with ``f(T0 + t T1, N0 + t N1) = 0`` and ``N > 0``: the quadratic
        :math:`(T_0 + tT_1)^T M (T_0 + tT_1) = (N_0 + tN_1)^2`, shape ``(..., 2)`` (NaN: none)."""
        M = self.M
        TM1 = T1 @ M
        A = np.sum(TM1 * T1, axis=-1) - N1**2
        B = 2.0 * (np.sum(TM1 * T0, axis=-1) - N0 * N1)
        C = np.sum((T0 @ M) * T0, axis=-1) - N0**2
        A, B, C = np.broadcast_arrays(A, B, C)
        disc = B**2 - 4.0 * A * C
        with np.errstate(divide="ignore", invalid="ignore"):
            sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
            q = -0.5 * (B + np.where(B >= 0, 1.0, -1.0) * sq)
            scale = np.abs(B) + np.abs(C) + 1e-300
            r1 = np.where(np.abs(A) > 1e-14 * scale, q / A, np.where(B != 0, -C / B, np.nan))
            r2 = np.where(q != 0, C / q, np.nan)
        t = np.stack((r1, r2), axis=-1)
        t = np.where(np.isfinite(t) & (t >= -1e-12), np.clip(t, 0.0, None), np.nan)
        N = N0[..., None] + t * N1[..., None]
        return np.where(N > 0, t, np.nan)

    def slip(self, T, N) -> np.ndarray:
        r"""Unit slip :math:`(\nabla\rho, d)/|\cdot|` (zero at the apex)."""
        g = T @ self.M
        rho = np.sqrt(np.sum(g * T, axis=-1))
        g = np.divide(g, rho[..., None], out=np.zeros_like(g), where=rho[..., None] > 0)
        v = np.concatenate((g, np.broadcast_to(self.cone.dilatancy, rho.shape)[..., None]), -1)
        norm = np.linalg.norm(v, axis=-1, keepdims=True)
        return np.divide(v, norm, out=np.zeros_like(v), where=norm > 0)

    def inverse(self, theta):
        """(1.13) at ``N = 1``: the force sliding at ``theta``; never locked."""
        c = self.cone
        t = theta - c.angle
        co, si = np.cos(t), np.sin(t)
        den = np.sqrt((c.mu_x * co) ** 2 + (c.mu_y * si) ** 2)
        a, b = c.mu_x**2 * co / den, c.mu_y**2 * si / den
        ca, sa = np.cos(c.angle), np.sin(c.angle)
        return np.stack((ca * a - sa * b, sa * a + ca * b), axis=-1), np.zeros(np.shape(t), bool)

    def dilatancy(self, theta):
        r""":math:`\psi = d\sqrt{(\mu_x\cos\theta')^2 + (\mu_y\sin\theta')^2}`."""
        c = self.cone
        t = theta - c.angle
        return c.dilatancy * np.sqrt((c.mu_x * np.cos(t)) ** 2 + (c.mu_y * np.sin(t)) ** 2)

    def boundary(self, p):
        """Parameter: the slip angle."""
        psi = self.dilatancy(p)
        v = np.stack((np.cos(p), np.sin(p), psi), axis=-1)
        return v / np.sqrt(1.0 + psi**2)[..., None]

    def boundary_force(self, p):
        return self.inverse(p)[0]


class CurveLocal(_Local):
    """A law known by its functions, homogeneous (checked on its symbolic form): the limit
    curve at ``N = 1`` is found along rays from :meth:`frictionrules.FrictionLaw.centre`."""

    def __init__(self, law, dilatant: bool, twin_of: bool):
        self.law, self.twin_of = law, twin_of
        self.dilatant = dilatant or twin_of
        self.associated = twin_of or law.associated
        self.coulomb = None
        self.centre = np.asarray(law.centre(1.0), dtype=float).reshape(2)
        try:
            inside = float(law.limit(self.centre, 1.0)) < 0
        except FrictionRulesError:   # a kink of f at the centre: look next to it
            inside = float(law.limit(self.centre + [1e-9, 0.0], 1.0)) < 0
        if not inside:
            raise FrictionRulesError(
                f"law = {_short(law)}: f(centre, N = 1) violates f < 0 (the limit curve must "
                "enclose the law's centre)")

    def twin(self) -> "CurveLocal":
        return self if self.associated else CurveLocal(self.law, True, twin_of=True)

    def _slip(self, T, N):
        return self.law.normal_direction(T, N) if self.twin_of else self.law.slip_direction(T, N)

    def slip(self, T, N):
        return self._slip(T, N)

    # ---- the limit curve at N = 1 ----------------------------------------------------------
    def _f_ray(self, beta, r):
        u = np.stack((np.cos(beta), np.sin(beta)), axis=-1)
        return self.law.limit(self.centre + r[..., None] * u, np.ones(np.shape(r)))

    def radius(self, beta: np.ndarray) -> np.ndarray:
        """Distance from the centre to the limit curve at ``N = 1`` along ``beta`` (inf: none).

        Bracketed about the sampled curve where it is known, else by halving and doubling
        from 1."""
        beta = np.asarray(beta, dtype=float).ravel()
        lo, hi = np.zeros_like(beta), np.ones_like(beta)
        f_lo, f_hi = np.full_like(beta, -1.0), self._f_ray(beta, hi) if "_table" not in \
            self.__dict__ else np.ones_like(beta)
        fresh = np.ones(len(beta), dtype=bool)
        if "_table" in self.__dict__:
            r0 = self._radius_estimate(beta)
            fin = np.isfinite(r0)
            lo, hi = np.where(fin, 0.98 * r0, 0.0), np.where(fin, 1.02 * r0, 1.0)
            f_lo = np.where(fin, self._f_ray(beta, np.where(fin, lo, 1.0)), -1.0)
            f_hi = self._f_ray(beta, hi)
            fresh = ~fin | (f_lo > 0) | (f_hi <= 0)
        if fresh.any():
            lo[fresh], hi[fresh], f_lo[fresh], f_hi[fresh] = self._bracket(beta[fresh])
        r = bracketed_root(lambda x, i: self._f_ray(beta[i], x), lo, hi, f_lo, f_hi)
        return np.where(f_hi > 0, r, np.inf)

    def _bracket(self, beta):
        """``[lo, hi]`` with ``f(lo) <= 0 < f(hi)`` along ``beta``: halve from 1 while outside,
        then double while inside (``f(hi) <= 0`` left where the curve is unbounded)."""
        hi = np.ones_like(beta)
        f_hi = self._f_ray(beta, hi)
        for _ in range(60):
            out = f_hi > 0
            if not out.any():
                break
            hi = np.where(out, 0.5 * hi, hi)
            f_hi = np.where(out, self._f_ray(beta, hi), f_hi)
        lo, f_lo = hi.copy(), f_hi.copy()
        for _ in range(60):
            inside = f_hi <= 0
            if not inside.any():
                break
            lo, f_lo = np.where(inside, hi, lo), np.where(inside, f_hi, f_lo)
            hi = np.where(inside, 2.0 * hi, hi)
            f_hi = np.where(inside, self._f_ray(beta, hi), f_hi)
        return lo, hi, f_lo, f_hi

    def _radius_estimate(self, beta):
        beta_s, T, fin, *_ = self._table
        r = np.where(fin, np.hypot(*(T - self.centre).T), np.nan)
        step = 2.0 * np.pi / CURVE_SAMPLES
        x = (np.asarray(beta) - beta_s[0]) / step
        i = np.floor(x).astype(int) % CURVE_SAMPLES
        w = x - np.floor(x)
        return (1.0 - w) * r[i] + w * r[(i + 1) % CURVE_SAMPLES]

    def _point(self, beta):
        r = self.radius(beta)
        fin = np.isfinite(r)
        u = np.stack((np.cos(beta), np.sin(beta)), axis=-1)
        return self.centre + np.where(fin, r, 0.0)[:, None] * u, fin

    @functools.cached_property
    def _table(self):
        beta = -np.pi + _TWO_PI * np.arange(CURVE_SAMPLES) / CURVE_SAMPLES
        T, fin = self._point(beta)
        s = self._slip(T, np.ones(len(beta)))
        vt = np.hypot(s[:, 0], s[:, 1])
        fin &= vt > 0
        psi = s[:, 2] / np.where(fin, vt, 1.0)
        return beta, T, fin, _slip_angle(s), psi

    @property
    def psi_range(self):
        *_, fin, _, psi = self._table
        lo, hi = float(np.min(psi[fin])), float(np.max(psi[fin]))
        pad = 1e-3 * (hi - lo) + 1e-6 * (1.0 + abs(hi))
        return lo - pad, hi + pad

    def boundary(self, p):
        """Parameter: the polar angle of the force about the centre."""
        p = np.asarray(p, dtype=float)
        T, fin = self._point(p.ravel())
        s = self._slip(T, np.ones(len(T)))
        return np.where(fin[:, None], s, np.nan).reshape(p.shape + (3,))

    def boundary_force(self, p):
        p = np.asarray(p, dtype=float)
        T, fin = self._point(p.ravel())
        return np.where(fin[:, None], T, np.inf).reshape(p.shape + (2,))

    def inverse(self, theta):
        """Force at ``N = 1`` sliding at ``theta`` (the smallest ``|T|`` where several do),
        bracketed on the sampled curve and refined on the force angle to machine precision."""
        theta = np.asarray(theta, dtype=float)
        flat = theta.ravel()
        beta, T_s, fin, ang, _ = self._table
        out = np.full((len(flat), 2), np.inf)
        step = _TWO_PI / CURVE_SAMPLES
        for lo in range(0, len(flat), 2048):
            th = flat[lo:lo + 2048]
            d = wrap(ang[None, :] - th[:, None])
            dn, fn = np.roll(d, -1, axis=1), np.roll(fin, -1)
            br = fin & fn & (d * dn <= 0) & (np.abs(d - dn) < np.pi)
            q, i = np.nonzero(br)
            if len(q) == 0:
                continue

            def mismatch(b, idx):
                Tb, _ = self._point(b)
                return wrap(_slip_angle(self._slip(Tb, np.ones(len(b)))) - th[q[idx]])

            b = bracketed_root(mismatch, beta[i], beta[i] + step, d[q, i], dn[q, i])
            Tb, ok = self._point(b)
            norm = np.where(ok, np.hypot(*Tb.T), np.inf)
            best = np.full(len(th), np.inf)
            np.minimum.at(best, q, norm)
            pick = ok & (norm == best[q])
            out[lo + q[pick]] = Tb[pick]
        locked = ~np.all(np.isfinite(out), axis=-1)
        return out.reshape(theta.shape + (2,)), locked.reshape(theta.shape)

    def dilatancy(self, theta):
        theta = np.asarray(theta, dtype=float)
        if not self.dilatant:
            return np.zeros(theta.shape)
        T, locked = self.inverse(theta)
        s = self._slip(np.where(locked[..., None], self.centre, T), np.ones(theta.shape))
        vt = np.hypot(s[..., 0], s[..., 1])
        locked = locked | (vt == 0)
        return np.where(locked, np.inf, s[..., 2] / np.where(locked, 1.0, vt))

    def dilatancy_estimate(self, theta):
        """ψ(theta) interpolated on the sampled curve: for brackets only."""
        _, _, fin, ang, psi = self._table
        order = np.argsort(ang[fin])
        a, p = ang[fin][order], psi[fin][order]
        return np.interp(theta, np.concatenate((a - _TWO_PI, a, a + _TWO_PI)),
                         np.concatenate((p, p, p)))

    # ---- a facet's limit load --------------------------------------------------------------
    def line_roots(self, T0, N0, T1, N1) -> np.ndarray:
        r"""``t >= 0`` with ``f(T0 + t T1, N0 + t N1) = 0``, ``N > 0``, shape ``(..., 4)``.

        By homogeneity the roots are those of :math:`f((1-s)X_0 + sX_1)` for
        :math:`s = t/(1+t) \in [0, 1)`, bracketed on :data:`PATH_SAMPLES` points of ``s``
        (and around sampled minima that come close to zero, where the path grazes the cone).
        """
        T0, N0, T1, N1 = np.broadcast_arrays(T0, N0[..., None], T1, N1[..., None])
        shape = T0.shape[:-1]
        T0, T1 = T0.reshape(-1, 2), T1.reshape(-1, 2)
        N0, N1 = N0[..., 0].ravel(), N1[..., 0].ravel()
        with np.errstate(divide="ignore", invalid="ignore"):
            s_end = np.where(N1 < 0, N0 / (N0 - N1), 1.0)
        s_end = np.minimum(s_end, 1.0)

        def f(s, idx):
            s = np.asarray(s)
            X = (1.0 - s)[..., None] * T0[idx] + s[..., None] * T1[idx]
            N = np.maximum((1.0 - s) * N0[idx] + s * N1[idx], 0.0)
            return self.law.limit(X, N)

        L = len(N0)
        grid = np.linspace(0.0, 1.0, PATH_SAMPLES + 1)[None, :] * s_end[:, None]     # (L, S)
        rows = np.repeat(np.arange(L), grid.shape[1])
        fs = f(grid.ravel(), rows).reshape(grid.shape)
        brackets = [np.nonzero(fs[:, :-1] * fs[:, 1:] <= 0)]
        # grazing: a sampled local minimum above zero may hide two roots
        mid = fs[:, 1:-1]
        curv = fs[:, :-2] - 2.0 * mid + fs[:, 2:]    # ~ 2 c h^2 for f ~ f_min + c (s - s_m)^2
        q, i = np.nonzero((mid > 0) & (mid <= fs[:, :-2]) & (mid <= fs[:, 2:]) & (mid <= curv))
        extra_q, extra_lo, extra_hi = [], [], []
        if len(q):
            a, b = grid[q, i], grid[q, i + 2]
            sm, fm = golden_min(lambda s: f(s, q), a, b, iters=40)
            neg = fm < 0
            for lo_, hi_ in ((a, sm), (sm, b)):
                extra_q.append(q[neg])
                extra_lo.append(lo_[neg])
                extra_hi.append(hi_[neg])
        q0, i0 = brackets[0]
        qs = np.concatenate([q0] + extra_q)
        lo = np.concatenate([grid[q0, i0]] + extra_lo)
        hi = np.concatenate([grid[q0, i0 + 1]] + extra_hi)
        roots = np.full((L, MAX_ROOTS), np.nan)
        if len(qs):
            s = bracketed_root(lambda x, idx: f(x, qs[idx]), lo, hi, f(lo, qs), f(hi, qs))
            with np.errstate(divide="ignore"):
                t = s / (1.0 - s)
            N = (1.0 - s) * N0[qs] + s * N1[qs]
            good = (s < 1.0 - 1e-12) & (N > 0)
            qs, t = qs[good], t[good]
            order = np.lexsort((t, qs))
            qs, t = qs[order], t[order]
            first = np.searchsorted(qs, qs)
            slot = np.arange(len(qs)) - first
            keep = slot < MAX_ROOTS
            roots[qs[keep], slot[keep]] = t[keep]
        return roots.reshape(shape + (MAX_ROOTS,))
