"""Two blocks stacked on a wedge asperity, pushed horizontally: when does the stack move?

Block 1 rests on a plane inclined at ``alpha`` (local Coulomb ``mu1``), block 2 on block 1's
horizontal top face (``mu2``); a horizontal push ``P`` acts on block 1, gravity on both. One
Moreau step from rest is a global FCLIB-type problem (M v = h f + H r, u = H^T v), condensed
and solved by frictionrules. Block 2 rides on block 1 and the stack moves as one block, up
the slope, once ``P`` exceeds the wedge limit (2.2) for the total weight ``Q = (m1 + m2) g``:

    P* = Q tan(alpha + rho1),   rho1 = arctan(mu1),

which the example recovers by bisection on the solver's answer (moving or not).

Run: ``python examples/multicontact_wedge_stack.py`` (prints the results and saves the
figure in the current folder).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.sparse as sp

from frictionrules import FrictionContactProblem, WedgeAsperity, solve
from frictionrules.io import GlobalProblem

M1, M2, G, H = 1.0, 0.5, 9.81, 1e-3
ALPHA, MU1, MU2 = 0.25, 0.3, 0.9


def stack_problem(push: float) -> GlobalProblem:
    """Unknowns v = (v1, v2) (block translations, xyz); contact frames (n, t1, t2)."""
    n = np.array([-np.sin(ALPHA), 0.0, np.cos(ALPHA)])
    t1 = np.array([np.cos(ALPHA), 0.0, np.sin(ALPHA)])
    e2 = np.array([0.0, 1.0, 0.0])
    H1 = np.stack((n, t1, e2), axis=1)                       # wedge / block 1
    H2 = np.stack(([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], e2), axis=1)  # block 1 / block 2
    Hg = np.zeros((6, 6))
    Hg[:3, :3] = H1
    Hg[:3, 3:] = -H2
    Hg[3:, 3:] = H2
    f = H * np.array([push, 0.0, -M1 * G, 0.0, 0.0, -M2 * G])
    return GlobalProblem(sp.diags([M1] * 3 + [M2] * 3), sp.csr_matrix(Hg), f, np.zeros(6),
                         np.array([MU1, MU2]))


def velocities(push: float, method: str = "nsgs") -> np.ndarray:
    g = stack_problem(push)
    local = g.condense()
    s = solve(FrictionContactProblem(local.W, local.q, local.laws), method=method, tol=1e-13)
    return np.linalg.solve(g.M.toarray(), g.H @ s.r + g.f)


def onset_push() -> float:
    """Smallest push that moves the stack, by bisection on the solver's answer."""
    lo, hi = 0.0, 20.0
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if np.abs(velocities(mid)).max() > 1e-12 else (mid, hi)
    return 0.5 * (lo + hi)


def main(out_dir=None) -> dict:
    """Print the onset beside the closed form; with ``out_dir``, save the speeds there."""
    Q = (M1 + M2) * G
    closed = Q * np.tan(ALPHA + np.arctan(MU1))
    found = onset_push()
    law = WedgeAsperity(ALPHA, MU1)
    v = velocities(1.2 * closed)
    print(f"onset push: solver {found:.6f}, closed form Q tan(alpha + rho) {closed:.6f}")
    print(f"at 1.2 P*: block 1 moves {v[:3]}, block 2 {v[3:]}")
    print(f"slip direction {v[:3] / np.linalg.norm(v[:3])}, wedge law (2.7) "
          f"{law.slip_direction([1.2 * closed, 0.0], Q)}")
    if out_dir is not None:
        import matplotlib.pyplot as plt
        ratio = np.linspace(0.8, 1.4, 25)
        speed = [np.abs(velocities(k * closed)).max() for k in ratio]
        fig, ax = plt.subplots(figsize=(6.0, 3.8))
        ax.plot(ratio, speed, "C0o-", ms=3, label="largest block speed after one step")
        ax.axvline(1.0, color="k", ls=":", lw=0.8, label="$P^* = Q\\tan(\\alpha + \\rho_1)$ (2.2)")
        ax.set_xlabel("push $P/P^*$")
        ax.set_ylabel("speed $|v|$ after one step $h$")
        ax.set_title("two stacked blocks on a wedge: the stack moves above $P^*$", fontsize=9)
        ax.legend(fontsize=8)
        path = Path(out_dir) / "multicontact_wedge_stack.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {path}")
    return {"onset": found, "closed_form": closed}


if __name__ == "__main__":
    main(out_dir=".")
