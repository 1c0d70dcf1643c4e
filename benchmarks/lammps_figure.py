"""A picture of a LAMMPS run driven by a library law: the 400-sphere sample of
``assembly_lammps.py`` (seed 1) with the dilatant ``UserLaw`` (g = |T| − βN, β = μ/3, μ = 0.3)
through its exported pair style, sheared in LAMMPS (``engine="lammps"``) to ``--strain``; the
contacts of the last restart file read back by LAMMPS itself (``compute property/local
patom1 patom2`` beside the pair style's ``compute pair/local p1 p2 p3 p4``: N, |T|, the
sliding flag, the dissipation) and drawn with matplotlib (3-D): the force chains (N) and
where the law dissipated.

One command: ``python benchmarks/lammps_figure.py [--strain 0.05] [--out docs/figures]``
(the run is kept under ``results/lammps_figure``; about two minutes of CPU).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
FOLDER = HERE / "results" / "lammps_figure"


def run(strain: float) -> Path:
    """The LAMMPS run (kept), then the contacts and grains of its last restart file."""
    import assembly_lammps as bench
    import frictionrules as fr
    from frictionrules.assembly._lammps._runner import (lammps_environment, lammps_install,
                                                        run_lammps)
    a = bench.assembly_of(bench.sample(1), bench.make_law("dilatant", 0.3))
    stages = FOLDER / "stages.txt"
    if not stages.exists() or "shear done" not in stages.read_text():
        files = fr.write_lammps_triaxial(a, "axisymmetric", FOLDER, pressure=bench.PRESSURE,
                                         axial_strain=strain, consolidation="frictionless",
                                         record_every=1e-3, restart_every=strain)
        print(run_lammps(files))
    last = max(FOLDER.glob("shear.*.restart"), key=lambda p: int(p.name.split(".")[1]))
    plugin = next(line for line in (FOLDER / "in.resume").read_text().splitlines()
                  if line.startswith("plugin load"))
    script = f"""{plugin}
read_restart {last.name}
comm_modify vel yes
neighbor 0.1 bin
fix carrying all property/atom i_fr_carrying
compute pairs all property/local patom1 patom2
compute laws all pair/local p1 p2 p3 p4
run 0
write_dump all local contacts.dump c_pairs[1] c_pairs[2] c_laws[1] c_laws[2] c_laws[3] &
    c_laws[4] modify format float %.17g
write_dump all custom grains.dump id x y z radius modify sort id format float %.17g
"""
    (FOLDER / "in.contacts").write_text(script)
    out = subprocess.run([str(lammps_install().lmp), "-in", "in.contacts", "-log", "contacts.log"],
                         cwd=FOLDER, env=lammps_environment(), capture_output=True, text=True)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
    return FOLDER


def draw(folder: Path, out: Path) -> Path:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Line3DCollection
    grains = np.loadtxt(folder / "grains.dump", skiprows=9)
    box = np.loadtxt(folder / "grains.dump", skiprows=5, max_rows=3)
    lo, size = box[:, 0], box[:, 1] - box[:, 0]
    x = np.empty((len(grains), 3))
    x[grains[:, 0].astype(int) - 1] = grains[:, 1:4]
    radius = np.empty(len(grains))
    radius[grains[:, 0].astype(int) - 1] = grains[:, 4]
    rows = np.loadtxt(folder / "contacts.dump", skiprows=9, ndmin=2)
    i, j = rows[:, 0].astype(int) - 1, rows[:, 1].astype(int) - 1
    N, T, slid, diss = rows[:, 2], rows[:, 3], rows[:, 4], rows[:, 5]
    keep = N > 0.0
    i, j, N, T, slid, diss = i[keep], j[keep], N[keep], T[keep], slid[keep], diss[keep]
    d = x[j] - x[i]
    d -= size * np.round(d / size)                       # the nearest image of j
    gap = np.linalg.norm(d, axis=1) - radius[i] - radius[j]
    segments = np.stack((x[i], x[i] + d), axis=1)
    fig = plt.figure(figsize=(12, 5.2))
    for k, (value, name, cmap) in enumerate(((N, "normal force N", "inferno_r"),
                                             (diss, "dissipation of the contact since it formed",
                                              "viridis_r"))):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        order = np.argsort(value)
        top = np.quantile(value, 0.98) if np.any(value > 0) else 1.0
        scale = plt.Normalize(0.0, top, clip=True)
        cm = plt.get_cmap(cmap)
        width = 0.3 + 3.0 * scale(value[order])
        ax.add_collection3d(Line3DCollection(segments[order], linewidths=width,
                                             colors=cm(0.1 + 0.9 * scale(value[order]))))
        pushing = gap > 0.0                               # dilatant contacts open, still pushing
        if k == 0 and pushing.any():
            mid = segments[pushing].mean(axis=1)
            ax.scatter(*mid.T, s=3, color="C0", alpha=0.6, depthshade=False,
                       label=f"midpoints of the {pushing.sum()} contacts pushing with a "
                             "positive gap (dilatancy)")
            ax.legend(loc="upper left", fontsize=7, frameon=False)
        ax.scatter(*x.T, s=1, color="0.6", depthshade=False)
        corners = lo + size * np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)])
        for p in range(8):
            for q in range(p + 1, 8):
                if np.count_nonzero(corners[p] != corners[q]) == 1:
                    ax.plot(*corners[[p, q]].T, color="C0", lw=0.6, ls="--")
        ax.set(xlabel="x", ylabel="y", zlabel="z (axial)", xlim=(lo[0] - 1, lo[0] + size[0] + 1),
               ylim=(lo[1] - 1, lo[1] + size[1] + 1), zlim=(lo[2] - 1, lo[2] + size[2] + 1))
        ax.set_box_aspect(size + 2)
        ax.view_init(elev=12, azim=-60)
        for axis in "xyz":
            ax.locator_params(axis=axis, nbins=4)
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_pane_color((1, 1, 1, 0))
        sm = plt.cm.ScalarMappable(norm=scale, cmap=cm)
        fig.colorbar(sm, ax=ax, shrink=0.55, pad=0.08, extend="max", label=name)
    fig.suptitle(f"LAMMPS, the exported dilatant UserLaw at every contact: {len(N)} force-carrying "
                 f"contacts of 400 spheres, {int(slid.sum())} sliding (the last restart file, read "
                 "back by LAMMPS)", fontsize=10, y=0.95)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "assembly_lammps_contacts.png"
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    print(f"wrote {path}: {len(N)} contacts, {int(np.count_nonzero(gap > 0))} with a positive gap, "
          f"{int(slid.sum())} sliding, N max {N.max():.3g}, dissipation total {diss.sum():.4g}")
    return path


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strain", type=float, default=0.05)
    parser.add_argument("--out", default=str(HERE.parent / "docs" / "figures"))
    args = parser.parse_args(argv)
    draw(run(args.strain), Path(args.out))
    # the records of the run, for the caption
    import assembly_lammps as bench
    import frictionrules as fr
    r = fr.read_lammps_triaxial(bench.assembly_of(bench.sample(1), bench.make_law("dilatant", 0.3)),
                                FOLDER)
    print(f"at axial strain {r.axial_strain[-1]:.4f}: ε_v {r.volumetric_strain[-1]:.4f}, "
          f"Z {r.coordination[-1]:.3f}, sliding fraction {r.sliding_fraction[-1]:.3f}, "
          f"peak angle {r.peak_friction_angle:.2f}°")


if __name__ == "__main__":
    main()
