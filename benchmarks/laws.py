"""Benchmark: ``limit`` + ``slip_direction`` of EllipticOrthotropic on 10^6 points against a bare
NumPy expression of the same formulas (goal: within 3x).

Run: ``python benchmarks/laws.py`` (writes ``benchmarks/results/laws.md``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _table import best_of, write_table  # noqa: E402

from frictionrules import EllipticOrthotropic  # noqa: E402


def bare_numpy(T, N, mx, my, angle):
    """The same formulas written out once, no checks: f, and the unit slip (no normal part)."""
    c, s = np.cos(angle), np.sin(angle)
    a, b = c * T[:, 0] + s * T[:, 1], -s * T[:, 0] + c * T[:, 1]  # principal frame
    f = np.sqrt((a / mx) ** 2 + (b / my) ** 2) - N
    g1, g2 = a / mx**2, b / my**2
    norm = np.sqrt(g1**2 + g2**2)
    g1, g2 = g1 / norm, g2 / norm
    return f, np.stack((c * g1 - s * g2, s * g1 + c * g2, np.zeros_like(norm)), axis=-1)


def main(n: int = 1_000_000) -> float:
    rng = np.random.default_rng(0)
    T = rng.normal(size=(n, 2))
    N = rng.uniform(0.5, 2.0, n)
    rows = []
    ratios = []
    for angle in (0.0, 0.4):
        law = EllipticOrthotropic(0.6, 0.3, angle)
        f_ref, v_ref = bare_numpy(T, N, 0.6, 0.3, angle)
        assert np.allclose(law.limit(T, N), f_ref) and np.allclose(law.slip_direction(T, N), v_ref)

        def ours():
            law.limit(T, N)
            law.slip_direction(T, N)

        t_ours = best_of(ours)
        t_bare = best_of(lambda: bare_numpy(T, N, 0.6, 0.3, angle))
        ratios.append(t_ours / t_bare)
        rows.append([f"EllipticOrthotropic(0.6, 0.3, angle={angle})", f"{n:.0e}", f"{t_bare * 1e3:.1f}",
                     f"{t_ours * 1e3:.1f}", f"{t_ours / t_bare:.2f}", "yes" if t_ours / t_bare <= 3 else "NO"])
    write_table("laws", "limit + slip_direction on 10^6 points",
                ["law", "points", "bare NumPy (ms)", "frictionrules (ms)", "ratio", "within 3x"], rows,
                notes="bare NumPy: the same formulas (frame rotation included) without input checks.")
    return max(ratios)


if __name__ == "__main__":
    main()
