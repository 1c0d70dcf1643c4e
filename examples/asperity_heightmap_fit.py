"""A machined height map -> its global law mu(theta), then fits of four models to it.

Run: python examples/asperity_heightmap_fit.py
"""

import numpy as np

from frictionrules import (EllipticOrthotropic, Huber, TransformedCoulomb, TwoFlankAsperity,
                           from_heightmap)
from frictionrules.asperities import compare_fits, format_fits
from frictionrules.asperities.surfaces import machined_surface


def main(n=256):
    h = machined_surface(n, roughness=0.1, correlation=4.0)
    law = from_heightmap(h, dx=1.0, dy=1.0, mu=0.2)
    theta = np.linspace(-np.pi, np.pi, 73)[:-1]
    mu = law.friction_coefficient(theta)
    print(f"{len(law.normals)} facet groups; mu(theta) from {mu.min():.3f} to {mu.max():.3f}")
    results = compare_fits(theta, mu, {
        "EllipticOrthotropic": EllipticOrthotropic(0.5, 0.4),
        "Huber": Huber(0.5, 0.4),
        "TransformedCoulomb": TransformedCoulomb(0.5, 0.4),
        "TwoFlankAsperity": TwoFlankAsperity(0.4, 2.8, 0.3)})
    print(format_fits(results))
    return min(r.rms for r in results.values())


if __name__ == "__main__":
    main()
