"""A cylinder sliding over a layer of parallel cylinders of the same diameter (§3, Fig. 8)."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import check_scalar
from ..laws import FrictionLaw
from ._model import GrainOnLayer, deprecated_load, local_law
from .geometry import Layer

__all__ = ["CylinderOnLayer"]


@dataclass(frozen=True, init=False, repr=False)
class CylinderOnLayer(GrainOnLayer):
    r"""A rigid cylinder (axis along y) pushed over a layer of touching cylinders (axes along y
    at :math:`x = (i + 1/2)d`), loaded by the horizontal force ``T = (Tx, Ty)`` and the vertical
    load ``Q`` (an argument of the methods).

    Each contact carries the local law ``law`` in its frame (``docs/conventions.md``); the plane
    tangent to both cylinders has the inclination ``alpha``, which varies along the motion
    ((3.6), ``psi = 0``):

    .. math:: \dot\alpha = -\frac{V_x}{d\cos\alpha},\qquad V_z = V_x\tan\alpha,

    ``d`` the diameter (the centre moves on a circle of radius ``d`` about the layer cylinder's
    axis). With local Coulomb friction the contact is the wedge (2.2), (2.6): pushed along x
    from the groove (``alpha = pi/6``), the force falls from :math:`Q\tan(\pi/6 + \varrho)` to
    :math:`\mu Q` on the top (``alpha = 0``) and to :math:`Q\tan(\varrho - \pi/6)` at the next
    groove: contact softening.

    Parameters
    ----------
    diameter : float
        Diameter ``d`` of all cylinders, ``> 0``.
    mu : float, optional
        Local Coulomb friction coefficient, ``>= 0`` (the law ``Coulomb(mu)``).
    law : FrictionLaw, optional
        The local law of the contacts instead of ``mu``: a law of the protocol in ``(T, N)``
        without internal variables (orthotropic, user laws, ...).
    Q : float, optional
        Deprecated: the vertical load is an argument of the methods (``Q=``). Given here, it is
        their default (with a ``DeprecationWarning``).
    """

    diameter: float
    law: FrictionLaw
    _load: float | None = field(default=None)

    def __init__(self, diameter, mu=None, Q=None, *, law=None):
        object.__setattr__(self, "diameter", check_scalar("diameter", diameter, lo=0.0,
                                                          lo_open=True))
        object.__setattr__(self, "law", local_law(mu, law, "CylinderOnLayer"))
        object.__setattr__(self, "_load", None if Q is None else deprecated_load("CylinderOnLayer", Q))

    @property
    def layer(self) -> Layer:
        return Layer("line", self.diameter)
