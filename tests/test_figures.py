"""Every figure is readable and shows what its caption says (layout checks in
``tests/_figure_checks.py``)."""

import os

import matplotlib.pyplot as plt
import numpy as np
import pytest

from _figure_checks import assert_readable

from frictionrules import plot
from frictionrules.cli import main
from frictionrules.paper import EXTRA, FIGURES, PAPER, make_figures, select, write_index


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


def test_fig10a_and_10c_show_the_paper_s_points_and_lines():
    """Fig. 10c: test A peaks at A' and softens to A_c; test B rises monotonically to an interior
    peak B' and slowly diminishes to B_c; both end on T = m N; A' and the elastic branch are off
    the axis. Fig. 10a: 3-D in (T1, T2, N) with the labels A, B, A', B', A_c, B_c, one line
    through the peaks and one through the asymptotic points (the critical-state line T1 = m N)."""
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
    assert {t.get_text() for t in ax.texts} == {"A′", "B′", "A$_c$", "B$_c$"}
    assert_readable(ax)
    plt.close(ax.figure)

    ax = plot.cap_surface()
    assert ax.name == "3d" and ax.collections                      # the shaded surface
    assert {"A′", "B′", "A$_c$", "B$_c$", "A", "B"} <= {t.get_text() for t in ax.texts}
    lines = [ln for ln in ax.lines if ln.get_label().startswith("through")]
    assert len(lines) == 2

    def passes(line, points):
        N, _, T1 = (np.asarray(c) for c in line.get_data_3d())
        return all(abs(np.interp(n, N, T1) - t) < 1e-9 for n, t in points)

    crit = [ln for ln in lines if "critical" in ln.get_label()]
    peak = [ln for ln in lines if "peaks" in ln.get_label()]
    assert passes(peak[0], [(t.N, t.T[t.peak]) for t in (a, b)])
    N, _, T1 = crit[0].get_data_3d()
    np.testing.assert_allclose(np.asarray(T1), FIG10.m * np.asarray(N))
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
    assert "<dc:date>" not in text and "fig1a_coulomb_cone" in text     # provenance, no date
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
    # a caption with |T| keeps its table cell: the pipes are escaped
    (tmp_path / "extra" / "pocket_breakout_force_polar.svg").write_text("")
    rows = [r for r in write_index(tmp_path).read_text().splitlines() if r.startswith("| `")]
    assert len(rows) == 3 and all(r.replace("\\|", "").count("|") == 3 for r in rows)
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
    assert main(["paper", "--help"]) == 0
    out = capsys.readouterr().out
    assert "--numbers" in out and "--only" in out and "extra/" in out
