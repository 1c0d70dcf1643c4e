"""Rowe's stress–dilatancy for the hexagonal array of disks, σ1 normal to the rows, with the
force network and the roses of contact normals and mobilized friction at the end.

R = σ1/σ3 = tan(θ + φμ) tan θ and D = −dεx/dεy = tan²θ with θ = 60°, i.e. Rowe's
R = D tan(θ + φμ)/tan θ (docs/assembly.md).
Run: ``python examples/assembly_hex2d_rowe.py`` (prints the results and saves the figure
in the current folder).
"""

from pathlib import Path

import numpy as np

from frictionrules import Assembly, ContactModel, Coulomb, triaxial


def main(out_dir=None) -> dict:
    """Print R and D beside Rowe's relation; with ``out_dir``, save the figure."""
    mu = 0.3
    model = ContactModel(Coulomb(mu), kn=1e6, kt=1e6)
    r = triaxial(Assembly.lattice("hex2d", model), "biaxial", pressure=1.0,
                 axial_strain=2e-4, increments=40)
    theta, phi = np.pi / 3, np.arctan(mu)
    k = int(np.argmax(r.stress_ratio)) + 1
    ex, ey = r.strain[:, 0, 0], r.strain[:, 1, 1]
    D = float(-(ex[k + 3] - ex[k]) / (ey[k + 3] - ey[k]))
    print(f"R = {r.peak_ratio:.6f} (tan(θ+φμ) tanθ = {np.tan(theta + phi) * np.tan(theta):.6f}); "
          f"D = {D:.5f} (tan²θ = 3); R/D = {r.peak_ratio / D:.5f}, "
          f"tan(θ+φμ)/tanθ = {np.tan(theta + phi) / np.tan(theta):.5f}")
    if out_dir is not None:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from frictionrules.plot.assembly import force_network, friction_rose, normal_rose, plot_response
        fig = plt.figure(figsize=(11, 6.5))
        a = fig.add_subplot(2, 3, 1)
        b = fig.add_subplot(2, 3, 2)
        plot_response(r, axes=(a, b))
        force_network(r, ax=fig.add_subplot(2, 3, 3), plane="xy")
        normal_rose(r, ax=fig.add_subplot(2, 3, 4, projection="polar"), plane="xy")
        friction_rose(r, ax=fig.add_subplot(2, 3, 5, projection="polar"), plane="xy")
        fig.tight_layout()
        path = Path(out_dir) / "assembly_hex2d_rowe.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        print(f"wrote {path}")
    return {"R": r.peak_ratio, "D": D}


if __name__ == "__main__":
    main(out_dir=".")
