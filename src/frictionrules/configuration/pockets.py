r"""Breaking out of a pocket: which contacts slide when a grain at rest is pushed in any direction.

The grain rests in the pocket (the origin) on 2 (cylinder groove), 3 (hexagonal) or 4 (square)
layer grains. A horizontal force :math:`T = t\,(\cos\beta, \sin\beta)` grows from zero; motion
starts by one of the mechanisms

* **over one** grain k: contact k slides (the wedge (2.2) of contact k in its frame (3.11), on
  its climbing branch :math:`T_1 > 0`), its slip (2.3) rotated by :math:`\psi_k`,
  :math:`V = R(\psi_k)(e_1\cos\alpha, e_2, e_1\sin\alpha)`, must separate the grain from all the
  other pocket grains, :math:`(p - c_j)\cdot V > 0`;
* **over two** grains j, k at once (a ridge): the grain moves along the intersection of both
  contact spheres, :math:`V \parallel n_j\times n_k` (upwards), both contacts slide with
  :math:`N (n - \mu\hat V)`, and equilibrium
  :math:`t\,e_\beta + N_j (n_j - \mu\hat V) + N_k (n_k - \mu\hat V) = Q e_z` needs
  :math:`t, N_j, N_k \ge 0` and separation from the others.

The break-out force is the smallest ``t`` over the admissible mechanisms (the first one the
growing force meets); past it the grain softens, so it is the peak force in that direction.
"""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError
from .geometry import angles
from .state import PeakForcePolar


def pocket_contacts(model):
    """Centres ``(K, 3)`` and unit normals ``(K, 3)`` of the grains touching the grain at rest."""
    d = model.diameter
    ids, centres = model.layer.grains(np.zeros((1, 2)))
    r = model.layer.offsets(np.zeros((1, 2)), centres)[0]
    rho = np.hypot(r[:, 0], r[:, 1])
    z0 = np.sqrt(max(d * d - rho.min() ** 2, 0.0))
    touch = np.abs(rho - rho.min()) <= 1e-9 * d
    r = r[touch]
    normals = np.concatenate((r, np.full((len(r), 1), z0)), axis=1) / d
    return normals, [tuple(int(v) for v in i) for i in ids[touch]]


def _over_one(model, n, beta, others):
    """Force magnitude for climbing over the contact with normal ``n`` under a force along
    ``beta``, or ``inf`` if that mechanism is not admissible. The climbing branch of the limit
    curve is scanned in the in-plane force angle (4000 points) and the crossing with the ray
    ``beta`` interpolated linearly (relative error below 1e-6)."""
    mu, Q = model.mu, model.Q
    a, p = angles(n, False)            # alpha >= 0, up-slope azimuth psi (also for cylinders)
    phi = np.linspace(-np.pi / 2, np.pi / 2, 4001)[1:-1]           # climbing branch e1 > 0
    den = np.cos(a) - mu * np.cos(phi) * np.sin(a)
    ok = den > 0
    N = Q / np.where(ok, den, 1.0)
    tp = np.stack((N * (np.sin(a) + mu * np.cos(phi) * np.cos(a)), mu * N * np.sin(phi)), axis=-1)
    c, s = np.cos(p), np.sin(p)
    T = np.stack((c * tp[:, 0] - s * tp[:, 1], s * tp[:, 0] + c * tp[:, 1]), axis=-1)
    e = np.array([np.cos(beta), np.sin(beta)])
    cross = T[:, 0] * e[1] - T[:, 1] * e[0]
    along = T @ e
    best = np.inf
    for i in np.flatnonzero(ok[:-1] & ok[1:] & (np.sign(cross[:-1]) != np.sign(cross[1:]))):
        w = cross[i] / (cross[i] - cross[i + 1])
        f = phi[i] + w * (phi[i + 1] - phi[i])
        t = along[i] + w * (along[i + 1] - along[i])
        if t <= 0:
            continue
        vp = np.array([np.cos(f) * np.cos(a), np.sin(f), np.cos(f) * np.sin(a)])
        V = np.array([c * vp[0] - s * vp[1], s * vp[0] + c * vp[1], vp[2]])
        if all(np.dot(m, V) > 1e-12 for m in others):
            best = min(best, t)
    return best


def _over_two(model, nj, nk, beta, others):
    mu, Q = model.mu, model.Q
    V = np.cross(nj, nk)
    if np.linalg.norm(V) < 1e-12:
        return np.inf
    V /= np.linalg.norm(V)
    if V[2] < 0 or (V[2] == 0 and np.dot(V[:2], [np.cos(beta), np.sin(beta)]) < 0):
        V = -V
    if not all(np.dot(m, V) > 1e-12 for m in others):
        return np.inf
    aj, ak = nj - mu * V, nk - mu * V
    A = np.array([[np.cos(beta), aj[0], ak[0]], [np.sin(beta), aj[1], ak[1]], [0.0, aj[2], ak[2]]])
    if abs(np.linalg.det(A)) < 1e-12:
        return np.inf
    t, Nj, Nk = np.linalg.solve(A, [0.0, 0.0, Q])
    return t if min(t, Nj, Nk) >= -1e-12 else np.inf


def breakout_force(model, directions) -> PeakForcePolar:
    """Break-out (peak) force of the grain at rest for forces along ``directions`` (radians).

    Returns a :class:`PeakForcePolar` whose ``direction`` is the force direction, ``peak`` the
    force magnitude, ``start`` the force vector and ``count`` the number of layer grains the
    grain climbs over (1 or 2). Raises :class:`FrictionRulesError` for a direction in which no
    mechanism can start (the pocket jams).
    """
    normals, _ = pocket_contacts(model)
    beta = np.atleast_1d(np.asarray(directions, dtype=float))
    peak = np.full(beta.shape, np.inf)
    count = np.zeros(beta.shape, dtype=int)
    K = len(normals)
    for i, b in enumerate(beta):
        for k in range(K):
            t = _over_one(model, normals[k], b, [normals[j] for j in range(K) if j != k])
            if t < peak[i] - 1e-12:
                peak[i], count[i] = t, 1
        for j in range(K):
            for k in range(j + 1, K):
                t = _over_two(model, normals[j], normals[k], b,
                              [normals[m] for m in range(K) if m not in (j, k)])
                if t < peak[i] - 1e-12:
                    peak[i], count[i] = t, 2
        if not np.isfinite(peak[i]):
            raise FrictionRulesError(f"directions[{i}] = {b!r}: no mechanism starts for a force "
                                     "in that direction (the pocket jams)")
    start = peak[:, None] * np.stack((np.cos(beta), np.sin(beta)), axis=-1)
    return PeakForcePolar(beta, peak, start, count)
