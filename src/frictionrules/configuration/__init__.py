"""Configuration softening (§3): grains sliding over layers of grains, with path following.

Each grain contact is a friction law of the library (``Coulomb(mu)`` by default) acting in the
contact's frame; the geometry moves the frame — the inclination ``alpha`` and azimuth ``psi``
of the plane tangent to both grains — as the grain moves. With local Coulomb friction a contact
is the wedge law of §2; climbing a convex neighbour lowers the force needed to keep sliding
(contact softening by geometry). A grain at rest on several layer grains is a block on facets:
its break-out force is the limit load of :class:`frictionrules.FacetSet`.
"""

from ._contact import GrainContact
from .cylinder import CylinderOnLayer
from .sphere import SphereOnLayer
from .state import ForceControlResult, GrainState, LimitPoint, PathResult, PeakForcePolar

__all__ = ["CylinderOnLayer", "SphereOnLayer", "GrainContact", "GrainState", "PathResult",
           "LimitPoint", "ForceControlResult", "PeakForcePolar"]
