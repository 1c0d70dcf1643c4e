"""Benchmark: a 512 x 512 height map -> its directional friction mu(theta), on one core.

Run: ``python benchmarks/heightmap.py`` (writes ``benchmarks/results/heightmap.md`` and the polar
figure ``benchmarks/results/heightmap_mu.png``). Goal: under 2 s for the whole path: facet
gradients, grouping (convex hull), the facet law and mu(theta) at 720 slip angles.

With SurfaceTopography and the instrument files of ``../shared/surfaces`` it also times each
file (read, then ``from_topography`` at the default scale: detrending, smoothing, facets,
mu(theta) at 360 directions and the carrying facets) and writes
``benchmarks/results/heightmap_files.md``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")   # one core

import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import RESULTS, best_of, write_table  # noqa: E402

from frictionrules import from_heightmap, from_topography, read_surface  # noqa: E402
from frictionrules._atomic import atomic_path  # noqa: E402
from frictionrules.asperities.surfaces import (group_gradients, heightmap_gradients,  # noqa: E402
                                               machined_surface)


def main():
    theta = np.linspace(-np.pi, np.pi, 720, endpoint=False)
    rows = []
    for n in (128, 256, 512):
        h = machined_surface(n)

        def full():
            return from_heightmap(h, 1.0, 1.0, 0.2).friction_coefficient(theta)

        t_grad = best_of(lambda: heightmap_gradients(h, 1.0, 1.0), 5)
        p = heightmap_gradients(h, 1.0, 1.0)
        t_group = best_of(lambda: group_gradients(p), 5)
        t_full = best_of(full, 5)
        law = from_heightmap(h, 1.0, 1.0, 0.2)
        mu = law.friction_coefficient(theta)
        rows.append([f"{n} x {n}", len(p), len(law.normals), f"{t_grad * 1e3:.1f}",
                     f"{t_group * 1e3:.1f}", f"{t_full * 1e3:.1f}",
                     f"{mu.min():.3f} .. {mu.max():.3f}", "yes" if t_full < 2.0 else "NO"])
    write_table("heightmap", "Height map -> mu(theta) (720 slip angles), one core",
                ["map", "facets (triangles)", "facet groups", "gradients [ms]", "grouping [ms]",
                 "total [ms]", "mu(theta)", "< 2 s"], rows,
                notes="Synthetic machined surface (`machined_surface`: grooves rising 0.35 / "
                      "falling 0.2 across the lay, roughness 0.4 with correlation 3 cells), "
                      "local mu = 0.2, non-associated. Best of 5 runs; total = from_heightmap + "
                      "friction_coefficient. Figure: heightmap_mu.png.")
    import matplotlib
    matplotlib.use("Agg")
    from frictionrules.plot.asperities import heightmap_polar
    ax = heightmap_polar(mu=0.2, n=512)
    with atomic_path(RESULTS / "heightmap_mu.png") as tmp:
        ax.figure.savefig(tmp, format="png", dpi=120, bbox_inches="tight")
    files()


SURFACES = Path(__file__).resolve().parents[1].parent / "shared" / "surfaces"


def files(names=("di-1.di", "x3p-2.x3p", "opdx-3.opdx"), mu=0.3):
    """Each instrument file at the default scale: the table of docs/surfaces.md."""
    import importlib.util
    import time
    import warnings

    if importlib.util.find_spec("SurfaceTopography") is None or not SURFACES.is_dir():
        print(f"no SurfaceTopography or no {SURFACES}: the instrument files are not timed")
        return
    rows = []
    for name in names:
        t0 = time.perf_counter()
        topo = read_surface(SURFACES / name)
        t_read = time.perf_counter() - t0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            t_law = best_of(lambda: from_topography(topo, mu), 3)
            r = from_topography(topo, mu)
        lo, hi = r.mu_range
        free = ~r.locked
        rows.append([name, " x ".join(map(str, r.shape[::-1])), f"{r.scale:.4g} {r.unit}",
                     f"{lo:.4f} .. {hi:.4f}", f"{r.upper_bound:.4f}", f"{r.anisotropy:.3f}",
                     f"{int(r.locked.sum())}/{len(r.mu)}",
                     int(r.carrying[free].min()) if free.any() else 0, len(r.law.normals),
                     f"{t_read:.2f}", f"{t_law:.2f}"])
    write_table("heightmap_files", "Instrument files -> mu(theta) at the default scale, one core",
                ["file", "grid", "scale", "mu(theta)", "bound", "anisotropy", "locked",
                 "fewest carrying facets", "facet groups", "read [s]", "law [s]"], rows,
                notes=f"Local mu = {mu}, mean plane removed, ISO Gaussian cut-off five pixels, "
                      "360 directions; law = from_topography (best of 3).")


if __name__ == "__main__":
    main()
