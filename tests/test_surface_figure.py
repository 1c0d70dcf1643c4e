"""The limit curve of a measured surface, drawn for hundreds of facets, and its noise corners.

The three shared instrument files (``../shared/surfaces``: tests/test_topography_files.py says
where they are looked for) give facet sets of 33-68 facets whose limit curves have 16-51 corners
within a degree or so of 180°: features of the facet estimate, not of the surface. They are
merged away (:meth:`LimitCurve.merged`), and the figure names mechanism families, not facets.
"""

from __future__ import annotations

import csv

import matplotlib.pyplot as plt
import numpy as np
import pytest

from frictionrules import TwoFlankAsperity
from frictionrules.cli import main
from frictionrules.plot import surface_limit_curve

from _figure_checks import assert_readable
from test_topography_files import FILES, MU, law, shared

NOISE_DEG = 2.0


def test_merged_drops_only_the_corners_within_the_tolerance():
    """Fig. 5 (α1 = π/3, α2 = 5π/6, μ = 1): concave corners of 226.67° and 200.79° (2.9),
    (2.12). A tolerance of 25° merges the two of 200.79° (turning 20.79°) and keeps the others;
    the default (2°) keeps all four."""
    curve = TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 1.0).limit_curve(1.0, n=720)
    assert len(curve.merged().corners) == 4
    kept = curve.merged(np.deg2rad(25.0)).corners
    assert sorted(round(np.rad2deg(c.interior), 2) for c in kept) == [226.67, 226.67]
    assert curve.NOISE_CORNER == pytest.approx(np.deg2rad(NOISE_DEG))


@pytest.mark.parametrize("name", FILES)
def test_measured_figure_is_readable(name):
    """A legend of families (at most four entries, whatever the number of facets), no label
    crossed by the curve or covering another, the whole curve inside the frame."""
    result = law(name)
    curve = result.law.limit_curve(1.0, n=360).merged()
    assert all(abs(np.rad2deg(c.interior) - 180.0) > NOISE_DEG for c in curve.corners)
    ax = surface_limit_curve(curve)
    assert len(ax.get_legend().get_texts()) <= 4
    assert len(result.law.normals) > 30 and len(ax.texts) <= 8
    assert_readable(ax)
    renderer = ax.figure.canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for t in ax.texts]
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    for line in ax.lines:
        xy = line.get_xydata()
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        assert np.all((xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1))
    plt.close(ax.figure)


def test_cli_merges_noise_corners_and_says_so(tmp_path, capsys):
    """``asperity x3p-2.x3p --mu 0.3 --out d``: its 51 corners are all within 2° of 180°: none
    is listed or called concave; the text and the table's metadata state the tolerance."""
    out = tmp_path / "d"
    assert main(["asperity", str(shared("x3p-2.x3p")), "--mu", str(MU), "--out", str(out),
                 "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "corners: 0, concave: 0 (and 51 within 2 deg of 180 deg, merged away" in text
    lines = (out / "corners.csv").read_text().splitlines()
    assert any("within 2 deg of 180 deg are merged" in line for line in lines)
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    assert rows == []
    assert (out / "limit_curve.png").stat().st_size > 10_000


def test_cli_keeps_real_corners_of_the_afm_map(tmp_path, capsys):
    out = tmp_path / "d"
    assert main(["asperity", str(shared("di-1.di")), "--mu", str(MU), "--out", str(out),
                 "--quiet"]) == 0
    capsys.readouterr()
    lines = (out / "corners.csv").read_text().splitlines()
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    assert len(rows) > 5
    assert all(abs(float(r["interior"]) - 180.0) > NOISE_DEG for r in rows)
