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

from .._optional import require
from ..asperities import FacetSet
from ..errors import FrictionRulesError
from ..laws import Coulomb
from ._contact import GrainContact
from .geometry import Touching, angles, touching
from .state import GrainState, PeakForcePolar

#: Loads up to this many ``Q`` along a ray are searched for the edge of a one-contact support;
#: a ray still inside there never leaves it (an open branch of the limit curve).
FAR = 1e6


@dataclass(frozen=True)
class Mechanism:
    """How the grain starts to move at a load on the edge of its support.

    ``contacts`` are the indices (into the support's contacts) of the sliding contacts, empty
    where none starts (the support jams); ``velocity`` (3,) the unit grain velocity;
    ``quasi_static`` False where the grain loses equilibrium without a mechanism of the local
    sliding rule (:class:`frictionrules.FacetSet`, non-associated local laws).
    """

    contacts: tuple
    velocity: np.ndarray
    quasi_static: bool = True


def facet_set(normals: np.ndarray, law) -> FacetSet:
    """The contacts as the facets of a block, each with the local law ``law`` in its frame."""
    if type(law) is Coulomb:
        return FacetSet(normals, law.mu, "associated" if law.dilatant else "non-associated")
    return FacetSet(normals, law)


class Support:
    """The contacts of a grain at rest at one position and the loads they carry.

    ``limit(T, Q)`` is negative inside (the grain sticks), zero on the edge (it starts to move,
    :meth:`mechanism`), positive outside.
    """

    def __init__(self, model, position):
        self.model = model
        self.touching: Touching = touching(model.layer, position)
        self.position = np.asarray(position, dtype=float).reshape(2)
        normals = self.touching.normals
        if len(normals) == 1:
            a, p = angles(normals[0], model.layer.cylindrical)
            self.contact, self.facets = GrainContact(model.law, float(a), float(p)), None
        else:
            self.contact = None
            try:
                self.facets = facet_set(normals, model.law)
            except FrictionRulesError as exc:
                raise FrictionRulesError(
                    f"the grain at {tuple(self.position)!r} rests on the layer grains "
                    f"{self.touching.ids}, which cannot carry it at rest: {exc}") from None

    def limit(self, T, Q: float) -> np.ndarray:
        T = np.asarray(T, dtype=float)
        if self.facets is not None:
            return self.facets.limit(T, np.full(T.shape[:-1], Q))
        return self.contact.climbing_limit(T, np.full(T.shape[:-1], Q))

    def climbing(self, T, Q: float) -> bool:
        """For one contact: whether the load's in-plane part points up the slope (the grain
        climbs; else the pocket holds it and it would slide down, not followed)."""
        return bool(self.contact.upslope_force(T, Q) > 0)

    def mechanism(self, T, Q: float) -> Mechanism:
        """The mechanism that starts at the load ``T`` on the edge of the support."""
        T = np.asarray(T, dtype=float)
        if self.facets is None:
            if not self.climbing(T, Q):
                return Mechanism((), np.zeros(3))
            return Mechanism((0,), self.contact.slip_direction(T, Q))
        load = self.facets.limit_load(T / np.hypot(*T), Q)
        if load.mechanism is None:
            return Mechanism((), np.zeros(3))
        return Mechanism(tuple(int(k) for k in load.mechanism), np.asarray(load.velocity),
                         bool(load.quasi_static))

    def limit_load(self, direction, Q: float) -> tuple[float, Mechanism]:
        """The load factor ``t`` at which ``T = t (cos b, sin b)`` reaches the edge, and the
        mechanism (``inf`` and no contacts where none starts)."""
        e = np.array([np.cos(direction), np.sin(direction)])
        if self.facets is not None:
            load = self.facets.limit_load(e, Q)
            if load.mechanism is None:
                return np.inf, Mechanism((), np.zeros(3))
            return float(load.load), Mechanism(tuple(int(k) for k in load.mechanism),
                                               np.asarray(load.velocity), bool(load.quasi_static))
        if self.limit(FAR * Q * e, Q) <= 0:
            return np.inf, Mechanism((), np.zeros(3))
        t = crossing(lambda s: float(self.limit(s * e, Q)), 0.0, FAR * Q)
        mech = self.mechanism(t * e, Q)
        return (t, mech) if mech.contacts else (np.inf, mech)

    def state(self, contacts: tuple, height: float | None = None) -> GrainState:
        """The configuration with the contacts ``contacts`` (indices) sliding."""
        n = self.touching.normals[list(contacts)]
        a, p = angles(n, self.model.layer.cylindrical)
        return GrainState(self.position.copy(), self.touching.height if height is None else height,
                          tuple(self.touching.ids[k] for k in contacts),
                          tuple(float(v) for v in a), tuple(float(v) for v in p))


def crossing(fun, a: float, b: float) -> float:
    """The root of ``fun`` in ``[a, b]`` where it changes sign (Brent's method, SciPy)."""
    brentq = require("scipy.optimize", extra="solvers").brentq
    return float(brentq(fun, a, b, xtol=1e-14 * max(abs(b), 1.0), rtol=4 * np.finfo(float).eps))


def breakout_force(model, directions, Q: float) -> PeakForcePolar:
    """Break-out (peak) force of the grain at rest for forces along ``directions`` (radians).

    Returns a :class:`PeakForcePolar` whose ``direction`` is the force direction, ``peak`` the
    force magnitude, ``start`` the force vector, ``count`` the number of layer grains the grain
    climbs over (1 or 2) and ``mechanism`` their ids. Raises :class:`FrictionRulesError` for a
    direction in which no mechanism can start (the pocket jams).
    """
    beta = np.atleast_1d(np.asarray(directions, dtype=float))
    support = Support(model, np.zeros(2))
    peak = np.zeros(beta.shape)
    count = np.zeros(beta.shape, dtype=int)
    mechanism = []
    for i, b in enumerate(beta):
        peak[i], mech = support.limit_load(b, Q)
        if not mech.contacts:
            raise FrictionRulesError(f"directions[{i}] = {b!r}: no mechanism starts for a force "
                                     "in that direction (the pocket jams)")
        count[i] = len(mech.contacts)
        mechanism.append(tuple(support.touching.ids[k] for k in mech.contacts))
    start = peak[:, None] * np.stack((np.cos(beta), np.sin(beta)), axis=-1)
    return PeakForcePolar(beta, peak, start, count, tuple(mechanism))
