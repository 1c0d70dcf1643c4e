"""A sphere sliding over a layer of spheres of the same diameter (§3, Fig. 9)."""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field

import numpy as np

from ..errors import FrictionRulesError, check_scalar
from ..laws import FrictionLaw
from ._model import GrainOnLayer, deprecated_load, local_law
from .geometry import Layer
from .state import PeakForcePolar

__all__ = ["SphereOnLayer"]

PACKINGS = ("single", "square", "hexagonal")


@dataclass(frozen=True, init=False, repr=False)
class SphereOnLayer(GrainOnLayer):
    r"""A rigid sphere translating (no rotation) over a layer of spheres, loaded by the
    horizontal force ``T = (Tx, Ty)`` and the vertical load ``Q`` (an argument of the methods).

    Each contact carries the local law ``law`` in its frame (``docs/conventions.md``); the
    inclination ``alpha`` of the plane tangent to both spheres and the azimuth ``psi`` of its
    up-slope direction (3.1) vary along the motion (re-derived (3.12), see ``docs/errata.md``):

    .. math:: \dot\alpha = -\frac{V\cdot e_\psi}{d\cos\alpha},\qquad
              \dot\psi = -\frac{V\cdot e_\psi^\perp}{d\sin\alpha}.

    With local Coulomb friction each contact is the wedge (2.2), (2.6) written in the frame
    rotated by ``psi`` (3.11).

    Parameters
    ----------
    diameter : float
        Diameter ``d`` of all spheres, ``> 0``.
    mu : float, optional
        Local Coulomb friction coefficient, ``>= 0`` (the law ``Coulomb(mu)``).
    packing : {"single", "square", "hexagonal"}
        The layer: one sphere at ``(d/sqrt(3), 0)`` (the paper's one-contact model), a square
        layer (the pocket at the origin touches 4 spheres) or a close-packed layer (3 spheres,
        at azimuths 0, 120 and 240 degrees).
    law : FrictionLaw, optional
        The local law of the contacts instead of ``mu``: a law of the protocol in ``(T, N)``
        without internal variables (orthotropic, user laws, ...).
    Q : float, optional
        Deprecated: the vertical load is an argument of the methods (``Q=``). Given here (also
        as the third positional argument), it is their default (with a ``DeprecationWarning``).
    """

    diameter: float
    law: FrictionLaw
    packing: str = "single"
    _load: float | None = field(default=None)

    def __init__(self, diameter, mu=None, *args, packing=None, law=None, Q=None):
        # the former positional form (diameter, mu, Q, packing): a number third is the load
        args = list(args)
        if len(args) > 2:
            raise FrictionRulesError(f"SphereOnLayer takes at most 4 positional arguments "
                                     f"(diameter, mu, Q, packing), got {2 + len(args)}")
        if args and isinstance(args[0], numbers.Real) and not isinstance(args[0], bool):
            if Q is not None:
                raise FrictionRulesError("SphereOnLayer: Q given twice")
            Q = args.pop(0)
        if args:
            if packing is not None or len(args) > 1:
                raise FrictionRulesError(f"SphereOnLayer: packing given twice or extra "
                                         f"positional arguments {args!r}")
            packing = args[0]
        packing = "single" if packing is None else packing
        if packing not in PACKINGS:
            raise FrictionRulesError(f"packing = {packing!r} violates packing in {PACKINGS}")
        object.__setattr__(self, "diameter", check_scalar("diameter", diameter, lo=0.0,
                                                          lo_open=True))
        object.__setattr__(self, "law", local_law(mu, law, "SphereOnLayer"))
        object.__setattr__(self, "packing", packing)
        object.__setattr__(self, "_load", None if Q is None else deprecated_load("SphereOnLayer", Q))

    @property
    def layer(self) -> Layer:
        return Layer(self.packing, self.diameter)

    def peak_force(self, directions, n: int = 121, Q=None) -> PeakForcePolar:
        """Direction-dependent peak force when the grain is pushed out of its pocket along a
        prescribed straight displacement.

        For each displacement direction (radians) the straight trajectory from the pocket is
        followed exactly (:func:`.path.exact_path`) up to the highest point within one diameter;
        the largest ``|T|`` on the way up is the peak. ``count`` tells whether the grain climbs
        over one layer grain or rides the ridge between two at once.
        """
        Q = self.load(Q)
        directions = np.atleast_1d(np.asarray(directions, dtype=float))
        peak = np.zeros(directions.shape)
        start = np.zeros(directions.shape + (2,))
        count = np.zeros(directions.shape, dtype=int)
        mechanism = []
        for i, th in enumerate(directions):
            res = self.displacement_path(self.straight_path(th, self.diameter, n), Q=Q)
            down = np.diff(res.height) < 0
            top = int(np.argmax(down)) if np.any(down) else n - 1
            peak[i] = res.force_magnitude[: top + 1].max()
            start[i] = res.force[0]
            count[i] = len(res.contacts[0])
            mechanism.append(res.contacts[0])
        return PeakForcePolar(directions, peak, start, count, tuple(mechanism))
