r"""Contacts of an assembly: detection with a tolerance, frames, and their histories.

A contact joins grain ``i`` to grain ``j`` seen through the image shift ``K`` (integers):
its branch vector is ``l = x_j + H K - x_i`` and its normal ``n = l/|l|`` points from ``i`` to
``j``. The frame is ``(t1, t2, n)`` with ``t1`` the unit projection of the reference axis onto
the contact plane and ``t2 = n × t1``; the local displacement ``(δt1, δt2, δn)`` is the motion
of ``j``'s contact point relative to ``i``'s in that frame (``δn > 0`` opening), and the force
``(T1, T2, N)`` of the law is the force of ``j`` on ``i``, ``T1 t1 + T2 t2 - N n``
(``docs/conventions.md``, "A facet's frame", with ``i`` the support).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..contact import ContactState
from ..errors import FrictionRulesError
from ..laws import LawState

__all__ = ["find_contacts", "frames", "ContactSet", "Found"]

#: Grains up to this many are paired by brute force; more use a k-d tree (SciPy).
BRUTE_FORCE_LIMIT = 120
#: Pairs closer than this many mean radii (or the tolerance, if larger) enter the contact set,
#: open: an increment's Newton iteration can close them (a grain rolls onto a neighbour).
SKIN = 0.05


def skin(assembly) -> float:
    """Gap below which a pair of grains is in the contact set (open or closed)."""
    return max(assembly.tolerance, SKIN * float(np.mean(assembly.radii)))


def embed(v: np.ndarray) -> np.ndarray:
    """Vectors ``(..., 2)`` of the xy plane as ``(..., 3)`` (z = 0); 3-vectors unchanged."""
    if v.shape[-1] == 3:
        return v
    return np.concatenate((v, np.zeros(v.shape[:-1] + (1,))), axis=-1)


@dataclass(frozen=True)
class Found:
    """Pairs of grains within the contact distance: ``i``, ``j``, shifts ``K`` (m, d) and gaps."""

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray
    gap: np.ndarray


def _offsets(d: int) -> np.ndarray:
    return np.stack(np.meshgrid(*[[-1, 0, 1]] * d, indexing="ij"), -1).reshape(-1, d)


def find_contacts(positions: np.ndarray, radii: np.ndarray, cell: np.ndarray,
                  tolerance: float) -> Found:
    """Every pair with gap ``|l| - r_i - r_j <= tolerance`` (one entry per contact).

    Fractional differences are wrapped to ``[-1/2, 1/2)`` and the nearest layer of images
    searched (the cell is at least one diameter wide, :class:`Assembly` checks it).
    """
    n, d = positions.shape
    inv = np.linalg.inv(cell)
    s = positions @ inv.T
    sw = s - np.floor(s)
    cutoff = 2 * radii.max() + tolerance
    if n <= BRUTE_FORCE_LIMIT:
        ii, jj = np.triu_indices(n)
        ds = sw[jj] - sw[ii]
        ds -= np.round(ds)
        off = _offsets(d)
        frac = ds[:, None, :] + off[None, :, :]
        ii = np.repeat(ii, len(off))
        jj = np.repeat(jj, len(off))
        frac = frac.reshape(-1, d)
    else:
        spatial = _require_scipy()
        off = _offsets(d)
        xw = sw @ cell.T
        images = (xw[None, :, :] + (off @ cell.T)[:, None, :]).reshape(-1, d)
        tree_x, tree_img = spatial.cKDTree(xw), spatial.cKDTree(images)
        pairs = tree_x.sparse_distance_matrix(tree_img, cutoff, output_type="ndarray")
        ii = pairs["i"].astype(np.intp)
        img = pairs["j"].astype(np.intp)
        jj = img % n
        frac = sw[jj] + off[img // n] - sw[ii]
        keep = ii <= jj
        ii, jj, frac = ii[keep], jj[keep], frac[keep]
    # One entry per contact: i < j, or a grain and its own image with the shift "positive".
    self_image = ii == jj
    first = _first_nonzero(frac)
    keep = ~self_image | (first > 0)
    ii, jj, frac = ii[keep], jj[keep], frac[keep]
    l = frac @ cell.T
    dist = np.linalg.norm(l, axis=1)
    gap = dist - radii[ii] - radii[jj]
    close = gap <= tolerance
    ii, jj, frac, gap = ii[close], jj[close], frac[close], gap[close]
    shift = np.rint(frac - (s[jj] - s[ii])).astype(np.int64)
    order = np.lexsort((*shift.T[::-1], jj, ii))
    return Found(ii[order], jj[order], shift[order], gap[order])


def _first_nonzero(frac: np.ndarray) -> np.ndarray:
    """The first component of each row that is not zero (to 1e-9), 0 for a zero row."""
    nz = np.abs(frac) > 1e-9
    idx = np.argmax(nz, axis=1)
    val = frac[np.arange(len(frac)), idx]
    return np.where(nz.any(axis=1), val, 0.0)


def _require_scipy():
    from .._optional import require
    return require("scipy.spatial", purpose="contact detection in assemblies of more than "
                   f"{BRUTE_FORCE_LIMIT} grains")


def branches(positions, cell, i, j, shift) -> np.ndarray:
    """Branch vectors ``l = x_j + H K - x_i`` (m, d)."""
    return positions[j] + shift @ cell.T - positions[i]


def frames(normals: np.ndarray, reference_axis: np.ndarray) -> np.ndarray:
    r"""Contact frames, rows ``(t1, t2, n)`` (m, 3, 3) from unit normals (m, 3).

    ``t1 = (a - (a·n) n)/|a - (a·n) n|`` for the reference axis ``a``; where ``a`` is normal to
    the contact the next global axis after ``a``'s largest component takes its place.
    ``t2 = n × t1``.
    """
    a = np.asarray(reference_axis, dtype=float)
    p = a[None, :] - (normals @ a)[:, None] * normals
    norm = np.linalg.norm(p, axis=1)
    bad = norm < 1e-6
    if bad.any():
        other = np.zeros(3)
        other[(int(np.argmax(np.abs(a))) + 1) % 3] = 1.0
        nb = normals[bad]
        p[bad] = other[None, :] - (nb @ other)[:, None] * nb
        norm[bad] = np.linalg.norm(p[bad], axis=1)
    t1 = p / norm[:, None]
    t1 -= np.sum(t1 * normals, axis=1)[:, None] * normals  # a second pass: orthogonal to rounding
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    t2 = np.cross(normals, t1)
    return np.stack((t1, t2, normals), axis=1)


# ---- histories ----------------------------------------------------------------------------
def take(state: ContactState, idx: np.ndarray) -> ContactState:
    """The contacts ``idx`` of a one-dimensional batch."""
    internal = state.internal
    return ContactState(state.elastic[idx], state.plastic[idx], state.kappa[idx], state.beta[idx],
                        LawState(internal.names, internal.values[idx]))


def concat(states: list[ContactState]) -> ContactState:
    """One batch of several one-dimensional batches of the same law."""
    if len(states) == 1:
        return states[0]
    names = states[0].internal.names
    return ContactState(np.concatenate([s.elastic for s in states]),
                        np.concatenate([s.plastic for s in states]),
                        np.concatenate([s.kappa for s in states]),
                        np.concatenate([s.beta for s in states]),
                        LawState(names, np.concatenate([s.internal.values for s in states])))


def reframe(state: ContactState, old: np.ndarray, new: np.ndarray) -> ContactState:
    """Carry the tangential displacements of a batch from frames ``old`` to frames ``new``.

    The tangential parts (vectors in the contact plane) are projected on the new plane and
    rescaled to their length; the normal parts are kept.
    """
    def move(v):
        g = np.einsum("ma,mab->mb", v[:, :2], old[:, :2, :])
        t = np.einsum("mab,mb->ma", new[:, :2, :], g)
        length, now = np.linalg.norm(v[:, :2], axis=1), np.linalg.norm(t, axis=1)
        t *= np.divide(length, now, out=np.zeros_like(now), where=now > 0)[:, None]
        return np.concatenate((t, v[:, 2:]), axis=1)
    return ContactState(move(state.elastic), move(state.plastic), state.kappa, state.beta, state.internal)


@dataclass(frozen=True, eq=False)
class ContactSet:
    """The contacts of an assembly and their histories.

    Attributes
    ----------
    i, j : (m,) int
        Grains of each contact (``j`` seen through the image ``shift``).
    shift : (m, d) int
        Image shift ``K``.
    group : (m,) int
        Index into :attr:`models` of each contact's model.
    models : tuple of ContactModel
        The distinct contact models.
    states : tuple of ContactState
        One batch per model, holding that model's contacts in the order they appear.
    frames : (m, 3, 3)
        Rows ``(t1, t2, n)`` of each contact at the geometry the set was made for.
    force, status : (m, 3), (m,) or None
        ``(T1, T2, N)`` and the update status of the increment that led here (None when built).
    """

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray
    group: np.ndarray
    models: tuple
    states: tuple
    frames: np.ndarray
    force: np.ndarray | None = None
    status: np.ndarray | None = None

    @property
    def size(self) -> int:
        return len(self.i)

    def keys(self) -> list[tuple]:
        return [(int(a), int(b), *map(int, k)) for a, b, k in zip(self.i, self.j, self.shift)]

    def members(self, g: int) -> np.ndarray:
        """Indices of the contacts of model ``g`` (in the order of its state batch)."""
        return np.flatnonzero(self.group == g)

    def per_contact(self, name: str) -> np.ndarray:
        """A field of the states (``elastic``, ``plastic``, ``kappa``) in contact order."""
        first = getattr(self.states[0], name) if self.states else np.zeros((0, 3))
        out = np.zeros((self.size,) + first.shape[1:])
        for g, state in enumerate(self.states):
            out[self.members(g)] = getattr(state, name)
        return out


def build(assembly, positions, cell, previous: ContactSet | None = None, *,
          check_overlap: bool = True) -> ContactSet:
    """The contacts at the given geometry; those of ``previous`` keep their histories.

    Pairs within the :func:`skin` gap are contacts (those beyond the tolerance start open); a
    contact of ``previous`` is also kept while its law still carries a force. A new contact
    starts virgin with its gap as the elastic normal displacement (an overlap is a
    compression).
    """
    found = find_contacts(positions, assembly.radii, cell, skin(assembly))
    keys = [(int(a), int(b), *map(int, k)) for a, b, k in zip(found.i, found.j, found.shift)]
    old_index = {} if previous is None else {k: c for c, k in enumerate(previous.keys())}
    if previous is not None:
        # keep contacts that still carry a force although a little further than the skin
        elastic = previous.per_contact("elastic")
        present = set(keys)
        extra = [c for c, k in enumerate(previous.keys())
                 if k not in present and elastic[c, 2] < 0]
        if extra:
            extra = np.asarray(extra)
            ei, ej, es = previous.i[extra], previous.j[extra], previous.shift[extra]
            l = branches(positions, cell, ei, ej, es)
            gap = np.linalg.norm(l, axis=1) - assembly.radii[ei] - assembly.radii[ej]
            found = Found(np.concatenate((found.i, ei)), np.concatenate((found.j, ej)),
                          np.concatenate((found.shift, es)), np.concatenate((found.gap, gap)))
            keys += [previous.keys()[c] for c in extra]
    if check_overlap and previous is None and np.any(found.gap < -assembly.tolerance):
        c = int(np.argmin(found.gap))
        raise FrictionRulesError(
            f"grains {int(found.i[c])} and {int(found.j[c])} overlap by {-float(found.gap[c])!r}; "
            f"constraint: overlap <= tolerance = {assembly.tolerance!r}")
    l3 = embed(branches(positions, cell, found.i, found.j, found.shift))
    normals = l3 / np.linalg.norm(l3, axis=1)[:, None]
    fr = frames(normals, assembly.reference_axis)
    models: list = [] if previous is None else list(previous.models)
    group = np.empty(len(keys), dtype=np.intp)
    for c, (a, b) in enumerate(zip(found.i, found.j)):
        m = assembly.model_of(a, b)
        try:
            group[c] = models.index(m)
        except ValueError:
            models.append(m)
            group[c] = len(models) - 1
    states = []
    for g, model in enumerate(models):
        idx = np.flatnonzero(group == g)
        parts = []
        old = [old_index.get(keys[c]) for c in idx]
        kept = [c for c, o in zip(idx, old) if o is not None]
        if kept:
            olds = np.array([o for o in old if o is not None])
            pos = np.searchsorted(previous.members(g), olds)
            parts.append(reframe(take(previous.states[g], pos), previous.frames[olds], fr[kept]))
        fresh = [c for c, o in zip(idx, old) if o is None]
        if fresh:
            s0 = model.initial_state(len(fresh))
            e = np.zeros((len(fresh), 3))
            e[:, 2] = found.gap[fresh]
            parts.append(ContactState(e, s0.plastic, s0.kappa, s0.beta, s0.internal))
        order = np.argsort(np.concatenate((kept, fresh)).astype(np.intp), kind="stable")
        states.append(take(concat(parts), order) if parts else model.initial_state(0))
    return ContactSet(found.i, found.j, found.shift, group, tuple(models), tuple(states), fr)
