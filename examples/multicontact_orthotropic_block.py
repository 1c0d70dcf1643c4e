"""A block on an orthotropic support pushed obliquely: the slip is not along the push.

One contact with the elliptic orthotropic law (1.9) (``mu_x = 0.6``, ``mu_y = 0.2``, principal
axis at 30 deg), a block of mass m pushed at 45 deg with a force above the limit: one Moreau
step W = I/m, q = (-g h, h F/m). The solver's slip direction is checked against the law's own
inverse relation (1.13): the friction force is ``force_for_slip(u_T, N)``.
"""

from __future__ import annotations

import numpy as np

from frictionrules import EllipticOrthotropic, FrictionContactProblem, solve

M, G, H = 2.0, 9.81, 0.01
LAW = EllipticOrthotropic(mu_x=0.6, mu_y=0.2, angle=np.deg2rad(30.0))


def main(push_deg: float = 45.0, push: float = 12.0) -> dict:
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
    return {"slip_deg": float(slip_deg), "inverse_gap": float(gap)}


if __name__ == "__main__":
    main()
