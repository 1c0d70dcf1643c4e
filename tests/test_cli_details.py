"""Details a new user meets in the second hour: outputs refused before the work, options that
would do nothing, the units a command prints back, tables that fit a terminal, the quick start."""

from __future__ import annotations

import re
import subprocess
import sys
import warnings
from pathlib import Path
from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pytest

from frictionrules.cli import main

ROOT = Path(__file__).resolve().parents[1]


# ---- paper --------------------------------------------------------------------------------
@pytest.mark.parametrize("where", ["/proc/frictionrules-figures", "a-file"])
def test_paper_refuses_an_unwritable_out_before_any_figure(where, tmp_path, monkeypatch, capsys):
    import frictionrules.paper as paper

    def never(*args, **kwargs):
        raise AssertionError("a figure was drawn before --out was checked")
    monkeypatch.setattr(paper, "make_figures", never)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a-file").write_text("")
    assert main(["paper", "--out", where, "--only", "fig5_two_flank"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"frictionrules paper: error: --out = '{where}") and len(err.splitlines()) == 1


def test_key_number_table_fits_100_columns():
    """Rows of one subject are listed under it; a long cell continues on the next line."""
    from frictionrules.paper import TABLE_WIDTH, format_table
    rows = [("wedge alpha=30.0 deg, mu=0.5: limit curve", "ellipse", "(2.2)"),
            ("wedge alpha=30.0 deg, mu=0.5: sliding-plane angle, associated vs actual slip at "
             "phi=2.0", "12.25 deg", "(2.4) vs (2.5)"),
            ("a single quantity " + "with a long name " * 8, "1.0 " * 20, "beyond the paper " * 3)]
    text = format_table(rows)
    assert max(map(len, text.splitlines())) <= TABLE_WIDTH == 100
    lines = text.splitlines()
    assert "wedge alpha=30.0 deg, mu=0.5" in lines and "  limit curve" in "\n".join(lines)
    assert (text.count("long"), text.count("1.0"), text.count("beyond")) == (8, 20, 3)  # all there


def test_pocket_rows_say_what_over_two_means():
    from frictionrules.configuration.summary import key_numbers
    rows = [r for r in key_numbers() if "pocket" in r[0]]
    assert len(rows) == 4
    assert all(re.search(r"climbing over [12] layer spheres?", q) for q, _, _ in rows)
    assert all(re.fullmatch(r"\d\.\d{4} at \d+ deg", v) for _, v, _ in rows)


def test_configuration_polar_prints_degrees_beside_radians(capsys):
    assert main(["configuration", "--grain", "sphere", "--packing", "square", "--polar", "8",
                 "--quiet"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"least 1\.\d{4} at 0 rad \(0 deg\), climbing over 2 layer spheres", out)
    assert "(over" not in out
    assert main(["configuration", "--grain", "sphere", "--packing", "square", "--polar", "8",
                 "--deg", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "at 0 deg, climbing" in out and "rad" not in out


# ---- asperity -----------------------------------------------------------------------------
def test_asperity_format_without_out_is_refused(capsys):
    assert main(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--format",
                 "json"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--format json" in err and "--out" in err and len(err.splitlines()) == 1


# ---- law ----------------------------------------------------------------------------------
def test_law_deg_prints_the_law_back_in_degrees(capsys):
    assert main(["law", "wedge", "--alpha", "30", "--deg", "--mu", "0.5", "--force", "1", "0.2",
                 "--normal", "1"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.endswith("WedgeAsperity(alpha=30 deg, mu=0.5, local='non-associated')")
    assert main(["law", "elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--angle", "30", "--deg",
                 "--force", "1", "0.2", "--normal", "1", "--json"]) == 0
    assert '"law": "EllipticOrthotropic(mu_x=0.6, mu_y=0.3, angle=30 deg)"' in capsys.readouterr().out
    assert main(["law", "wedge", "--alpha", "0.5", "--mu", "0.5", "--force", "1", "0.2",
                 "--normal", "1"]) == 0
    assert "alpha=0.5," in capsys.readouterr().out.splitlines()[0]     # radians stay radians


@pytest.mark.parametrize("law", [["coulomb", "--mu", "0.3"], ["huber", "--mu_1", "0.3", "--mu_2", "0.5"],
                                 ["elliptic", "--mu_x", "0.3", "--mu_y", "0.5"],
                                 ["transformed", "--mu_x", "0.3", "--mu_y", "0.5"]])
def test_law_with_huge_forces_warns_nothing(capsys, law):
    """T = (1e308, 1e308): |T| overflows the sum of the input check, and the squares of an
    orthotropic law's |T|: no warning, a finite f or inf (past the largest float), never NaN."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["law", *law, "--force", "1e308", "1e308", "--normal", "1"]) == 0
    out = capsys.readouterr().out
    assert "inadmissible" in out and "nan" not in out
    res = subprocess.run([sys.executable, "-W", "error", "-m", "frictionrules", "law", "coulomb",
                          "--mu", "0.3", "--force", "1e308", "1e308", "--normal", "1"],
                         capture_output=True, text=True)
    assert res.returncode == 0 and res.stderr == ""


# ---- assembly figure ----------------------------------------------------------------------
def _triaxial(failed=True):
    eps = np.linspace(0.0, 2e-3, 11)
    ratio = np.minimum(1.0 + 2000.0 * eps, 3.0)
    return SimpleNamespace(kind="axisymmetric", converged=np.ones(11, bool), axial_strain=eps,
                           stress_ratio=ratio, volumetric_strain=-0.3 * eps, failed=failed,
                           peak_ratio=3.0, peak_friction_angle=30.0)


def test_assembly_figure_has_a_title_a_peak_legend_and_strains_as_fractions():
    """Volumetric strain plotted as the fraction the summary line prints, not in %."""
    from frictionrules.plot.assembly import plot_response
    r = _triaxial()
    a, b = plot_response(r)
    np.testing.assert_array_equal(b.lines[0].get_ydata(), r.volumetric_strain)
    np.testing.assert_array_equal(a.lines[0].get_xdata(), r.axial_strain)
    assert "peak $\\sigma_1/\\sigma_3$ = 3" in a.get_title() and "30" in a.get_title()
    assert [t.get_text() for t in a.get_legend().get_texts()] == ["peak $\\sigma_1/\\sigma_3$"]
    assert "%" not in a.get_xlabel() + b.get_ylabel() and "varepsilon_v" in b.get_ylabel()
    plt.close(a.figure)


def test_assembly_figure_of_several_runs_names_the_peak_once():
    from frictionrules.plot.assembly import plot_response
    _, axes = plt.subplots(1, 2)
    for label in ("one", "two"):
        plot_response(_triaxial(), axes=axes, label=label)
    texts = [t.get_text() for t in axes[0].get_legend().get_texts()]
    assert sorted(texts) == sorted(["one", "two", "peak $\\sigma_1/\\sigma_3$"])
    assert axes[0].get_title() == "axisymmetric test"
    plt.close(axes[0].figure)


# ---- README -------------------------------------------------------------------------------
def test_quick_start_says_each_command_makes_its_own_environment():
    text = (ROOT / "README.md").read_text()
    start = text.index("## Quick start")
    section = text[start:text.index("\n## ", start + 1)]
    visible = re.sub(r"<!--.*?-->", "", section, flags=re.S)
    assert "Each command makes\nits own new virtual environment" in visible
    commands = re.search(r"```bash\n(.*?)```", visible, re.S).group(1)
    venvs = re.findall(r"python3 -m venv (\S+)", commands)
    assert venvs == [".venv-paper", ".venv"]
    assert "s\nof CPU time" in visible or "s of CPU time" in visible
