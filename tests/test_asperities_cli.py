"""``frictionrules asperity``: options, TOML, outputs (strict JSON, units) and one-line errors."""

import json
import os

import numpy as np
import pytest

from frictionrules.cli import main


def test_two_flank_options_write_table_and_figure(tmp_path, capsys):
    out = tmp_path / "fig5"
    assert main(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--n", "180",
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "concave: 4" in text and "226.669" in text
    rows = (out / "limit_curve.csv").read_text().splitlines()
    assert rows[0].startswith("direction,Tx,Ty,load,locked,mechanism")
    assert rows[1].startswith("# units: direction=rad, Tx=force")
    data = np.loadtxt(out / "mu_theta.csv", delimiter=",", comments="#", skiprows=1)
    assert data.shape == (180, 3)
    locked = data[:, 2] == 1
    assert np.all(np.isinf(data[locked, 1])) and np.all(np.isfinite(data[~locked, 1]))
    assert locked.sum() == 71          # Fig. 5's groove locks near +x (141 of 360)
    assert (out / "limit_curve.png").stat().st_size > 1000
    corners = [r for r in (out / "corners.csv").read_text().splitlines() if r[0] != "#"]
    assert corners[0] == "Tx,Ty,direction,before,after,interior,concave" and len(corners) == 5


def test_written_files_have_the_umask_permissions(tmp_path):
    old = os.umask(0o022)
    try:
        assert main(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--n", "8",
                     "--no-figure", "--out", str(tmp_path / "o")]) == 0
    finally:
        os.umask(old)
    assert (tmp_path / "o" / "mu_theta.csv").stat().st_mode & 0o777 == 0o644


def test_json_is_strict_and_locked_values_are_flagged(tmp_path):
    """No Infinity/NaN tokens; a locked mu is null with locked = true beside it."""
    out = tmp_path / "j"
    assert main(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--n", "36",
                 "--format", "json", "--no-figure", "--out", str(out)]) == 0
    for name in ("limit_curve", "mu_theta", "corners"):
        text = (out / f"{name}.json").read_text()
        assert "Infinity" not in text and "NaN" not in text
        json.loads(text, parse_constant=lambda c: pytest.fail(f"{name}: non-strict {c}"))
    doc = json.loads((out / "mu_theta.json").read_text())
    mu, locked = doc["columns"]["mu"], doc["columns"]["locked"]
    assert all((m is None) == flag for m, flag in zip(mu, locked)) and any(locked)
    assert doc["units"]["mu"] == "1" and doc["units"]["theta"] == "rad"
    assert doc["metadata"]["software"].startswith("frictionrules")


def test_toml_config_and_json(tmp_path, capsys):
    conf = tmp_path / "g.toml"
    conf.write_text('geometry = "two-flank"\nalpha1 = 60\nalpha2 = 150\ndeg = true\nmu = 0.5\n'
                    'local = "associated"\n')
    out = tmp_path / "o"
    assert main(["asperity", "--config", str(conf), "--format", "json", "--no-figure", "--n",
                 "90", "--out", str(out)]) == 0
    data = json.loads((out / "limit_curve.json").read_text())
    assert len(data["columns"]["direction"]) == 90
    assert not any(json.loads((out / "corners.json").read_text())["columns"]["concave"])
    assert "concave: 0" in capsys.readouterr().out


def test_profile_with_header_and_heightmap_files(tmp_path, capsys):
    x = np.linspace(0, 4, 9)
    prof = tmp_path / "p.csv"
    prof.write_text("x,z\n" + "\n".join(f"{a},{b}" for a, b in zip(x, 0.4 * (np.arange(9) % 2))))
    assert main(["asperity", "--profile", str(prof), "--mu", "0.3", "--n", "36"]) == 0
    assert "max 1.44737" in capsys.readouterr().out          # tan(atan 0.8 + atan 0.3)
    swapped = tmp_path / "q.csv"                               # columns taken by name
    swapped.write_text("z,x\n" + "\n".join(f"{b},{a}" for a, b in zip(x, 0.4 * (np.arange(9) % 2))))
    assert main(["asperity", "--profile", str(swapped), "--mu", "0.3", "--n", "36"]) == 0
    assert "max 1.44737" in capsys.readouterr().out
    hm = tmp_path / "h.npy"
    np.save(hm, np.add.outer(np.zeros(16), 0.3 * (np.arange(16) % 2)))
    assert main(["asperity", "--heightmap", str(hm), "--dx", "0.5", "--mu", "0.3", "--n",
                 "36"]) == 0


def test_nothing_is_written_without_out(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--n", "8"]) == 0
    assert list(tmp_path.iterdir()) == []


def test_v_profile_has_no_spurious_corners(tmp_path, capsys):
    """A V of 11 points: 4 corners of the groove, none of 180.000 deg between facets that
    differ by round-off."""
    x = np.linspace(0.0, 1.0, 11)
    prof = tmp_path / "v.csv"
    np.savetxt(prof, np.stack((x, np.abs(x - 0.5)), -1), delimiter=",")
    assert main(["asperity", "--profile", str(prof), "--mu", "0.3"]) == 0
    out = capsys.readouterr().out
    assert "2 facet(s)" in out and "corners: 4" in out and "180.000" not in out


def test_negative_numbers_are_values(tmp_path, capsys):
    assert main(["asperity", "--normals", "-0.5,0,0.866;0.5,0,0.866", "--mu", "0.4",
                 "--n", "36"]) == 0
    assert "2 facet(s)" in capsys.readouterr().out
    hm = tmp_path / "h.npy"
    np.save(hm, np.zeros((4, 4)))
    assert main(["asperity", "--heightmap", str(hm), "--dx", "-1e-6", "--mu", "0.3"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "dx = -1e-06 violates dx > 0" in err


def one_line_error(argv, capsys, *needles):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("frictionrules asperity: error:"), err
    for needle in needles:
        assert needle in err, err
    return err


@pytest.mark.parametrize("n", ["0", "-5", "2"])
def test_bad_number_of_directions(n, capsys):
    one_line_error(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1", "--n", n],
                   capsys, "n", n)


def test_bad_files_give_one_line(tmp_path, capsys):
    garbage = tmp_path / "garbage.npy"
    garbage.write_bytes(b"not numpy at all")
    one_line_error(["asperity", "--heightmap", str(garbage), "--mu", "0.3"], capsys, "garbage.npy")
    pickled = tmp_path / "pickled.npy"
    np.save(pickled, np.array([{"a": 1}], dtype=object), allow_pickle=True)
    one_line_error(["asperity", "--heightmap", str(pickled), "--mu", "0.3"], capsys,
                   "object arrays are not read")
    text = tmp_path / "t.csv"
    text.write_text("x,z\n0,0\n1,abc\n")
    one_line_error(["asperity", "--profile", str(text), "--mu", "0.3"], capsys, "line 3")
    one_line_error(["asperity", "--profile", str(tmp_path / "missing.csv"), "--mu", "1"], capsys,
                   "missing.csv")


def test_toml_missing_or_extra_keys_are_named(tmp_path, capsys):
    missing = tmp_path / "m.toml"
    missing.write_text('geometry = "two-flank"\nalpha1 = 60\ndeg = true\nmu = 0.5\n')
    one_line_error(["asperity", "--config", str(missing)], capsys, "alpha2")
    extra = tmp_path / "e.toml"
    extra.write_text('geometry = "two-flank"\nalpha1 = 60\nalpha2 = 150\ndeg = true\nmu = 0.5\n'
                     'alpha3 = 1\n')
    one_line_error(["asperity", "--config", str(extra)], capsys, "alpha3")
    wrong = tmp_path / "w.toml"
    wrong.write_text('geometry = "two-flank"\nalpha1 = "sixty"\nalpha2 = 150\nmu = 0.5\n')
    one_line_error(["asperity", "--config", str(wrong)], capsys, "alpha1 = 'sixty'")


def test_outputs_are_checked_before_the_work(tmp_path, capsys):
    one_line_error(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1",
                    "--out", str(tmp_path / "res.png")], capsys, "--out")
    afile = tmp_path / "afile"
    afile.write_text("")
    one_line_error(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1",
                    "--out", str(afile)], capsys, "--out")


def test_errors_exit_2(tmp_path, capsys):
    one_line_error(["asperity", "--mu", "1"], capsys, "geometry")
    one_line_error(["asperity", "--two-flank", "60", "150", "--deg"], capsys, "mu missing")
    one_line_error(["asperity", "--two-flank", "100", "150", "--deg", "--mu", "1"], capsys,
                   "alpha1")
    one_line_error(["asperity", "--two-flank", "60", "150", "--normals", "0,0,1", "--mu", "1"],
                   capsys, "only one")
