"""frictionrules: contact friction treated as plasticity.

Limit conditions f, sliding potentials g and the sliding rules, dissipation and inverse
relations they imply (Michałowski & Mróz, 1978), asperity mechanisms, contact integration and
multi-contact solvers. The public API is re-exported here; the SymPy symbols ``T1, T2, N``
for user laws are imported lazily (SymPy loads on first use).
"""

from .errors import FrictionRulesError
from .laws import (
    Coulomb,
    EllipticOrthotropic,
    FrictionLaw,
    Huber,
    RuleComparison,
    TransformedCoulomb,
    UserLaw,
    WedgeAsperity,
    compare_rules,
)

__version__ = "0.1.0"

__all__ = [
    "FrictionRulesError",
    # laws (issue: core)
    "FrictionLaw",
    "Coulomb",
    "EllipticOrthotropic",
    "Huber",
    "TransformedCoulomb",
    "UserLaw",
    "WedgeAsperity",
    "RuleComparison",
    "compare_rules",
    "T1",
    "T2",
    "N",
]

_SYMBOLS = ("T1", "T2", "N")


def __getattr__(name):
    if name in _SYMBOLS:
        from .laws import symbols
        return getattr(symbols, name)
    raise AttributeError(f"module 'frictionrules' has no attribute {name!r}")
