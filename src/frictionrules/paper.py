"""Reproduce the paper: every figure the library can make, and a table of key numbers.

``FIGURES`` and ``KEY_NUMBERS`` are registries of import paths (``"module:function"``), so that
nothing is imported until the figures are made. A figure function takes ``ax=None`` and
returns the Axes it drew on; a key-number function returns a list of
``(quantity, value, reference)`` rows.
"""

from __future__ import annotations

import importlib
from pathlib import Path

from ._atomic import atomic_path
from ._optional import require

#: What the figures and key numbers import beyond NumPy: the packages of the ``paper`` extra.
REQUIRES: tuple[str, ...] = ("matplotlib", "numba", "scipy", "sympy")


def check_requirements() -> None:
    """Raise one :class:`~frictionrules.FrictionRulesError` line naming the ``paper`` extra
    if any package of :data:`REQUIRES` is missing, before any work starts."""
    for name in REQUIRES:
        require(name, extra="paper", purpose="frictionrules paper")

#: (file stem, "module:function") of every figure, in the paper's order.
FIGURES: tuple[tuple[str, str], ...] = (
    ("fig1a_coulomb_cone", "frictionrules.plot.laws:coulomb_cone"),
    ("fig1b_orthotropic_ellipse", "frictionrules.plot.laws:orthotropic_ellipse"),
    ("fig1c_dissipation", "frictionrules.plot.laws:dissipation_function"),
    ("fig1d_directional_friction", "frictionrules.plot.laws:directional_friction"),
    ("fig3a_wedge_elliptic", "frictionrules.plot.laws:wedge_elliptic"),
    ("fig3b_wedge_parabolic", "frictionrules.plot.laws:wedge_parabolic"),
    # asperity mechanisms (§2)
    ("fig5_two_flank", "frictionrules.plot.asperities:fig5_two_flank"),
    ("fig6a_limit_surface", "frictionrules.plot.asperities:fig6a_limit_surface"),
    ("fig6b_potential_surface", "frictionrules.plot.asperities:fig6b_potential_surface"),
    ("fig7_associated", "frictionrules.plot.asperities:fig7_associated"),
    ("heightmap_polar_mu", "frictionrules.plot.asperities:heightmap_polar"),
    # configuration softening (§3)
    ("fig8_cylinder_limit_evolution", "frictionrules.plot.configuration:cylinder_limit_evolution"),
    ("fig9_sphere_limit_evolution", "frictionrules.plot.configuration:sphere_limit_evolution"),
    ("fig8x_softening_curve", "frictionrules.plot.configuration:softening_curve"),
    ("fig9x_pocket_peak_force", "frictionrules.plot.configuration:pocket_peak_force"),
    # elastic-plastic contact (§4)
    ("fig10a_cap_surface", "frictionrules.plot.contact:cap_surface"),
    ("fig10b_cap_hardening", "frictionrules.plot.contact:cap_hardening"),
    ("fig10c_cap_shear_curves", "frictionrules.plot.contact:cap_shear_curves"),
)

#: "module:function" of every key-number table.
KEY_NUMBERS: tuple[str, ...] = (
    "frictionrules.laws.summary:key_numbers",
    "frictionrules.asperities.summary:key_numbers",
    "frictionrules.configuration.summary:key_numbers",
    "frictionrules.contact.summary:key_numbers",
)


def _resolve(target: str):
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def make_figures(out_dir, formats=("png", "svg"), names=None) -> list[Path]:
    """Draw the registered figures (or those in ``names``) and save them atomically."""
    check_requirements()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = Path(out_dir)
    written = []
    for stem, target in FIGURES:
        if names is not None and stem not in names:
            continue
        ax = _resolve(target)()
        fig = ax.figure
        for fmt in formats:
            path = out_dir / f"{stem}.{fmt}"
            with atomic_path(path) as tmp:
                fig.savefig(tmp, format=fmt, dpi=150, bbox_inches="tight")
            written.append(path)
        plt.close(fig)
    return written


def key_numbers() -> list[tuple[str, str, str]]:
    """Rows ``(quantity, value, reference)`` from every registered table."""
    check_requirements()
    rows = []
    for target in KEY_NUMBERS:
        rows.extend(_resolve(target)())
    return rows


def format_table(rows) -> str:
    """Plain-text table of ``(quantity, value, reference)`` rows."""
    head = ("quantity", "value", "paper")
    rows = [tuple(map(str, r)) for r in rows]
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(3)]
    line = "  ".join("{:<%d}" % w for w in widths)
    out = [line.format(*head), line.format(*("-" * w for w in widths))]
    out += [line.format(*r) for r in rows]
    return "\n".join(out)
