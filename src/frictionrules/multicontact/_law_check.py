"""Which laws the law path takes (:mod:`._law_path`), checked where a law enters a
:class:`~frictionrules.FrictionContactProblem`, and which methods take them."""

from __future__ import annotations

from ..errors import FrictionRulesError

__all__ = ["LAW_METHODS", "check_law", "short"]

#: The methods that take a problem on the law path (``"auto"`` runs ``"nsgs"`` and ``"polish"``).
LAW_METHODS = ("auto", "nsgs", "polish")


def check_law(law, index: int) -> None:
    """Raise unless ``law`` can enter the law path (see the module docstring), naming the
    missing property."""
    from ..laws import FrictionLaw
    where = f"FrictionContactProblem: law = {short(law)} of contact {index}"
    if not isinstance(law, FrictionLaw):
        raise FrictionRulesError(f"{where} violates: a friction law of frictionrules or a "
                                 "coefficient")
    if "symbolic" not in law.capabilities:
        raise FrictionRulesError(f"{where} violates: a symbolic form (capability 'symbolic') "
                                 "or the capability 'cone'")
    if law.state_names:
        raise FrictionRulesError(f"{where} violates: no internal variables (it has "
                                 f"{', '.join(law.state_names)}) unless it declares the "
                                 "capability 'cone'")
    t = law.traits
    if t.degree != 1.0:
        raise FrictionRulesError(f"{where} violates: its limit condition is not a cone in "
                                 "(T, N) (f not homogeneous of degree one)")
    if t.slip_degree != 0.0:
        raise FrictionRulesError(f"{where} violates: its sliding potential is not a cone in "
                                 "(T, N) (g not homogeneous of degree one)")


def short(law) -> str:
    text = repr(law)
    return text if len(text) <= 120 else text[:117] + "..."
