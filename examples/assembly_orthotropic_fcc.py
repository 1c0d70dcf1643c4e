"""The fcc array with an orthotropic elliptic law at every contact (axis 1 on t1, the
projection of the reference axis x onto the contact plane).

The contacts in the xz planes slide along t1 with μx, those in the yz planes along t2 with
μy: σzz/σ3 = (1 + μx)/(1 − μx) + (1 + μy)/(1 − μy) (docs/assembly.md).
Run: ``python examples/assembly_orthotropic_fcc.py`` (prints the results and saves the
figure in the current folder).
"""

from pathlib import Path

from frictionrules import Assembly, ContactModel, EllipticOrthotropic, triaxial


def main(out_dir=None) -> dict:
    """Print the peak beside the closed form, for the reference axis x and y; with
    ``out_dir``, save the response curves there."""
    mx, my = 0.2, 0.4
    model = ContactModel(EllipticOrthotropic(mx, my), kn=1e6, kt=1e6)
    out, runs = {}, []
    for axis in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)):
        r = triaxial(Assembly.lattice("fcc", model, reference_axis=axis), "axisymmetric",
                     pressure=1.0, axial_strain=2e-4, increments=40)
        out[axis] = r.peak_ratio
        runs.append((f"reference axis {'x' if axis[0] else 'y'}", r))
        print(f"reference axis {axis}: peak σzz/σxx = {r.peak_ratio:.6f}; σyy/σxx = "
              f"{r.stress[-1, 1, 1] / r.stress[-1, 0, 0]:.6f}")
    print(f"closed form: {(1 + mx) / (1 - mx) + (1 + my) / (1 - my):.6f}")
    if out_dir is not None:
        import matplotlib.pyplot as plt

        from frictionrules.plot.assembly import plot_response
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
        for label, r in runs:
            plot_response(r, axes=axes, label=label, linestyle="-" if "x" in label else "--")
        fig.tight_layout()
        path = Path(out_dir) / "assembly_orthotropic_fcc.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {path}")
    return out


if __name__ == "__main__":
    main(out_dir=".")
