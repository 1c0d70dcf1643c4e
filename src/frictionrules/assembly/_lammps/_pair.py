"""The pair lines of a contact model in LAMMPS: the one place that says how a law reaches
LAMMPS's contacts.

Exported (the default, any law with a symbolic form): the pair style
``frictionrules/<name>`` of ``export(law, "lammps", ..., build=True)``, compiled into the run's
folder, with the contact kinematics of our engine and the assembly's reference axis, our
engine's skin (``skin``: a contact keeps its history, and a dilatant one its force, until its gap
exceeds ``SKIN`` times the mean radius, as :func:`.._dem._passes.contact_range`) and the box's
velocity gradient in the tangential increment (``affine yes``: the script's ``fix deform``
remaps positions, not velocities); it offers ``compute pair/local p1 p2 p3 p4`` = N, |T|, the
sliding flag and the accumulated dissipation.

Built in (``pair_style="gran/hooke/history"``, what the benchmark compares against):
``pair_style gran/hooke/history kn kt 0 0 μ 0`` (GRANULAR: linear normal and
tangential springs, Coulomb's cone, no viscous damping), for a law whose cone (capability
``"cone"``, no internal variables) is circular without dilatancy: Coulomb's (1.4), (1.5); the frictionless stages use it with
μ = 0 whatever the law (its tangential history stays zero: the laws start from virgin
histories). It offers no sliding flag and no dissipation to a
compute: the result's sliding fraction is NaN, as is its dissipation.

Either way the frictionless stages run ``gran/hooke/history`` with μ = 0 (the general return
map substeps at the axis of the degenerate cone; the exported pair style's docs say so).
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import FrictionRulesError

__all__ = ["PairLines", "pair_lines", "builtin_lines", "coulomb_mu", "PAIR_STYLES"]


@dataclass(frozen=True)
class PairLines:
    """The input-script lines of the frictionless stage and of the laws' stage; ``outputs``
    True where the laws' pair style offers ``compute pair/local p3 p4`` (sliding flag,
    accumulated dissipation); ``name`` says which pair style runs the laws."""

    frictionless: tuple
    law: tuple
    outputs: bool
    name: str
    normal: str = "force"


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


#: The pair styles of the laws' stage.
PAIR_STYLES = ("exported", "gran/hooke/history")


def pair_lines(assembly, folder=None, pair_style: str = "exported") -> PairLines:
    """The pair lines of the assembly's contact model (module docstring); "exported" builds
    the plugin into ``folder/pair`` (needs a C and a C++ compiler)."""
    if pair_style not in PAIR_STYLES:
        raise FrictionRulesError(f"pair_style = {pair_style!r} violates: one of "
                                 f"{', '.join(PAIR_STYLES)}")
    model = _single_model(assembly)
    law = model.effective_law
    frictionless = tuple(builtin_lines(model.kn, model.kt, 0.0))
    if pair_style == "exported":
        from .._dem._dynamics import SKIN
        skin = SKIN * float(sum(assembly.radii) / len(assembly.radii))
        lines = _exported(model, assembly.reference_axis, skin, folder)
        style = next(line.split()[1] for line in lines if line.startswith("pair_style"))
        return PairLines(frictionless, tuple(lines), True, f"{style} (exported)", "p1")
    mu = coulomb_mu(law)
    if mu is not None:
        return PairLines(frictionless, tuple(builtin_lines(model.kn, model.kt, mu)), False,
                         "gran/hooke/history (LAMMPS's linear spring-Coulomb)")
    raise FrictionRulesError(f"law = {law!r} violates: Coulomb's cone (non-dilatant) for "
                             "pair_style = 'gran/hooke/history'; other laws run through the "
                             "exported pair style (pair_style = 'exported')")


def _exported(model, axis, skin, folder) -> list[str]:
    """``export(law, "lammps", folder/pair, build=True)``'s ``pair.lmp`` lines, the frame's
    axis set to the assembly's reference axis, with ``skin`` and ``affine yes``."""
    from pathlib import Path

    from ..._export import export
    out = Path(folder) / "pair"
    export(model.law, "lammps", out, kt=model.kt, kn=model.kn, hardening=model.hardening,
           build=True)
    lines = [line for line in (out / "pair.lmp").read_text().splitlines() if line.strip()]
    ax = " ".join(repr(float(a)) for a in axis)
    return [line.replace(" axis 1.0 0.0 0.0", f" axis {ax} skin {skin!r} affine yes")
            if line.startswith("pair_style") else line for line in lines]
