"""Contact softening of a cylinder pushed over its neighbour (§3, Fig. 8).

The force that keeps the cylinder sliding falls from Q tan(pi/6 + rho) in the groove to mu Q
on the top of the neighbour. The paper's incremental rate form (explicit Euler steps of
(3.6)–(3.10) with the consistency condition (3.5)) converges to the exact geometric result with
order 1. A force-controlled ramp finds the limit point, where softening begins.

Run: ``python examples/configuration_cylinder_softening.py`` (prints the results and saves the
figure in the current folder).
"""

from pathlib import Path

import numpy as np

from frictionrules import CylinderOnLayer


def main(mu: float = 0.3, Q: float = 1.0, out_dir=None) -> dict:
    """Print the errors, the order and the limit point; with ``out_dir``, save the figure."""
    cyl = CylinderOnLayer(diameter=1.0, mu=mu)
    steps, errors = [], []
    for n in (11, 21, 41, 81, 161):
        path = cyl.straight_path(direction=0.0, length=0.5, n=n)     # groove -> top
        exact = cyl.displacement_path(path, Q=Q)
        inc = cyl.displacement_path(path, method="incremental", Q=Q)
        steps.append(0.5 / (n - 1))
        errors.append(np.abs(inc.force - exact.force).max())
        print(f"step {steps[-1]:.5f}: T at top {inc.force[-1, 0]:.5f} (exact {exact.force[-1, 0]:.5f}),"
              f" max error {errors[-1]:.2e}")
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    print(f"observed order of the incremental scheme: {order:.2f}")

    ramp = np.stack((np.linspace(0.0, 2.0, 101), np.zeros(101)), axis=-1)
    lp = cyl.force_path(Q * ramp, Q=Q).limit_point
    print(f"force control: limit point at T = {lp.force[0] / Q:.5f} Q "
          f"(Q tan(pi/6 + rho) = {np.tan(np.pi / 6 + np.arctan(mu)):.5f} Q)")
    if out_dir is not None:
        import matplotlib.pyplot as plt
        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.8))
        a.plot(exact.distance, exact.force[:, 0] / Q, "k-", label="exact")
        a.plot(inc.distance, inc.force[:, 0] / Q, "C0o", ms=2.5, mfc="none",
               label=f"incremental, {len(path) - 1} Euler steps")
        a.set_xlabel("distance travelled $|u|/d$")
        a.set_ylabel("force to keep sliding $T_x/Q$")
        a.set_title("groove to the top of the neighbour", fontsize=9)
        a.legend(fontsize=8)
        b.loglog(steps, errors, "C0o-", label=f"observed order {order:.2f}")
        b.loglog(steps, errors[-1] * np.array(steps) / steps[-1], "k:", label="order 1")
        b.set_xlabel("step $|\\Delta u|/d$")
        b.set_ylabel("largest error of $T/Q$")
        b.set_title("convergence of the rate form (3.6)–(3.10)", fontsize=9)
        b.legend(fontsize=8)
        fig.tight_layout()
        path = Path(out_dir) / "configuration_cylinder_softening.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {path}")
    return {"order": order, "limit_force": lp.force[0] / Q, "top_force": exact.force[-1, 0] / Q}


if __name__ == "__main__":
    main(out_dir=".")
