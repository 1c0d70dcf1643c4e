"""Facet sets with local laws: construction + one limit load for small K (a grain in a pocket),
and 720 limit loads at once, for local Coulomb, orthotropic and numerically handled laws.

Run: python benchmarks/facets.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _table import best_of, write_table  # noqa: E402

from frictionrules import Coulomb, EllipticOrthotropic, FacetSet, Huber, UserLaw  # noqa: E402


def pocket(K: int) -> np.ndarray:
    """Contact normals of a grain resting on K grains (K facets around the vertical)."""
    a = 2.0 * np.pi * np.arange(K) / K + 0.1
    tilt = np.deg2rad(35.0) if K > 1 else 0.3
    return np.stack((-np.sin(tilt) * np.cos(a), -np.sin(tilt) * np.sin(a),
                     np.full(K, np.cos(tilt))), axis=-1)


LAWS = {
    "Coulomb 0.4 (number)": 0.4,
    "Coulomb(0.4, dilatant)": Coulomb(0.4, dilatant=True),
    "EllipticOrthotropic(0.5, 0.3)": EllipticOrthotropic(0.5, 0.3, 0.2),
    "Huber(0.5, 0.4)": Huber(0.5, 0.4, 0.2),
    "UserLaw (elliptic limit, dilatant potential)": UserLaw(
        "sqrt((T1/a)**2 + (T2/b)**2) - N", potential="sqrt(T1**2 + T2**2) - psi*N",
        params={"a": 0.5, "b": 0.4, "psi": 0.1}),
}


def main() -> None:
    rows = []
    phi = np.linspace(-np.pi, np.pi, 720, endpoint=False)
    d = np.stack((np.cos(phi), np.sin(phi)), axis=-1)
    for name, law in LAWS.items():
        FacetSet(pocket(3), law).limit_load([1.0, 0.0])          # symbolic checks, imports
        for K in (1, 2, 3, 4):
            n = pocket(K)
            fast = "cone" in getattr(law, "capabilities", {"cone"})
            repeat = 7 if fast else 2
            one = best_of(lambda: FacetSet(n, law).limit_load([1.0, 0.2]), repeat)
            fs = FacetSet(n, law)
            solve = best_of(lambda: fs.limit_load([1.0, 0.2]), repeat)
            many = best_of(lambda: fs.limit_load(d), 3 if fast else 1)
            rows.append([name, K, f"{one * 1e3:.2f}", f"{solve * 1e3:.2f}", f"{many * 1e3:.1f}"])
    write_table("facets", "FacetSet: construction and limit loads with local laws",
                ["local law", "K", "FacetSet(...).limit_load(d) [ms]", "limit_load(d) [ms]",
                 "limit_load(720 directions) [ms]"], rows,
                "Best of several runs, one process. Cone laws (Coulomb, elliptic) are closed "
                "form; Huber and user laws are solved numerically from the law's functions.")


if __name__ == "__main__":
    main()
