"""The words of the exported files and of the console line: each host's own (Abaqus keywords
for FRIC, VFRIC, UINTER; C arrays and types for the C target), and a user law's parameters
described in the user's words or as "user parameter", never guessed from their names."""

from __future__ import annotations

import re

import pytest

from frictionrules import FrictionRulesError, UserLaw, export
from frictionrules.cli import main

#: A non-associated user law whose parameter names look like the built-in laws' (mu_x, mu_y):
#: the README must not call them "friction coefficient along x".
LAW_TOML = """
[law]
limit = "sqrt((T1/mu_x)**2 + (T2/mu_y)**2) - N"
potential = "sqrt(T1**2 + T2**2)"
params = { mu_x = { value = 0.6, description = "friction along the grooves of the plate" }, mu_y = 0.3 }
"""
ABAQUS_WORDS = re.compile(r"UNSYMM|PROPS|PROPERTIES|DEPVAR|STATEV|\*STEP|\*FRICTION|Abaqus")


def _law():
    return UserLaw("sqrt((T1/mu_x)**2 + (T2/mu_y)**2) - N", potential="sqrt(T1**2 + T2**2)",
                   params={"mu_x": 0.6, "mu_y": 0.3},
                   descriptions={"mu_x": "friction along the grooves of the plate"})


@pytest.mark.parametrize("target", ["abaqus-fric", "abaqus-vfric", "abaqus-uinter"])
def test_abaqus_files_say_how_the_contact_pair_refers_to_the_interaction(target, tmp_path):
    res = export(_law(), target, tmp_path, kt=1e4, kn=1e5 if target == "abaqus-uinter" else None,
                 name="ortho")
    snippet = next(p for p in res.files if p.suffix == ".inp").read_text()
    readme = next(p for p in res.files if p.name.endswith("README.md")).read_text()
    assert "** *CONTACT PAIR, INTERACTION=ORTHO" in snippet
    assert "\n*CONTACT PAIR, INTERACTION=ORTHO\nSLAVE_SURFACE, MASTER_SURFACE\n" in readme
    assert ("*STEP, UNSYMM=YES" in readme) == (target != "abaqus-vfric")    # non-associated


def test_c_files_speak_c(tmp_path):
    """README, header, source and example of the C target: no Abaqus keyword or array; the
    unsymmetric tangent is said in C terms."""
    res = export(_law(), "c", tmp_path, kt=1e4, kn=1e5, name="ortho")
    assert res.unsymmetric
    for path in res.files:
        text = path.read_text()
        assert not ABAQUS_WORDS.search(text), (path.name, ABAQUS_WORDS.search(text).group(0))
    readme = next(p for p in res.files if p.name.endswith("README.md")).read_text()
    assert "## Call" in readme and "ORTHO_NPARAMS" in readme and "ORTHO_NSTATE" in readme
    assert "a linear solver for unsymmetric matrices" in readme


@pytest.mark.parametrize("target", ["abaqus-fric", "c"])
def test_a_user_parameter_is_described_in_the_users_words(target, tmp_path):
    res = export(_law(), target, tmp_path, kt=1e4, kn=1e5, name="ortho")
    readme = next(p for p in res.files if p.name.endswith("README.md")).read_text()
    assert "| `mu_x` | 0.6 | friction along the grooves of the plate | as in the law |" in readme
    assert "| `mu_y` | 0.3 | user parameter | as in the law |" in readme
    assert "coefficient along" not in readme


def test_built_in_laws_keep_their_parameter_meanings(tmp_path):
    from frictionrules import EllipticOrthotropic
    res = export(EllipticOrthotropic(0.6, 0.3), "abaqus-fric", tmp_path, kt=1e4)
    readme = next(p for p in res.files if p.name.endswith("README.md")).read_text()
    assert "| `mu_x` | 0.6 | friction coefficient along principal axis 1 | 1 |" in readme


@pytest.mark.parametrize("target, line", [
    ("abaqus-fric", "abaqus-fric: *FRICTION, USER, DEPVAR=2, PROPERTIES=3 (mu_x=0.6, mu_y=0.3, "
                    "kt=10000); unsymmetric tangent: *STEP, UNSYMM=YES"),
    ("abaqus-uinter", "abaqus-uinter: *SURFACE INTERACTION, USER, DEPVAR=6, PROPERTIES=4 "
                      "(mu_x=0.6, mu_y=0.3, kn=100000, kt=10000); unsymmetric tangent: *STEP, "
                      "UNSYMM=YES"),
    ("abaqus-vfric", "abaqus-vfric: *FRICTION, USER, DEPVAR=0, PROPERTIES=3 (mu_x=0.6, mu_y=0.3, "
                     "frame_angle=0)"),
    ("c", "c: params[4] = {kt=10000, kn=100000, mu_x=0.6, mu_y=0.3}, state[6]; the tangent is "
          "unsymmetric (a general 3 x 3 matrix)"),
])
def test_console_line_in_the_hosts_words(target, line, tmp_path, capsys):
    spec = tmp_path / "law.toml"
    spec.write_text(LAW_TOML)
    assert main(["export", str(spec), "--target", target, "--kt", "1e4", "--kn", "1e5", "--out",
                 str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == line
    readme = next((tmp_path / "out").glob("*README.md")).read_text()
    assert "friction along the grooves of the plate" in readme


def test_descriptions_round_trip_and_leave_the_law_unchanged():
    law = _law()
    assert law.parameter_descriptions == {"mu_x": "friction along the grooves of the plate",
                                          "mu_y": "user parameter"}
    again = UserLaw.from_mapping(law.to_mapping())
    assert again.parameter_descriptions == law.parameter_descriptions
    plain = UserLaw(law.limit_expr, law.potential_expr, law.parameters)
    assert plain == law and hash(plain) == hash(law)          # not part of the law's identity
    assert law.replace(mu_x=0.5).parameter_descriptions == law.parameter_descriptions
    from frictionrules import SlipHardening
    assert SlipHardening(0.2, 0.05).apply(law).parameter_descriptions == law.parameter_descriptions


@pytest.mark.parametrize("params, message", [
    ({"mu": {"description": "no value"}}, "params.mu"),
    ({"mu": {"value": 0.3, "unit": "1"}}, "params.mu"),
])
def test_a_bad_parameter_table_is_one_error(params, message):
    with pytest.raises(FrictionRulesError, match=message):
        UserLaw.from_mapping({"limit": "sqrt(T1**2 + T2**2) - mu*N", "params": params})
    with pytest.raises(FrictionRulesError, match="descriptions"):
        UserLaw("sqrt(T1**2 + T2**2) - mu*N", params={"mu": 0.3}, descriptions={"nu": "x"})
