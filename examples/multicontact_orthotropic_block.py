"""A block on an orthotropic support pushed obliquely: the slip is not along the push.

One contact with the elliptic orthotropic law (1.9) (``mu_x = 0.6``, ``mu_y = 0.2``, principal
axis at 30 deg), a block of mass m pushed at 45 deg with a force above the limit: one Moreau
step W = I/m, q = (-g h, h F/m). The solver's slip direction is checked against the law's own
inverse relation (1.13): the friction force is ``force_for_slip(u_T, N)``.

Run: ``python examples/multicontact_orthotropic_block.py`` (prints the results and saves the
figure in the current folder).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from frictionrules import EllipticOrthotropic, FrictionContactProblem, solve

M, G, H = 2.0, 9.81, 0.01
LAW = EllipticOrthotropic(mu_x=0.6, mu_y=0.2, angle=np.deg2rad(30.0))


def main(push_deg: float = 45.0, push: float = 12.0, out_dir=None) -> dict:
    """Print the slip beside the push; with ``out_dir``, save the figure there."""
    e = np.array([np.cos(np.deg2rad(push_deg)), np.sin(np.deg2rad(push_deg))])
    q = np.r_[-G * H, H * push / M * e]
    p = FrictionContactProblem(np.eye(3) / M, q, [LAW])
    out = {}
    for method in ("nsgs", "newton", "prox"):
        s = solve(p, method=method, tol=1e-12)
        out[method] = s
    s = out["nsgs"]
    T, N = -s.r[1:], s.r[0]
    slip_deg = np.rad2deg(np.arctan2(s.u[2], s.u[1]))
    gap = np.abs(T - LAW.force_for_slip(s.u[1:], N)).max()
    print(f"push at {push_deg:.1f} deg, slip at {slip_deg:.3f} deg, friction force {T}, N = {N:.4f}")
    print(f"|T - force_for_slip(u_T, N)| = {gap:.2e} (inverse relation (1.13))")
    for method, sol in out.items():
        print(f"  {method:6s} iterations {sol.iterations:3d} error {sol.error:.1e}")
    if out_dir is not None:
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5.5, 5.0))
        phi = np.linspace(0.0, 2 * np.pi, 361)
        ring = LAW.force_for_slip(np.stack((np.cos(phi), np.sin(phi)), axis=-1), N)
        ax.plot(*ring.T, "k-", lw=1, label=f"limit ellipse at $N$ = {N:.3f}")
        slip = s.u[1:] / np.hypot(*s.u[1:])
        for vec, colour, text in ((e, "C0", f"push, {push_deg:g}°"),
                                  (slip, "C3", f"slip, {slip_deg:.1f}°"),
                                  (-T, "C2", "friction force on the support")):
            angle = np.angle(np.exp(1j * (np.arctan2(ring[:, 1], ring[:, 0])
                                          - np.arctan2(vec[1], vec[0]))))
            reach = 0.9 * np.hypot(*ring[np.argmin(np.abs(angle))])    # to the ellipse
            ax.annotate("", xy=tuple(vec / np.hypot(*vec) * reach), xytext=(0, 0),
                        arrowprops=dict(arrowstyle="->", color=colour, lw=1.5))
            ax.plot([], [], color=colour, label=text)
        ax.plot(*T, "ko", ms=4, label="friction force T on the block")
        ax.set_aspect("equal")
        ax.set_xlabel("$T_x$")
        ax.set_ylabel("$T_y$")
        ax.set_title("a block on an orthotropic support: the slip is not along the push",
                     fontsize=9)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=8, ncol=2)
        path = Path(out_dir) / "multicontact_orthotropic_block.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {path}")
    return {"slip_deg": float(slip_deg), "inverse_gap": float(gap)}


if __name__ == "__main__":
    main(out_dir=".")
