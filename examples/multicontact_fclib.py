"""Read an FCLIB problem and solve it with every method (Siconos' error measure).

Run: ``python examples/multicontact_fclib.py`` (prints the results and saves the
figure in the current folder).
"""

from __future__ import annotations

import os
from pathlib import Path

from frictionrules import read_fclib, solve


def default_file() -> Path:
    root = Path(__file__).resolve().parents[2] / "shared" / "fclib"
    root = root if root.is_dir() else Path(os.environ.get("FRICTIONRULES_FCLIB", root))
    return root / "Capsules-i125-1213.hdf5"


def main(path=None, out_dir=None) -> dict:
    """Print each method's iterations and error; with ``out_dir``, save their error histories."""
    problem = read_fclib(path or default_file())
    print(problem)
    errors, history = {}, {}
    for method in ("nsgs", "newton", "prox"):
        trace = []
        s = solve(problem, method=method, tol=1e-8,
                  callback=lambda info, trace=trace: trace.append((info.iteration, info.error)))
        errors[method], history[method] = s.error, trace
        print(f"{method:6s} iterations {s.iterations:5d} error {s.error:.2e} time {s.seconds:.3f} s")
    if out_dir is not None:
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6.0, 4.0))
        for method, trace in history.items():
            ax.semilogy(*zip(*trace), label=method)
        ax.axhline(1e-8, color="k", ls=":", lw=0.8, label="tolerance 1e-8")
        ax.set_xscale("log")
        ax.set_xlabel("iteration")
        ax.set_ylabel("error (Siconos' measure)")
        ax.set_title(f"{problem.title or 'FCLIB problem'}: {problem.nc} contacts", fontsize=9)
        ax.legend(fontsize=8)
        path = Path(out_dir) / "multicontact_fclib.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {path}")
    return errors


if __name__ == "__main__":
    main(out_dir=".")
