r"""Dense random packings by seeded compaction (:meth:`Assembly.random`).

The procedure (``docs/assembly.md``, "Random packings"):

1. radii ``r_i = r (1 + p u_i)``, ``u_i`` uniform in ``[-1, 1]`` (``p`` the polydispersity);
2. centres uniform in a cubic (square) periodic cell at the solid fraction 0.3 (0.5 for disks);
3. compaction: the cell and the centres shrink together by a factor ``1 - δ``, then the
   overlaps are relaxed by minimizing :math:`E = \tfrac12\sum_{c}\max(0, r_i + r_j -
   |l_c|)^2` (frictionless grains with linear normal springs, no gravity; L-BFGS). A stage
   is accepted when the largest overlap falls below ``1e-7 r_min``; otherwise the stage is
   undone and ``δ`` halved. ``δ`` grows by 1.5 after each accepted stage. Compaction stops at
   ``solid_fraction`` or where ``δ < 2e-4`` (jammed);
4. the cell is scaled up by the least factor that removes the last overlaps (``<= 1e-7
   r_min``): the grains just touch, and the pairs closer than ``2 δ r_mean`` (the last
   compaction step) are the contacts (the returned ``tolerance``). Consolidation then closes
   their gaps.

The same ``seed`` gives the same packing (NumPy's PCG64 generator).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_scalar

__all__ = ["Packing", "random_packing", "minimum_grains"]

#: Solid fraction of the random start, per dimension.
START = {2: 0.5, 3: 0.3}
#: Solid fraction of random close packing of equal grains (disks, spheres): the densest a
#: random packing gets, so the smallest its cell can be.
JAMMED = {2: 0.84, 3: 0.64}


@dataclass(frozen=True)
class Packing:
    """A packing: centres (n, d), radii (n,), cubic cell (d, d), the gap tolerance of its
    contacts, and whether compaction stopped at jamming."""

    positions: np.ndarray
    radii: np.ndarray
    cell: np.ndarray
    tolerance: float
    jammed: bool


def _pairs(x, radii, L, spatial):
    """Overlapping pairs (minimum image in the cubic cell of side L): i, j, branch, overlap."""
    d = x.shape[1]
    xw = np.mod(x, L)
    xw[xw >= L] = 0.0  # rounding of mod at L
    cutoff = 2 * radii.max()
    if spatial is not None:
        tree = spatial.cKDTree(xw, boxsize=L)
        pairs = tree.query_pairs(cutoff, output_type="ndarray")
        i, j = pairs[:, 0], pairs[:, 1]
    else:
        i, j = np.triu_indices(len(x), 1)
    l = xw[j] - xw[i]
    l -= L * np.round(l / L)
    dist = np.linalg.norm(l, axis=1)
    ov = radii[i] + radii[j] - dist
    keep = ov > 0
    return i[keep], j[keep], l[keep], dist[keep], ov[keep], d


class _Relaxed(Exception):
    def __init__(self, x):
        self.x = x


def _relax(x, radii, L, spatial, tol, iterations):
    """Minimize the overlap energy (L-BFGS) until the largest overlap is ``<= tol`` or
    ``iterations`` are done; returns (x, largest overlap)."""
    from .._optional import require
    optimize = require("scipy.optimize", purpose="random packings")
    shape = x.shape

    def energy(flat):
        y = flat.reshape(shape)
        i, j, l, dist, ov, _ = _pairs(y, radii, L, spatial)
        if not len(ov) or ov.max() <= tol:
            raise _Relaxed(y)
        push = (ov / np.maximum(dist, 1e-300))[:, None] * l
        grad = np.zeros_like(y)
        np.add.at(grad, i, push)
        np.add.at(grad, j, -push)
        return 0.5 * float(np.sum(ov**2)), grad.ravel()
    try:
        res = optimize.minimize(energy, x.ravel(), jac=True, method="L-BFGS-B",
                                options={"maxiter": iterations, "ftol": 0.0, "gtol": 0.0})
        x = res.x.reshape(shape)
    except _Relaxed as done:
        x = done.x
    ov = _pairs(x, radii, L, spatial)[4]
    return x, (float(ov.max()) if len(ov) else 0.0)


def minimum_grains(dim: int, polydispersity: float = 0.0,
                   solid_fraction: float | None = None) -> int:
    r"""The fewest grains of a random packing: its periodic cell must be at least two largest
    diameters wide, ``L >= 4 r_max``, so that a grain and its own image are at least a
    diameter apart and other grains come between them.

    With the cell of the grains at the solid fraction ``φ`` (random close packing unless
    given), ``L^d = n ⟨v⟩/φ``: ``n >= φ (4 r_max)^d/⟨v⟩``, with ``r_max = r (1 + p)`` and the
    mean grain volume ``⟨v⟩`` of radii ``r (1 + p u)``, ``u`` uniform in ``[-1, 1]``
    (``⟨(1 + p u)²⟩ = 1 + p²/3``, ``⟨(1 + p u)³⟩ = 1 + p²``). Equal spheres: 10; equal
    disks: 5.
    """
    phi = JAMMED[dim] if solid_fraction is None else solid_fraction
    if dim == 2:
        mean = np.pi * (1 + polydispersity**2 / 3)
    else:
        mean = 4 / 3 * np.pi * (1 + polydispersity**2)
    return int(np.ceil(phi * (4 * (1 + polydispersity)) ** dim / mean))


def random_packing(n: int, dim: int, *, radius=1.0, polydispersity: float = 0.0,
                   solid_fraction: float | None = None, seed: int = 0,
                   max_sweeps: int = 400) -> Packing:
    """A dense random packing of ``n`` grains by the compaction described in the module.

    Parameters
    ----------
    n : int
        Number of grains, at least :func:`minimum_grains` (a cell two largest diameters wide).
    dim : {2, 3}
        Disks or spheres.
    radius : float
        Mean radius.
    polydispersity : float
        Half-width of the uniform radius distribution relative to ``radius``, in ``[0, 1)``.
    solid_fraction : float, optional
        Stop compaction there (it must be below jamming); default: compact until jammed.
    seed : int
        Seed of the generator.
    max_sweeps : int
        Bound on the relaxation iterations of one stage.
    """
    if dim not in (2, 3):
        raise FrictionRulesError(f"dim = {dim!r} violates: 2 or 3")
    r0 = check_scalar("radius", radius, lo=0.0, lo_open=True)
    p = check_scalar("polydispersity", polydispersity, lo=0.0, hi=1.0, hi_open=True)
    top = 0.9 if dim == 2 else 0.74
    if solid_fraction is not None:
        solid_fraction = check_scalar("solid_fraction", solid_fraction, lo=0.05, lo_open=True,
                                      hi=top, hi_open=True)
    least = minimum_grains(dim, p, solid_fraction)
    if not isinstance(n, (int, np.integer)) or n < least:
        grains = "disks" if dim == 2 else "spheres"
        raise FrictionRulesError(
            f"n = {n!r} violates: an integer >= {least} for {grains} of polydispersity {p!r}: "
            "a random packing needs a periodic cell at least two largest diameters wide (else "
            "grains touch their own images and the sample is a crystal of a few grains)")
    if not isinstance(seed, (int, np.integer)):
        raise FrictionRulesError(f"seed = {seed!r} violates: an integer")
    rng = np.random.default_rng(int(seed))
    radii = r0 * (1 + p * rng.uniform(-1, 1, n))
    solid = np.pi * np.sum(radii**2) if dim == 2 else 4 / 3 * np.pi * np.sum(radii**3)
    L = (solid / START[dim]) ** (1 / dim)
    L = max(L, 2.2 * radii.max())
    x = rng.uniform(0, L, (n, dim))
    from .._optional import require
    spatial = require("scipy.spatial", purpose="random packings") if n > 60 else None
    tol = 1e-7 * radii.min()
    x, worst = _relax(x, radii, L, spatial, tol, max_sweeps)
    delta, jammed = 0.05, False
    goal = solid_fraction if solid_fraction is not None else top
    while True:
        phi = solid / L**dim
        if phi >= goal * (1 - 1e-12) or delta < 2e-4:
            jammed = delta < 2e-4
            break
        f = 1 - delta
        if solid_fraction is not None and phi / f**dim > solid_fraction:
            f = (phi / solid_fraction) ** (1 / dim)
        x_new, worst = _relax(x * f, radii, L * f, spatial, tol, max_sweeps)
        if worst <= tol:
            x, L = x_new, L * f
            delta = min(1.5 * delta, 0.05)
        else:
            delta *= 0.5
    # the least expansion that leaves no overlap: the grains of the densest accepted stage
    # just touch, the gaps of the near contacts within the tolerance
    x = np.mod(x, L)
    x[x >= L] = 0.0
    i, j, l, dist, ov, _ = _pairs(x, radii, L, spatial)
    scale = float(np.max((radii[i] + radii[j]) / dist)) if len(ov) else 1.0
    x, L = x * scale, L * scale
    tolerance = max(2 * delta, 1e-6) * float(radii.mean())
    return Packing(x, radii, L * np.eye(dim), tolerance, jammed)


def frictionless_compression(positions, radii, cell, kn: float, pressure: float,
                             max_sweeps: int = 2000, report=None):
    r"""Scale the cell isotropically until frictionless grains with linear normal springs
    ``kn`` carry the mean stress ``pressure`` in equilibrium (DEM's frictionless preparation).

    The positions minimize :math:`E = \tfrac12 k_n \sum_c \delta_c^2` (overlaps ``δ``) at each
    trial scale; the scale is found by bisection on the mean stress
    :math:`p = \frac{1}{dV}\sum_c k_n\delta_c |l_c|`. Returns ``(positions, cell)``;
    ``report(text)``, when given, hears the mean stress of every trial scale.
    """
    from .._optional import require
    optimize = require("scipy.optimize", purpose="the frictionless preparation of a sample")
    from ._contacts import branches, find_contacts
    n, d = positions.shape

    def relax(x, h):
        def energy(flat):
            y = flat.reshape(n, d)
            f = find_contacts(y, radii, h, 0.0)
            l = branches(y, h, f.i, f.j, f.shift)
            dist = np.linalg.norm(l, axis=1)
            ov = -f.gap
            push = (ov / dist)[:, None] * l
            grad = np.zeros_like(y)
            np.add.at(grad, f.i, push)
            np.add.at(grad, f.j, -push)
            return 0.5 * float(np.sum(ov**2)), grad.ravel()
        res = optimize.minimize(energy, x.ravel(), jac=True, method="L-BFGS-B",
                                options={"maxiter": max_sweeps, "ftol": 0.0, "gtol": 1e-13 * radii.mean()})
        y = res.x.reshape(n, d)
        f = find_contacts(y, radii, h, 0.0)
        l = branches(y, h, f.i, f.j, f.shift)
        p = kn * float(np.sum(-f.gap * np.linalg.norm(l, axis=1))) / (d * abs(np.linalg.det(h)))
        trials[0] += 1
        if report is not None:
            report(f"frictionless compression: trial {trials[0]}, mean stress {p:.4g} of "
                   f"{pressure:.4g}")
        return y, p

    trials = [0]
    x0, h0 = np.asarray(positions, float), np.asarray(cell, float)
    lo, hi = None, 1.0  # scales with p > pressure (lo) and p <= pressure (hi)
    x_hi = x0
    step = pressure * 2 * float(radii.mean()) / kn / float(radii.mean())
    for _ in range(60):
        s = 1 - step
        y, p = relax(x0 * s, h0 * s)
        if p > pressure:
            lo = s
            break
        hi, x_hi = s, y
        step *= 2
    if lo is None:
        raise FrictionRulesError(f"pressure = {pressure!r}: the frictionless compression found no "
                                 "jammed state (the sample is too loose)")
    for _ in range(40):
        s = 0.5 * (lo + hi)
        y, p = relax(x_hi * (s / hi), h0 * s)
        if p > pressure:
            lo = s
        else:
            hi, x_hi = s, y
        if abs(p - pressure) <= 1e-6 * pressure or hi - lo < 1e-15:
            break
    return y, h0 * s
