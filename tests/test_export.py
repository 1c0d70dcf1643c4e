"""``frictionrules.export`` and ``frictionrules export`` without a compiler: what is written,
reproducibility, the printers of one program, the layouts, and bad specs (exit 2, one line,
nothing written)."""

import re

import numpy as np
import pytest

import frictionrules as fr
from frictionrules import cli
from frictionrules.codegen import c_function, fortran_subroutine, local_program

NONASSOC = fr.UserLaw("sqrt((T1/mu_x)**2 + (T2/mu_y)**2) - N", potential="sqrt(T1**2 + T2**2)",
                      params={"mu_x": 0.5, "mu_y": 0.3})


@pytest.mark.parametrize("target", ["abaqus-fric", "abaqus-vfric", "abaqus-uinter", "c"])
def test_files_are_reproducible_and_carry_version_and_parameters(target, tmp_path):
    a = fr.export(NONASSOC, target, tmp_path / "a", kt=1e4, kn=1e5, name="ortho")
    b = fr.export(NONASSOC, target, tmp_path / "b", kt=1e4, kn=1e5, name="ortho")
    assert [p.name for p in a.files] == [p.name for p in b.files]
    for p, q in zip(a.files, b.files):
        assert p.read_bytes() == q.read_bytes()
    code = a.files[1 if target == "c" else 0].read_text()
    assert f"frictionrules {fr.__version__}" in code and "mu_x = 0.5" in code
    assert not re.search(r"20\d\d-\d\d-\d\d", code)  # no dates
    readme = a.files[-1].read_text()
    for name in a.props_names + a.statev_names:
        assert f"`{name}`" in readme


@pytest.mark.parametrize("target", ["abaqus-fric", "abaqus-vfric", "abaqus-uinter"])
def test_fortran_is_fixed_form_within_72_columns(target, tmp_path):
    res = fr.export(fr.EllipsoidCap(m=0.6) if target == "abaqus-uinter" else NONASSOC, target,
                    tmp_path, kt=1e4, kn=1e5)
    for line in res.files[0].read_text().splitlines():
        assert len(line) <= 72 and "\t" not in line
        if line and line[0] not in "Cc":
            assert line[:5].strip() == "" or line[:5].strip().isdigit()


def test_props_order_and_state_layout(tmp_path):
    res = fr.export(fr.Coulomb(0.3), "abaqus-fric", tmp_path, kt=1e4,
                    hardening=fr.SlipHardening(0.2, 0.05))
    assert res.props == (0.3, 0.2, 0.05, 1e4) and res.props_names[-1] == "kt"
    assert res.statev_names == ("kappa", "e_t1", "e_t2") and res.nstatv == 3
    snippet = res.files[1].read_text()
    assert "*FRICTION, USER, DEPVAR=3, PROPERTIES=4" in snippet and "UNSYMM" not in snippet
    u = fr.export(fr.EllipsoidCap(m=0.6), "abaqus-uinter", tmp_path, kt=1e4, kn=1e5)
    assert u.props_names[-2:] == ("kn", "kt") and u.nstatv == 8
    assert "*SURFACE INTERACTION, NAME=ELLIPSOIDCAP, USER, DEPVAR=8, PROPERTIES=8" in \
        u.files[1].read_text()
    c = fr.export(fr.EllipsoidCap(m=0.6), "c", tmp_path, kt=1e4, kn=1e5)
    assert c.props[:2] == (1e4, 1e5) and c.nstatv == 8
    assert "#define ELLIPSOIDCAP_NSTATE 8" in (tmp_path / "ellipsoidcap.h").read_text()


def test_printers_print_the_same_program():
    """C and Fortran print the one program (no second derivation): one assignment per
    temporary and output, and no division by a variable (guarded reciprocals)."""
    law = fr.HardenedLaw(fr.Coulomb(0.3), fr.SlipHardening(0.2, 0.05))
    prog = local_program(law.symbolic_form(), "full")
    c = c_function(prog, "local_full", "hc")
    f = fortran_subroutine(prog, "HCL2", "HC")
    n = len(prog.temps) + len(prog.outputs)
    assert len(re.findall(r"^    (?:const double t\d+|w\[\d+\]) = ", c, re.M)) == n
    assert len(re.findall(r"^      (?:T\d+|W\(\d+\)) = ", f, re.M)) == n
    assert not re.search(r"/\s*[a-z(]", c.replace("3.0/2.0", ""))


@pytest.mark.parametrize("bad, text", [
    (dict(target="ansys"), "target"), (dict(kt=0.0), "kt"), (dict(kt=np.nan), "kt"),
    (dict(kn=-1.0), "kn"), (dict(name="1x"), "name"), (dict(target="c", kn=None), "kn"),
])
def test_bad_arguments_raise_and_write_nothing(bad, text, tmp_path):
    kwargs = dict(target="abaqus-fric", kt=1e4, kn=1e5) | bad
    target = kwargs.pop("target")
    with pytest.raises(fr.FrictionRulesError, match=text):
        fr.export(fr.Coulomb(0.3), target, tmp_path / "out", **kwargs)
    assert not (tmp_path / "out").exists()


def test_laws_a_target_cannot_express(tmp_path):
    with pytest.raises(fr.FrictionRulesError, match="abaqus-uinter"):
        fr.export(fr.Coulomb(0.3, dilatant=True), "abaqus-fric", tmp_path, kt=1e4)
    with pytest.raises(fr.FrictionRulesError, match="cone"):
        fr.export(fr.EllipsoidCap(m=0.6), "abaqus-vfric", tmp_path, kt=1e4)
    with pytest.raises(fr.FrictionRulesError, match="symbolic"):
        fr.export(fr.FacetSet([[-0.5, 0, 0.866], [0.5, 0, 0.866]], mu=0.3), "c", tmp_path,
                  kt=1e4, kn=1e5)
    assert not list(tmp_path.iterdir())


# ---- the CLI ------------------------------------------------------------------------------
def test_cli_writes_the_files(tmp_path, capsys):
    rc = cli.main(["export", "elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--angle", "20",
                   "--deg", "--target", "abaqus-fric", "--kt", "1e4", "--out", tmp_path / "f"])
    assert rc == 0
    names = sorted(p.name for p in (tmp_path / "f").iterdir())
    assert names == ["ellipticorthotropic_fric.f", "ellipticorthotropic_fric.inp",
                     "ellipticorthotropic_fric_README.md"]
    assert "angle=0.349066" in capsys.readouterr().out


def test_cli_toml_user_law_with_hardening(tmp_path):
    spec = tmp_path / "law.toml"
    spec.write_text('[law]\nlimit = "sqrt((T1/mu_x)**2 + (T2/mu_y)**2) - N"\n'
                    'potential = "sqrt(T1**2 + T2**2)"\nparams = { mu_x = 0.5, mu_y = 0.3 }\n'
                    '[hardening]\nh = 0.2\nkappa_h = 0.05\n')
    rc = cli.main(["export", spec, "--target", "c", "--kt", "100", "--kn", "200", "--out",
                   tmp_path / "c", "--name", "ortho"])
    assert rc == 0
    header = (tmp_path / "c" / "ortho.h").read_text()
    assert "#define ORTHO_NSTATE 7" in header  # δᵉ, δᵖ, κ


@pytest.mark.parametrize("argv, text", [
    (["user", "--limit", "sqrt(T1^2 + T2^2) - mu*N + foo", "--param", "mu=0.3"], "'foo'"),
    (["user", "--limit", "sqrt(T1^2 + T2^2) - mu*N"], "'mu'"),
    (["coulomb"], "--mu"),
    (["facets.toml"], "unknown law 'FacetSet'"),      # not a law of the table
    (["nosuchlaw"], "LAW_SPEC"),
    (["coulomb", "--mu", "0.3", "--dilatant"], "abaqus-uinter"),
])
def test_cli_bad_specs_exit_2_with_one_line_and_write_nothing(argv, text, tmp_path, capsys,
                                                             monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "facets.toml").write_text('[law]\ntype = "FacetSet"\n'
                                          'normals = [[-0.5, 0, 0.866], [0.5, 0, 0.866]]\n'
                                          'mu = 0.3\n')
    rc = cli.main(["export", *argv, "--target", "abaqus-fric", "--kt", "1e4", "--out", "out"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and text in err[0], err
    assert not (tmp_path / "out").exists()


def test_compile_tests_skip_without_a_compiler_and_fail_in_ci(monkeypatch):
    """No compiler: the compiled tests skip with the reason; in CI (CI=true) they fail."""
    import _export_harness as harness
    monkeypatch.setattr(harness.shutil, "which", lambda name: None)
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception, match="gfortran"):
        harness.compiler("fortran")
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match="CI=true"):
        harness.compiler("c")


def test_files_are_the_same_bytes_in_another_process(tmp_path):
    """Reproducible across processes (string hashing randomized differently): no order of a
    set or dict leaks into the printed code."""
    import os
    import subprocess
    import sys
    code = ("import frictionrules as fr, sys\n"
            "fr.export(fr.EllipsoidCap(m=0.6), 'abaqus-uinter', sys.argv[1], kt=1e4, kn=1e5)\n")
    for k, seed in enumerate(("1", "2")):
        env = os.environ | {"PYTHONHASHSEED": seed}
        subprocess.run([sys.executable, "-c", code, str(tmp_path / str(k))], check=True, env=env)
    for p in (tmp_path / "0").iterdir():
        assert p.read_bytes() == (tmp_path / "1" / p.name).read_bytes(), p.name
