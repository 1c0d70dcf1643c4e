r"""The mechanism search with local Coulomb friction on every facet: the fast path.

Facet ``j`` has the unit normal :math:`n_j` (into the block, :math:`n_{jz} > 0`) and reacts on
the block with :math:`R_j = N_j n_j + f_j`, :math:`N_j \ge 0`, :math:`|f_j| \le \mu N_j`.

* non-associated (1.5): a loaded facet slides in its plane, :math:`V\cdot n_j = 0`, with
  :math:`f_j = -\mu N_j V/|V|`. One facet slides along its in-plane load; two facets along the
  line :math:`\pm n_j\times n_k` of their intersection. Three facets with independent normals
  cannot slide; facets whose normals are coplanar with ``n_j, n_k`` lie on the same line, and
  the smallest load over such a group is always carried by two neighbouring facets of it (the
  load factor is a linear programme with three equality constraints), so pairs suffice.
* associated (1.6): a loaded facet slides with :math:`V\cdot n_j = \sin\varrho\,|V|`,
  :math:`\varrho = \arctan\mu`, and :math:`f_j = -\mu N_j w_j`, :math:`w_j` the unit in-plane
  part of ``V``; so :math:`R_j \perp V`. Admissibility is :math:`V\cdot n_m \ge
  \sin\varrho\,|V|` for every facet (the dual of the friction cone).

Everything here is at ``Q = 1``; the callers scale.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ._hull import TOL, cross, unit
from ._inverse import climb_force, support_force
from ._results import Mechanisms

#: Entries per direction chunk of the solver's temporaries.
CHUNK_ENTRIES = 1 << 22


@dataclass(frozen=True)
class CoulombGeometry:
    """The sliding facets of a Coulomb facet set and their two-facet mechanisms."""

    index: np.ndarray    # (K,) facets that can slide (of the user's numbering)
    n: np.ndarray        # (K, 3) their unit normals
    slope: np.ndarray    # (K, 2) gradients p = -n_h / n_z of the facet planes
    mu: float
    associated: bool
    threshold: float     # admissibility V.n_m >= threshold (0 or sin rho)
    pair_j: np.ndarray   # (P,) candidate pairs and their velocities
    pair_k: np.ndarray
    pair_v: np.ndarray   # (P, 3)
    pair_r: np.ndarray   # (P, 2, 3) unit-N reactions r = n - mu w of the two facets
    static: "CoulombGeometry | None"  # associated twin of a non-associated set
    normals: np.ndarray  # (K_all, 3) every facet's unit normal, user numbering

    @classmethod
    def build(cls, normals: np.ndarray, index: np.ndarray, mu: float, associated: bool):
        n = normals[index]

        def make(assoc, static):
            thr = float(np.sin(np.arctan(mu))) if assoc else 0.0
            j, k, v, r = _pairs(n, mu, assoc, thr)
            return cls(index=index, n=n, slope=-n[:, :2] / n[:, 2:], mu=mu, associated=assoc,
                       threshold=thr, pair_j=j, pair_k=k, pair_v=v, pair_r=r, static=static,
                       normals=normals)

        # the associated twin gives the static maximum, an upper bound for both rules
        return make(True, None) if associated else make(False, make(True, None))

    def solve(self, d: np.ndarray) -> Mechanisms:
        """Limit loads (``Q = 1``) in the unit directions ``d`` (M, 2): smallest admissible
        mechanism over all one-facet and two-facet candidates (in chunks of directions that
        keep the admissibility tensor ``(M, K, 2, K)`` to a few million entries)."""
        K = len(self.n)
        step = max(1, CHUNK_ENTRIES // (2 * K * K + len(self.pair_j)))
        out = Mechanisms.concat([self._chunk(d[i:i + step]) for i in range(0, len(d), step)])
        return static_cap(out, self.static, d)

    def one_facet_terms(self, F: np.ndarray, j: np.ndarray, quasi_static: np.ndarray):
        """Gradient in ``F`` of the one-facet limit :math:`f_j = |F_t| + \\mu F\\cdot n_j`, the
        potential :math:`g = |F_t|` (plus :math:`\\mu F\\cdot n_j` for the dilatant rule and
        beyond the static maximum) and its gradient, at loads ``F`` (P, 3) on facets ``j``."""
        nj = self.normals[j]
        Ft = F - np.sum(F * nj, axis=-1, keepdims=True) * nj
        Ftn = np.linalg.norm(Ft, axis=-1, keepdims=True)
        w = np.divide(Ft, Ftn, out=np.zeros_like(Ft), where=Ftn > 0)
        dil = np.where(self.associated | ~quasi_static, self.mu, 0.0)
        return w + self.mu * nj, np.sum(F * w, axis=-1) + dil * np.sum(F * nj, axis=-1), \
            w + dil[:, None] * nj

    def slide_force(self, u: np.ndarray) -> np.ndarray:
        """Load (``Q = 1``) whose block velocity slides at the horizontal unit vectors ``u``."""
        return support_force(self, u) if self.associated else climb_force(self, u)

    def _chunk(self, d: np.ndarray) -> Mechanisms:
        M, n, mu = len(d), self.n, self.mu
        D = np.concatenate((d, np.zeros((M, 1))), axis=-1)
        z = np.array([0.0, 0.0, 1.0])
        best = Best(M)

        # one facet: |F_t| = mu (-F.n), F = t D - z, a quadratic in t
        a = D @ n.T                                     # (M, K)
        nz = n[:, 2][None, :]
        k2 = 1.0 + mu**2
        A, B, C = 1.0 - k2 * a**2, 2.0 * k2 * a * nz, np.broadcast_to(1.0 - k2 * nz**2, a.shape)
        disc = B**2 - 4.0 * A * C
        with np.errstate(divide="ignore", invalid="ignore"):
            sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
            q = -0.5 * (B + np.where(B >= 0, 1.0, -1.0) * sq)
            r1 = np.where(np.abs(A) > 1e-14, q / A, np.where(B != 0, -C / B, np.nan))
            r2 = np.where(q != 0, C / q, np.nan)
        roots = np.stack((r1, r2), axis=-1)             # (M, K, 2)
        roots = np.where(np.isfinite(roots) & (roots >= -1e-12), np.clip(roots, 0.0, None), np.nan)
        F = roots[..., None] * D[:, None, None, :] - z   # (M, K, 2, 3)
        Fn = np.einsum("mkri,ki->mkr", np.nan_to_num(F), n)
        Ft = np.nan_to_num(F) - Fn[..., None] * n[None, :, None, :]
        Ftn = np.linalg.norm(Ft, axis=-1, keepdims=True)
        w = np.divide(Ft, Ftn, out=np.zeros_like(Ft), where=Ftn > 0)
        if self.associated:
            rho = np.arctan(mu)
            V = np.cos(rho) * w + np.sin(rho) * n[None, :, None, :]
        else:
            V = w
        ok = np.isfinite(roots) & (Fn < 0) & (Ftn[..., 0] > 0)
        ok &= np.all(np.einsum("mkri,li->mkrl", V, n) >= self.threshold - TOL, axis=-1)
        t1 = np.where(ok, roots, np.inf)
        flat = t1.reshape(M, -1)
        idx = np.argmin(flat, axis=-1)
        m_ix = np.arange(M)
        kk, rr = np.divmod(idx, 2)
        best.single(flat[m_ix, idx], kk, -Fn[m_ix, kk, rr], V[m_ix, kk, rr],
                    lambda take: unit(w[m_ix, kk, rr] + mu * n[kk])[take])
        best.pairs(D, self)
        return best.result(self.index)


class Best:
    """The smallest admissible mechanism per direction while a solver scans its candidates
    (facets numbered by position among the solver's sliding facets)."""

    def __init__(self, M: int):
        self.load = np.full(M, np.inf)
        self.facets = np.zeros((M, 2), dtype=int)
        self.active = np.zeros((M, 2), dtype=bool)
        self.forces = np.zeros((M, 2))
        self.velocity = np.zeros((M, 3))
        self.normal = np.zeros((M, 3))

    def single(self, load, facet, force, velocity, normal) -> None:
        """One-facet candidates (M,): kept where they beat the best so far; ``normal`` maps
        the kept rows to the limit surface's unit normals (computed for those only)."""
        take = load < self.load
        self.load = np.where(take, load, self.load)
        self.facets[take, 0] = facet[take]
        self.active[take, 0] = True
        self.forces[take, 0] = force[take]
        self.velocity[take] = velocity[take]
        self.normal[take] = normal(take)

    def pairs(self, D: np.ndarray, geo) -> None:
        """Two-facet mechanisms of ``geo`` (``pair_j, pair_k, pair_v, pair_r``): ``t D + N_j r_j
        + N_k r_k = z`` (Cramer), kept where ``t, N >= 0`` and smaller than the best; a
        one-facet mechanism wins a tie (a corner end of the pair's range)."""
        if len(geo.pair_j) == 0:
            return
        m_ix = np.arange(len(D))
        t, Nj, Nk, det, cjk = pair_loads(D, geo.pair_r[:, 0][None], geo.pair_r[:, 1][None])
        ok = np.isfinite(t) & (t >= -1e-12) & (Nj >= -1e-10) & (Nk >= -1e-10)
        t2 = np.where(ok, np.clip(t, 0.0, None), np.inf)
        p = np.argmin(t2, axis=-1)
        t_pair = t2[m_ix, p]
        take = t_pair < self.load * (1.0 - 1e-12)
        self.load = np.where(take, t_pair, self.load)
        self.facets[take, 0] = geo.pair_j[p][take]
        self.facets[take, 1] = geo.pair_k[p][take]
        self.active[take] = True
        self.forces[take, 0] = np.clip(Nj[m_ix, p], 0.0, None)[take]
        self.forces[take, 1] = np.clip(Nk[m_ix, p], 0.0, None)[take]
        self.velocity[take] = geo.pair_v[p][take]
        m = unit(cjk[0, p]) * np.sign(det[m_ix, p])[:, None]   # outward: m.D > 0
        self.normal[take] = m[take]

    def result(self, index: np.ndarray) -> Mechanisms:
        """The record, facets in the user's numbering (``index``: the sliding facets)."""
        return Mechanisms(load=self.load, facets=np.where(self.active, index[self.facets], 0),
                          active=self.active, forces=self.forces, velocity=self.velocity,
                          normal=self.normal, quasi_static=np.ones(len(self.load), dtype=bool))


def static_cap(out: Mechanisms, static, d: np.ndarray) -> Mechanisms:
    """Beyond the static maximum (the limit load of the associated twins, ``static``) no
    equilibrium exists with any forces the local limit conditions allow: where it comes before
    every sliding equilibrium of the local rules, the block loses equilibrium there (and
    accelerates) instead, flagged ``quasi_static = False``."""
    if static is None:
        return out
    st = static.solve(d)
    lose = st.load < out.load * (1.0 - 1e-9)
    return replace(out.where(lose, st), quasi_static=~lose)


def pair_loads(D: np.ndarray, rj: np.ndarray, rk: np.ndarray):
    """Solve ``t D + N_j r_j + N_k r_k = z`` (Cramer) for directions ``D`` (M, 3) and pairs of
    unit-N reactions ``rj, rk`` (1, P, 3): ``t, N_j, N_k, det`` (M, P) (NaN where singular) and
    ``r_j x r_k`` (1, P, 3)."""
    z = np.array([0.0, 0.0, 1.0])
    Dm = D[:, None, :]
    cjk = cross(rj, rk)
    det = np.sum(Dm * cjk, axis=-1)                                  # (M, P)
    scale = np.linalg.norm(cjk, axis=-1)
    good = np.abs(det) > 1e-12 * scale
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.where(good, 1.0 / det, np.nan)
        t = np.sum(z * cjk, axis=-1) * inv
        Nj = np.sum(Dm * cross(z, rk), axis=-1) * inv
        Nk = np.sum(Dm * cross(rj, z), axis=-1) * inv
    return t, Nj, Nk, det, cjk


def _pairs(n: np.ndarray, mu: float, associated: bool, threshold: float):
    """Two-facet mechanisms that are kinematically admissible for some load."""
    K = len(n)
    j, k = np.triu_indices(K, 1)
    e = cross(n[j], n[k])
    norm = np.linalg.norm(e, axis=-1)
    ok = norm > 1e-12
    j, k, e = j[ok], k[ok], e[ok] / norm[ok, None]
    if associated:
        g = np.sum(n[j] * n[k], axis=-1)
        a = threshold / (1.0 + g)
        c2 = 1.0 - 2.0 * a**2 * (1.0 + g)
        ok = c2 >= -1e-12
        j, k, e, a, c = j[ok], k[ok], e[ok], a[ok], np.sqrt(np.clip(c2[ok], 0.0, None))
        base = a[:, None] * (n[j] + n[k])
        single = c <= 1e-12  # the two cones touch along one ray
        v = np.concatenate((base + c[:, None] * e, (base - c[:, None] * e)[~single]))
        j, k = np.concatenate((j, j[~single])), np.concatenate((k, k[~single]))
    else:
        v = np.concatenate((e, -e))
        j, k = np.concatenate((j, j)), np.concatenate((k, k))
    admissible = np.all(v @ n.T >= threshold - TOL, axis=-1)
    j, k, v = j[admissible], k[admissible], v[admissible]
    if not associated and len(j):
        # a facet coplanar with (n_j, n_k) lying strictly between them carries the same line
        # mechanism at a smaller load: keep neighbouring pairs only
        ax = unit(cross(n[j], n[k]))
        coplanar = np.abs(n @ ax.T).T < TOL                               # (P, K)
        left = np.einsum("pki,pi->pk", cross(n[j][:, None, :], n[None, :, :]), ax) > TOL
        right = np.einsum("pki,pi->pk", cross(n[None, :, :], n[k][:, None, :]), ax) > TOL
        keep = ~np.any(coplanar & left & right, axis=-1)
        j, k, v = j[keep], k[keep], v[keep]
    r = np.stack((_reaction(n[j], v, mu), _reaction(n[k], v, mu)), axis=1)
    return j, k, v, r


def downward_velocity(n: np.ndarray, mu: float):
    r"""A unit velocity that makes the block descend freely, or ``None`` if there is none.

    The vertical load alone is carried iff :math:`Q z \in \sum_j K_j` (friction cones); by
    duality iff every ``V`` of the dual cone :math:`\bigcap_j\{V: V\cdot n_j \ge
    \sin\varrho|V|\}` has :math:`V_z \ge 0`. The lowest point of that cone on the unit
    sphere is the lowest point of one facet's cone, :math:`\sin\varrho\, n_j +
    \cos\varrho\, w_j` (``w_j`` down-slope), or an intersection of two cones; the candidates
    that are admissible for every facet are checked.
    """
    rho = np.arctan(mu)
    sr = float(np.sin(rho))
    up = np.array([0.0, 0.0, 1.0]) - n[:, 2:] * n
    upn = np.linalg.norm(up, axis=-1, keepdims=True)
    steep = upn[:, 0] > 1e-12
    cands = [np.sin(rho) * n[steep] - np.cos(rho) * up[steep] / upn[steep]]
    cands.append(_pairs(n, mu, True, sr)[2])
    V = np.concatenate(cands)
    V = V[np.all(V @ n.T >= sr - TOL, axis=-1) & (V[:, 2] < -1e-12)]
    return V[0] if len(V) else None


def _reaction(n: np.ndarray, v: np.ndarray, mu: float) -> np.ndarray:
    """Reaction per unit normal force, :math:`r = n - \\mu w`, ``w`` the unit in-plane part of v."""
    w = v - np.sum(v * n, axis=-1, keepdims=True) * n
    wn = np.linalg.norm(w, axis=-1, keepdims=True)
    w = np.divide(w, wn, out=np.zeros_like(w), where=wn > 0)
    return n - mu * w
