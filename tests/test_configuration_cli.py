"""``frictionrules configuration``: options or TOML in, CSV/JSON and a figure out."""

import json

import numpy as np
import pytest

from frictionrules.cli import main


def test_straight_path_csv_and_figure(tmp_path, capsys):
    out, fig = tmp_path / "t.csv", tmp_path / "f.png"
    rc = main(["configuration", "--grain", "cylinder", "--mu", "0.3", "--length", "0.5",
               "--steps", "11", "--out", str(out), "--figure", str(fig)])
    assert rc == 0
    data = np.genfromtxt(out, delimiter=",", names=True)
    assert data["Tx"][0] == pytest.approx(np.tan(np.pi / 6 + np.arctan(0.3)))
    assert data["Tx"][-1] == pytest.approx(0.3)
    assert fig.stat().st_size > 1000
    assert "start 1.0611" in capsys.readouterr().out


def test_toml_polyline_json(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('grain = "sphere"\npacking = "hexagonal"\nmu = 0.3\nmethod = "incremental"\n'
                   'path = [[0.0, 0.0], [0.1, 0.0], [0.2, 0.05]]\n')
    out = tmp_path / "t.json"
    assert main(["configuration", "--config", str(cfg), "--out", str(out)]) == 0
    table = json.loads(out.read_text())
    assert len(table["columns"]["Tx"]) == 3 and table["columns"]["contacts"] == [1, 1, 1]
    assert table["units"]["Tx"] == "force" and table["units"]["alpha"] == "rad"
    assert "SphereOnLayer" in table["metadata"]["model"]
    assert table["metadata"]["command"].startswith("frictionrules configuration --config")


def test_polar_mode(tmp_path, capsys):
    out = tmp_path / "p.csv"
    assert main(["configuration", "--grain", "sphere", "--packing", "square", "--polar", "8",
                 "--deg", "--out", str(out)]) == 0
    data = np.genfromtxt(out, delimiter=",", names=True)
    assert list(data["contacts"][:2]) == [2, 1]
    assert data["peak"][1] == pytest.approx((1 + 0.3) / (1 - 0.3))
    assert data["direction"][1] == pytest.approx(45.0)


@pytest.mark.parametrize("argv, text", [
    (["--mu", "-1"], "mu"),
    (["--grain", "cylinder", "--packing", "square"], "packing"),
    (["--path", "0,0;x"], "--path"),
    (["--path", "0,0"], "at least two points"),
    (["--polar", "0"], "argument --polar: 0 violates: must be an integer >= 1 and <= 1000000"),
    (["--polar", "-3"], "argument --polar: -3 violates: must be an integer >= 1"),
    (["--mu", "inf"], "argument --mu: 'inf' violates: must be a finite number"),
])
def test_bad_input_exits_2(argv, text, capsys):
    assert main(["configuration", *argv]) == 2
    err = capsys.readouterr().err
    assert text in err and len(err.strip().splitlines()) == 1


def test_bad_toml(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text('colour = "red"\n')
    assert main(["configuration", "--config", str(cfg)]) == 2
    assert "unknown keys" in capsys.readouterr().err


@pytest.mark.parametrize("toml, text", [
    ("polar = 0\n", "polar = 0 violates 1 <= polar <= 1000000"),
    ("steps = 10000000\n", "steps = 10000000 violates 1 <= steps <= 1000000"),
    ("polar = true\n", "polar = True violates: must be int"),
    ("mu = nan\n", "mu = nan violates: must be finite"),
    ('path = [[0.0, 0.0], "x"]\n', "path = [[0.0, 0.0], 'x'] violates"),
])
def test_bad_toml_values(toml, text, tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text(toml)
    assert main(["configuration", "--config", str(cfg)]) == 2
    assert text in capsys.readouterr().err


def test_polar_sweep_reports_jammed_directions(tmp_path, capsys):
    """A cylinder with mu = 2 jams for forces pointing into the layer: those directions are
    flagged in the table (peak = inf, strict JSON null), the others computed."""
    out = tmp_path / "p.json"
    assert main(["configuration", "--grain", "cylinder", "--mu", "2", "--polar", "24", "--deg",
                 "--out", str(out), "--figure", str(tmp_path / "p.svg")]) == 0
    text = capsys.readouterr().out
    assert "jammed (no mechanism starts) in 6 of 24 directions" in text
    doc = json.loads(out.read_text(), parse_constant=lambda c: pytest.fail(f"JSON token {c}"))
    cols = doc["columns"]
    jammed = np.array(cols["jammed"])
    assert jammed.sum() == 6 and doc["units"]["direction"] == "deg" and doc["units"]["jammed"] == "1"
    assert all(cols["peak"][i] is None for i in np.flatnonzero(jammed))
    assert all(cols["peak"][i] > 0 for i in np.flatnonzero(~jammed))
    assert {f"/columns/peak/{i}" for i in np.flatnonzero(jammed)} <= set(doc["non_finite"])
    assert cols["direction"][1] == pytest.approx(15.0)
    assert (tmp_path / "p.svg").stat().st_size > 1000


def test_degrees_everywhere_with_deg(tmp_path):
    base = ["configuration", "--grain", "sphere", "--packing", "hexagonal", "--steps", "5",
            "--length", "0.3"]
    assert main([*base, "--direction", "30", "--deg", "--out", str(tmp_path / "d.json")]) == 0
    assert main([*base, "--direction", str(np.pi / 6), "--out", str(tmp_path / "r.json")]) == 0
    deg, rad = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("d", "r"))
    assert deg["units"]["alpha"] == "deg" and rad["units"]["alpha"] == "rad"
    for key in ("alpha", "psi"):
        np.testing.assert_allclose(deg["columns"][key], np.rad2deg(rad["columns"][key]))
    assert main([*base, "--deg", "--out", str(tmp_path / "d.csv")]) == 0
    lines = (tmp_path / "d.csv").read_text().splitlines()
    assert lines[1].startswith("# units: distance=length,") and "alpha=deg, psi=deg" in lines[1]


@pytest.mark.parametrize("flag, name", [("--figure", "fig.xyz"), ("--out", "table.txt")])
def test_output_suffix_is_checked_before_the_work(flag, name, tmp_path, capsys, monkeypatch):
    import frictionrules.cli.configuration as cli

    def never(*args, **kwargs):
        raise AssertionError("the model was built before the output was checked")
    monkeypatch.setattr(cli, "build_model", never)
    assert main(["configuration", flag, str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert f"{flag} = " in err and "suffix" in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())
