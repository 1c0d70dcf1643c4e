"""A random packing of spheres sheared by the dynamic (DEM) engine, its records written as VTK
files for ParaView, and the force chains of the last record drawn from those files as they
read back (meshio): the lines from grain i to the image of j, widths and colours ∝ the normal
force N (docs/assembly.md, "Dynamic runs").

Run: ``python examples/assembly_dem_paraview.py`` (prints the run's summary, writes the VTK
files into ``vtk/`` and saves the figure in the current folder).
"""

from pathlib import Path

import numpy as np

from frictionrules import Assembly, ContactModel, Coulomb, triaxial, write_vtk


def render_force_chains(folder, record: int, ax):
    """Draw a record's files in ``folder`` on 3-D Axes as ParaView would show them: the
    force-carrying contacts of ``contacts_*.vtu`` (line widths and colours ∝ ``normal_force``,
    full above its 98th percentile),
    the grains' centres of ``grains_*.vtu`` (dots), the cell of ``cell_*.vtu`` (its edges).
    Returns the colour scale (a ScalarMappable, for a colour bar)."""
    import matplotlib.cm as cm
    import matplotlib.colors as mcolors
    import matplotlib.pyplot as plt
    import meshio
    from mpl_toolkits.mplot3d.art3d import Line3DCollection
    mesh = meshio.read(Path(folder) / f"contacts_{record:06d}.vtu")
    lines = mesh.cells_dict["line"]
    N = mesh.cell_data_dict["normal_force"]["line"]
    carrying = N > 0
    order = np.argsort(N[carrying])  # the strongest drawn last, on top
    segments = mesh.points[lines[carrying]][order]
    force = N[carrying][order]
    scale = plt.Normalize(0.0, np.quantile(force, 0.98), clip=True)  # a few chains far above
    cmap = plt.get_cmap("inferno_r")
    ax.add_collection3d(Line3DCollection(segments, linewidths=0.3 + 3.5 * scale(force),
                                         colors=cmap(0.1 + 0.9 * scale(force))))
    grains = meshio.read(Path(folder) / f"grains_{record:06d}.vtu").points
    ax.scatter(*grains.T, s=4, color="0.55", depthshade=False)
    box = meshio.read(Path(folder) / f"cell_{record:06d}.vtu").points
    for a, b in ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
                 (0, 4), (1, 5), (2, 6), (3, 7)):
        ax.plot(*box[[a, b]].T, color="C0", lw=0.7, ls="--")
    lo = np.minimum(segments.reshape(-1, 3).min(axis=0), box.min(axis=0))
    hi = np.maximum(segments.reshape(-1, 3).max(axis=0), box.max(axis=0))
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]), xlabel="x", ylabel="y",
           zlabel="z (axial)")
    ax.set_box_aspect(hi - lo)
    ax.grid(False)
    for axis in "xyz":
        ax.locator_params(axis=axis, nbins=4)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_pane_color((1, 1, 1, 0))
    part = mcolors.ListedColormap(cmap(np.linspace(0.1, 1.0, 256)))  # the lines' colours
    return cm.ScalarMappable(norm=scale, cmap=part)


def main(out_dir=None, n: int = 200, axial_strain: float = 5e-3) -> dict:
    """Shear ``n`` spheres to ``axial_strain``; with ``out_dir``, write the VTK files into
    ``out_dir/vtk`` and save the rendering of the last record's force chains."""
    model = ContactModel(Coulomb(0.5), kn=1e4, kt=1e4)
    sample = Assembly.random(n, 3, model, polydispersity=0.2, seed=1)
    r = triaxial(sample, "axisymmetric", pressure=1.0, axial_strain=axial_strain, method="dem")
    print(f"{n} spheres: peak friction angle {r.peak_friction_angle:.3g}°, volumetric strain "
          f"{r.volumetric_strain[-1]:.3g}, Z {r.coordination[-1]:.3g}, energy balance error "
          f"{100 * r.energy.relative_error:.2g} %")
    if out_dir is not None:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        folder = Path(out_dir) / "vtk"
        write_vtk(r, folder)
        last = len(r.time) - 1
        print(f"wrote {folder / 'grains.pvd'}, {folder / 'contacts.pvd'}, {folder / 'cell.pvd'}")
        fig = plt.figure(figsize=(7.5, 6.5))
        ax = fig.add_subplot(projection="3d")
        colours = render_force_chains(folder, last, ax)
        fig.colorbar(colours, ax=ax, shrink=0.6, pad=0.1, extend="max", label="normal force N")
        ax.view_init(elev=12, azim=-60)
        ax.set_title(f"force chains at axial strain {r.axial_strain[-1]:.3g}: a rendering of "
                     f"contacts_{last:06d}.vtu\n(line width and colour ∝ normal force; "
                     "ParaView: Tube filter on contacts.pvd)", fontsize=9)
        path = Path(out_dir) / "assembly_dem_force_chains.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {path}")
    return {"peak_friction_angle": r.peak_friction_angle, "contacts": r.contacts[-1].size,
            "records": len(r.time)}


if __name__ == "__main__":
    main(out_dir=".")
