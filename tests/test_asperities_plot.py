"""The asperity figures draw what they claim (Figs. 5-7, polar mu of a height map)."""

import numpy as np
import pytest

from frictionrules import TwoFlankAsperity
from frictionrules.paper import FIGURES
from frictionrules.plot import asperities as plots


@pytest.mark.parametrize("fun", [plots.fig5_two_flank, plots.fig6a_limit_surface,
                                 plots.fig6b_potential_surface, plots.fig7_associated])
def test_figures_return_axes_with_content(fun):
    import matplotlib.pyplot as plt
    ax = fun()
    assert ax.lines or ax.collections
    plt.close(ax.figure)


def test_fig5_marks_the_four_concave_corners():
    import matplotlib.pyplot as plt
    ax = plots.fig5_two_flank()
    marks = [ln for ln in ax.lines if ln.get_marker() == "o" and len(ln.get_xdata()) == 1]
    assert len(marks) == 4
    plt.close(ax.figure)


def test_heightmap_polar_small():
    import matplotlib.pyplot as plt
    ax = plots.heightmap_polar(n=64)
    r = ax.lines[0].get_ydata()
    assert np.all(np.isfinite(r)) and np.all(r > 0.2)
    plt.close(ax.figure)


def test_registered_in_paper():
    stems = {stem for stem, _ in FIGURES}
    assert {"fig5_two_flank", "fig6a_limit_surface", "fig6b_potential_surface",
            "fig7_associated", "heightmap_polar_mu"} <= stems


def test_limit_surface_is_a_cone():
    law = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 0.5)
    S = law.limit_surface([0.5, 1.0, 2.0], n=90)
    assert S.shape == (3, 90, 3)
    np.testing.assert_allclose(S[2, :, :2], 4 * S[0, :, :2])
    np.testing.assert_allclose(law.limit(S[1, :, :2], 1.0), 0.0, atol=1e-12)
