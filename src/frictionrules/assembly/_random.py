r"""Dense random packings by seeded compaction (:meth:`Assembly.random`).

The procedure (``docs/assembly.md``, "Random packings"):

1. radii ``r_i = r (1 + p u_i)``, ``u_i`` uniform in ``[-1, 1]`` (``p`` the polydispersity);
2. a cloud at the solid fraction 0.3 (0.5 for disks) in a cubic (square) periodic cell:
   centres drawn uniform in the cell, each kept where it overlaps no grain placed before
   (random sequential addition, largest grains first, as YADE's ``makeCloud``), then
   numbered by position (bins of a grid two largest diameters wide, in lexicographic order):
   the grains of a neighbourhood are near one another in memory, which on 10⁴ spheres takes
   13 % off a step of the dynamic engine;
3. compaction by the dynamic engine (:mod:`frictionrules.assembly`, "Dynamic runs"):
   frictionless grains with unit normal springs ``kn`` are compressed by the cell's servo
   until they carry the isotropic stress ``kn/(κ d)`` (``κ`` = :data:`PREPARATION_KAPPA`,
   ``d`` the mean diameter: overlaps of about ``d/κ``) with an unbalanced-force ratio below
   :data:`PREPARATION_UNBALANCED` (the grains moving by FIRE) — random close
   packing, the jammed state of frictionless grains; with ``solid_fraction`` given the cell
   is compressed to it at a constant rate and held until no grains overlap;
4. the cell is scaled up by the least factor that removes the overlaps: the grains of the
   compressed packing's contacts just touch, their gaps within the returned ``tolerance``.
   Consolidation then closes them.

The same ``seed`` gives the same packing (NumPy's PCG64 generator).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ..errors import FrictionRulesError, check_scalar

__all__ = ["Packing", "random_packing", "minimum_grains", "PREPARATION_KAPPA"]

#: Solid fraction of the random start, per dimension.
START = {2: 0.5, 3: 0.3}
#: Stiffness number ``kn/(p d)`` of the compaction's end: the packing's contacts overlap by
#: about ``d/κ`` before the cell is scaled to remove the overlaps.
PREPARATION_KAPPA = 1e3
#: ... and its unbalanced-force ratio (consolidation then balances the forces to its own).
#: (Measured on spheres r(1 ± 0.2): κ = 1e4 with a ratio of 1e-3 took 23 s for 400 grains and
#: 236 s for 1000, these 4.6 s and 8.7 s by damped dynamics: near jamming the servo's every
#: move of the cell stirs the packing again; by FIRE 2000 grains take 10–14 s against 26 s,
#: 3.4–4.9 s approached from above as every frictionless consolidation is, and 2.2–3.0 s with
#: the normal response alone at its contacts.)
PREPARATION_UNBALANCED = 1e-2
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


@njit(cache=True)
def _add(x, placed, cand, radii, L, nb, head, nxt):
    """Random sequential addition from the candidates ``cand`` (rows in the unit cell) into
    ``x``, grains ``placed, placed + 1, ...`` (bins of ``head``/``nxt``, ``nb`` per side,
    at least 3, or 1 bin searched whole). Returns the grains placed and the candidates used."""
    n, d = x.shape
    used = 0
    while placed < n and used < cand.shape[0]:
        r = radii[placed]
        y = np.empty(d)
        b = np.empty(d, np.int64)
        for a in range(d):
            y[a] = cand[used, a] * L
            b[a] = min(int(cand[used, a] * nb), nb - 1)
        used += 1
        ok = True
        span = 1 if nb >= 3 else 0
        for o in range(3 ** d if span else 1):
            key = 0
            rest = o
            for a in range(d):
                k = (b[a] + rest % 3 - 1) % nb if span else 0
                rest //= 3
                key = key * nb + k
            g = head[key]
            while g >= 0 and ok:
                dd = 0.0
                for a in range(d):
                    u = x[g, a] - y[a]
                    u -= L * np.floor(u / L + 0.5)
                    dd += u * u
                if dd < (r + radii[g]) ** 2:
                    ok = False
                g = nxt[g]
            if not ok:
                break
        if ok:
            key = 0
            for a in range(d):
                key = key * nb + (b[a] if nb >= 3 else 0)
            x[placed] = y
            nxt[placed] = head[key]
            head[key] = placed
            placed += 1
    return placed, used


def _cloud(rng, radii, L: float, dim: int) -> np.ndarray:
    """Centres of grains that do not overlap, by random sequential addition (candidates drawn
    from ``rng`` in blocks)."""
    n = len(radii)
    nb = int(L // (2 * radii.max()))
    nb = nb if nb >= 3 else 1
    x = np.zeros((n, dim))
    head = np.full(nb**dim, -1, dtype=np.int64)
    nxt = np.full(n, -1, dtype=np.int64)
    placed = 0
    for _ in range(1000):
        placed, _used = _add(x, placed, rng.uniform(0, 1, (4 * n, dim)), radii, L, nb, head, nxt)
        if placed == n:
            return x
    raise FrictionRulesError(f"n = {n!r}: random sequential addition could not place the grains "
                             "in the cloud; constraint: a cloud below the solid fraction of "
                             "random sequential addition")


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


def _by_position(x: np.ndarray, L: float, width: float) -> np.ndarray:
    """The grains in the lexicographic order of the bins (about ``width`` wide) of the cube of
    side ``L`` they lie in (a stable sort: within a bin, as placed)."""
    bins = max(1, int(L // width))
    b = np.clip((x / L * bins).astype(np.int64), 0, bins - 1)
    key = np.zeros(len(x), dtype=np.int64)
    for a in range(x.shape[1]):
        key = key * bins + b[:, a]
    return np.argsort(key, kind="stable")


def random_packing(n: int, dim: int, *, radius=1.0, polydispersity: float = 0.0,
                   solid_fraction: float | None = None, seed: int = 0,
                   report=None) -> Packing:
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
    report : callable, optional
        ``report(text)`` hears how the compaction goes.
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
    radii = -np.sort(-radii)
    x = _cloud(rng, radii, L, dim)
    order = _by_position(x, L, 4.0 * float(radii.max()))
    x, radii = x[order], radii[order]
    cell = L * np.eye(dim)
    if solid_fraction is not None and solid / L**dim >= solid_fraction:
        return Packing(x, radii, cell, 0.0, False)
    from ._dem import compress_to, frictionless_compression
    if solid_fraction is not None:
        x, cell = compress_to(x, radii, cell, solid_fraction)
        return Packing(x, radii, cell, 0.0, False)
    x, cell = frictionless_compression(x, radii, cell, 1.0, 1.0 / (PREPARATION_KAPPA * 2 * r0),
                                       unbalanced_tol=PREPARATION_UNBALANCED,
                                       report=report,
                                       name="packing")
    # the least expansion that leaves no overlap: the contacts of the compressed packing just
    # touch, their gaps the tolerance
    from ._contacts import find_contacts
    touching = find_contacts(x, radii, cell, 0.0)
    dist = touching.gap + radii[touching.i] + radii[touching.j]
    scale = float(np.max((radii[touching.i] + radii[touching.j]) / dist)) if len(dist) else 1.0
    x, cell = x * scale, cell * scale
    gaps = scale * dist - radii[touching.i] - radii[touching.j]
    tolerance = float(gaps.max()) * (1 + 1e-9) + 1e-12 * r0 if len(gaps) else 0.0
    return Packing(x, radii, cell, tolerance, True)


