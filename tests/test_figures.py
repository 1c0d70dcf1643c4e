"""Every figure is readable and shows what its caption says.

Layout checks work in display coordinates, written here independently of the plotting helpers:
the data of an Axes (lines, collections, arrows) is turned into points at most one pixel apart,
and a legend, a label or a polar tick label must not contain any of them.
"""

import os
import sys

import matplotlib.pyplot as plt
import numpy as np
import pytest

from frictionrules import plot
from frictionrules.cli import main
from frictionrules.paper import EXTRA, FIGURES, PAPER, make_figures, select


def _polyline(disp):
    """Points of a display-space polyline, at most 1 px apart."""
    disp = disp[np.all(np.isfinite(disp), axis=1)]
    out = [disp[:1]]
    for a, b in zip(disp[:-1], disp[1:]):
        k = max(1, int(np.ceil(np.hypot(*(b - a)))))
        out.append(a + np.linspace(0, 1, k + 1)[1:, None] * (b - a))
    return np.concatenate(out) if len(disp) else np.zeros((0, 2))


def data_points(ax):
    """Display points of everything drawn as data, within the axes (the artists are clipped)."""
    ax.figure.canvas.draw()
    pts = [np.zeros((0, 2))]
    for line in ax.lines:
        xy = np.asarray(line.get_xydata(), dtype=float)
        if line.get_visible() and len(xy):
            if ax.name == "polar":   # an arc between two samples: interpolate in (theta, r)
                xy = np.concatenate([a + np.linspace(0, 1, 8, endpoint=False)[:, None] * (b - a)
                                     for a, b in zip(xy[:-1], xy[1:])] + [xy[-1:]])
            pts.append(_polyline(line.get_transform().transform(xy)))
    for artist in list(ax.collections) + list(ax.patches):
        paths = artist.get_paths() if hasattr(artist, "get_paths") else [artist.get_path()]
        for path in paths:
            for poly in path.to_polygons(closed_only=False):
                pts.append(_polyline(artist.get_transform().transform(poly)))
    pts = np.concatenate(pts)
    box = ax.bbox
    return pts[(pts[:, 0] >= box.x0) & (pts[:, 0] <= box.x1) & (pts[:, 1] >= box.y0) & (pts[:, 1] <= box.y1)]


def inside(bbox, pts, margin=1.0):
    return np.flatnonzero((pts[:, 0] > bbox.x0 + margin) & (pts[:, 0] < bbox.x1 - margin)
                          & (pts[:, 1] > bbox.y0 + margin) & (pts[:, 1] < bbox.y1 - margin))


def assert_readable(ax):
    """No legend over data, no label (ax.texts) struck by a curve, no polar tick label on a curve."""
    renderer = ax.figure.canvas.get_renderer()
    pts = data_points(ax)
    legend = ax.get_legend()
    if legend is not None:
        hit = inside(legend.get_window_extent(renderer), pts)
        assert not len(hit), f"legend covers data at {pts[hit[0]]}"
    inline = {id(t) for c in ax.collections for t in getattr(c, "labelTexts", ())}
    for text in ax.texts:
        if id(text) in inline:      # contour labels sit in a gap cut into their own line
            continue
        hit = inside(text.get_window_extent(renderer), pts)
        assert not len(hit), f"label {text.get_text()!r} is crossed by data"
    if ax.name == "polar":
        for text in ax.yaxis.get_ticklabels():
            if text.get_visible() and text.get_text():
                hit = inside(text.get_window_extent(renderer), pts)
                assert not len(hit), f"polar tick label {text.get_text()!r} sits on a curve"


@pytest.mark.parametrize("name", ["orthotropic_ellipse", "wedge_elliptic", "wedge_parabolic",
                                  "dissipation_function", "directional_friction", "fig5_two_flank",
                                  "softening_curve", "cylinder_limit_evolution",
                                  "sphere_limit_evolution", "cap_hardening"])
def test_no_legend_or_label_over_data(name):
    """Figs. 1b, 1c, 3a, 3b, 5, 8, 9, 10b and the softening and mu(theta) plots (Fig. 7, 10c
    below)."""
    ax = getattr(plot, name)()
    for a in ax.figure.axes:
        assert_readable(a)
    plt.close(ax.figure)


def test_fig7_labels_exist_and_are_clear():
    """Fig. 7: the four concave corners of the non-associated curve carry their angles."""
    ax = plot.fig7_associated()
    angles = sorted(t.get_text() for t in ax.texts)
    assert len(angles) == 4 and all(a.endswith("°") for a in angles)
    assert_readable(ax)
    plt.close(ax.figure)


def test_fig10a_is_the_surface_in_t1_t2_n_with_its_points_and_lines():
    """Fig. 10a: 3-D, labels A', B', A_c, B_c; one line through the peaks, one through the
    asymptotic points (the critical-state line T1 = m N through the origin)."""
    from frictionrules.contact.summary import FIG10, fig10c_results
    ax = plot.cap_surface()
    assert ax.name == "3d" and ax.collections                      # the shaded surface
    labels = {t.get_text() for t in ax.texts}
    assert {"A′", "B′", "A$_c$", "B$_c$", "A", "B"} <= labels
    tests = fig10c_results()
    lines = [ln for ln in ax.lines if ln.get_label().startswith("through")]
    assert len(lines) == 2

    def passes(line, points):
        N, _, T1 = (np.asarray(c) for c in line.get_data_3d())
        return all(abs(np.interp(n, N, T1) - t) < 1e-9 for n, t in points)

    peaks = [(t.N, t.T[t.peak]) for t in tests]
    ends = [(t.N, t.T[-1]) for t in tests]
    assert any(passes(ln, peaks) for ln in lines)
    crit = [ln for ln in lines if "critical" in ln.get_label()][0]
    N, _, T1 = crit.get_data_3d()
    np.testing.assert_allclose(np.asarray(T1), FIG10.m * np.asarray(N))
    for n, t in ends:                                 # A_c, B_c on the critical-state line
        assert t == pytest.approx(FIG10.m * n, rel=2e-3)
    plt.close(ax.figure)


def test_fig10c_peak_b_is_an_interior_maximum_and_the_elastic_branch_is_readable():
    """Fig. 10c: test B rises to B' and slowly diminishes to B_c; A' is off the axis."""
    from frictionrules.contact.summary import FIG10, fig10c_results
    a, b = fig10c_results()
    assert a.N < FIG10.A0 < b.N
    for t in (a, b):
        k = t.peak
        assert 0 < k < len(t.T) - 1
        assert t.T[k] > 1.05 * t.T[-1]                        # a visible peak, then a fall
        assert np.all(np.diff(t.T[k:]) <= 1e-9)               # diminishing after the peak
        assert t.T[-1] == pytest.approx(FIG10.m * t.N, rel=2e-3)
    assert np.all(np.diff(b.T[:b.peak + 1]) >= -1e-9)         # B rises monotonically to B'
    ax = plot.cap_shear_curves()
    width = np.diff(ax.get_xlim())[0]
    assert a.slip[a.peak] / width > 0.05                      # A' not against the axis
    elastic = a.slip[np.argmax(a.result.status == 1)]         # end of the elastic branch
    assert elastic / width > 0.03
    labels = {t.get_text() for t in ax.texts}
    assert labels == {"A′", "B′", "A$_c$", "B$_c$"}
    assert_readable(ax)
    plt.close(ax.figure)


def test_polar_tick_labels_clear_of_curves():
    ax = plot.heightmap_polar(n=64)
    assert_readable(ax)
    plt.close(ax.figure)


def test_svg_is_the_same_on_every_run(tmp_path):
    """Same bytes twice: fixed svg.hashsalt (ids) and no date in the metadata."""
    names = ["fig1a_coulomb_cone", "fig1b_orthotropic_ellipse"]    # 3-D and 2-D
    first = make_figures(tmp_path / "a", formats=("svg", "pdf"), names=names)
    second = make_figures(tmp_path / "b", formats=("svg", "pdf"), names=names)
    assert len(first) == 4
    for p, q in zip(first, second):
        assert p.read_bytes() == q.read_bytes()
    text = first[0].read_text()
    assert "<dc:date>" not in text
    assert (tmp_path / "a" / "index.md").read_text() == (tmp_path / "b" / "index.md").read_text()


def test_paper_and_extra_folders_and_index(tmp_path):
    stems = {f.stem for f in FIGURES}
    assert len(stems) == len(FIGURES) and {f.folder for f in FIGURES} == {PAPER, EXTRA}
    assert all(f.stem.startswith("fig") for f in FIGURES if f.folder == PAPER)
    assert not any(f.stem.startswith("fig") for f in FIGURES if f.folder == EXTRA)
    written = make_figures(tmp_path, formats=("png",),
                           names=["fig1b_orthotropic_ellipse", "extra/orthotropic_friction_polar"])
    assert written == [tmp_path / "paper" / "fig1b_orthotropic_ellipse.png",
                       tmp_path / "extra" / "orthotropic_friction_polar.png"]
    index = (tmp_path / "index.md").read_text()
    for f in select(["fig1b_orthotropic_ellipse", "orthotropic_friction_polar"]):
        assert f"`{f.stem}`" in index and f.caption in index
    assert "fig5_two_flank" not in index                 # only what the folder holds
    assert not list(tmp_path.rglob(".*"))                 # no temporary files left behind
    mask = os.umask(0)
    os.umask(mask)
    for path in [*written, tmp_path / "index.md"]:         # readable as the umask allows
        assert path.stat().st_mode & 0o777 == 0o666 & ~mask


def test_paper_only_computes_no_key_numbers(tmp_path, monkeypatch, capsys):
    import frictionrules.paper as paper

    def forbidden():
        raise AssertionError("key numbers computed for --only")
    monkeypatch.setattr(paper, "key_numbers", forbidden)
    assert main(["paper", "--out", str(tmp_path), "--only", "fig1b_orthotropic_ellipse",
                 "--format", "png"]) == 0
    captured = capsys.readouterr()
    assert "quantity" not in captured.out
    assert (tmp_path / "paper" / "fig1b_orthotropic_ellipse.png").stat().st_size > 1000
    # stderr is not a terminal here: one summary line, no progress frames
    assert captured.err.count("\n") == 1 and "\r" not in captured.err


def test_paper_only_with_numbers_prints_the_table(tmp_path, monkeypatch, capsys):
    import frictionrules.paper as paper
    monkeypatch.setattr(paper, "KEY_NUMBERS", ("frictionrules.laws.summary:key_numbers",))
    assert main(["paper", "--out", str(tmp_path), "--only", "fig1b_orthotropic_ellipse",
                 "--format", "svg", "--numbers"]) == 0
    out = capsys.readouterr().out
    assert "quantity" in out and "(1.15)" in out


def test_paper_list_and_bad_name(capsys):
    assert main(["paper", "--list"]) == 0
    out = capsys.readouterr().out
    assert all(f.name in out for f in FIGURES)
    assert main(["paper", "--only", "fig99"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--only 'fig99' is not a figure" in err and len(err.splitlines()) == 1


def test_paper_help_documents_only_and_numbers(capsys):
    with pytest.raises(SystemExit):
        main(["paper", "--help"])
    out = capsys.readouterr().out
    assert "--numbers" in out and "--only" in out and "extra/" in out


def test_progress_counter_on_a_terminal(monkeypatch, capsys):
    from frictionrules.cli.paper import _progress
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    with _progress(3, "paper") as step:
        for k in range(1, 4):
            step(k, 3)
    err = capsys.readouterr().err
    assert "\rpaper: 2/3" in err and err.rstrip().endswith("s")
