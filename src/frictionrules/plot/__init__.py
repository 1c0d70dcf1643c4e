"""Figures: each function takes ``ax=None`` (a new figure is made when omitted) and returns the
Axes it drew on. matplotlib is imported inside the functions, on first use; it comes with the
``figures`` extra.

``frictionrules paper`` draws them all (:mod:`frictionrules.paper` lists them with their
captions); the layout helpers keep legends beside the data and labels clear of the curves.
"""

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
# asperity mechanisms, Figs. 5-7
from .asperities import (
    fig5_two_flank,
    fig6a_limit_surface,
    fig6b_potential_surface,
    fig7_associated,
    heightmap_polar,
    limit_curve,
    surface_limit_curve,
)
# configuration softening, Figs. 8-9
from .configuration import (
    cylinder_limit_evolution,
    limit_evolution,
    path_force,
    pocket_peak_force,
    softening_curve,
    sphere_limit_evolution,
)
# elastic-plastic contact, Fig. 10
from .contact import cap_hardening, cap_shear_curves, cap_surface, drive_curves

__all__ = [
    # laws, Figs. 1 and 3
    "coulomb_cone",
    "orthotropic_ellipse",
    "dissipation_function",
    "directional_friction",
    "wedge_limit_curve",
    "wedge_elliptic",
    "wedge_parabolic",
    # asperity mechanisms, Figs. 5-7
    "limit_curve",
    "fig5_two_flank",
    "fig6a_limit_surface",
    "fig6b_potential_surface",
    "fig7_associated",
    "heightmap_polar",
    "surface_limit_curve",
    # configuration softening, Figs. 8-9
    "limit_evolution",
    "path_force",
    "cylinder_limit_evolution",
    "sphere_limit_evolution",
    "softening_curve",
    "pocket_peak_force",
    # elastic-plastic contact, Fig. 10
    "cap_surface",
    "cap_hardening",
    "cap_shear_curves",
    "drive_curves",
]
