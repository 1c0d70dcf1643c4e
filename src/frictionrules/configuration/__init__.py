"""Configuration softening (§3): grains sliding over layers of grains, with path following.

The contact is the wedge law of §2 whose inclination ``alpha`` (and azimuth ``psi`` for
spheres) changes as the grain moves; climbing a convex neighbour lowers the force needed to
keep sliding (contact softening by geometry).
"""

from .cylinder import CylinderOnLayer
from .sphere import SphereOnLayer
from .state import ForceControlResult, GrainState, LimitPoint, PathResult, PeakForcePolar

__all__ = ["CylinderOnLayer", "SphereOnLayer", "GrainState", "PathResult", "LimitPoint",
           "ForceControlResult", "PeakForcePolar"]
