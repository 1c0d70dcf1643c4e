r"""The grain at rest: which loads its contacts carry, and the break-out force out of a pocket.

A grain resting on K layer grains translates like a rigid block on K facets whose normals are
the contact normals :math:`n_k` and whose local laws are the contacts' laws, each in its own
frame (``docs/conventions.md``). So the set of horizontal loads it carries at the vertical load
``Q`` is the inside of the limit curve of :class:`frictionrules.FacetSet`, and the *break-out
force* in a load direction is the facet set's limit load
``FacetSet(normals, law).limit_load(direction, Q)`` — exact: a root of a quadratic where the
grain climbs over one layer grain (one facet slides, its local limit condition met), the
solution of a 3×3 linear system where it rides the ridge between two (two facets slide along
their intersection, :math:`V \parallel n_j\times n_k`), the smallest over the kinematically
admissible mechanisms (the slip separates the grain from the other layer grains). Past it the
grain softens, so it is the peak force in that direction.

A grain touching one layer grain only (``SphereOnLayer(packing="single")``, the paper's
one-contact model, or a grain part-way up a neighbour) cannot carry ``Q`` alone; its pull down
the slope is taken to be held by the pocket it comes from (:meth:`GrainContact.climbing_limit`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._roots import brent
from ..asperities import FacetSet
from ..errors import FrictionRulesError
from ._contact import GrainContact
from .geometry import Touching, angles, touching
from .state import GrainState, PeakForcePolar

#: Loads up to this many ``Q`` along a ray are searched for the edge of a one-contact support;
#: a ray still inside there never leaves it (an open branch of the limit curve).
FAR = 1e6


@dataclass(frozen=True)
class Mechanism:
    """How the grain starts to move when the load reaches the edge of its support.

    Attributes
    ----------
    load : float
        The load factor along the load's direction at the edge (``inf`` where none starts).
    contacts : tuple of int
        Indices (into the support's contacts) of the sliding contacts; empty where no mechanism
        starts (the support jams).
    velocity : array (3,)
        Unit grain velocity (zeros where none starts).
    quasi_static : bool
        False where the grain loses equilibrium without a mechanism of the local sliding rule
        (:class:`frictionrules.FacetSet`, non-associated local laws).
    """

    load: float
    contacts: tuple
    velocity: np.ndarray
    quasi_static: bool = True


_JAMMED = Mechanism(np.inf, (), np.zeros(3))


@dataclass(frozen=True)
class Support:
    """The contacts of a grain at rest at one position and the loads they carry: several
    contacts as a facet set (``facets``), a single one as a :class:`GrainContact` held down the
    slope by the pocket the grain comes from (``contact``).

    ``limit(T, Q)`` is negative inside (the grain sticks), zero on the edge (it starts to move,
    :meth:`mechanism`), positive outside.
    """

    model: object
    position: np.ndarray
    touching: Touching
    facets: FacetSet | None
    contact: GrainContact | None

    @classmethod
    def at(cls, model, position) -> "Support":
        position = np.asarray(position, dtype=float).reshape(2)
        t = touching(model.layer, position)
        if len(t.ids) == 1:
            a, p = angles(t.normals[0], model.layer.cylindrical)
            return cls(model, position, t, None, GrainContact(model.law, float(a), float(p)))
        try:
            facets = FacetSet(t.normals, model.law)  # the contacts as facets of a block
        except FrictionRulesError as exc:
            raise FrictionRulesError(f"the grain at {tuple(position)!r} rests on the layer grains "
                                     f"{t.ids}, which cannot carry it at rest: {exc}") from None
        return cls(model, position, t, facets, None)

    def limit(self, T, Q: float) -> np.ndarray:
        T = np.asarray(T, dtype=float)
        if self.facets is not None:
            return self.facets.limit(T, np.full(T.shape[:-1], Q))
        return self.contact.climbing_limit(T, np.full(T.shape[:-1], Q))

    def _facet_mechanism(self, direction: np.ndarray, Q: float) -> Mechanism:
        load = self.facets.limit_load(direction, Q)
        if load.mechanism is None:
            return _JAMMED
        return Mechanism(float(load.load), tuple(int(k) for k in load.mechanism),
                         np.asarray(load.velocity), bool(load.quasi_static))

    def mechanism(self, T, Q: float) -> Mechanism:
        """The mechanism that starts at the load ``T`` on the edge of the support. On one
        contact it climbs where the load's in-plane part points up the slope; elsewhere the
        grain would slide back down into the pocket, which is not followed (jammed)."""
        T = np.asarray(T, dtype=float)
        if self.facets is not None:
            return self._facet_mechanism(T / np.hypot(*T), Q)
        if self.contact.upslope_force(T, Q) <= 0:
            return _JAMMED
        return Mechanism(float(np.hypot(*T)), (0,), self.contact.slip_direction(T, Q))

    def limit_load(self, direction: float, Q: float) -> Mechanism:
        """The mechanism at the edge along the load direction ``direction`` (radians)."""
        e = np.array([np.cos(direction), np.sin(direction)])
        if self.facets is not None:
            return self._facet_mechanism(e, Q)
        if self.limit(FAR * Q * e, Q) <= 0:
            return _JAMMED
        t = crossing(lambda s: float(self.limit(s * e, Q)), 0.0, FAR * Q, Q)
        return self.mechanism(t * e, Q)

    def state(self, contacts: tuple, height: float | None = None) -> GrainState:
        """The configuration with the contacts ``contacts`` (indices) sliding."""
        n = self.touching.normals[list(contacts)]
        a, p = angles(n, self.model.layer.cylindrical)
        return GrainState(self.position.copy(), self.touching.height if height is None else height,
                          tuple(self.touching.ids[k] for k in contacts),
                          tuple(float(v) for v in a), tuple(float(v) for v in p))


#: Relative tolerance of a crossing of the support's edge (a few ulps).
CROSSING_RTOL = 4 * np.finfo(float).eps


def crossing(fun, a: float, b: float, scale: float = 1.0) -> float:
    """The root of ``fun`` in ``[a, b]`` where it changes sign (Brent's method), to a few ulps
    of the root or of ``scale``."""
    return float(brent(fun, a, b, fun(a), fun(b), xtol=CROSSING_RTOL * scale))


def breakout_force(model, directions, Q: float) -> PeakForcePolar:
    """Break-out (peak) force of the grain at rest for forces along ``directions`` (radians).

    Returns a :class:`PeakForcePolar` whose ``direction`` is the force direction, ``peak`` the
    force magnitude, ``start`` the force vector, ``count`` the number of layer grains the grain
    climbs over (1 or 2) and ``mechanism`` their ids. Raises :class:`FrictionRulesError` for a
    direction in which no mechanism can start (the pocket jams).
    """
    beta = np.atleast_1d(np.asarray(directions, dtype=float))
    support = Support.at(model, np.zeros(2))
    peak = np.zeros(beta.shape)
    count = np.zeros(beta.shape, dtype=int)
    mechanism = []
    for i, b in enumerate(beta):
        mech = support.limit_load(b, Q)
        peak[i] = mech.load
        if not mech.contacts:
            raise FrictionRulesError(f"directions[{i}] = {b!r}: no mechanism starts for a force "
                                     "in that direction (the pocket jams)")
        count[i] = len(mech.contacts)
        mechanism.append(tuple(support.touching.ids[k] for k in mech.contacts))
    start = peak[:, None] * np.stack((np.cos(beta), np.sin(beta)), axis=-1)
    return PeakForcePolar(beta, peak, start, count, tuple(mechanism))
