"""Result records of the facet mechanisms: one limit load, many, a limit curve and its corners.

``Mechanisms`` is the solvers' internal record (unit vertical load, user facet numbering), from
which the public records are built.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import ClassVar

import numpy as np

__all__ = ["LimitLoad", "LimitLoads", "LimitCurve", "Corner"]

#: |turning| below which a mechanism change is a smooth join, not a corner (radians): the
#: bisection of a corner's direction leaves the two tangents this close at a tangent join.
SMOOTH = 1e-7


@dataclass(frozen=True)
class Mechanisms:
    """Limit loads at ``Q = 1`` in ``M`` unit directions, as the solvers return them.

    ``facets[:, i]`` is meaningful where ``active[:, i]``; ``forces`` are the normal forces of
    those facets; ``normal`` is the unit outward normal of the limit surface in ``(Tx, Ty, -Q)``.
    """

    load: np.ndarray          # (M,) inf where locked
    facets: np.ndarray        # (M, 2) int, user numbering
    active: np.ndarray        # (M, 2) bool
    forces: np.ndarray        # (M, 2)
    velocity: np.ndarray      # (M, 3)
    normal: np.ndarray        # (M, 3)
    quasi_static: np.ndarray  # (M,) bool

    @classmethod
    def concat(cls, parts) -> "Mechanisms":
        return cls(**{f.name: np.concatenate([getattr(p, f.name) for p in parts])
                      for f in fields(cls)})

    def where(self, mask: np.ndarray, other: "Mechanisms") -> "Mechanisms":
        """Rows of ``other`` where ``mask``, of ``self`` elsewhere."""
        out = {}
        for f in fields(self):
            a, b = getattr(self, f.name), getattr(other, f.name)
            out[f.name] = np.where(mask.reshape((-1,) + (1,) * (a.ndim - 1)), b, a)
        return Mechanisms(**out)

    def mechanism(self, i: int) -> tuple[int, ...]:
        """The sliding facets of row ``i`` (empty when locked)."""
        return tuple(int(f) for f, a in zip(self.facets[i], self.active[i]) if a)

    def labelled_facets(self) -> np.ndarray:
        """``(M, 2)`` facets with -1 for an inactive slot (the :class:`LimitCurve` layout)."""
        return np.where(self.active, self.facets, -1)


@dataclass(frozen=True)
class LimitLoad:
    """The limit load of a facet set in one horizontal direction.

    Attributes
    ----------
    load : float
        Load factor ``t``: the limit load is ``T = t d`` (``|d| = 1``); ``inf`` when locked.
    T : (2,) array
        Horizontal limit load ``(Tx, Ty)`` (``inf`` when locked).
    mechanism : tuple of int or None
        Indices of the sliding facets (one or two); ``None`` when locked.
    normal_forces : (K,) array
        Normal force on every facet (``>= 0``; zero off the mechanism).
    velocity : (3,) array
        Unit block velocity ``(Vx, Vy, Vz)``, ``Vz > 0`` upwards; zeros when locked.
    quasi_static : bool
        True when the block slides in equilibrium (a mechanism of the local rule). False
        (non-associated local laws only) when the static maximum comes first: beyond it no
        equilibrium exists, the block accelerates; ``mechanism``, ``normal_forces`` and
        ``velocity`` are then those of the static limit (the mechanism of the associated twins
        of the local laws, whose velocity is the normal of the static limit surface).
    """

    load: float
    T: np.ndarray
    mechanism: tuple[int, ...] | None
    normal_forces: np.ndarray
    velocity: np.ndarray
    quasi_static: bool = True


@dataclass(frozen=True)
class LimitLoads:
    """Limit loads of a facet set in ``M`` horizontal directions (:class:`LimitLoad` per row).

    Attributes
    ----------
    load : (M,) load factors ``t`` (``inf`` where locked).
    T : (M, 2) horizontal limit loads (``inf`` where locked).
    locked : (M,) bool, True where no mechanism exists in that direction.
    facets : (M, 2) int, the sliding facets; ``facets[i, s]`` is one only where ``active[i, s]``.
    active : (M, 2) bool, which of the two slots hold a sliding facet (none when locked, the
        first for a one-facet mechanism, both for a two-facet one).
    normal_forces : (M, K) normal force on every facet (zero off the mechanism).
    velocity : (M, 3) unit block velocities (zeros where locked).
    quasi_static : (M,) bool, see :class:`LimitLoad`.
    """

    load: np.ndarray
    T: np.ndarray
    locked: np.ndarray
    facets: np.ndarray
    active: np.ndarray
    normal_forces: np.ndarray
    velocity: np.ndarray
    quasi_static: np.ndarray

    def __len__(self) -> int:
        return len(self.load)

    def __getitem__(self, i: int) -> LimitLoad:
        """Row ``i`` as a :class:`LimitLoad`."""
        ids = tuple(int(f) for f, a in zip(self.facets[i], self.active[i]) if a)
        return LimitLoad(load=float(self.load[i]), T=self.T[i].copy(),
                         mechanism=ids if ids else None,
                         normal_forces=self.normal_forces[i].copy(),
                         velocity=self.velocity[i].copy(),
                         quasi_static=bool(self.quasi_static[i]))


@dataclass(frozen=True)
class Corner:
    """A corner of the limit curve, where the mechanism changes.

    Attributes
    ----------
    T : (2,) array
        Position ``(Tx, Ty)`` at the ``Q`` of the curve.
    direction : float
        Polar angle of ``T`` (radians).
    before, after : tuple of int
        Mechanisms on either side (counter-clockwise order).
    turning : float
        Signed turning angle of the tangent when the curve is run counter-clockwise
        (radians): ``> 0`` a convex corner, ``< 0`` a concave (re-entrant) one.
    interior : float
        Interior angle ``pi - turning``; ``> pi`` for a concave corner.
    """

    T: np.ndarray
    direction: float
    before: tuple[int, ...]
    after: tuple[int, ...]
    turning: float
    interior: float

    @property
    def concave(self) -> bool:
        """True for a re-entrant corner (``turning < -1e-7``; smaller turnings are smooth
        joins, e.g. the tangent joins of the associated rule)."""
        return self.turning < -SMOOTH


@dataclass(frozen=True)
class LimitCurve:
    """The limit curve of a facet set at fixed ``Q``, ordered by load direction.

    Attributes
    ----------
    Q : float
    direction : (M,) load directions (polar angles of ``T``), increasing over ``[-pi, pi)``.
    T : (M, 2) limit loads (``inf`` where locked).
    load : (M,) load factors ``|T|``.
    facets : (M, 2) int, sliding facets (``-1`` for none / the second of a one-facet mechanism).
    normal_forces : (M, 2) normal forces on those facets.
    velocity : (M, 3) unit block velocities (the global sliding rule).
    normal : (M, 3) unit outward normals of the limit surface in the space
        ``(Tx, Ty, -Q)`` conjugate to the velocity (the associated direction).
    rule_angle : (M,) angle between ``velocity`` and ``normal``: how non-associated the global
        rule is (0 where it is associated).
    tangential_rule_angle : (M,) the same for the horizontal parts (the sliding plane).
    corners : tuple of :class:`Corner`
    quasi_static : (M,) bool, see :class:`LimitLoad`.
    """

    Q: float
    direction: np.ndarray
    T: np.ndarray
    load: np.ndarray
    facets: np.ndarray
    normal_forces: np.ndarray
    velocity: np.ndarray
    normal: np.ndarray
    rule_angle: np.ndarray
    tangential_rule_angle: np.ndarray
    corners: tuple[Corner, ...]
    quasi_static: np.ndarray

    #: Default tolerance of :meth:`merged` (radians, 2°): the facets of a measured surface are
    #: its grouped gradients (the hull vertices in 128 directions, 2.8° apart), so a smoothly
    #: curved surface gives corners a degree or so from 180° that are not features of it.
    NOISE_CORNER: ClassVar[float] = float(np.deg2rad(2.0))

    def merged(self, tolerance: float | None = None) -> LimitCurve:
        """This curve with every corner whose interior angle lies within ``tolerance``
        (radians, default :attr:`NOISE_CORNER`) of 180° merged away: the pieces on either
        side count as one smooth piece, and such a corner is neither listed nor concave."""
        tol = self.NOISE_CORNER if tolerance is None else float(tolerance)
        return replace(self, corners=tuple(c for c in self.corners if abs(c.turning) > tol))

    @property
    def labels(self) -> list[str]:
        """Mechanism label per point: ``"1"``, ``"0+2"``, or ``"locked"`` (facet indices)."""
        return [_label(row) for row in self.facets]

    @property
    def concave_corners(self) -> tuple[Corner, ...]:
        return tuple(c for c in self.corners if c.concave)


def _label(row) -> str:
    ids = [int(i) for i in row if i >= 0]
    return "+".join(map(str, ids)) if ids else "locked"
