"""Figures: each function takes ``ax=None`` (a new figure is made when omitted) and returns the
Axes it drew on. matplotlib is imported inside the functions, on first use."""

from .laws import (
    coulomb_cone,
    directional_friction,
    dissipation_function,
    orthotropic_ellipse,
    wedge_elliptic,
    wedge_limit_curve,
    wedge_parabolic,
)

__all__ = [
    # laws (core)
    "coulomb_cone",
    "orthotropic_ellipse",
    "dissipation_function",
    "directional_friction",
    "wedge_limit_curve",
    "wedge_elliptic",
    "wedge_parabolic",
]
