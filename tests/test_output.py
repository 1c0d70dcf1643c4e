"""The output layer (atomic, umask permissions, strict JSON, units and provenance, suffix
checks) and the progress reporter (a terminal gets frames, anything else one summary line)."""

import io
import json
import os
import stat

import h5py
import matplotlib.pyplot as plt
import numpy as np
import pytest

from frictionrules import FrictionRulesError, __version__
from frictionrules._output import (
    atomic_path, check_output, dumps_json, file_mode, provenance, strict_json, write_figure,
    write_json, write_table, write_text)
from frictionrules._progress import Progress


@pytest.fixture
def umask():
    """Set a umask for one test and restore the old one."""
    old = os.umask(0o022)
    os.umask(old)
    yield lambda mask: os.umask(mask)
    os.umask(old)


@pytest.mark.parametrize("mask", [0o022, 0o002, 0o077])
def test_files_get_the_permissions_of_the_umask(mask, umask, tmp_path):
    umask(mask)
    assert file_mode() == 0o666 & ~mask
    for path in (write_text(tmp_path / "a.txt", "x"),
                 write_table(tmp_path / "t.csv", {"a": [1.0]}, units={"a": "1"}),
                 write_table(tmp_path / "t.h5", {"a": [1.0]}, units={"a": "1"})):
        assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask


def test_atomic_write_leaves_nothing_behind_on_failure(tmp_path):
    with pytest.raises(RuntimeError):
        with atomic_path(tmp_path / "x.csv") as tmp:
            tmp.write_text("half")
            raise RuntimeError("interrupted")
    assert list(tmp_path.iterdir()) == []
    write_text(tmp_path / "x.csv", "whole")
    assert [p.name for p in tmp_path.iterdir()] == ["x.csv"]


def test_write_errors_name_the_target_not_the_temporary_file(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    for target in (blocker / "x.csv", "/proc/frictionrules-test/x.csv"):
        with pytest.raises(OSError) as err:
            write_text(target, "x")
        assert str(target) in str(err.value) and ".x.csv." not in str(err.value)


def test_check_output_before_the_work(tmp_path):
    assert check_output(tmp_path / "new" / "t.CSV", (".csv",)) == tmp_path / "new" / "t.CSV"
    with pytest.raises(FrictionRulesError, match=r"--out = '.*out.xyz' has suffix '.xyz'; "
                                                 r"constraint: one of .csv, .h5"):
        check_output(tmp_path / "out.xyz", (".csv", ".h5"))
    (tmp_path / "d.csv").mkdir()
    with pytest.raises(FrictionRulesError, match="is a folder"):
        check_output(tmp_path / "d.csv", (".csv",))
    (tmp_path / "f").write_text("")
    with pytest.raises(FrictionRulesError, match="--figure = .* not a writable folder"):
        check_output(tmp_path / "f" / "g.png", (".png",), name="--figure")
    assert not list((tmp_path).glob("new"))  # checking writes nothing


def test_strict_json_replaces_non_finite_numbers_by_null_and_lists_them():
    doc = {"mu": np.inf, "cols": {"a/b": [1.0, -np.inf, np.float64("nan")]}, "n": np.int64(3)}
    clean, bad = strict_json(doc)
    assert clean == {"mu": None, "cols": {"a/b": [1.0, None, None]}, "n": 3}
    assert bad == {"/mu": "inf", "/cols/a~1b/1": "-inf", "/cols/a~1b/2": "nan"}

    def refuse(token):
        raise AssertionError(f"non-standard JSON token {token}")
    out = json.loads(dumps_json(doc), parse_constant=refuse)
    assert out["non_finite"] == bad and out["mu"] is None
    assert json.loads(dumps_json({"x": 1.0}))["non_finite"] == {}


def test_tables_carry_units_and_provenance(tmp_path):
    meta = provenance(command="frictionrules test --x 1", model="Coulomb(mu=0.3)",
                      parameters={"mu": 0.3})
    assert meta["software"] == f"frictionrules {__version__}"
    cols = {"theta": np.array([0.0, 1.0]), "mu": np.array([0.3, np.inf]),
            "locked": np.array([False, True]), "count": np.array([1, 2]),
            "label": np.array(["a", "b+c"])}
    units = {"theta": "rad", "mu": "1", "locked": "1", "count": "1", "label": "-"}
    csv = write_table(tmp_path / "t.csv", cols, units=units, metadata=meta).read_text()
    lines = csv.splitlines()
    assert lines[0] == "theta,mu,locked,count,label"
    assert lines[1] == "# units: theta=rad, mu=1, locked=1, count=1, label=-"
    assert f"# software: frictionrules {__version__}" in lines
    assert '# parameters: {"mu": 0.3}' in lines and lines[-1] == "1.0,inf,1,2,b+c"
    data = np.genfromtxt(tmp_path / "t.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert data["mu"][1] == np.inf and list(data["label"]) == ["a", "b+c"]

    doc = json.loads(write_table(tmp_path / "t.json", cols, units=units, metadata=meta).read_text())
    assert doc["columns"]["mu"] == [0.3, None] and doc["non_finite"] == {"/columns/mu/1": "inf"}
    assert doc["columns"]["locked"] == [False, True] and doc["units"] == units
    assert doc["metadata"]["command"] == "frictionrules test --x 1"

    with h5py.File(write_table(tmp_path / "t.h5", cols, units=units, metadata=meta)) as h5:
        assert h5["mu"].attrs["units"] == "1" and h5["mu"][1] == np.inf
        assert h5.attrs["model"] == "Coulomb(mu=0.3)" and json.loads(h5.attrs["parameters"]) == {"mu": 0.3}
        assert [s.decode() for s in h5["label"][:]] == ["a", "b+c"]
    with pytest.raises(FrictionRulesError, match="suffix"):
        write_table(tmp_path / "t.txt", cols, units=units)
    with pytest.raises(ValueError, match="without units"):
        write_table(tmp_path / "u.csv", cols, units={"theta": "rad"})
    write_json(tmp_path / "d.json", {"a": np.nan})
    assert json.loads((tmp_path / "d.json").read_text()) == {"a": None, "non_finite": {"/a": "nan"}}


def test_figures_are_reproducible_and_carry_provenance(tmp_path):
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1], label="x")
    ax.legend()
    meta = provenance(command="frictionrules test")
    a = write_figure(fig, tmp_path / "a.svg", metadata=meta).read_bytes()
    b = write_figure(fig, tmp_path / "b.svg", metadata=meta).read_bytes()
    assert a == b and b"frictionrules test" in a
    png = write_figure(fig, tmp_path / "c.png", metadata=meta).read_bytes()
    assert png.startswith(b"\x89PNG") and b"frictionrules" in png
    with pytest.raises(FrictionRulesError, match="suffix '.xyz'"):
        write_figure(fig, tmp_path / "fig.xyz")
    plt.close(fig)
    assert not (tmp_path / "fig.xyz").exists()


# ---- progress --------------------------------------------------------------------------------
class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_off_a_terminal_is_one_summary_line():
    log = io.StringIO()
    with Progress("drive", 500, stream=log) as bar:
        for k in range(500):
            bar(k + 1, 500)
    text = log.getvalue()
    assert "\r" not in text and text.count("\n") == 1
    assert text.startswith("drive: 500/500 steps in ")


def test_progress_on_a_terminal_redraws_one_line():
    tty = Terminal()
    with Progress("configuration --polar", 4, unit="directions", stream=tty, interval=0.0) as bar:
        bar.phase("sweeping")
        for k in range(4):
            bar(k + 1)
    text = tty.getvalue()
    assert text.count("\r") >= 5 and text.endswith("\n") and text.count("\n") == 1
    assert "[" + "#" * 30 + "] 4/4" in text and "4/4 directions in" in text.splitlines()[-1]


def test_progress_is_silent_on_failure_and_when_disabled():
    for stream in (io.StringIO(), Terminal()):
        with pytest.raises(RuntimeError), Progress("x", 10, stream=stream, interval=0.0) as bar:
            bar(3)
            raise RuntimeError
        assert "x: 3/10" not in stream.getvalue().replace("\r", "\n").splitlines()[-1:]
        assert stream.getvalue().count("\n") == 0
    quiet = Terminal()
    with Progress("x", 10, stream=quiet, enabled=False) as bar:
        bar(10)
    assert quiet.getvalue() == ""
