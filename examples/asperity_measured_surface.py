"""Measured surfaces -> friction laws at a stated scale: the instrument files of ../shared.

Reads an AFM map (Bruker .di), an X3P map of a machined surface and a stylus profile (Bruker
.opdx) with SurfaceTopography (``pip install "frictionrules[surfaces]"``), turns each into the
law of a rigid block on its facets (local mu = 0.3) at the default scale (the ISO Gaussian
cut-off five pixels long, mean plane removed), prints a table per file, and draws the scale
study of the X3P map (mu(theta) against the cut-off) and its mu(theta) at two scales.

Run: ``python examples/asperity_measured_surface.py`` (prints the results and saves the
figure in the current folder).
"""

import os
import time
import warnings
from pathlib import Path

import numpy as np

from frictionrules import from_topography, read_surface, scale_study

SURFACES = Path(__file__).resolve().parents[1].parent / "shared" / "surfaces"
if not SURFACES.is_dir():
    SURFACES = Path(os.environ.get("FRICTIONRULES_SURFACES", SURFACES))
FILES = ("di-1.di", "x3p-2.x3p", "opdx-3.opdx")
MU = 0.3


def table(files=FILES, folder=SURFACES):
    """One row per file: scale, mu(theta) range, anisotropy, locked directions, time."""
    rows = []
    for name in files:
        start = time.perf_counter()
        topo = read_surface(folder / name)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            r = from_topography(topo, MU)
        seconds = time.perf_counter() - start
        rows.append(dict(file=name, result=r, seconds=seconds, warned=bool(caught)))
        lo, hi = r.mu_range
        print(f"{name:12s} scale {r.scale:.4g} {r.unit:2s}  mu(theta) {lo:.4f} .. {hi:.4f}  "
              f"bound {r.upper_bound:.4f}  anisotropy {r.anisotropy:.3f}  "
              f"locked {int(r.locked.sum())}/{len(r.mu)}  {seconds:.1f} s"
              f"{'  (few pixels carry it)' if r.carried_by_few else ''}")
    return rows


def figures(name="x3p-2.x3p", folder=SURFACES, out="."):
    """The scale study of one file and its mu(theta) at the default and a larger scale."""
    import matplotlib.pyplot as plt

    topo = read_surface(folder / name)
    px = max(topo.pixel_size)
    study = scale_study(topo, MU, scales=px * np.array([2, 5, 10, 20, 50, 100]), n=120)
    ax = study.plot()
    ax.set_title(f"{name}: mu(theta) against the smoothing scale (local mu = {MU})", fontsize=9)
    path = Path(out) / "measured_surface_scale_study.png"
    ax.figure.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(ax.figure)
    print(f"wrote {path}")
    fig, ax = plt.subplots(figsize=(6.0, 3.6))
    for k, style in ((5, "k-"), (50, "k--")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            r = from_topography(topo, MU, scale=k * px, n=360)
        ax.plot(np.rad2deg(r.theta), r.mu, style,
                label=f"scale {k * px:.3g} {r.unit} ({k} pixels)")
    ax.axhline(MU, color="k", ls=":", lw=0.8, label=f"local $\\mu$ = {MU}")
    ax.set_xlim(-180, 180)
    ax.set_xticks(np.arange(-180, 181, 45))
    ax.set_ylim(0.0, 0.6)
    ax.set_xlabel(r"slip direction $\theta$ [deg from x]")
    ax.set_ylabel(r"$\mu(\theta)$")
    ax.set_title(f"{name}: directional friction coefficient at two scales", fontsize=9)
    ax.legend(loc="lower center", ncol=3, fontsize=7)
    path = Path(out) / "measured_surface_mu_theta.png"
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    print(f"wrote {path}")
    return study


def main(files=FILES, out_dir=None):
    """Print the table; with ``out_dir``, save the figures of the X3P map there."""
    missing = [f for f in files if not (SURFACES / f).is_file()]
    if missing:
        print(f"not found beside the repository (../shared/surfaces): {missing}")
        return None
    rows = table(files)
    study = figures(out=out_dir) if out_dir is not None else None
    return rows, study


if __name__ == "__main__":
    main(out_dir=".")
