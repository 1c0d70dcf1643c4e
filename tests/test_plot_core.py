"""The figures of §1–2 are drawn by tested code: each returns its Axes with the curves."""

import matplotlib.pyplot as plt
import numpy as np
import pytest

from frictionrules import WedgeAsperity
from frictionrules import plot


@pytest.mark.parametrize("name", ["coulomb_cone", "orthotropic_ellipse", "dissipation_function",
                                  "directional_friction", "wedge_elliptic", "wedge_parabolic"])
def test_figures_return_axes(name):
    ax = getattr(plot, name)()
    assert ax.figure is not None and ax.get_title()
    plt.close(ax.figure)


def test_figures_draw_on_given_axes():
    fig, ax = plt.subplots()
    assert plot.wedge_limit_curve(WedgeAsperity(0.5, 0.4), ax=ax) is ax
    x, y = ax.lines[0].get_data()
    law = WedgeAsperity(0.5, 0.4)
    np.testing.assert_allclose(law.limit(np.stack((x, y), -1), 1.0), 0.0, atol=1e-12)
    plt.close(fig)


def test_fig1b_arrows_are_in_the_legend():
    from matplotlib.patches import FancyArrowPatch
    ax = plot.orthotropic_ellipse()
    arrows = [h for h in ax.get_legend().legend_handles if isinstance(h, FancyArrowPatch)]
    assert len(arrows) == 2 and len([p for p in ax.patches if isinstance(p, FancyArrowPatch)]) == 10
    plt.close(ax.figure)


def test_directional_friction_plots_the_three_rules():
    ax = plot.directional_friction(mu_x=0.6, mu_y=0.3)
    radii = [line.get_ydata() for line in ax.lines[:3]]
    assert radii[0].max() == pytest.approx(0.6) and radii[0].min() == pytest.approx(0.3)
    assert np.all(radii[0] >= radii[2] - 1e-12) and np.all(radii[2] >= radii[1] - 1e-12)
    plt.close(ax.figure)
