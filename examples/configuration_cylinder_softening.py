"""Contact softening of a cylinder pushed over its neighbour (§3, Fig. 8).

The force that keeps the cylinder sliding falls from Q tan(pi/6 + rho) in the groove to mu Q
on the top of the neighbour. The paper's incremental rate form (explicit Euler steps of
(3.6)–(3.10) with the consistency condition (3.5)) converges to the exact geometric result with
order 1. A force-controlled ramp finds the limit point, where softening begins.

Run: ``python examples/configuration_cylinder_softening.py``
"""

import numpy as np

from frictionrules import CylinderOnLayer


def main(mu: float = 0.3, Q: float = 1.0) -> dict:
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
    return {"order": order, "limit_force": lp.force[0] / Q, "top_force": exact.force[-1, 0] / Q}


if __name__ == "__main__":
    main()
