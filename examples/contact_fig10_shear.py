"""Fig. 10c with the ellipsoidal cap: shear one contact at two fixed normal forces.

Below A0 = A(0, β0) the contact dilates, loses real contact area and softens after a peak;
above A0 it compacts and hardens. Both curves tend to T = m N, the critical-state line.
Run: ``python examples/contact_fig10_shear.py`` (prints the results and saves the figure
in the current folder).
"""

from pathlib import Path

from frictionrules import ContactModel, EllipsoidCap, drive


def main(out_dir=None) -> dict:
    """Print the peaks and the final T/N; with ``out_dir``, save the figure there."""
    m = 0.6
    model = ContactModel(EllipsoidCap(m), kn=100.0, kt=100.0)
    out = {}
    for N in (0.4, 1.6):
        res = drive(model, [{"N": N, "dt1": 0.0, "T2": 0.0, "steps": 10}, {"dt1": 0.8, "steps": 400}])
        T = res.force[:, 0]
        out[N] = {"peak": float(T.max()), "final_ratio": float(T[-1] / N), "beta": float(res.beta[-1])}
        print(f"N = {N}: peak T = {T.max():.4f}, final T/N = {T[-1] / N:.4f} (m = {m}), "
              f"beta {res.beta[0]:.2f} -> {res.beta[-1]:.4f}")
    if out_dir is not None:
        import matplotlib
        matplotlib.use("Agg")
        from frictionrules.plot import cap_shear_curves
        ax = cap_shear_curves()
        path = Path(out_dir) / "contact_fig10_shear.png"
        ax.figure.savefig(path, dpi=120)
        print(f"wrote {path}")
    return out


if __name__ == "__main__":
    main(out_dir=".")
