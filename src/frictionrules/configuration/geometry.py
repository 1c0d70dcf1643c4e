r"""Geometry of a grain resting on a layer of grains of the same diameter ``d``.

The upper grain translates (no rotation, as in the paper) with its centre kept on the *contact
surface*: the upper envelope of the spheres (cylinders) of radius ``d`` drawn about the centres
of the layer grains, ``d`` being the sum of the two radii ("R is the diameter" in (3.6), (3.12)).
Its height above the layer centres at horizontal position ``u`` is

.. math:: z(u) = \max_k \sqrt{d^2 - |u - c_k|^2},

and the active contacts are the layer grains attaining the maximum. The unit contact normal
(from the layer grain to the upper grain) of contact k is

.. math:: n = \frac{(u - c_k,\; z_k)}{d} = (-\sin\alpha\cos\psi,\; -\sin\alpha\sin\psi,\; \cos\alpha),

which defines the inclination ``alpha`` of the plane tangent to both grains and the azimuth
``psi`` of its up-slope direction (counter-clockwise from x). For cylinders (axes along y) the
offset has no y part, ``psi = 0`` and ``alpha`` is signed: positive while climbing towards +x,
negative past the top.

Layers (the rest position, the *pocket*, is always the origin ``u = 0``):

* ``"line"``: cylinders with axes at ``x = (i + 1/2) d``; rest inclination ``pi/6``;
* ``"single"``: one sphere at ``(d/sqrt(3), 0)`` (the +x neighbour of the hexagonal pocket);
* ``"square"``: spheres at ``((i + 1/2) d, (j + 1/2) d)``; the pocket touches 4, ``alpha = pi/4``;
* ``"hexagonal"``: a close-packed layer, pocket touching 3 spheres at azimuths 0, 120, 240 deg
  and horizontal distance ``d/sqrt(3)``, ``alpha = arcsin(1/sqrt(3))``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError

KINDS = ("line", "single", "square", "hexagonal")

#: Grains whose heights at a point agree within this fraction of ``d`` touch the upper grain at
#: once (round-off of the square roots in the envelope).
HEIGHT_TOL = 1e-9
#: Contacts whose heights grow along the motion at rates within this tolerance slide at once.
SLOPE_TOL = 1e-7

_S3 = np.sqrt(3.0)


@dataclass(frozen=True)
class Layer:
    """A layer of grains of diameter ``diameter``; ``kind`` in :data:`KINDS`."""

    kind: str
    diameter: float

    @property
    def cylindrical(self) -> bool:
        return self.kind == "line"

    def grains(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Ids ``(K, 2)`` (integer lattice coordinates) and centres ``(K, 2)`` of the layer grains
        that can touch the upper grain somewhere in the bounding box of ``points`` ``(n, 2)``."""
        d = self.diameter
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        lo, hi = pts.min(axis=0) - 1.5 * d, pts.max(axis=0) + 1.5 * d
        if self.kind == "single":
            return np.array([[0, 0]]), np.array([[d / _S3, 0.0]])
        if self.kind == "line":
            i = np.arange(np.floor(lo[0] / d) - 1, np.ceil(hi[0] / d) + 1).astype(int)
            ids = np.stack((i, np.zeros_like(i)), axis=-1)
            return ids, np.stack(((i + 0.5) * d, np.zeros(i.shape)), axis=-1)
        if self.kind == "square":
            i = np.arange(np.floor(lo[0] / d) - 1, np.ceil(hi[0] / d) + 1).astype(int)
            j = np.arange(np.floor(lo[1] / d) - 1, np.ceil(hi[1] / d) + 1).astype(int)
            I, J = np.meshgrid(i, j, indexing="ij")
            ids = np.stack((I.ravel(), J.ravel()), axis=-1)
            return ids, (ids + 0.5) * d
        # hexagonal: c = A + i a1 + j a2 with A = (d/sqrt3, 0), a1 = d(sqrt3/2, -1/2), a2 = d(sqrt3/2, 1/2)
        a = np.array([[_S3 / 2, -0.5], [_S3 / 2, 0.5]]) * d
        A = np.array([d / _S3, 0.0])
        corners = np.array([[lo[0], lo[1]], [lo[0], hi[1]], [hi[0], lo[1]], [hi[0], hi[1]]]) - A
        ij = np.linalg.solve(a.T, corners.T).T
        rng = [np.arange(np.floor(ij[:, k].min()) - 1, np.ceil(ij[:, k].max()) + 2).astype(int)
               for k in range(2)]
        I, J = np.meshgrid(*rng, indexing="ij")
        ids = np.stack((I.ravel(), J.ravel()), axis=-1)
        return ids, A + ids @ a

    def offsets(self, points, centres) -> np.ndarray:
        """Horizontal offsets ``u - c_k``, shape ``(n, K, 2)`` (no y part for cylinders)."""
        r = np.asarray(points, dtype=float)[:, None, :] - centres[None, :, :]
        if self.cylindrical:
            r[..., 1] = 0.0
        return r


@dataclass(frozen=True)
class Contacts:
    """Active contacts along a sequence of points (at most two slide at once)."""

    ids: tuple            # per point: tuple of layer-grain ids (tuples of two ints)
    count: np.ndarray     # (n,) number of active contacts, 1 or 2
    normal: np.ndarray    # (n, 2, 3) unit normals of the active contacts (second is 0 if none)
    height: np.ndarray    # (n,) height of the centre above the layer centres


def active_contacts(layer: Layer, points, tangents, *, max_count: int = 2) -> Contacts:
    r"""Contacts that carry the grain at ``points`` ``(n, 2)`` moving along ``tangents`` ``(n, 2)``.

    The candidates attain the envelope height; of those, the active ones are the grains whose
    own height grows fastest along the motion, :math:`\partial z_k/\partial s =
    -(u - c_k)\cdot t / z_k` (a one-sided choice: at a pocket or a groove the grain leaves the
    contacts it moves away from). Ties within ``1e-9 d`` in height and ``1e-7`` in slope are
    contacts sliding at once (a ridge between two grains, a groove along a cylinder axis).

    Raises :class:`FrictionRulesError` where the grain is off the layer or more than
    ``max_count`` contacts slide at once.
    """
    d = layer.diameter
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    t = np.asarray(tangents, dtype=float).reshape(-1, 2)
    ids, centres = layer.grains(pts)
    r = layer.offsets(pts, centres)
    rho2 = np.einsum("nki,nki->nk", r, r)
    reach = rho2 < d * d
    z = np.sqrt(np.where(reach, d * d - rho2, 1.0))
    if not reach.any(axis=1).all():
        bad = int(np.argmin(reach.any(axis=1)))
        raise FrictionRulesError(
            f"position[{bad}] = {tuple(pts[bad])!r} is off the layer: no layer grain within the "
            f"diameter d = {d!r} (constraint: |u - c| < d for some layer grain c)")
    zmax = np.max(np.where(reach, z, -np.inf), axis=1)
    cand = reach & (z >= zmax[:, None] - HEIGHT_TOL * d)
    if layer.cylindrical:
        slope = -(r[..., 0] * t[:, None, 0]) / z
    else:
        slope = -np.einsum("nki,ni->nk", r, t) / z
    smax = np.max(np.where(cand, slope, -np.inf), axis=1)
    act = cand & (slope >= smax[:, None] - SLOPE_TOL)
    count = act.sum(axis=1)
    if count.max() > max_count:
        bad = int(np.argmax(count > max_count))
        raise FrictionRulesError(
            f"position[{bad}] = {tuple(pts[bad])!r}: {int(count[bad])} contacts slide at once "
            f"(supported: at most {max_count})")
    normal = np.zeros((len(pts), 2, 3))
    out_ids = []
    for n in range(len(pts)):
        ks = np.flatnonzero(act[n])
        out_ids.append(tuple(tuple(int(v) for v in ids[k]) for k in ks))
        for m, k in enumerate(ks):
            normal[n, m] = (r[n, k, 0] / d, r[n, k, 1] / d, z[n, k] / d)
    return Contacts(tuple(out_ids), count, normal, zmax)


@dataclass(frozen=True)
class Touching:
    """The layer grains touching the upper grain at one position.

    ``ids`` (K ids, lattice coordinates), ``normals`` (K, 3) unit contact normals (from the layer
    grain into the upper grain), ``centres`` (K, 2) their horizontal centres, ``height`` the
    height of the upper grain's centre.
    """

    ids: tuple
    normals: np.ndarray
    centres: np.ndarray
    height: float


def touching(layer: Layer, point) -> Touching:
    """All the layer grains touching the upper grain at the horizontal position ``point``."""
    d = layer.diameter
    p = np.asarray(point, dtype=float).reshape(1, 2)
    ids, centres = layer.grains(p)
    r = layer.offsets(p, centres)[0]
    rho2 = np.einsum("ki,ki->k", r, r)
    if not np.any(rho2 < d * d):
        raise FrictionRulesError(f"position = {tuple(p[0])!r} is off the layer: no layer grain "
                                 f"within the diameter d = {d!r}")
    z = np.sqrt(np.maximum(d * d - rho2, 0.0))
    on = np.flatnonzero((rho2 < d * d) & (z >= z.max() - HEIGHT_TOL * d))
    normals = np.concatenate((r[on], z[on, None]), axis=1) / d
    return Touching(tuple(tuple(int(v) for v in ids[k]) for k in on), normals, centres[on],
                    float(z.max()))


def angles(normal, cylindrical: bool) -> tuple[np.ndarray, np.ndarray]:
    r"""``(alpha, psi)`` of unit normals ``(..., 3)``: :math:`n = (-\sin\alpha\, e_\psi, \cos\alpha)`.

    Spheres: ``alpha = arccos(n_z)`` in [0, pi/2), ``psi = atan2(-n_y, -n_x)`` (0 at the top).
    Cylinders: ``psi = 0`` and the signed ``alpha = -arcsin(n_x)``.
    """
    n = np.asarray(normal, dtype=float)
    if cylindrical:
        return -np.arcsin(np.clip(n[..., 0], -1.0, 1.0)), np.zeros(n.shape[:-1])
    rho = np.hypot(n[..., 0], n[..., 1])
    return np.arctan2(rho, n[..., 2]), np.where(rho > 0, np.arctan2(-n[..., 1], -n[..., 0]), 0.0) + 0.0
