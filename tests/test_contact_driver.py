"""drive(): mixed control, paths from Python/CSV/TOML, CSV/HDF5 writers, the CLI."""

import json

import h5py
import numpy as np
import pytest

from frictionrules import ContactModel, Coulomb, DriveResult, EllipsoidCap, FrictionRulesError, drive
from frictionrules.cli import main
from frictionrules.contact import Path, read_path
from frictionrules.contact.driver import COLUMNS, read_toml

WITHOUT_BETA = tuple(c for c in COLUMNS if c != "beta")

TOML = """
[model]
kn = 100.0
kt = 50.0
beta = 0.4
[model.law]
type = "Coulomb"
mu = 0.5
dilatant = true
[[segment]]
N = 1.0
dt1 = 0.0
dt2 = 0.0
steps = 4
[[segment]]
dt1 = 0.1
steps = 20
"""


def test_mixed_control_holds_prescribed_forces():
    """Dilatant Coulomb sheared at fixed N: N stays at its target while the contact opens."""
    m = ContactModel(Coulomb(0.5, dilatant=True), 100.0, 50.0)
    r = drive(m, [{"N": 1.0, "dt1": 0.0, "T2": 0.0, "steps": 4}, {"dt1": 0.1, "steps": 20}])
    assert isinstance(r, DriveResult) and len(r.kappa) == 25
    np.testing.assert_allclose(r.force[1:, 2], np.linspace(0.25, 1.0, 4).tolist() + [1.0] * 20, rtol=1e-10)
    np.testing.assert_allclose(r.force[1:, 1], 0.0, atol=1e-12)
    np.testing.assert_allclose(r.force[-1, 0], 0.5, rtol=1e-10)
    # dilatancy (1.6): opening equals mu times the tangential slip, on top of the elastic closure
    assert r.plastic[-1, 2] == pytest.approx(0.5 * r.kappa[-1], rel=1e-10)
    assert np.all(np.diff(r.work) >= -1e-14)


def test_force_controlled_shear_and_displacement_controlled_normal():
    m = ContactModel(EllipsoidCap(0.6), 100.0, 100.0)
    r = drive(m, [{"dn": -0.008, "dt1": 0.0, "dt2": 0.0, "steps": 4}, {"T1": 0.3, "T2": 0.1, "steps": 10}])
    np.testing.assert_allclose(r.force[-1, :2], [0.3, 0.1], rtol=1e-9)
    assert r.displacement[-1, 2] == pytest.approx(-0.008)


def test_path_from_segments_and_errors():
    p = Path.from_segments([{"N": 2.0, "dt1": 0.0, "steps": 2}, {"dt1": 1.0}])
    assert p.force_control.tolist() == [[False, False, True]] * 3
    np.testing.assert_allclose(p.values, [[0, 0, 2], [0, 0, 2], [1, 0, 2]])
    np.testing.assert_allclose(p.ramp, [0.5, 1, 1])
    np.testing.assert_array_equal(p.segment, [0, 0, 1])
    with pytest.raises(FrictionRulesError, match="unknown key"):
        Path.from_segments([{"X": 1.0}])
    with pytest.raises(FrictionRulesError, match="two targets"):
        Path.from_segments([{"N": 1.0, "dn": 0.0}])
    with pytest.raises(FrictionRulesError, match="steps"):
        Path.from_segments([{"N": 1.0, "steps": 0}])


def test_force_control_on_open_contact_closes_it():
    m = ContactModel(Coulomb(0.3), 100.0, 50.0)
    r = drive(m, [{"dn": 0.05, "steps": 1}, {"N": 0.5, "steps": 1}])
    assert r.status[1] == 2 and r.force[-1, 2] == pytest.approx(0.5)


def test_csv_and_hdf5_round_trip(tmp_path):
    m = ContactModel(Coulomb(0.5, dilatant=True), 100.0, 50.0)
    r = drive(m, [{"N": 1.0, "dt1": 0.0, "T2": 0.0, "steps": 4}, {"dt1": 0.1, "steps": 5}])
    r.write(tmp_path / "r.csv")
    data = np.genfromtxt(tmp_path / "r.csv", delimiter=",", names=True)
    assert data.dtype.names == WITHOUT_BETA     # Coulomb has no area fraction: no beta column
    np.testing.assert_allclose(data["T1"], r.force[:, 0], rtol=1e-15)
    r.write(tmp_path / "r.h5", attrs={"model": repr(m)})
    with h5py.File(tmp_path / "r.h5") as h5:
        np.testing.assert_array_equal(h5["kappa"][:], r.kappa)
        assert "Coulomb" in h5.attrs["model"] and h5["T1"].attrs["units"] == "force"
    r.to_csv(tmp_path / "r.txt")  # the explicit writers take any name
    np.testing.assert_allclose(np.genfromtxt(tmp_path / "r.txt", delimiter=",", names=True)["work"], r.work)
    with pytest.raises(FrictionRulesError, match="suffix"):
        r.write(tmp_path / "r.txt")


def test_read_csv_and_toml_paths(tmp_path):
    (tmp_path / "p.csv").write_text("N,dt1,T2\n0.5,0,0\n1.0,0,0\n1.0,0.05,0\n")
    p = read_path(tmp_path / "p.csv")
    assert p.force_control.tolist() == [[False, True, True]] * 3
    np.testing.assert_allclose(p.values[:, 0], [0, 0, 0.05])
    (tmp_path / "bad.csv").write_text("N,Q\n1,2\n")
    with pytest.raises(FrictionRulesError, match="unknown column"):
        read_path(tmp_path / "bad.csv")
    (tmp_path / "d.toml").write_text(TOML)
    model, path, opts = read_toml(tmp_path / "d.toml")
    assert model.law == Coulomb(0.5, dilatant=True) and len(path) == 24 and opts["beta"] == 0.4
    (tmp_path / "e.toml").write_text(TOML.replace('"Coulomb"', '"Nope"'))
    with pytest.raises(FrictionRulesError, match="type"):
        read_toml(tmp_path / "e.toml")


def test_cli_drive_writes_table_plot_and_progress(tmp_path, capsys):
    src = tmp_path / "d.toml"
    src.write_text(TOML.replace("steps = 20", "steps = 250"))
    rc = main(["drive", str(src), "--out", str(tmp_path / "o.csv"), "--plot", str(tmp_path / "o.png")])
    out, err = capsys.readouterr()
    assert rc == 0 and "254 steps" in out
    assert (tmp_path / "o.csv").exists() and (tmp_path / "o.png").stat().st_size > 1000
    # not a terminal: no progress frames, one summary line
    assert "\r" not in err and err.count("\n") == 1 and err.startswith("drive: 254/254 steps in ")
    assert "β" not in out  # Coulomb has no area fraction
    lines = (tmp_path / "o.csv").read_text().splitlines()
    assert lines[0] == ",".join(WITHOUT_BETA) and lines[1].startswith("# units: step=1, T1=force,")
    assert any(line.startswith("# command: frictionrules drive") for line in lines)
    assert main(["drive", str(tmp_path / "missing.toml")]) == 2


def test_cli_drive_quiet_and_cap_beta(tmp_path, capsys):
    src = tmp_path / "d.toml"
    src.write_text(TOML.replace('type = "Coulomb"\nmu = 0.5\ndilatant = true', 'type = "EllipsoidCap"\nm = 0.6'))
    assert main(["drive", str(src), "--quiet", "--out", str(tmp_path / "cap.csv")]) == 0
    out, err = capsys.readouterr()
    assert "β = " in out and err == ""
    assert (tmp_path / "cap.csv").read_text().splitlines()[0] == ",".join(COLUMNS)


def test_cli_drive_plot_has_a_panel_per_direction_under_the_law(tmp_path, monkeypatch):
    """A 45° path slides along T1 and T2 alike: the figure has the three panels T1–δt1,
    T2–δt2 and N–δn, under a title naming the law and the stiffnesses."""
    import matplotlib.pyplot as plt
    kept = {}
    monkeypatch.setattr(plt, "close", lambda fig: kept.setdefault("fig", fig))
    src = tmp_path / "d.toml"
    from test_cli_fuzz import DRIVE
    path45 = DRIVE.replace("dt1 = 0.05\nsteps = 3", "dt1 = 0.05\ndt2 = 0.05\nsteps = 10")
    assert path45 != DRIVE
    src.write_text(path45)
    assert main(["drive", str(src), "--plot", str(tmp_path / "p.png"), "--quiet"]) == 0
    fig = kept["fig"]
    axes = fig.axes
    assert [ax.get_ylabel() for ax in axes] == ["force $T_1$", "force $T_2$",
                                                 "force $N$ (compression > 0)"]
    title = fig.get_suptitle()
    assert "Coulomb(mu=0.5" in title and "kn = 100, kt = 100" in title
    T1, T2 = (ax.lines[0].get_ydata() for ax in axes[:2])
    np.testing.assert_allclose(T1, T2, atol=1e-12)        # the 45° path
    assert T2.max() == pytest.approx(0.5 / np.sqrt(2.0), rel=1e-6)   # mu N along 45°


def test_cli_drive_checks_outputs_before_the_run(tmp_path, capsys, monkeypatch):
    import frictionrules.contact.driver as driver

    def never(*args, **kwargs):
        raise AssertionError("the path was driven before the output was checked")
    monkeypatch.setattr(driver, "drive", never)
    src = tmp_path / "d.toml"
    src.write_text(TOML)
    for argv, message in ((["--out", str(tmp_path / "out.xyz")], "--out = "),
                          (["--out", str(tmp_path / "o.csv"), "--plot", str(tmp_path / "p.xyz")], "--plot = "),
                          (["--plot"], "--plot without FILE needs --out")):
        assert main(["drive", str(src), *argv]) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1
    src.write_text(TOML + '[output]\nfile = "r.txt"\n')
    assert main(["drive", str(src)]) == 2
    assert "[output] file = " in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]


def test_cli_drive_plot_goes_beside_the_table_not_the_toml(tmp_path, capsys, monkeypatch):
    (tmp_path / "inputs").mkdir()
    (tmp_path / "results").mkdir()
    src = tmp_path / "inputs" / "d.toml"
    src.write_text(TOML)
    monkeypatch.chdir(tmp_path)
    assert main(["drive", str(src), "--out", "results/s.json", "--plot", "--quiet"]) == 0
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == ["s.json", "s.png"]
    assert [p.name for p in (tmp_path / "inputs").iterdir()] == ["d.toml"]
    doc = json.loads((tmp_path / "results" / "s.json").read_text())
    assert doc["units"]["work"] == "force*length" and len(doc["columns"]["T1"]) == 25


@pytest.mark.parametrize("toml, message", [
    ("model = 3\n[[segment]]\nN = 1.0\n", "[model] = 3 violates: must be a table"),
    ("[model]\nkn = 1.0\nkt = 1.0\nlaw = 2\n[[segment]]\nN = 1.0\n", "[model.law] = 2"),
    (TOML + "[extra]\na = 1\n", "unknown tables ['extra']"),
    (TOML.replace("[[segment]]\nN = 1.0", "[[segment]]\nN = \"x\""), "segment 0: N"),
    (TOML + "[output]\nfile = 3\n", "[output] file = 3"),
    ("segment = [1, 2]\n" + TOML.split("[[segment]]")[0], "segment 0 = 1 violates"),
])
def test_malformed_drive_files_are_one_line(toml, message, tmp_path, capsys):
    src = tmp_path / "d.toml"
    src.write_text(toml)
    assert main(["drive", str(src)]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
