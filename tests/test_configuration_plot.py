"""Figures of §3 (Figs. 8, 9, the softening curve, the pocket polar plot) draw and register."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from frictionrules import plot  # noqa: E402
from frictionrules.paper import FIGURES, KEY_NUMBERS, make_figures  # noqa: E402

NAMES = ("paper/fig8_cylinder_limit_evolution", "paper/fig9_sphere_limit_evolution",
         "extra/softening_exact_vs_incremental", "extra/pocket_breakout_force_polar")


@pytest.mark.parametrize("name", ["cylinder_limit_evolution", "sphere_limit_evolution",
                                  "softening_curve"])
def test_figure_functions_return_axes(name):
    fig, ax = plt.subplots()
    assert getattr(plot, name)(ax=ax) is ax
    assert len(ax.lines) >= 3
    plt.close(fig)


def test_fig8_limit_curves_shrink_towards_mu_q():
    """Station 6 (top of the neighbour) has the circle |T| = mu Q about the station."""
    ax = plot.cylinder_limit_evolution()
    curves = [ln for ln in ax.lines if ln.get_label().startswith(("1:", "6:"))]
    first, last = (np.ptp(ln.get_xdata()) for ln in curves)
    assert last < first
    plt.close(ax.figure)


def test_fig8_has_a_force_scale_arrows_in_the_legend_and_the_force_panel():
    """Fig. 8: a scale bar for the forces drawn on the displacement axes, the force arrows in
    the legend, and the companion T(|u|) panel with the six stations; T falls (softening)
    from Q tan(alpha + rho) towards mu Q (pushed at 20 deg: |T| = 0.3 on the top)."""
    from matplotlib.offsetbox import AnchoredOffsetbox
    from matplotlib.patches import FancyArrowPatch
    ax = plot.cylinder_limit_evolution()
    bars = [a for a in ax.artists if isinstance(a, AnchoredOffsetbox)]
    assert len(bars) == 1
    handles = ax.get_legend().legend_handles
    assert any(isinstance(h, FancyArrowPatch) for h in handles)
    assert sum(isinstance(p, FancyArrowPatch) for p in ax.patches) == 6
    force_ax = ax.figure.axes[1]
    d, T = force_ax.lines[0].get_data()
    assert np.all(np.diff(T) < 0) and T[-1] == pytest.approx(0.3, abs=1e-6)
    assert {t.get_text() for t in force_ax.texts} == {str(k) for k in range(1, 7)}
    plt.close(ax.figure)


def test_fig9_has_no_unexplained_marks():
    """Every kind of mark of Fig. 9 is in the legend: no dotted circle; the + is the layer sphere."""
    from matplotlib.patches import Circle
    ax = plot.sphere_limit_evolution()
    assert not any(isinstance(p, Circle) for p in ax.patches)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    for expected in ("trajectory", "force $T/Q$", "stations 1–6", "top of the layer sphere"):
        assert any(lab.startswith(expected) for lab in labels), expected
    assert sum(lab[:2] in {f"{k}:" for k in range(1, 7)} for lab in labels) == 6
    plt.close(ax.figure)


def test_registered_in_paper(tmp_path):
    names = {f.name for f in FIGURES}
    assert set(NAMES) <= names
    assert "frictionrules.configuration.summary:key_numbers" in KEY_NUMBERS
    written = make_figures(tmp_path, formats=("png",), names={"extra/softening_exact_vs_incremental"})
    assert written == [tmp_path / "extra" / "softening_exact_vs_incremental.png"]
    assert written[0].stat().st_size > 10_000


def test_pocket_polar_is_readable():
    """The polar plot of the pocket break-out force: legend under it, radius labels off the
    curves (the layout checks of tests/test_figures.py)."""
    from _figure_checks import assert_readable
    ax = plot.pocket_peak_force(n=121)
    assert_readable(ax)
    plt.close(ax.figure)


def test_key_numbers():
    from frictionrules.configuration.summary import key_numbers
    rows = dict((q, v) for q, v, _ in key_numbers())
    assert rows["cylinder, mu = 0.3: T/Q on top of the neighbour"] == "0.3000"
    assert float(rows["cylinder, mu = 0.3: incremental (Euler) convergence order"]) == pytest.approx(1, abs=0.1)
