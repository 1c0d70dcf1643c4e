"""Figures of §3: evolution of the limit curves along a path (Figs. 8, 9), the softening curve
T(|u|) and the direction-dependent peak force of a grain in a square or hexagonal pocket."""

from __future__ import annotations

import numpy as np

__all__ = ["limit_evolution", "cylinder_limit_evolution", "sphere_limit_evolution", "softening_curve",
           "pocket_peak_force"]


def limit_evolution(model, path, ax=None, points: int = 6, scale: float | None = None,
                    title: str | None = None):
    """Limit curves f = 0 drawn in the displacement plane at ``points`` stations of ``path``.

    The trajectory is drawn in the ``(u_x, u_y)`` plane; at each station (numbered 1, 2, ...)
    the force axes ``(T_x, T_y)`` are attached (the local frame translating along the path,
    as in Figs. 8 and 9), with the limit curve of the current configuration and the force
    ``T`` that keeps the grain sliding, both scaled by ``scale`` (length per unit force).
    """
    import matplotlib.pyplot as plt

    from ..configuration import GrainState

    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 5.5))
    res = model.displacement_path(path)
    idx = np.linspace(0, len(res.position) - 1, points).round().astype(int)
    if scale is None:
        step = np.hypot(*(res.position[idx[1]] - res.position[idx[0]]))
        scale = 0.7 * step / max(res.force_magnitude.max(), model.Q * model.mu)
    ax.plot(res.position[:, 0], res.position[:, 1], "k-", lw=1.0, label="trajectory")
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, points))
    for m, (i, col) in enumerate(zip(idx, colours), start=1):
        st = GrainState(res.position[i], res.height[i], res.contacts[i], (res.alpha[i],),
                        (res.psi[i],))
        o = res.position[i]
        curve = model.limit_curve(st)
        ax.plot(o[0] + scale * curve[:, 0], o[1] + scale * curve[:, 1], color=col, lw=1.4,
                label=f"{m}: alpha = {np.degrees(res.alpha[i]) + 0.0:.1f} deg"
                      + ("" if model.layer.cylindrical
                         else f", psi = {np.degrees(res.psi[i]) + 0.0:.0f} deg"))
        ax.annotate("", o + scale * res.force[i], o,
                    arrowprops=dict(arrowstyle="->", color=col, lw=1.2))
        ax.plot(*o, "o", color=col, ms=4)
        ax.annotate(str(m), o, xytext=(-10, -12), textcoords="offset points", fontsize=9)
    ax.set_aspect("equal")
    ax.set_xlabel("u_x / d  (force axes T_x at each station)")
    ax.set_ylabel("u_y / d  (force axes T_y)")
    ax.set_title(title or "limit curves along the path")
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)
    return ax


def cylinder_limit_evolution(ax=None, mu: float = 0.3):
    """Fig. 8: a cylinder pushed obliquely (20 deg to x) from the groove to the top of its
    neighbour; the limit ellipses (2.2) shrink towards the circle ``|T| = mu Q`` and their
    centre ``Q tan(alpha)`` moves to the origin: contact softening."""
    from ..configuration import CylinderOnLayer

    cyl = CylinderOnLayer(1.0, mu)
    th = np.radians(20.0)
    path = cyl.straight_path(th, 0.5 / np.cos(th), 201)
    return limit_evolution(cyl, path, ax, title=f"Fig. 8: cylinder on a layer of cylinders, mu = {mu}")


def sphere_limit_evolution(ax=None, mu: float = 0.3):
    """Fig. 9: a sphere pushed along a straight line (30 deg to x) that passes beside the top of
    the layer sphere; the limit curves translate, shrink and rotate with ``psi``."""
    from ..configuration import SphereOnLayer

    sph = SphereOnLayer(1.0, mu)
    path = sph.straight_path(np.radians(30.0), 1.0, 201)
    ax = limit_evolution(sph, path, ax, title=f"Fig. 9: sphere sliding over a layer sphere (+), mu = {mu}")
    ax.plot(1 / np.sqrt(3), 0.0, "k+", ms=10)
    ax.add_patch(__import__("matplotlib.patches", fromlist=["Circle"]).Circle(
        (1 / np.sqrt(3), 0.0), 0.5, fill=False, ls=":", color="0.5"))
    return ax


def softening_curve(ax=None, mu: float = 0.3):
    """T(|u|): the force component along the motion that keeps a grain sliding, exact (lines)
    and from the incremental rate form with 40 explicit Euler steps (markers), for a cylinder
    over two neighbours and a sphere over the top of the single layer sphere and beside it."""
    import matplotlib.pyplot as plt

    from ..configuration import CylinderOnLayer, SphereOnLayer

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4.5))
    cyl = CylinderOnLayer(1.0, mu)
    sph = SphereOnLayer(1.0, mu)
    cases = [(cyl, 0.0, 1.999, "cylinder", "C0"),
             (sph, 0.0, 1.0, "sphere, over the top", "C1"),
             (sph, np.radians(30.0), 1.0, "sphere, 30 deg beside the top", "C2")]
    for model, th, length, label, col in cases:
        e = np.array([np.cos(th), np.sin(th)])
        ex = model.displacement_path(model.straight_path(th, length, 401))
        ax.plot(ex.distance, ex.force @ e / model.Q, color=col, label=f"{label} (exact)")
        inc = model.displacement_path(model.straight_path(th, length, 41), "incremental")
        ax.plot(inc.distance, inc.force @ e / model.Q, "o", color=col, ms=3.5, mfc="none",
                label=f"{label} (incremental, 40 steps)")
    ax.axhline(mu, color="0.5", ls="--", lw=0.8)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.annotate("mu Q: top of the neighbour", (1.2, mu), xytext=(0, 4), textcoords="offset points",
                fontsize=8)
    ax.set_xlabel("|u| / d")
    ax.set_ylabel("T (along the motion) / Q")
    ax.set_title(f"Contact softening: force to keep sliding, mu = {mu}")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return ax


def pocket_peak_force(ax=None, mu: float = 0.3, n: int = 361):
    """Polar plot: peak force ``|T|/Q`` to push a sphere out of a square or hexagonal pocket.

    Solid: against the direction of the force (break-out by the first admissible mechanism,
    :mod:`frictionrules.configuration.pockets`), thick where the grain rides the ridge between
    two layer spheres (climbs over two at once), thin where it climbs over one. Dashed: against
    the direction of a prescribed straight displacement (largest force on the way up).
    """
    import matplotlib.pyplot as plt

    from ..configuration import SphereOnLayer

    if ax is None:
        _, ax = plt.subplots(figsize=(6.5, 6.5), subplot_kw={"projection": "polar"})
    th = np.linspace(0.0, 2 * np.pi, n)
    for packing, col in (("square", "C0"), ("hexagonal", "C3")):
        sph = SphereOnLayer(1.0, mu, packing=packing)
        bo = sph.breakout_force(th)
        ax.plot(th, bo.peak, color=col, lw=1.0, label=f"{packing}: force direction, over one")
        ax.plot(th, np.where(bo.count == 2, bo.peak, np.nan), color=col, lw=3.5, alpha=0.7,
                label=f"{packing}: force direction, over two (ridge)")
        pk = sph.peak_force(th[::4], n=61)
        ax.plot(pk.direction, pk.peak, "--", color=col, lw=0.8,
                label=f"{packing}: displacement direction")
    ax.set_title(f"peak |T|/Q to leave the pocket, mu = {mu}", fontsize=10)
    ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.12, -0.2), ncol=2)
    return ax
