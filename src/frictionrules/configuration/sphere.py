"""A sphere sliding over a layer of spheres of the same diameter (§3, Fig. 9)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError
from ._model import GrainOnLayer
from .geometry import Layer
from .state import PeakForcePolar

__all__ = ["SphereOnLayer"]

PACKINGS = ("single", "square", "hexagonal")


@dataclass(frozen=True)
class SphereOnLayer(GrainOnLayer):
    r"""A rigid sphere translating (no rotation) over a layer of spheres, loaded by the
    horizontal force ``T = (Tx, Ty)`` and the vertical load ``Q``.

    Each sliding contact is the wedge (2.2), (2.6) written in the frame rotated by the azimuth
    ``psi`` of its up-slope direction (3.11); the inclination ``alpha`` and ``psi`` vary along
    the motion (re-derived (3.12), see ``docs/errata.md``):

    .. math:: \dot\alpha = -\frac{V\cdot e_\psi}{d\cos\alpha},\qquad
              \dot\psi = -\frac{V\cdot e_\psi^\perp}{d\sin\alpha}.

    Parameters
    ----------
    diameter : float
        Diameter ``d`` of all spheres, ``> 0``.
    mu : float
        Local friction coefficient, ``>= 0``.
    Q : float
        Vertical load, ``> 0``.
    packing : {"single", "square", "hexagonal"}
        The layer: one sphere at ``(d/sqrt(3), 0)`` (the paper's one-contact model), a square
        layer (the pocket at the origin touches 4 spheres) or a close-packed layer (3 spheres,
        at azimuths 0, 120 and 240 degrees).
    """

    diameter: float
    mu: float
    Q: float = 1.0
    packing: str = "single"

    def __post_init__(self):
        self._check()
        if self.packing not in PACKINGS:
            raise FrictionRulesError(f"packing = {self.packing!r} violates packing in {PACKINGS}")

    @property
    def layer(self) -> Layer:
        return Layer(self.packing, self.diameter)

    def peak_force(self, directions, n: int = 121) -> PeakForcePolar:
        """Direction-dependent peak force when the grain is pushed out of its pocket.

        For each displacement direction (radians) the straight trajectory from the pocket is
        followed exactly (:func:`.path.exact_path`) up to the highest point within one diameter;
        the largest ``|T|`` on the way up is the peak. ``count`` tells whether the grain climbs
        over one layer grain or rides the ridge between two at once.
        """
        directions = np.atleast_1d(np.asarray(directions, dtype=float))
        peak = np.zeros(directions.shape)
        start = np.zeros(directions.shape + (2,))
        count = np.zeros(directions.shape, dtype=int)
        for i, th in enumerate(directions):
            res = self.displacement_path(self.straight_path(th, self.diameter, n))
            top = int(np.argmax(np.diff(res.height) < 0)) if np.any(np.diff(res.height) < 0) else n - 1
            peak[i] = res.force_magnitude[: top + 1].max()
            start[i] = res.force[0]
            count[i] = len(res.contacts[0])
        return PeakForcePolar(directions, peak, start, count)
