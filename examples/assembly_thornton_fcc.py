"""Thornton's face-centred cubic array of equal spheres in axisymmetric compression.

Coulomb contacts: the 45-degree contacts slide and those in the xy planes open at the peak
σzz/σxx = 2(1 + μ)/(1 − μ); above μ = 1 the array never fails. The associated (dilatant) rule
(1.6) gives the same strength and dilates faster, dεv/dεz = −(1 + 3μ)/(1 − μ) against −1.
Run: ``python examples/assembly_thornton_fcc.py`` (prints the results and saves the figure
in the current folder).
"""

from pathlib import Path

import numpy as np

from frictionrules import Assembly, ContactModel, Coulomb, triaxial


def main(out_dir=None) -> dict:
    """Print the peak ratios beside the closed form; with ``out_dir``, save the figure."""
    out = {}
    runs = []
    for mu, dilatant in ((0.1, False), (0.3, False), (0.5, False), (0.3, True), (1.2, False)):
        model = ContactModel(Coulomb(mu, dilatant=dilatant), kn=1e6, kt=1e6)
        r = triaxial(Assembly.lattice("fcc", model), "axisymmetric", pressure=1.0,
                     axial_strain=2e-4, increments=40)
        exact = 2 * (1 + mu) / (1 - mu) if mu < 1 else np.inf
        rule = "dilatant" if dilatant else "non-associated"
        rate = np.nan
        if r.failed:
            k = int(np.argmax(r.stress_ratio)) + 1
            ev, ax = r.volumetric_strain, r.axial_strain
            rate = (ev[k + 3] - ev[k]) / (ax[k + 3] - ax[k])
            print(f"mu = {mu} ({rule}): peak ratio {r.peak_ratio:.6f}, closed form {exact:.6f}, "
                  f"dilatancy after the peak {rate:.4f}")
        else:
            print(f"mu = {mu} ({rule}): no failure (peak ratio {r.peak_ratio}); σzz/σxx at the end "
                  f"{r.stress_ratio[-1]:.1f}")
        out[(mu, dilatant)] = {"peak": r.peak_ratio, "exact": exact, "dilatancy": rate}
        runs.append((f"μ = {mu} {rule}", r))
    if out_dir is not None:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from frictionrules.plot.assembly import plot_response
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
        for label, r in runs[:-1]:
            # dashed: the dilatant run has the same strength and would hide its twin
            plot_response(r, axes=axes, label=label, linestyle="--" if "dilatant" in label else "-")
        axes[1].legend(fontsize=7)
        fig.tight_layout()
        path = Path(out_dir) / "assembly_thornton_fcc.png"
        fig.savefig(path, dpi=120)
        plt.close(fig)
        print(f"wrote {path}")
    return out


if __name__ == "__main__":
    main(out_dir=".")
