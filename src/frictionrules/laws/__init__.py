"""Friction laws: the protocol (with internal variables, capabilities and traits), the built-in
laws of §1–2 and §4, the law table and the one layout of a law in a file."""

from ._layout import law_from_mapping, law_to_mapping, law_to_toml, read_law
from ._params import Parameter
from ._records import ClosedFormReturn, Cone, InverseRelation
from ._state import LawState
from ._symbolic import LocalDerivatives, SymbolicLaw, form_of
from ._table import LAWS, LawEntry, law_entry
from ._traits import LawTraits, derive_traits
from .base import CAPABILITIES, FrictionLaw, RuleComparison, compare_rules, require
from .cap import AreaGrowth, AreaHardening, EllipsoidCap
from .coulomb import Coulomb
from .hardening import HardenedLaw, SlipHardening
from .orthotropic import EllipticOrthotropic, Huber, TransformedCoulomb
from .user import UserLaw
from .wedge import WedgeAsperity

__all__ = [
    "FrictionLaw",
    "LawTraits",
    "derive_traits",
    "LAWS",
    "LawEntry",
    "law_entry",
    "Parameter",
    "read_law",
    "law_from_mapping",
    "law_to_mapping",
    "law_to_toml",
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
