"""A machined surface whose facets carry an orthotropic or a dilatant local law: from the height
map to the global law mu(theta), end to end.

The grooves run along y; each facet carries its local law in its own frame (t1 the projection of
x onto the facet: across the lay, t2 along it; docs/conventions.md). A machined facet with a
finer lay of its own along the grooves is ``EllipticOrthotropic(mu_across, mu_along)``.

Run: ``python examples/asperity_machined_local_law.py`` (prints the results and saves the
figure in the current folder).
"""

from pathlib import Path

import numpy as np

from frictionrules import Coulomb, EllipticOrthotropic, UserLaw, from_heightmap
from frictionrules.asperities.surfaces import machined_surface

LAWS = {
    "Coulomb 0.2": 0.2,
    "machined: 0.25 across, 0.12 along the lay": EllipticOrthotropic(0.25, 0.12),
    "dilatant Coulomb 0.2 (1.6)": Coulomb(0.2, dilatant=True),
    "dilatant machined (g = f)": UserLaw("sqrt((T1/a)**2 + (T2/b)**2) - N",
                                         params={"a": 0.25, "b": 0.12}),
}


def main(n: int = 128, out_dir=None) -> dict:
    """Print mu(theta) of each local law; with ``out_dir``, save the polar figure there."""
    h = machined_surface(n, roughness=0.1, correlation=4.0)
    theta = np.deg2rad([0.0, 45.0, 90.0, 135.0, 180.0])
    print("mu(theta) at theta = 0, 45, 90, 135, 180 deg (slip across the lay at 0 and 180)")
    out = {}
    for name, law in LAWS.items():
        facets = from_heightmap(h, 1.0, 1.0, law)
        mu = facets.friction_coefficient(theta)
        out[name] = mu
        print(f"  {name:42s} {np.array2string(mu, precision=4)}")
    if out_dir is not None:
        import matplotlib.pyplot as plt
        fine = np.linspace(-np.pi, np.pi, 361)
        ax = plt.figure(figsize=(6.0, 6.0)).add_subplot(projection="polar")
        for name, law in LAWS.items():
            ax.plot(fine, from_heightmap(h, 1.0, 1.0, law).friction_coefficient(fine), label=name)
        ax.set_title(r"$\mu(\theta)$ of the machined map for sliding at $\theta$ (grooves along "
                     "$y$)", fontsize=9)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), fontsize=7)
        path = Path(out_dir) / "asperity_machined_local_law.png"
        ax.figure.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(ax.figure)
        print(f"wrote {path}")
    return out


if __name__ == "__main__":
    main(out_dir=".")
