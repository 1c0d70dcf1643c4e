"""Layout of the paper's figures: what the eye needs, checked on the drawn Axes.

One convention for normalised axes (docs/conventions.md): the quantity and its scale on every
axis (``T_x/Q``, ``|u|/d``); curves inside their frame; neighbouring curves apart; no line
across a jump; titles and captions naming the same function.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.path import Path as Polygon

from frictionrules import plot
from frictionrules.paper import FIGURES


@pytest.fixture(scope="module")
def fig8():
    ax = plot.cylinder_limit_evolution()
    yield ax
    plt.close(ax.figure)


def test_normalised_axes_name_quantity_and_scale(fig8):
    left, right = fig8.figure.axes[:2]
    assert "$u_x/d$" in left.get_xlabel() and "$T_x/Q$" in left.get_xlabel()
    assert "$u_y/d$" in left.get_ylabel() and "$T_y/Q$" in left.get_ylabel()
    assert right.get_xlabel() == "distance travelled $|u|/d$"
    assert "$|T|/Q$" in right.get_ylabel()
    for draw in (plot.softening_curve, plot.fig7_associated, plot.orthotropic_ellipse):
        ax = draw()
        for text in (ax.get_xlabel(), ax.get_ylabel()):
            assert any(s in text for s in ("/Q", "/d", "/N")), (draw.__name__, text)
        plt.close(ax.figure)


def test_fig8_limit_curves_of_neighbouring_stations_are_apart(fig8):
    """The curves about stations k and k+1 (Fig. 8) share no point: each lies outside the
    other's polygon."""
    curves = [line.get_xydata() for line in fig8.lines if line.get_label()[:2] in
              {f"{k}:" for k in range(1, 7)}]
    assert len(curves) == 6
    for a, b in zip(curves, curves[1:]):
        assert not Polygon(a).contains_points(b).any() and not Polygon(b).contains_points(a).any()


def test_fig8_panels_are_equally_tall(fig8):
    """Equal aspect adjusts the data limits, not the box: no empty band beside a squashed
    panel."""
    left, right = fig8.figure.axes[:2]
    fig8.figure.canvas.draw()
    assert left.get_position().height == pytest.approx(right.get_position().height, rel=1e-6)


def test_fig10a_curves_stay_inside_the_box():
    """3-D lines are not clipped by matplotlib: each meridian of a final surface ends at the
    largest N shown (it used to run over the tick labels)."""
    ax = plot.cap_surface()
    n_max = ax.get_xlim()[1]
    for line in ax.lines:
        N = np.asarray(line.get_data_3d()[0], dtype=float)
        assert np.all(N <= n_max * (1 + 1e-9)), line.get_label()
    assert "$k_n$" in ax.get_title() and "$\\kappa_h$" in ax.get_title()     # math text
    plt.close(ax.figure)


def test_fig10b_title_and_caption_name_the_same_function():
    ax = plot.cap_hardening()
    caption = next(f.caption for f in FIGURES if f.stem == "fig10b_cap_hardening")
    assert "A(\\kappa, \\beta)" in ax.get_title() and "A(κ, β)" in caption
    plt.close(ax.figure)


def test_fig7_shows_both_rules_where_they_coincide():
    """The associated curve is drawn wide and pale under the narrow dashed non-associated one."""
    ax = plot.fig7_associated()
    wide = [ln for ln in ax.lines if ln.get_label().startswith("associated")]
    narrow = [ln for ln in ax.lines if ln.get_label().startswith("non-associated")]
    assert wide and narrow
    assert min(ln.get_linewidth() for ln in wide) > 2 * max(ln.get_linewidth() for ln in narrow)
    assert all(ln.get_alpha() < 1 for ln in wide)
    plt.close(ax.figure)


def test_softening_curve_is_not_drawn_across_the_jump():
    """The cylinder moves onto its second neighbour at |u|/d = 1: the force jumps from about
    -0.24 Q to 1.06 Q; the exact line has a gap there instead of a vertical stroke."""
    ax = plot.softening_curve()
    line = next(ln for ln in ax.lines if ln.get_label() == "cylinder over two neighbours (exact)")
    x, y = (np.asarray(v, dtype=float) for v in line.get_data())
    gap = np.flatnonzero(np.isnan(y))
    assert len(gap) == 1 and x[gap[0] - 1] == pytest.approx(1.0, abs=0.01)
    steps = np.abs(np.diff(y))
    assert np.nanmax(steps) < 0.05
    plt.close(ax.figure)


def test_fig6a_q_axis_has_three_ticks():
    ax = plot.fig6a_limit_surface()
    assert list(ax.get_zticks()) == [0.0, 0.5, 1.0]
    plt.close(ax.figure)
