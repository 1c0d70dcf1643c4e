"""Calibration on measured anisotropic friction: fits with confidence intervals and residuals.

The data are our own synthetic "rotating-table" measurements (no published data set of
mu(theta) with its uncertainties could be obtained here): a machined height map (grooves along
y, roughness) is turned into the law of a rigid block on its facets (local mu = 0.2, scale two
pixels), its mu(theta) is "measured" every 10 degrees with a 2 % Gaussian error (seeded), and
four models are fitted with that uncertainty: the facet model (two-flank groove) and three
orthotropic laws. The table gives each fit's rms, chi2/dof and parameters with 95 % intervals;
the figure shows the data with error bars, the fits and the normalized residuals.

Run: ``python examples/asperity_heightmap_fit.py`` (prints the results and saves the
figure in the current folder).
"""

import warnings
from pathlib import Path

import numpy as np

from frictionrules import (EllipticOrthotropic, Huber, TransformedCoulomb, TwoFlankAsperity,
                           from_topography)
from frictionrules.asperities import compare_fits, format_fits
from frictionrules.asperities.surfaces import machined_surface


class Map:
    """A height map h[iy, ix] with SurfaceTopography's interface (heights indexed [ix, iy])."""

    def __init__(self, h, pixel):
        self._h, self.pixel_size, self.unit = h, (pixel, pixel), "um"

    def heights(self):
        return self._h.T


def measurements(n=256, error=0.02, seed=0):
    """Slip angles every 10 deg, mu(theta) with a relative Gaussian error, and sigma."""
    h = machined_surface(n, roughness=0.1, correlation=4.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        surface = from_topography(Map(h, 1.0), 0.2, scale=2.0)
    theta = np.deg2rad(np.arange(-180, 180, 10.0))
    mu_true = surface.law.friction_coefficient(theta)
    sigma = error * mu_true
    mu = mu_true + sigma * np.random.default_rng(seed).standard_normal(theta.shape)
    return theta, mu, sigma


def main(n=256, out_dir=None):
    """Print the fits; with ``out_dir``, save the figure there. Returns the best rms."""
    theta, mu, sigma = measurements(n)
    print(f"{len(theta)} measurements; mu from {mu.min():.3f} to {mu.max():.3f} (+- 2 %)")
    results = compare_fits(theta, mu, {
        "EllipticOrthotropic": EllipticOrthotropic(0.5, 0.4),
        "Huber": Huber(0.5, 0.4),
        "TransformedCoulomb": TransformedCoulomb(0.5, 0.4),
        "TwoFlankAsperity": TwoFlankAsperity(0.4, 2.8, 0.3)}, sigma=sigma)
    print(format_fits(results))
    if out_dir is not None:
        path = Path(out_dir) / "asperity_heightmap_fit.png"
        draw(theta, mu, sigma, results, path)
        print(f"wrote {path}")
    return min(r.rms for r in results.values())


def draw(theta, mu, sigma, results, out):
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.5, 5.5), sharex=True,
                                      gridspec_kw={"height_ratios": [2, 1]})
    deg = np.rad2deg(theta)
    fine = np.linspace(-np.pi, np.pi, 721)
    top.errorbar(deg, mu, yerr=sigma, fmt="ko", ms=3, capsize=2, label="measured +- sigma")
    styles = {"EllipticOrthotropic": "C0-", "Huber": "C1--", "TransformedCoulomb": "C2-.",
              "TwoFlankAsperity": "k-"}
    for name, r in results.items():
        top.plot(np.rad2deg(fine), r.law.friction_coefficient(fine), styles[name], lw=1,
                 label=f"{name} (chi2/dof {r.reduced_chi2:.2g})")
        bottom.plot(deg, r.normalized_residuals, styles[name][:2] + "o", ms=3, lw=0)
    bottom.axhline(0.0, color="k", lw=0.6)
    bottom.axhspan(-2, 2, color="0.9", zorder=0)
    top.set_ylabel(r"$\mu(\theta)$")
    top.legend(fontsize=7, loc="upper center", ncol=2, bbox_to_anchor=(0.5, 1.32))
    bottom.set_ylabel("residual / sigma")
    bottom.set_xlabel(r"slip direction $\theta$ [deg from x]")
    bottom.set_xlim(-180, 180)
    bottom.set_xticks(np.arange(-180, 181, 45))
    fig.savefig(out, dpi=120, bbox_inches="tight")
    plt.close(fig)


if __name__ == "__main__":
    main(out_dir=".")
