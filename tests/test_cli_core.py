"""The CLI: `frictionrules law` and `frictionrules paper`, exit code 2 on bad input."""

import json
import subprocess
import sys

import numpy as np
import pytest

from frictionrules.cli import main


def test_law_json(capsys):
    assert main(["law", "elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--force", "0.6", "0.0",
                 "--normal", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["limit"] == pytest.approx(0.0, abs=1e-15)
    assert out["state"].startswith("sliding")
    assert out["slip_direction"] == pytest.approx([1.0, 0.0, 0.0])
    assert out["friction_coefficient"] == pytest.approx(0.6)


def test_law_text_and_aliases(capsys):
    assert main(["law", "WedgeAsperity", "--alpha", "30", "--deg", "--mu", "0.5", "--force", "1", "0.2",
                 "--normal", "1"]) == 0
    assert "mu(theta)" in capsys.readouterr().out
    assert main(["law", "user", "--limit", "sqrt(T1**2+T2**2) - 0.3*N", "--force", "0.3", "0", "--normal",
                 "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["friction_coefficient"] == pytest.approx(0.3)
    assert main(["law", "coulomb", "--param", "mu=0.4", "--force", "0.4", "0", "--normal", "1", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["limit"] == pytest.approx(0.0)


@pytest.mark.parametrize("argv,message", [
    (["law", "coulomb", "--mu", "-1", "--force", "0", "0", "--normal", "1"], "mu = -1.0 violates mu >= 0"),
    (["law", "coulomb", "--mu", "0.3", "--force", "0", "0", "--normal", "-1"], "violates N >= 0"),
    (["law", "coulomb", "--mu", "0.3", "--alpha", "1", "--force", "0", "0", "--normal", "1"], "not alpha"),
    (["law", "nonsense", "--force", "0", "0", "--normal", "1"], "unknown law"),
    (["law", "coulomb", "--mu", "0.3", "--force", "0", "--normal", "1"], "expected 2 arguments"),
    (["paper", "--only", "fig99"], "is not a figure"),
])
def test_bad_input_exits_2_with_one_line(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        sys.exit(main(argv))
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


def test_console_script_help_everywhere():
    for argv in ([], ["law"], ["paper"]):
        res = subprocess.run([sys.executable, "-m", "frictionrules", *argv, "--help"], capture_output=True,
                             text=True, check=True)
        assert "usage: frictionrules" in res.stdout


def test_paper_writes_figures_and_table(tmp_path, capsys):
    names = ["fig1b_orthotropic_ellipse", "fig3a_wedge_elliptic"]
    argv = ["paper", "--out", str(tmp_path), "--numbers"]
    for name in names:
        argv += ["--only", name]
    assert main(argv) == 0
    out = capsys.readouterr().out
    for name in names:
        for ext in ("png", "svg"):
            assert (tmp_path / "paper" / f"{name}.{ext}").stat().st_size > 1000
    assert "tan(alpha+rho)" in out and "(1.15)" in out
    assert not list(tmp_path.rglob(".*"))  # no temporary files left behind
    rows = [r for r in out.splitlines() if "Tx/Q pushing up-slope" in r]
    assert float(rows[0].split()[-2]) == pytest.approx(np.tan(np.pi / 6 + np.arctan(0.5)), rel=1e-4)


@pytest.mark.parametrize("argv", [["asperity", "--config"], ["configuration", "--config"], ["drive"]])
def test_invalid_toml_exits_2_naming_the_file(argv, tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("mu = = 0.3\n")
    assert main(argv + [str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.toml" in err and "not valid TOML" in err and len(err.strip().splitlines()) == 1
