"""The law table, the traits of a law and the one TOML layout of a law.

* Every built-in law declares its traits in closed form; each declaration equals the traits
  derived from its symbolic form (SymPy), for parameter values on both sides of every case
  the closed form distinguishes.
* User laws get derived traits, checked against the closed forms of the laws they write.
* A law written in the layout of :func:`frictionrules.read_law` is read back equal by the API
  and by every command that takes a law: ``law``, ``drive``, ``export``, ``assembly``.
"""

import json
import tomllib

import numpy as np
import pytest

import frictionrules as fr
from frictionrules import cli
from frictionrules.laws import LawTraits, derive_traits

NORM = "sqrt(T1**2 + T2**2)"

#: Built-in laws on both sides of every case their declared traits distinguish.
BUILT_IN = [
    fr.Coulomb(0.3), fr.Coulomb(0.3, dilatant=True), fr.Coulomb(0.0, dilatant=True),
    fr.EllipticOrthotropic(0.6, 0.3, 0.4),
    fr.TransformedCoulomb(0.6, 0.3, 0.4), fr.TransformedCoulomb(0.3, 0.3, 0.4),
    fr.Huber(0.6, 0.3, 0.4), fr.Huber(0.4, 0.3), fr.Huber(0.3, 0.3),
    fr.WedgeAsperity(0.5, 0.3), fr.WedgeAsperity(0.5, 0.3, "associated"),
    fr.WedgeAsperity(2.0, 0.0), fr.WedgeAsperity(1.2, 1.0),
    fr.EllipsoidCap(0.6), fr.EllipsoidCap(0.6, normal_ratio=0.5),
]


@pytest.mark.parametrize("law", BUILT_IN, ids=repr)
def test_declared_traits_equal_the_derived_ones(law):
    """Closed forms (e.g. Huber's convexity for max/min <= 1.5, from r² + 2r'² − rr'' >= 0 on
    the polar curve (1.16)) against the derivation from the symbolic form."""
    declared = law.declared_traits()
    assert isinstance(declared, LawTraits)
    assert declared == derive_traits(law)
    assert law.traits is law.traits                      # cached per law
    assert law.tangentially_associated is declared.tangentially_associated


def test_traits_of_the_paper_laws():
    """(1.10): the elliptic rule is normal to the limit curve in the sliding plane, Huber's
    (1.16) and the transformed rule (1.18) are not; (1.6) opens the contact; (2.4) against
    (2.5): the wedge's non-associated rule is not normal in the plane of the loads."""
    assert fr.EllipticOrthotropic(0.6, 0.3).traits.tangentially_associated
    assert not fr.Huber(0.6, 0.3).traits.tangentially_associated
    assert not fr.TransformedCoulomb(0.6, 0.3).traits.tangentially_associated
    assert fr.Coulomb(0.3, dilatant=True).traits.normal_slip
    assert not fr.WedgeAsperity(0.5, 0.3).traits.tangentially_associated
    assert not fr.Huber(0.6, 0.3).traits.convex and fr.Huber(0.4, 0.3).traits.convex
    cap = fr.EllipsoidCap(0.6).traits
    assert not cap.conical and cap.normal_slip and not cap.symmetric_tangent


USER = {
    "coulomb": (fr.UserLaw(f"{NORM} - mu*N", NORM, params={"mu": 0.3}), fr.Coulomb(0.3)),
    "dilatant": (fr.UserLaw(f"{NORM} - mu*N", params={"mu": 0.3}), fr.Coulomb(0.3, True)),
    "elliptic": (fr.UserLaw("sqrt((T1/a)**2 + (T2/b)**2) - N", "sqrt((T1/a)**2 + (T2/b)**2)",
                            params={"a": 0.6, "b": 0.3}), fr.EllipticOrthotropic(0.6, 0.3)),
    "huber": (fr.UserLaw(f"{NORM} - N*(0.6*T1**2 + 0.3*T2**2)/(T1**2 + T2**2)", NORM),
              fr.Huber(0.6, 0.3)),
}


@pytest.mark.parametrize("name", sorted(USER))
def test_user_laws_have_the_traits_of_the_laws_they_write(name):
    user, built_in = USER[name]
    assert user.declared_traits() is None
    assert user.traits == built_in.traits


def test_derived_traits_of_user_laws_without_a_built_in_twin():
    # f not homogeneous (a cohesion c): not conical
    t = fr.UserLaw(f"{NORM} - mu*N - c", NORM, params={"mu": 0.4, "c": 0.1}).traits
    assert t.degree is None and not t.conical
    # g = |T|²: its gradient is of degree one, the slip direction of degree zero: conical
    t = fr.UserLaw(f"{NORM} - 0.4*N", "T1**2 + T2**2").traits
    assert t.degree == 1.0 and t.slip_degree == 1.0 and t.conical
    # a slip potential parallel to f in the plane but scaled: normality holds
    assert fr.UserLaw(f"{NORM} - 0.4*N", f"2*{NORM}").traits.tangentially_associated
    # internal variables: kappa' = |dg/dT| = 1 for g = |T| couples nothing; for an
    # elliptic g it depends on the direction of T and couples the tangential directions
    slip = dict(state={"kappa": 0.0}, rates={"kappa": "slip"})
    t = fr.UserLaw(f"{NORM} - 0.4*N*(1 + kappa)", NORM, **slip).traits
    assert not t.tangent_coupling and t.symmetric_tangent
    ell = "sqrt(T1**2 + 4*T2**2)"
    t = fr.UserLaw(f"{ell} - 0.4*N*(1 + kappa)", ell, **slip).traits
    assert t.tangent_coupling and not t.symmetric_tangent and t.tangentially_associated
    # slip hardening scales N: the traits of the law at the virgin state
    hard = fr.SlipHardening(0.2, 0.05)
    for law in (fr.Coulomb(0.3), fr.Huber(0.6, 0.3), fr.EllipticOrthotropic(0.6, 0.3)):
        a, b = hard.apply(law).traits, law.traits
        assert (a.degree, a.slip_degree, a.normal_slip, a.tangentially_associated, a.convex) \
            == (b.degree, b.slip_degree, b.normal_slip, b.tangentially_associated, b.convex)


# ---- the table ------------------------------------------------------------------------------
def test_every_law_of_the_table_and_its_parameters():
    assert list(fr.LAWS) == ["coulomb", "elliptic", "huber", "transformed", "wedge", "cap",
                             "user"]
    for entry in fr.LAWS.values():
        assert issubclass(entry.cls, fr.FrictionLaw) and entry.summary
        assert fr.laws.law_entry(entry.type) is entry is fr.laws.law_entry(entry.name.upper())
        for p in entry.parameters.values():
            assert p.meaning and p.kind in (float, bool, str, dict)
    assert list(fr.LAWS["cap"].parameters) == ["m", "p", "h", "kappa_h", "b", "normal_ratio"]
    with pytest.raises(fr.FrictionRulesError, match="unknown law 'Cap2'"):
        fr.laws.law_entry("Cap2")


BOUNDED = [(e.cls, p) for e in fr.LAWS.values() for p in e.parameters.values()
           if p.kind is float and p.lo is not None]


@pytest.mark.parametrize("cls, par", BOUNDED, ids=[f"{c.__name__}.{p.name}" for c, p in BOUNDED])
def test_the_declared_bound_is_the_constraint_of_the_error(cls, par):
    """A value just outside the declared lower bound raises, naming the parameter, the value
    and that bound as the table declares it; a value inside is accepted."""
    entry = next(e for e in fr.LAWS.values() if e.cls is cls)
    good = {n: (0.3 if n != "alpha" else 0.5) for n, p in entry.parameters.items()
            if p.required}
    outside = par.lo if par.lo_open else par.lo - 0.1
    with pytest.raises(fr.FrictionRulesError) as err:
        cls.from_parameters(**{**good, par.name: outside})
    bound = f"{par.name} {'>' if par.lo_open else '>='} {par.lo}"
    assert f"{par.name} = {outside!r} violates {bound}" in str(err.value)
    assert bound in par.constraint
    cls.from_parameters(**{**good, par.name: par.lo + 0.2})


def test_parameters_replace_and_rebuild():
    cap = fr.EllipsoidCap(0.6, normal_ratio=0.5)
    assert cap.parameters == {"m": 0.6, "p": 2.0, "h": 0.25, "kappa_h": 0.05, "b": 20.0,
                              "normal_ratio": 0.5}
    assert cap.replace(p=3.0, b=10.0) == fr.EllipsoidCap(0.6, fr.laws.AreaHardening(p=3.0),
                                                         fr.laws.AreaGrowth(10.0), 0.5)
    assert fr.Coulomb(0.3).replace(mu=0.4) == fr.Coulomb(0.4)
    with pytest.raises(fr.FrictionRulesError, match="dilatant = 'yes' violates"):
        fr.Coulomb(0.3, "yes")
    with pytest.raises(fr.FrictionRulesError, match="local = 'x' violates local in"):
        fr.WedgeAsperity(0.5, 0.3, "x")
    with pytest.raises(fr.FrictionRulesError, match="A = 2 violates: must be of type AreaHard"):
        fr.EllipsoidCap(0.6, 2)
    with pytest.raises(fr.FrictionRulesError, match=r"missing; constraint: Coulomb needs \['mu'"):
        fr.Coulomb.from_parameters(dilatant=True)
    with pytest.raises(fr.FrictionRulesError, match=r"unknown parameters \['mu_z'\]"):
        fr.EllipticOrthotropic.from_parameters(mu_x=0.3, mu_y=0.2, mu_z=0.1)


# ---- one layout, every command -----------------------------------------------------------------
#: A law of each kind the layout holds: the built-in laws, the cap with its A and B, a user
#: law with parameters, internal variables and their evolution, and slip hardening.
LAYOUT = {
    "coulomb": fr.Coulomb(0.3, dilatant=True),
    "elliptic": fr.EllipticOrthotropic(0.6, 0.3, 0.4),
    "huber": fr.Huber(0.4, 0.3, -0.2),
    "transformed": fr.TransformedCoulomb(0.5, 0.3),
    "wedge": fr.WedgeAsperity(0.5, 0.3, "associated"),
    "cap": fr.EllipsoidCap(0.6, fr.laws.AreaHardening(2.5, 0.2, 0.04), fr.laws.AreaGrowth(15.0),
                           0.7),
    "user": fr.UserLaw(f"{NORM} - mu*N*(1 + a*kappa/(kappa + k0))", NORM,
                       params={"mu": 0.4, "a": 0.5, "k0": 0.02}, state={"kappa": 0.0},
                       rates={"kappa": "slip"}),
    "hardened": fr.SlipHardening(0.2, 0.05).apply(
        fr.UserLaw("sqrt((T1/mx)**2 + (T2/my)**2) - N", NORM, params={"mx": 0.5, "my": 0.3})),
}


@pytest.mark.parametrize("name", sorted(LAYOUT))
def test_the_layout_round_trips_through_the_api(name, tmp_path):
    law = LAYOUT[name]
    text = fr.law_to_toml(law)
    assert text.startswith("[law]\ntype = ")
    (tmp_path / "law.toml").write_text(text)
    assert fr.read_law(tmp_path / "law.toml") == law
    assert fr.law_from_mapping(tomllib.loads(text)["law"]) == law
    nested = fr.law_to_toml(law, "model.law")
    (tmp_path / "run.toml").write_text(nested)
    assert fr.read_law(tmp_path / "run.toml", "model.law") == law


@pytest.mark.parametrize("name", ["coulomb", "elliptic", "wedge", "cap", "user"])
def test_the_law_command_reads_the_layout(name, tmp_path, capsys):
    law = LAYOUT[name]
    (tmp_path / "law.toml").write_text(fr.law_to_toml(law))
    argv = ["--force", "0.05", "0.02", "--normal", "0.5", "--json", "--quiet"]
    assert cli.main(["law", str(tmp_path / "law.toml"), *argv]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["law"] == repr(law)
    assert out["limit"] == pytest.approx(float(law.limit([0.05, 0.02], 0.5)), rel=1e-14)
    # a law file takes no parameter options
    assert cli.main(["law", str(tmp_path / "law.toml"), "--mu", "0.3", *argv]) == 2
    assert "the law's parameters go in the file" in capsys.readouterr().err


def _drive_file(law, tmp_path, hardening_alias=False):
    text = "[model]\nkn = 100.0\nkt = 80.0\n" + fr.law_to_toml(law, "model.law")
    text += "[[segment]]\nN = 0.5\ndt1 = 0.0\nT2 = 0.0\nsteps = 2\n"
    text += "[[segment]]\ndt1 = 0.02\nsteps = 8\n"
    path = tmp_path / "drive.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("name", sorted(LAYOUT))
def test_drive_files_hold_the_law_in_the_layout(name, tmp_path):
    from frictionrules.contact.driver import read_toml
    model, path, _ = read_toml(_drive_file(LAYOUT[name], tmp_path))
    assert model.law == LAYOUT[name] and len(path) == 10


def test_drive_runs_a_user_law_with_internal_variables(tmp_path, capsys):
    """The drive command takes ``type = "UserLaw"`` with parameters, internal variables and
    their evolution, and its result is the library's."""
    law = LAYOUT["user"]
    file = _drive_file(law, tmp_path)
    assert cli.main(["drive", str(file), "--out", str(tmp_path / "d.csv"), "--quiet"]) == 0
    assert "10 steps" in capsys.readouterr().out
    table = np.genfromtxt(tmp_path / "d.csv", delimiter=",", names=True)
    ref = fr.drive(fr.ContactModel(law, 100.0, 80.0), [
        {"N": 0.5, "dt1": 0.0, "T2": 0.0, "steps": 2}, {"dt1": 0.02, "steps": 8}])
    np.testing.assert_allclose(table["T1"], ref.force[:, 0], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(table["kappa"], ref.kappa, rtol=1e-12, atol=1e-15)
    assert table["kappa"][-1] > 0


def test_drive_and_export_keep_their_hardening_tables(tmp_path):
    """``[model.hardening]`` (drive) and ``[hardening]`` (export) beside the law are read as
    the law's own ``hardening`` table."""
    from frictionrules.contact.driver import read_toml
    base = fr.Coulomb(0.3)
    path = _drive_file(base, tmp_path)
    path.write_text(path.read_text().replace("[model.law]", "[model.hardening]\nh = 0.2\n"
                                             "kappa_h = 0.05\n[model.law]"))
    model, _, _ = read_toml(path)
    assert model.effective_law == fr.SlipHardening(0.2, 0.05).apply(base)
    (tmp_path / "law.toml").write_text(fr.law_to_toml(base) + "[hardening]\nh = 0.2\n"
                                       "kappa_h = 0.05\n")
    assert fr.read_law(tmp_path / "law.toml") == fr.SlipHardening(0.2, 0.05).apply(base)


@pytest.mark.parametrize("name, target", [("user", "c"), ("hardened", "abaqus-fric"),
                                          ("cap", "abaqus-uinter")])
def test_export_reads_the_layout(name, target, tmp_path, capsys):
    law = LAYOUT[name]
    (tmp_path / "law.toml").write_text(fr.law_to_toml(law))
    assert cli.main(["export", str(tmp_path / "law.toml"), "--target", target, "--kt", "100",
                     "--kn", "200", "--out", str(tmp_path / "cli"), "--name", "x"]) == 0
    api = fr.export(law, target, tmp_path / "api", kt=100.0, kn=200.0, name="x")
    for path in api.files:
        assert (tmp_path / "cli" / path.name).read_bytes() == path.read_bytes()


@pytest.mark.parametrize("name", ["coulomb", "elliptic", "huber", "transformed", "user",
                                  "hardened"])
def test_assembly_configurations_hold_the_law_in_the_layout(name, tmp_path):
    from frictionrules.assembly import read_config
    law = LAYOUT[name]
    cfg = tmp_path / "run.toml"
    cfg.write_text('[sample]\nlattice = "fcc"\n[model]\nkn = 1e6\nkt = 1e6\n'
                   + fr.law_to_toml(law, "model.law")
                   + '[loading]\nkind = "axisymmetric"\npressure = 1.0\n')
    assembly, loading = read_config(cfg)
    assert assembly.model.law == law and loading["pressure"] == 1.0


def test_old_assembly_spelling_of_a_user_law(tmp_path):
    from frictionrules.assembly import read_config
    cfg = tmp_path / "run.toml"
    cfg.write_text('[sample]\nlattice = "fcc"\n[model]\nkn = 1e6\nkt = 1e6\n[model.law]\n'
                   f'type = "User"\nlimit = "{NORM} - mu*N"\nparams = {{ mu = 0.3 }}\n'
                   '[loading]\nkind = "axisymmetric"\npressure = 1.0\n')
    assert read_config(cfg)[0].model.law == fr.UserLaw(f"{NORM} - mu*N", params={"mu": 0.3})


@pytest.mark.parametrize("text, message", [
    ('[law]\ntype = "Colomb"\nmu = 0.3\n', "unknown law 'Colomb'"),
    ('[law]\ntype = "Coulomb"\nmu = -0.3\n', "mu = -0.3 violates mu >= 0"),
    ('[law]\ntype = "Coulomb"\nmu = 0.3\nnu = 1\n', "unknown parameters ['nu']"),
    ('[law]\ntype = "Coulomb"\n', "the parameters ['mu'] are missing"),
    ('[law]\ntype = "Coulomb"\nmu = 0.3\nhardening = 2\n', "hardening = 2 violates"),
    ('[law]\ntype = "EllipsoidCap"\nm = 0.6\nhardening = { h = 0.1, kappa_h = 0.1 }\n',
     "without internal variables"),
    ('[law]\nlimit = "T1 - mu*N"\n', "'mu'"),
    ('[laws]\ntype = "Coulomb"\n', "no [law] table"),
    ('[law]\ntype = "Coulomb"\nmu = 0.3\n[other]\n', "unknown tables ['other']"),
])
def test_bad_law_files_are_one_line_errors(text, message, tmp_path, capsys):
    (tmp_path / "law.toml").write_text(text)
    with pytest.raises(fr.FrictionRulesError, match=None) as err:
        fr.read_law(tmp_path / "law.toml")
    assert message in str(err.value) and "law.toml" in str(err.value)
    assert cli.main(["law", str(tmp_path / "law.toml"), "--force", "0", "0", "--normal", "1"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0]
