"""Friction laws: the protocol and the built-in laws of §1–2."""

from .base import FrictionLaw, RuleComparison, compare_rules
from .coulomb import Coulomb
from .orthotropic import EllipticOrthotropic, Huber, TransformedCoulomb
from .user import UserLaw
from .wedge import WedgeAsperity

__all__ = [
    "FrictionLaw",
    "RuleComparison",
    "compare_rules",
    "Coulomb",
    "EllipticOrthotropic",
    "Huber",
    "TransformedCoulomb",
    "UserLaw",
    "WedgeAsperity",
]
