"""Benchmark (a measurement, not of speed): the bottom of W's spectrum on the FCLIB piles, and
q's components along it.

Usage (one command, from the repository root)::

    python benchmarks/fclib_spectrum.py [FILE.hdf5 ...] [--fractions 1e-10,1e-8,1e-6]

For each file (by default the three piles: ``../shared/fclib/SpheresPile-nc1812.hdf5`` and the
two of ``../shared/fclib-large``): the eigenpairs of a symmetric W below 1e-4 of its largest
eigenvalue (LAPACK's ``evr`` on the dense matrix: 4 minutes and 3 GB at 11,910 unknowns), or
every singular triple of a nonsymmetric one (its left singular vectors: u = W r + q moves in
their span). The null space is taken below 1e-12 of the largest value. The table gives its
dimension and q's projection on it, and, for each fraction, the directions beyond it below
that fraction of the largest value, with the norm of q's projection on them. The reactions
that would hold such a component with every contact sticking grow as the component over the
value; docs/multicontact.md ("The bottom of W's spectrum on the piles") reads the table. Writes
``benchmarks/results/fclib_spectrum.md``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "benchmarks"))

#: Below this fraction of the largest value: the null space.
NULL = 1e-12
#: Eigenpairs of a symmetric W computed: those below this fraction of the largest.
BOTTOM = 1e-4
#: Largest nonsymmetric W decomposed (a full SVD: a minute at 3,792 unknowns, cubic beyond).
SVD_MAX_UNKNOWNS = 6000


def symmetric(W) -> bool:
    return W.nnz == 0 or abs(W - W.T).max() <= 1e-12 * abs(W).max()


def bottom(W, sym: bool):
    """``(values, vectors, largest, kind)``: the bottom of the spectrum of the sparse ``W``
    (``sym``: whether it is symmetric). ``values`` are magnitudes (a null eigenvalue comes out
    of ``eigh`` as a round-off of either sign), not sorted; ``vectors`` their columns."""
    import scipy.linalg as sl
    import scipy.sparse.linalg as spla
    if sym:
        half = (W + W.T) * 0.5
        largest = float(spla.eigsh(half, k=1, which="LA")[0][0])
        values, vectors = sl.eigh(half.toarray(), subset_by_value=[-np.inf, BOTTOM * largest], driver="evr",
                                  overwrite_a=True)
        return np.abs(values), vectors, largest, "eigenvalues"
    U, s, _ = sl.svd(W.toarray(), overwrite_a=True)
    return s[::-1], U[:, ::-1], float(s[0]), "singular values"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*")
    ap.add_argument("--fractions", default="1e-10,1e-8,1e-6")
    args = ap.parse_args(argv)
    from _table import write_table
    from frictionrules import read_fclib
    fractions = [float(x) for x in args.fractions.split(",")]
    if any(not NULL < f <= BOTTOM for f in fractions):
        ap.error(f"--fractions: each in ({NULL:g}, {BOTTOM:g}]")
    shared = ROOT.parent / "shared"
    files = [Path(f) for f in args.files] or [shared / "fclib" / "SpheresPile-nc1812.hdf5",
                                               shared / "fclib-large" / "SpheresPile-nc3970.hdf5",
                                               shared / "fclib-large" / "BoxesPile-nc1264.hdf5"]
    rows = []
    for f in files:
        if not f.is_file():
            print(f"{f}: not found, skipped", flush=True)
            continue
        p = read_fclib(f)
        W = p.W.tocsr()
        sym = symmetric(W)
        if not sym and W.shape[0] > SVD_MAX_UNKNOWNS:
            print(f"{f.name}: nonsymmetric with {W.shape[0]} unknowns (> {SVD_MAX_UNKNOWNS}), skipped", flush=True)
            continue
        t0 = time.perf_counter()
        values, vectors, largest, kind = bottom(W, sym)
        q = p.q
        null = values < NULL * largest
        row = [f.stem, W.shape[0], kind, f"{largest:.3g}", f"{np.linalg.norm(q):.3g}", int(null.sum()),
               f"{np.linalg.norm(vectors[:, null].T @ q):.1e}"]
        for frac in fractions:
            sel = ~null & (values < frac * largest)
            row.append(f"{int(sel.sum())}, {np.linalg.norm(vectors[:, sel].T @ q):.1e}" if sel.any() else "0")
        row.append(f"{time.perf_counter() - t0:.0f}")
        rows.append(row)
        print(" | ".join(str(x) for x in row), flush=True)
    write_table("fclib_spectrum", "The bottom of W's spectrum, and q along it",
                ["file", "unknowns", "of", "largest", "|q|", "null space (< 1e-12)", "|q| on it"]
                + [f"beyond it, < {f:g}: count, |q| on them" for f in fractions] + ["s"], rows,
                notes="Fractions of the largest value. The eigenvectors are orthonormal, so q's "
                      "projection on them has the norm of its coordinates.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
