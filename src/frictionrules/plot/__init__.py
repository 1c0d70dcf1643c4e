"""Figures: each function takes ``ax=None`` (a new figure is made when omitted) and returns the
Axes it drew on. matplotlib is imported inside the functions, on first use; it comes with the
``figures`` extra."""

from .._optional import require

require("matplotlib", extra="figures")

from .laws import (
    coulomb_cone,
    directional_friction,
    dissipation_function,
    orthotropic_ellipse,
    wedge_elliptic,
    wedge_limit_curve,
    wedge_parabolic,
)
# configuration softening (§3)
from .configuration import (
    cylinder_limit_evolution,
    limit_evolution,
    pocket_peak_force,
    softening_curve,
    sphere_limit_evolution,
)
# elastic-plastic contact, Fig. 10 (§4)
from .contact import cap_hardening, cap_shear_curves, cap_surface
# asperity mechanisms, Figs. 5-7 (§2)
from .asperities import (
    fig5_two_flank,
    fig6a_limit_surface,
    fig6b_potential_surface,
    fig7_associated,
    heightmap_polar,
    limit_curve,
)

__all__ = [
    # asperity mechanisms (§2)
    "limit_curve",
    "fig5_two_flank",
    "fig6a_limit_surface",
    "fig6b_potential_surface",
    "fig7_associated",
    "heightmap_polar",
    # laws (core)
    "coulomb_cone",
    "orthotropic_ellipse",
    "dissipation_function",
    "directional_friction",
    "wedge_limit_curve",
    "wedge_elliptic",
    "wedge_parabolic",
    # configuration softening (§3)
    "limit_evolution",
    "cylinder_limit_evolution",
    "sphere_limit_evolution",
    "softening_curve",
    "pocket_peak_force",
    # elastic-plastic contact, Fig. 10 (§4)
    "cap_surface",
    "cap_hardening",
    "cap_shear_curves",
]
