"""The pair lines of a contact model in LAMMPS: the one place that says how a law reaches
LAMMPS's contacts.

Built in: ``pair_style gran/hooke/history kn kt 0 0 μ 0`` (GRANULAR: linear normal and
tangential springs, Coulomb's cone, no viscous damping), for a law whose cone (capability
``"cone"``, no internal variables) is circular without dilatancy: Coulomb's (1.4), (1.5); the frictionless stages use it with
μ = 0 whatever the law (its tangential history stays zero: the laws start from virgin
histories). It offers no sliding flag and no dissipation to a
compute: the result's sliding fraction is NaN, as is its dissipation.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import FrictionRulesError

__all__ = ["PairLines", "pair_lines", "builtin_lines", "coulomb_mu"]


@dataclass(frozen=True)
class PairLines:
    """The input-script lines of the frictionless stage and of the laws' stage; ``outputs``
    True where the laws' pair style offers ``compute pair/local p3 p4`` (sliding flag,
    accumulated dissipation); ``name`` says which pair style runs the laws."""

    frictionless: tuple
    law: tuple
    outputs: bool
    name: str


def builtin_lines(kn: float, kt: float, mu: float) -> list[str]:
    """``gran/hooke/history`` with the stiffnesses and friction coefficient, no damping."""
    return [f"pair_style gran/hooke/history {float(kn)!r} {float(kt)!r} 0.0 0.0 {float(mu)!r} 0",
            "pair_coeff * *"]


def _single_model(assembly):
    from ...contact import ContactModel
    if not isinstance(assembly.model, ContactModel):
        raise FrictionRulesError(f"assembly.model = {assembly.model!r} violates: one ContactModel "
                                 "for every contact with engine = 'lammps' (one atom type)")
    return assembly.model


def coulomb_mu(law) -> float | None:
    """μ of a law that is Coulomb's cone without dilatancy and without internal variables
    (what ``gran/hooke/history`` integrates), else None."""
    if "cone" not in law.capabilities or law.state_names:
        return None
    cone = law.cone()
    if cone.mu_x != cone.mu_y or cone.dilatancy != 0.0:
        return None
    return float(cone.mu_x)


def pair_lines(assembly) -> PairLines:
    """The pair lines of the assembly's contact model (module docstring)."""
    model = _single_model(assembly)
    law = model.effective_law
    frictionless = tuple(builtin_lines(model.kn, model.kt, 0.0))
    mu = coulomb_mu(law)
    if mu is not None:
        return PairLines(frictionless, tuple(builtin_lines(model.kn, model.kt, mu)), False,
                         "gran/hooke/history (LAMMPS's linear spring-Coulomb)")
    raise FrictionRulesError(f"law = {law!r} violates: Coulomb's cone (non-dilatant) for "
                             "engine = 'lammps' (the "
                             "built-in gran/hooke/history); other laws need the exported pair "
                             "style (export(law, 'lammps', ...))")
