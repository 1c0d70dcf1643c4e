"""Figures of §3 (Figs. 8, 9, the softening curve, the pocket polar plot) draw and register."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from frictionrules import plot  # noqa: E402
from frictionrules.paper import FIGURES, KEY_NUMBERS, make_figures  # noqa: E402

STEMS = ("fig8_cylinder_limit_evolution", "fig9_sphere_limit_evolution", "fig8x_softening_curve",
         "fig9x_pocket_peak_force")


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


def test_registered_in_paper(tmp_path):
    stems = {s for s, _ in FIGURES}
    assert set(STEMS) <= stems
    assert "frictionrules.configuration.summary:key_numbers" in KEY_NUMBERS
    written = make_figures(tmp_path, formats=("png",), names={"fig9x_pocket_peak_force"})
    assert written and written[0].stat().st_size > 10_000


def test_key_numbers():
    from frictionrules.configuration.summary import key_numbers
    rows = dict((q, v) for q, v, _ in key_numbers())
    assert rows["cylinder T/Q on top of the neighbour"] == "0.3000"
    assert float(rows["incremental (Euler) convergence order, cylinder"]) == pytest.approx(1, abs=0.1)
