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
    assert len(table["Tx"]) == 3 and table["contacts"] == [1, 1, 1]


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
])
def test_bad_input_exits_2(argv, text, capsys):
    assert main(["configuration", *argv]) == 2
    assert text in capsys.readouterr().err


def test_bad_toml(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text('colour = "red"\n')
    assert main(["configuration", "--config", str(cfg)]) == 2
    assert "unknown keys" in capsys.readouterr().err
