"""A cylinder sliding over a layer of parallel cylinders of the same diameter (§3, Fig. 8)."""

from __future__ import annotations

from dataclasses import dataclass

from ._model import GrainOnLayer
from .geometry import Layer

__all__ = ["CylinderOnLayer"]


@dataclass(frozen=True)
class CylinderOnLayer(GrainOnLayer):
    r"""A rigid cylinder (axis along y) pushed over a layer of touching cylinders (axes along y
    at :math:`x = (i + 1/2)d`), loaded by the horizontal force ``T = (Tx, Ty)`` and the vertical
    load ``Q``.

    The sliding contact is the wedge (2.2), (2.6) with the inclination ``alpha`` of the plane
    tangent to both cylinders; ``alpha`` varies along the motion ((3.6), ``psi = 0``):

    .. math:: \dot\alpha = -\frac{V_x}{d\cos\alpha},\qquad V_z = V_x\tan\alpha,

    ``d`` the diameter (the centre moves on a circle of radius ``d`` about the layer cylinder's
    axis). Pushed along x from the groove (``alpha = pi/6``), the force falls from
    :math:`Q\tan(\pi/6 + \varrho)` to :math:`\mu Q` on the top (``alpha = 0``) and to
    :math:`Q\tan(\varrho - \pi/6)` at the next groove: contact softening.

    Parameters
    ----------
    diameter : float
        Diameter ``d`` of all cylinders, ``> 0``.
    mu : float
        Local friction coefficient, ``>= 0``.
    Q : float
        Vertical load pressing the cylinder down, ``> 0``.
    """

    diameter: float
    mu: float
    Q: float = 1.0

    def __post_init__(self):
        self._check()

    @property
    def layer(self) -> Layer:
        return Layer("line", self.diameter)
