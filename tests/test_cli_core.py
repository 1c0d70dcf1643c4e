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
    assert out["state"] == "slip" and out["locked"] is False
    assert out["slip_direction"] == pytest.approx([1.0, 0.0, 0.0])
    assert out["friction_coefficient"] == pytest.approx(0.6)
    assert out["units"]["theta"] == "rad" and out["non_finite"] == {}


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
    argv = ["paper", "--out", str(tmp_path)]
    for name in names:
        argv += ["--only", name]
    assert main(argv) == 0
    out = capsys.readouterr().out
    for name in names:
        for ext in ("png", "svg"):
            assert (tmp_path / f"{name}.{ext}").stat().st_size > 1000
    assert "tan(alpha+rho)" in out and "(1.15)" in out
    assert not list(tmp_path.glob(".*"))  # no temporary files left behind
    rows = [r for r in out.splitlines() if "Tx/Q pushing up-slope" in r]
    assert float(rows[0].split()[-2]) == pytest.approx(np.tan(np.pi / 6 + np.arctan(0.5)), rel=1e-4)


@pytest.mark.parametrize("argv", [["asperity", "--config"], ["configuration", "--config"], ["drive"]])
def test_invalid_toml_exits_2_naming_the_file(argv, tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("mu = = 0.3\n")
    assert main(argv + [str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.toml" in err and "not valid TOML" in err and len(err.strip().splitlines()) == 1


# ---- law: honest labels, strict JSON, safe expressions ---------------------------------------
def strict_loads(text):
    def refuse(token):
        raise AssertionError(f"invalid JSON token {token}")
    return json.loads(text, parse_constant=refuse)


def test_law_locked_wedge_writes_valid_json(capsys):
    """alpha = 60 deg, mu = 1 pushed horizontally: stick, and mu(0) is infinite (self-locking,
    alpha + rho = 105 deg > 90 deg, (2.2)): null with "locked": true, never Infinity."""
    assert main(["law", "wedge", "--alpha", "60", "--deg", "--mu", "1", "--force", "1", "0",
                 "--normal", "1", "--theta", "0", "--json"]) == 0
    out = strict_loads(capsys.readouterr().out)
    assert out["friction_coefficient"] is None and out["locked"] is True
    assert out["non_finite"] == {"/friction_coefficient": "inf"}
    assert out["state"] == "stick" and out["slip_direction"] is None and "force_angle" not in out
    assert out["units"]["theta"] == "deg"


def test_law_text_labels_state_and_angles(capsys):
    # a stick state has no slip direction; theta is then the direction of T
    assert main(["law", "wedge", "--alpha", "60", "--deg", "--mu", "1", "--force", "1", "0",
                 "--normal", "1"]) == 0
    text = capsys.readouterr().out
    assert "state                 stick" in text and "slip direction        none (stick)" in text
    assert "(the direction of T)" in text and "locked" in text and "force angle beta" not in text
    # sliding: the limit force at theta is labelled as such, and differs from the given force
    assert main(["law", "elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--force", "0.3", "0.2",
                 "--normal", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["force_direction"] == pytest.approx(np.arctan2(0.2, 0.3))
    assert out["theta_from"] == "force" and out["state"] == "stick"
    T = np.array([0.6 * np.cos(0.4), 0.3 * np.sin(0.4)])  # on the ellipse (1.10), parameter 0.4
    assert main(["law", "elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--force", *map(str, T),
                 "--normal", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["state"] == "slip" and out["theta_from"] == "slip"
    # the slip is normal to the ellipse: along (T1 / 0.36, T2 / 0.09) (1.11)
    assert out["theta"] == pytest.approx(np.arctan2(T[1] / 0.09, T[0] / 0.36))
    assert out["force_angle"] == pytest.approx(np.arctan2(T[1], T[0]))     # beta(theta) (1.14)
    assert main(["law", "elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--force", *map(str, T),
                 "--normal", "1"]) == 0
    assert "limit force at theta  angle beta" in capsys.readouterr().out


def test_negative_numbers_are_values(capsys):
    assert main(["law", "coulomb", "--mu", "0.5", "--force", "-0.5", "-1e-6", "--normal", "1",
                 "--theta", "-.5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["force"] == [-0.5, -1e-6] and out["theta"] == -0.5


@pytest.mark.parametrize("argv, message", [
    (["law", "coulomb", "--param", "mu=abc"], "--param 'mu=abc': mu = 'abc' violates: must be a finite number"),
    (["law", "coulomb", "--param", "dilatant=maybe"], "dilatant = 'maybe' violates: true or false"),
    (["law", "user", "--limit", "foo(T1)"], "limit = 'foo(T1)': unknown function 'foo' at position 0"),
    (["law", "user", "--limit", "T1", "--potential", "T1.real"], "potential = 'T1.real': character"),
    (["law", "user", "--param", "limit=T1[0]"], "limit = 'T1[0]': character not allowed '['"),
    (["law", "user", "--limit", "T1 - mu*N"], "unknown name 'mu' at position 5"),
    (["law", "coulomb", "--mu", "nan"], "argument --mu: 'nan' violates: must be a finite number"),
])
def test_law_bad_parameters_are_one_line(argv, message, capsys):
    assert main(argv + ["--force", "0.1", "0", "--normal", "1"]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_law_string_never_runs(tmp_path, capsys):
    canary = tmp_path / "pwned"
    for text in (f"__import__('os').system('touch {canary}')", f"open('{canary}', 'w')",
                 "(lambda: __import__('os'))()"):
        assert main(["law", "user", "--limit", text, "--force", "0.1", "0.1", "--normal", "1"]) == 2
        assert "at position" in capsys.readouterr().err
    assert not canary.exists()


def test_user_law_accepts_carets_and_reports_progress_off_a_terminal(capsys):
    assert main(["law", "user", "--limit", "sqrt(T1^2 + T2^2) - 0.3*N", "--potential",
                 "sqrt(T1^2 + T2^2)", "--force", "0.3", "0", "--normal", "1", "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["friction_coefficient"] == pytest.approx(0.3)
    assert err.startswith("law user: done in ") and "\r" not in err and err.count("\n") == 1
    # named parameters of the expressions: --param NAME=VALUE (or a number option of that name)
    for given in (["--param", "mu=0.4"], ["--mu", "0.4"]):
        assert main(["law", "user", "--limit", "sqrt(T1^2 + T2^2) - mu*N", *given, "--force",
                     "0.4", "0", "--normal", "1", "--json", "--quiet"]) == 0
        out, err = capsys.readouterr()
        assert json.loads(out)["friction_coefficient"] == pytest.approx(0.4) and err == ""


# ---- main: internal errors, --debug ------------------------------------------------------------
def test_internal_error_is_one_line_exit_1(monkeypatch, capsys):
    from frictionrules.cli import law

    def broken(*args, **kwargs):
        raise ZeroDivisionError("division by zero\nsecond line")
    monkeypatch.setattr(law, "evaluate", broken)
    monkeypatch.delenv("FRICTIONRULES_DEBUG", raising=False)
    argv = ["law", "coulomb", "--mu", "0.3", "--force", "0", "0", "--normal", "1"]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "internal error: ZeroDivisionError: division by zero second line" in err and "FRICTIONRULES_DEBUG" in err
    with pytest.raises(ZeroDivisionError):
        main(["--debug", *argv])
    with pytest.raises(ZeroDivisionError):
        main([*argv, "--debug"])
    monkeypatch.setenv("FRICTIONRULES_DEBUG", "1")
    with pytest.raises(ZeroDivisionError):
        main(argv)
