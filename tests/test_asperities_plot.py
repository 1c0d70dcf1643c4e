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
    names = {f.name for f in FIGURES}
    assert {"paper/fig5_two_flank", "paper/fig6a_limit_surface", "paper/fig6b_potential_surface",
            "paper/fig7_associated", "extra/heightmap_friction_polar"} <= names


def test_fig6a_shows_the_concavity():
    """Fig. 6a: the section Q = 1 falls inside its convex hull near the concave corners of
    Fig. 5 (shaded), and the generators through the four corners are drawn."""
    import matplotlib.pyplot as plt
    from scipy.spatial import ConvexHull

    from frictionrules.plot.asperities import _pockets
    ax = plots.fig6a_limit_surface()
    edges = [ln for ln in ax.lines if len(ln.get_data_3d()[0]) == 2]
    assert len(edges) == 4
    law = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 1.0)
    corners = [c.T for c in law.limit_curve(1.0, 720).concave_corners]
    for (x, y, z), T in zip((ln.get_data_3d() for ln in edges), corners):
        np.testing.assert_allclose([x[1], y[1], z[1]], [T[0], T[1], 1.0])
    # a square with a notch: one pocket, the notch
    square = np.array([[0, 0], [1, 0], [1, 1], [0.5, 0.6], [0, 1], [0, 0]], dtype=float)
    pockets = _pockets(square)
    assert len(pockets) == 1 and len(pockets[0]) == 3
    assert ConvexHull(square).volume == pytest.approx(1.0)
    plt.close(ax.figure)


def test_limit_surface_is_a_cone():
    law = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 0.5)
    S = law.limit_surface([0.5, 1.0, 2.0], n=90)
    assert S.shape == (3, 90, 3)
    np.testing.assert_allclose(S[2, :, :2], 4 * S[0, :, :2])
    np.testing.assert_allclose(law.limit(S[1, :, :2], 1.0), 0.0, atol=1e-12)
