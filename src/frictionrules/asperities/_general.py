r"""The mechanism search with any local law on each facet.

Facet ``j`` (unit normal :math:`n_j` into the block, frame :math:`(t_{1j}, t_{2j}, n_j)`) carries
the force :math:`P_j = T_{1}t_{1j} + T_{2}t_{2j} - N n_j` of the block, and equilibrium of the
block under :math:`F = (t d, -Q)` is :math:`\sum_j P_j = F`. A facet in contact admits the block
velocities :math:`V\cdot n_j \ge |V_{tj}|\,\psi_j(\theta_j)` (``._local``: its sliding rule's
normal slip, or more opening); a sliding facet meets its rule exactly.

* **One facet** ``j``: :math:`P_j = F`, so its local forces
  :math:`(F\cdot t_{1j}, F\cdot t_{2j}, -F\cdot n_j)` are linear in ``t``; the load factor is a
  root of the local limit condition along that line (a quadratic for a cone), the velocity the
  local slip there, admissible against every other facet.
* **Two facets** ``j, k``: the velocity is fixed by the two local sliding rules alone — along
  :math:`\pm n_j\times n_k` when neither has normal slip, else on the intersection of their
  dilatancy cones (a root on the boundary of one cone) — so the local forces per unit normal
  force follow from the local inverse relations, :math:`r = n - T_1t_1 - T_2t_2` per facet,
  and equilibrium :math:`t D + N_j r_j + N_k r_k = Q z` is a 3×3 linear system.

The smallest admissible load factor wins. For non-associated local laws the static maximum —
the limit load with every law replaced by its associated twin (same f, g = f) — caps it, as for
Coulomb (``._coulomb``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ._coulomb import Best, static_cap
from ._hull import TOL, cross, facet_frames, unit
from ._inverse import directions, nearest_on_segments
from ._local import wrap
from ._results import Mechanisms
from .._roots import bracketed_root, golden_min

#: Samples on a cone's boundary when intersecting two dilatancy cones.
BOUNDARY_SAMPLES = 720
#: Directions sampled to bracket a slip direction on the limit curve.
CURVE_DIRECTIONS = 720


@dataclass(frozen=True, eq=False)
class GeneralGeometry:
    """Sliding facets with their frames and local laws, and their two-facet mechanisms."""

    normals: np.ndarray   # (K_all, 3) user numbering
    index: np.ndarray     # (K,) sliding facets
    n: np.ndarray         # (K, 3)
    t1: np.ndarray        # (K, 3)
    t2: np.ndarray        # (K, 3)
    laws: tuple           # distinct local-law adaptors
    law_of: np.ndarray    # (K,) index into laws
    pair_j: np.ndarray    # (P,) positions in the sliding facets
    pair_k: np.ndarray
    pair_v: np.ndarray    # (P, 3)
    pair_r: np.ndarray    # (P, 2, 3) unit-N reactions of the block on the two facets
    static: "GeneralGeometry | None"

    @classmethod
    def build(cls, normals: np.ndarray, index: np.ndarray, local: list):
        """``local[j]``: the adaptor of facet ``j`` (user numbering)."""
        n = normals[index]
        t1, t2 = facet_frames(n)
        laws, law_of = [], []
        for j in index:
            if not any(local[j] is a for a in laws):
                laws.append(local[j])
            law_of.append(next(i for i, a in enumerate(laws) if a is local[j]))
        law_of = np.array(law_of, dtype=int)

        def make(adaptors, static):
            geo = cls(normals=normals, index=index, n=n, t1=t1, t2=t2, laws=tuple(adaptors),
                      law_of=law_of, pair_j=np.zeros(0, int), pair_k=np.zeros(0, int),
                      pair_v=np.zeros((0, 3)), pair_r=np.zeros((0, 2, 3)), static=static)
            return replace(geo, **geo._pairs())

        if all(a.associated for a in laws):
            return make(laws, None)
        return make(laws, make([a.twin() for a in laws], None))

    @property
    def associated(self) -> bool:
        return all(a.associated for a in self.laws)

    # ---- frames ----------------------------------------------------------------------------
    def _global(self, s: np.ndarray, j) -> np.ndarray:
        """A local slip ``(..., 3)`` of facets ``j`` as a global vector."""
        return (s[..., :1] * self.t1[j] + s[..., 1:2] * self.t2[j] + s[..., 2:] * self.n[j])

    def _tangential(self, V: np.ndarray, j):
        """Tangential part of velocities ``V`` on facets ``j``: ``(|V_t|, angle)``."""
        v1, v2 = np.sum(V * self.t1[j], axis=-1), np.sum(V * self.t2[j], axis=-1)
        return np.hypot(v1, v2), np.arctan2(v2, v1)

    def admissible(self, V: np.ndarray, skip=None) -> np.ndarray:
        r"""``V (..., 3)`` is admissible for every facet: :math:`V\cdot n_m \ge |V_t|\psi_m`;
        ``skip (..., S)``: positions of facets left out per velocity (the sliding ones, on
        their cones by construction)."""
        shape = V.shape[:-1]
        ok = np.ones(shape, dtype=bool)
        for g, law in enumerate(self.laws):
            J = np.flatnonzero(self.law_of == g)
            a = V @ self.n[J].T                                        # (..., Kg)
            if law.dilatant:
                v1, v2 = V @ self.t1[J].T, V @ self.t2[J].T
                vt, theta = np.hypot(v1, v2), np.arctan2(v2, v1)
                lo, hi = law.psi_range
                res = a >= vt * hi + TOL
                unsure = ~res & (a >= vt * lo - TOL)
                if unsure.any():
                    psi = law.dilatancy(theta[unsure])      # inf where the law locks that way
                    vu = vt[unsure]
                    res[unsure] = a[unsure] >= vu * np.where(vu > 0, psi, 0.0) - TOL
            else:
                res = a >= -TOL
            if skip is not None:
                res |= np.any(np.asarray(skip)[..., None, :] == J[:, None], axis=-1)
            ok &= np.all(res, axis=-1)
        return ok

    # ---- two-facet mechanisms ------------------------------------------------------------
    def _pairs(self) -> dict:
        j, k = np.triu_indices(len(self.n), 1)
        e = cross(self.n[j], self.n[k])
        norm = np.linalg.norm(e, axis=-1)
        j, k, e = j[norm > 1e-12], k[norm > 1e-12], unit(e[norm > 1e-12])
        dil = np.array([a.dilatant for a in self.laws])
        plain = ~dil[self.law_of[j]] & ~dil[self.law_of[k]]
        js, ks, vs = [j[plain], j[plain]], [k[plain], k[plain]], [e[plain], -e[plain]]
        # a dilatant cone meets the other facet's cone (or plane): parametrize the dilatant one
        a = np.where(dil[self.law_of[j]], j, k)[~plain]
        b = np.where(dil[self.law_of[j]], k, j)[~plain]
        for la in np.unique(self.law_of[a]):
            for lb in np.unique(self.law_of[b]):
                sel = (self.law_of[a] == la) & (self.law_of[b] == lb)
                if sel.any():
                    rows, V = self._cone_intersections(a[sel], b[sel])
                    js.append(a[sel][rows])
                    ks.append(b[sel][rows])
                    vs.append(V)
        j, k, V = np.concatenate(js), np.concatenate(ks), np.concatenate(vs).reshape(-1, 3)
        if len(j) == 0:
            return {}
        ok = self.admissible(V, skip=np.stack((j, k), axis=-1))
        j, k, V = j[ok], k[ok], V[ok]
        j, k = np.minimum(j, k), np.maximum(j, k)
        r = np.stack((self._reaction(V, j), self._reaction(V, k)), axis=1)
        ok = np.all(np.isfinite(r), axis=(1, 2))
        return dict(pair_j=j[ok], pair_k=k[ok], pair_v=V[ok], pair_r=r[ok])

    def _cone_intersections(self, a: np.ndarray, b: np.ndarray):
        """Unit velocities on the boundary of facet ``a``'s dilatancy cone (a dilatant law)
        that lie on facet ``b``'s (or its plane): ``(pair rows, V)``."""
        la, lb = self.laws[self.law_of[a[0]]], self.laws[self.law_of[b[0]]]
        step = 2.0 * np.pi / BOUNDARY_SAMPLES
        p = -np.pi + step * np.arange(BOUNDARY_SAMPLES + 1)

        def h(s_local, rows, exact=True):
            V = self._global(s_local, a[rows])
            hb = np.sum(V * self.n[b[rows]], axis=-1)
            if lb.dilatant:
                v1, v2 = np.sum(V * self.t1[b[rows]], -1), np.sum(V * self.t2[b[rows]], -1)
                theta = np.arctan2(v2, v1)
                psi = lb.dilatancy(theta) if exact or not hasattr(lb, "dilatancy_estimate") \
                    else lb.dilatancy_estimate(theta)
                vt = np.hypot(v1, v2)
                hb = hb - np.where(vt > 0, vt, 0.0) * np.where(vt > 0, psi, 0.0)
            return hb

        P = len(a)
        grid = la.boundary(p)                                           # (G+1, 3)
        hs = h(grid[None], np.arange(P)[:, None], exact=False)          # (P, G+1)
        q, i = np.nonzero(np.isfinite(hs[:, :-1]) & np.isfinite(hs[:, 1:])
                          & (hs[:, :-1] * hs[:, 1:] <= 0))
        if len(q) == 0:
            return q, np.zeros((0, 3))
        lo, hi = p[i], p[i + 1]
        flo, fhi = h(la.boundary(lo), q), h(la.boundary(hi), q)
        widen = ~(flo * fhi <= 0)            # the estimate's bracket may be one sample off
        lo, hi = np.where(widen, lo - step, lo), np.where(widen, hi + step, hi)
        flo, fhi = h(la.boundary(lo), q), h(la.boundary(hi), q)
        good = flo * fhi <= 0
        q, lo, hi, flo, fhi = q[good], lo[good], hi[good], flo[good], fhi[good]
        root = bracketed_root(lambda x, idx: h(la.boundary(x), q[idx]), lo, hi, flo, fhi,
                              xtol=1e-13)
        V = unit(self._global(la.boundary(root), a[q]))
        # two samples that both bracket one root (a root on a sample) give it twice
        keep = np.ones(len(q), dtype=bool)
        keep[1:] = ~((q[1:] == q[:-1]) & (np.linalg.norm(V[1:] - V[:-1], axis=-1) < 1e-9))
        return q[keep], V[keep]

    def _reaction(self, V: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Unit-N reaction on the block of facets ``j`` sliding at ``V``: :math:`n - T_1t_1 -
        T_2t_2` with ``T`` the local inverse relation at the slip angle (inf where locked)."""
        out = np.empty(V.shape)
        for g, law in enumerate(self.laws):
            rows = np.flatnonzero(self.law_of[j] == g)
            if len(rows) == 0:
                continue
            jj = j[rows]
            _, theta = self._tangential(V[rows], jj)
            T, locked = law.inverse(theta)
            r = self.n[jj] - T[:, :1] * self.t1[jj] - T[:, 1:] * self.t2[jj]
            out[rows] = np.where(locked[:, None], np.inf, r)
        return out

    # ---- the search ----------------------------------------------------------------------
    def solve(self, d: np.ndarray) -> Mechanisms:
        """Limit loads (``Q = 1``) in the unit directions ``d`` (M, 2)."""
        M = len(d)
        D = np.concatenate((d, np.zeros((M, 1))), axis=-1)
        best = Best(M)
        m_ix = np.arange(M)
        for g, law in enumerate(self.laws):
            J = np.flatnonzero(self.law_of == g)
            n, t1, t2 = self.n[J], self.t1[J], self.t2[J]
            T0 = -np.stack((t1[:, 2], t2[:, 2]), axis=-1)[None]             # (1, Kg, 2)
            N0 = n[None, :, 2]                                               # (1, Kg)
            T1 = np.stack((D @ t1.T, D @ t2.T), axis=-1)                     # (M, Kg, 2)
            N1 = -(D @ n.T)                                                  # (M, Kg)
            t = law.line_roots(np.broadcast_to(T0, T1.shape), np.broadcast_to(N0, N1.shape),
                               T1, N1)                                       # (M, Kg, R)
            T = T0[..., None, :] + np.nan_to_num(t)[..., None] * T1[..., None, :]
            N = N0[..., None] + np.nan_to_num(t) * N1[..., None]
            ok = np.isfinite(t) & (N > 0) & (np.hypot(T[..., 0], T[..., 1]) > 0)
            s = law.slip(np.where(ok[..., None], T, 0.0), np.where(ok, N, 1.0))
            jj = np.broadcast_to(J[None, :, None], t.shape)
            V = self._global(s, jj)
            if ok.any():
                ok[ok] = self.admissible(V[ok], skip=jj[ok][:, None])
            loads = np.where(ok, t, np.inf).reshape(M, -1)
            idx = np.argmin(loads, axis=-1)
            c, r = np.divmod(idx, t.shape[-1])

            def normal(take, c=c, r=r, T=T, N=N, J=J, law=law):
                df = law.limit_gradient(T[m_ix, c, r][take], N[m_ix, c, r][take])
                return unit(self._global(df * [1.0, 1.0, -1.0], J[c][take]))

            best.single(loads[m_ix, idx], J[c], N[m_ix, c, r], V[m_ix, c, r], normal)
        best.pairs(D, self)
        return static_cap(best.result(self.index), self.static, d)

    # ---- what the protocol needs ---------------------------------------------------------
    def one_facet_terms(self, F: np.ndarray, j: np.ndarray, quasi_static: np.ndarray):
        """Gradients in ``F`` of the local limit condition and potential of facets ``j`` at
        their local forces :math:`(F\\cdot t_1, F\\cdot t_2, -F\\cdot n)`, and the potential
        (of the associated twin where ``quasi_static`` is False). Outside a facet's compression
        range (``N < 0``) the local functions are taken at ``N = 0``."""
        pos = np.searchsorted(self.index, j)
        pos = np.where((pos < len(self.index)) & (self.index[np.minimum(pos, len(self.index) - 1)]
                                                  == j), pos, 0)
        df, g, dg = np.zeros(F.shape), np.zeros(len(F)), np.zeros(F.shape)
        flip = np.array([1.0, 1.0, -1.0])
        for gi, law in enumerate(self.laws):
            for twin in (False, True):
                rows = np.flatnonzero((self.law_of[pos] == gi) & (quasi_static == (not twin)))
                if len(rows) == 0:
                    continue
                a = law.twin() if twin else law
                jj = pos[rows]
                T = np.stack((np.sum(F[rows] * self.t1[jj], -1), np.sum(F[rows] * self.t2[jj], -1)),
                             axis=-1)
                N = np.maximum(-np.sum(F[rows] * self.n[jj], -1), 0.0)
                df[rows] = self._global(a.limit_gradient(T, N) * flip, jj)
                g[rows] = a.potential(T, N)
                dg[rows] = self._global(a.potential_gradient(T, N) * flip, jj)
        return df, g, dg

    def slide_force(self, u: np.ndarray) -> np.ndarray:
        """Loads (``Q = 1``) on the limit curve whose block velocity slides at the horizontal
        unit vectors ``u`` (M, 2): sign changes of the velocity's angle over
        :data:`CURVE_DIRECTIONS` load directions, refined by bracketing; the smallest ``|T|``."""
        theta = np.arctan2(u[:, 1], u[:, 0])
        phi = -np.pi + 2.0 * np.pi * np.arange(CURVE_DIRECTIONS) / CURVE_DIRECTIONS
        sol = self.solve(directions(phi))
        V = sol.velocity
        ok = np.isfinite(sol.load) & (np.hypot(V[:, 0], V[:, 1]) > 1e-12)
        ang = np.arctan2(V[:, 1], V[:, 0])
        d = wrap(ang[None, :] - theta[:, None])
        dn, okn = np.roll(d, -1, axis=1), np.roll(ok, -1)
        q, i = np.nonzero(ok & okn & (d * dn <= 0) & (np.abs(d - dn) < np.pi / 2))
        lo, hi = phi[i], phi[i] + 2.0 * np.pi / CURVE_DIRECTIONS

        def mismatch(x, idx):
            s = self.solve(directions(x))
            dm = wrap(np.arctan2(s.velocity[:, 1], s.velocity[:, 0]) - theta[q[idx]])
            return np.where(np.isfinite(s.load), dm, np.pi)    # a locked gap acts as a jump

        root = bracketed_root(mismatch, lo, hi, d[q, i], dn[q, i], xtol=1e-12)
        s = self.solve(directions(root))
        loads = [(q, s.load[:, None] * directions(root))]
        loads.append(self._pair_segments(theta))
        out = np.full((len(u), 2), np.inf)
        for qq, T in loads:
            for row, Tr in zip(qq, T):
                if np.all(np.isfinite(Tr)) and np.hypot(*Tr) < np.hypot(*out[row]):
                    out[row] = Tr
        return out

    def _pair_segments(self, theta: np.ndarray):
        """Where a two-facet mechanism slides exactly at ``theta``: the smallest load on its
        segment of the limit curve (the segment's loads all slide one way)."""
        if len(self.pair_j) == 0:
            return np.zeros(0, int), np.zeros((0, 2))
        Vh = self.pair_v[:, :2]
        ang = np.arctan2(Vh[:, 1], Vh[:, 0])
        q, p = np.nonzero((np.abs(wrap(ang[None, :] - theta[:, None])) < 1e-9)
                          & (np.hypot(*Vh.T) > 1e-12)[None, :])
        rows, pts, pairs = [], [], []
        for qq, pp in zip(q, p):
            rj, rk = self.pair_r[pp]
            # F = -(N_j r_j + N_k r_k) with F_z = -1: loads between the ends N_k = 0, N_j = 0
            ends = np.array([-r[:2] / r[2] for r in (rj, rk) if r[2] > 0])
            if len(ends) == 2:
                rows.append(qq)
                pts.append(nearest_on_segments(ends))
                pairs.append(pp)
        if not rows:
            return np.zeros(0, int), np.zeros((0, 2))
        T, pairs = np.array(pts), np.array(pairs)
        size = np.hypot(T[:, 0], T[:, 1])
        s = self.solve(np.where(size[:, None] > 0, T / np.where(size > 0, size, 1.0)[:, None],
                                [1.0, 0.0]))
        want = self.index[np.stack((self.pair_j[pairs], self.pair_k[pairs]), axis=-1)]
        same = np.all(s.active, axis=-1) & np.all(np.sort(s.facets, axis=-1) == np.sort(want, -1),
                                                    axis=-1)
        same &= np.abs(s.load - size) <= 1e-9 * (1.0 + size)
        return np.array(rows)[same], T[same]

    def downward_velocity(self):
        """A unit velocity admissible for the associated twins that makes the block descend
        (the vertical load is then not carried), or ``None``: the lowest point of each facet's
        dual cone, and the twins' two-facet velocities (``._coulomb.downward_velocity``)."""
        geo = self.static if self.static is not None else self
        cands = [geo.pair_v]
        step = 2.0 * np.pi / BOUNDARY_SAMPLES
        p = -np.pi + step * np.arange(BOUNDARY_SAMPLES)
        for g, law in enumerate(geo.laws):
            J = np.flatnonzero(geo.law_of == g)

            def height(pp, facets):
                V = geo._global(law.boundary(pp), np.broadcast_to(facets, np.shape(pp)))
                return np.nan_to_num(V[..., 2], nan=np.inf)

            hs = height(np.broadcast_to(p[:, None], (len(p), len(J))), J)
            i = np.argmin(hs, axis=0)
            best = p[i]
            # the sampled minimum is within O(step^2) of the true one: refine near zero only
            near = np.abs(hs[i, np.arange(len(J))]) < 1e-3
            if near.any():
                best[near] = golden_min(lambda x: height(x, J[near]), best[near] - step,
                                        best[near] + step, iters=40)[0]
            cands.append(unit(geo._global(law.boundary(best), J)))
        V = np.concatenate(cands)
        V = V[(V[:, 2] < -1e-12)]
        V = V[geo.admissible(V)] if len(V) else V
        return V[0] if len(V) else None
