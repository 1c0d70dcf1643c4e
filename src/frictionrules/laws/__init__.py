"""Friction laws: the protocol (with internal variables and capabilities) and the built-in laws
of §1–2 and §4."""

from ._records import ClosedFormReturn, Cone, InverseRelation
from ._state import LawState
from ._symbolic import LocalDerivatives, SymbolicLaw, form_of
from .base import CAPABILITIES, FrictionLaw, RuleComparison, compare_rules, require
from .cap import AreaGrowth, AreaHardening, EllipsoidCap
from .coulomb import Coulomb
from .hardening import HardenedLaw, SlipHardening
from .orthotropic import EllipticOrthotropic, Huber, TransformedCoulomb
from .user import UserLaw
from .wedge import WedgeAsperity

__all__ = [
    "FrictionLaw",
    "LawState",
    "SymbolicLaw",
    "LocalDerivatives",
    "form_of",
    "Cone",
    "InverseRelation",
    "ClosedFormReturn",
    "CAPABILITIES",
    "require",
    "RuleComparison",
    "compare_rules",
    "Coulomb",
    "EllipticOrthotropic",
    "Huber",
    "TransformedCoulomb",
    "UserLaw",
    "WedgeAsperity",
    "EllipsoidCap",
    "AreaHardening",
    "AreaGrowth",
    "SlipHardening",
    "HardenedLaw",
]
