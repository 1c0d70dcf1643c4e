"""The summary table of ``benchmarks/fclib.py`` (``benchmarks/_fclib_report.py``)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

HEADER = "file,contacts,nnz,target,solver,iterations,error,reached,cpu_median,cpu_min,cpu_max,repeats,peak_mb,info"


def _report():
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "_fclib_report.py"
    spec = importlib.util.spec_from_file_location("_fclib_report", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _row(table: str, file: str) -> str:
    return next(line for line in table.splitlines() if line.startswith(f"| {file} |"))


def test_a_target_nobody_reached_names_the_lowest_error_and_never_a_missing_one():
    rows = [HEADER,
            "pile.hdf5,3970,296964,1e-08,siconos-NSGS,0,nan,0,inf,inf,inf,1,nan,timeout",
            "pile.hdf5,3970,296964,1e-08,pinocchio-ADMM,0,nan,0,inf,inf,inf,1,nan,crash",
            "pile.hdf5,3970,296964,1e-08,nsgs,19607,1.3e-04,0,15.1,15.1,15.1,1,186,nsgs",
            "pile.hdf5,3970,296964,1e-08,admm,5000,2.0e-04,0,15.2,15.2,15.2,1,229,admm",
            "box.hdf5,1264,90000,1e-08,siconos-ADMM,9000,4.0e-07,0,15.0,15.0,15.0,1,64,timeout",
            "box.hdf5,1264,90000,1e-08,siconos-NSGS,0,nan,0,inf,inf,inf,1,nan,timeout",
            "box.hdf5,1264,90000,1e-08,admm,20000,2.3e-08,0,5.1,5.1,5.1,1,195,admm"]
    table = _report().summary(rows)
    pile = _row(table, "pile")
    assert "not reached (no error reported: crash, timeout)" in pile and "nan" not in pile
    assert "not reached (best nsgs 1.3e-04)" in pile
    box = _row(table, "box")
    assert "not reached (best siconos-ADMM 4.0e-07)" in box and "not reached (best admm 2.3e-08)" in box
