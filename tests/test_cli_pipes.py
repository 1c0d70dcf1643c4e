"""Every command ends quietly when the reader of its output closes the pipe (``| head``): no
error line, its own exit code (never the bad-input code 2), the files it writes still written.

The reader's end is closed before the command starts, so that every write meets a closed pipe
(EPIPE) whatever the speed of the machine; ``test_reader_reads_one_line_then_leaves`` is the
``| head -1`` of a shell, where the command may or may not have more to write when it leaves.
"""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

import pytest

from test_io import FCLIB, needs_fclib
from test_topography_files import shared

COMMAND = [sys.executable, "-m", "frictionrules"]


def run_with_closed_reader(argv, cwd=None):
    """Run ``frictionrules argv`` with standard output a pipe whose reader has already left;
    returns (exit code, standard error)."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        res = subprocess.run(COMMAND + argv, stdout=write_end, stderr=subprocess.PIPE, text=True,
                             cwd=cwd, timeout=600)
    finally:
        os.close(write_end)
    return res.returncode, res.stderr


@pytest.mark.parametrize("argv", [
    ["law", "coulomb", "--mu", "0.3", "--force", "0.1", "0.2", "--normal", "1"],
    ["law", "elliptic", "--mu-x", "0.6", "--mu-y", "0.3", "--force", "0.3", "0.2", "--normal", "1",
     "--json"],
    ["paper", "--list"],
    ["--help"],
    ["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1"],
])
def test_closed_pipe_is_not_an_error(argv):
    code, err = run_with_closed_reader(argv)
    assert code == 0, err
    assert "error" not in err.lower() and "Traceback" not in err and "pipe" not in err.lower()


def test_closed_pipe_keeps_the_files(tmp_path):
    """A command that writes files still writes them all when nobody reads what it prints."""
    code, err = run_with_closed_reader(["asperity", "--two-flank", "60", "150", "--deg", "--mu", "1",
                                        "--format", "json", "--out", str(tmp_path / "a")])
    assert code == 0 and "error" not in err.lower()
    assert (tmp_path / "a" / "limit_curve.json").stat().st_size > 100
    assert (tmp_path / "a" / "limit_curve.png").stat().st_size > 1000


def test_reader_reads_one_line_then_leaves():
    """``frictionrules paper --list | head -1``."""
    proc = subprocess.Popen(COMMAND + ["paper", "--list"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    first = proc.stdout.readline()
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == 0 and err == ""
    assert first.startswith("paper/fig1a")


@needs_fclib
def test_folder_solve_keeps_going_to_its_csv(tmp_path):
    """``solve FOLDER --time-limit 2 --csv pipe.csv | head -1``: the whole folder is solved and
    tabulated. The folder holds the shared FCLIB problems that solve in well under a second."""
    names = ["CubeH8.hdf5", "LMGC_GlobalFrictionContactProblem00046.hdf5",
             "Box_Stacks-i0122-82-5.hdf5", "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5"]
    folder = tmp_path / "fclib"
    folder.mkdir()
    for name in names:
        (folder / name).symlink_to(FCLIB / name)
    code, err = run_with_closed_reader(["solve", str(folder), "--time-limit", "2", "--csv",
                                        "pipe.csv"], cwd=tmp_path)
    assert code == 0, err
    assert "error" not in err and "Broken pipe" not in err
    with open(tmp_path / "pipe.csv") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    assert sorted(r["file"] for r in rows) == sorted(names)
    assert all(r["converged"] == "1" for r in rows)


def test_measured_surface_to_a_closed_pipe(tmp_path):
    """``asperity FILE --mu 0.3 | head -1`` on a measured surface."""
    code, err = run_with_closed_reader(["asperity", str(shared("opdx-3.opdx")), "--mu", "0.3",
                                        "--quiet"])
    assert code == 0
    assert "error" not in err.lower()


def test_stream_errors_other_than_a_closed_pipe_still_raise():
    """Only EPIPE is the reader leaving; another failure of the stream is not hidden."""
    from frictionrules.cli._streams import _PipeTolerantStream

    class Full:
        def write(self, text):
            raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space"):
        _PipeTolerantStream(Full()).write("x")


def test_bad_input_into_a_closed_pipe_still_exits_2():
    code, err = run_with_closed_reader(["law", "coulomb", "--mu", "-1", "--force", "0", "0",
                                        "--normal", "1"])
    assert code == 2 and "mu = -1.0 violates" in err


def test_documented():
    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    assert "closes the pipe" in text
