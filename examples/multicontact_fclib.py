"""Read an FCLIB problem and solve it with every method (Siconos' error measure)."""

from __future__ import annotations

import os
from pathlib import Path

from frictionrules import read_fclib, solve


def default_file() -> Path:
    root = Path(__file__).resolve().parents[2] / "shared" / "fclib"
    root = root if root.is_dir() else Path(os.environ.get("FRICTIONRULES_FCLIB", root))
    return root / "Capsules-i125-1213.hdf5"


def main(path=None) -> dict:
    problem = read_fclib(path or default_file())
    print(problem)
    errors = {}
    for method in ("nsgs", "newton", "prox"):
        s = solve(problem, method=method, tol=1e-8)
        errors[method] = s.error
        print(f"{method:6s} iterations {s.iterations:5d} error {s.error:.2e} time {s.seconds:.3f} s")
    return errors


if __name__ == "__main__":
    main()
