"""``frictionrules asperity``: options, TOML, outputs and errors."""

import json

import numpy as np

from frictionrules.cli import main


def test_two_flank_options_write_table_and_figure(tmp_path, capsys):
    out = tmp_path / "fig5"
    assert main(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--n", "180",
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "concave: 4" in text and "226.669" in text
    rows = (out / "limit_curve.csv").read_text().splitlines()
    assert rows[0].startswith("direction,Tx,Ty,load,mechanism")
    assert len(rows) == 181
    assert (out / "limit_curve.png").stat().st_size > 1000
    mu = np.loadtxt(out / "mu_theta.csv", delimiter=",", skiprows=1)
    assert mu.shape == (180, 2)


def test_toml_config_and_json(tmp_path, capsys):
    conf = tmp_path / "g.toml"
    conf.write_text('geometry = "two-flank"\nalpha1 = 60\nalpha2 = 150\ndeg = true\nmu = 0.5\n'
                    'local = "associated"\n')
    out = tmp_path / "o"
    assert main(["asperity", "--config", str(conf), "--format", "json", "--no-figure", "--n", "90",
                 "--out", str(out)]) == 0
    data = json.loads((out / "limit_curve.json").read_text())
    assert len(data["rows"]) == 90 and not any(c["concave"] for c in data["corners"])
    assert "concave: 0" in capsys.readouterr().out


def test_profile_and_heightmap_files(tmp_path):
    x = np.linspace(0, 4, 9)
    prof = tmp_path / "p.csv"
    np.savetxt(prof, np.stack((x, 0.4 * (np.arange(9) % 2)), -1), delimiter=",")
    assert main(["asperity", "--profile", str(prof), "--mu", "0.3", "--no-figure", "--n", "36",
                 "--out", str(tmp_path / "a")]) == 0
    hm = tmp_path / "h.npy"
    np.save(hm, np.add.outer(np.zeros(16), 0.3 * (np.arange(16) % 2)))
    assert main(["asperity", "--heightmap", str(hm), "--dx", "0.5", "--mu", "0.3", "--no-figure",
                 "--n", "36", "--out", str(tmp_path / "b")]) == 0


def test_errors_exit_2(tmp_path, capsys):
    assert main(["asperity", "--mu", "1", "--out", str(tmp_path)]) == 2
    assert "geometry" in capsys.readouterr().err
    assert main(["asperity", "--two-flank", "60", "150", "--deg", "--out", str(tmp_path)]) == 2
    assert "mu is missing" in capsys.readouterr().err
    assert main(["asperity", "--two-flank", "100", "150", "--deg", "--mu", "1",
                 "--out", str(tmp_path)]) == 2
    assert "alpha1" in capsys.readouterr().err
    assert main(["asperity", "--profile", str(tmp_path / "missing.csv"), "--mu", "1",
                 "--out", str(tmp_path)]) == 2
