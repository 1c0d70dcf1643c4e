"""Figures of §3: evolution of the limit curves along a path (Figs. 8, 9) with the force along
the path, the exact and incremental softening curves T(|u|) and the direction-dependent peak
force of a grain in a square or hexagonal pocket."""

from __future__ import annotations

import numpy as np

from ._layout import arrow, label, legend_beside, place_labels, polar_radius_labels

__all__ = ["limit_evolution", "path_force", "cylinder_limit_evolution", "sphere_limit_evolution",
           "softening_curve", "pocket_peak_force"]

#: Diameter and local friction of the §3 figures; the vertical load is the default Q = 1, so
#: forces read in units of Q.
_D = 1.0


def _stations(res, points: int) -> np.ndarray:
    return np.linspace(0, len(res.position) - 1, points).round().astype(int)


def _colours(points: int):
    import matplotlib.pyplot as plt
    return plt.cm.viridis(np.linspace(0.0, 0.85, points))


def _nice(x: float) -> float:
    """The largest of 1, 2, 5 times a power of ten not above ``x``."""
    e = 10.0 ** np.floor(np.log10(x))
    return max(m * e for m in (1.0, 2.0, 5.0) if m * e <= x)


def _apart_scale(origins, curves, cap: float) -> float:
    """The force scale (length per unit force, at most ``cap``) at 85 % of the one at which
    the limit curves drawn about consecutive stations first touch (bisection on the scale; a
    curve touches its neighbour when a point of one lies inside the other)."""
    from matplotlib.path import Path

    def apart(scale):
        for k in range(len(curves) - 1):
            a, b = origins[k] + scale * curves[k], origins[k + 1] + scale * curves[k + 1]
            if Path(a).contains_points(b).any() or Path(b).contains_points(a).any():
                return False
        return True

    if apart(cap):
        return cap
    lo, hi = 0.0, cap
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if apart(mid) else (lo, mid)
    return 0.85 * lo


def limit_evolution(model, path, ax=None, points: int = 6, scale: float | None = None,
                    title: str | None = None, force_ax=None):
    """Limit curves f = 0 drawn in the displacement plane at ``points`` stations of ``path``.

    The trajectory is drawn in the plane ``(u_x/d, u_y/d)`` (displacements in grain diameters
    ``d``); at each station (numbered 1, 2, ...) the force axes ``(T_x/Q, T_y/Q)`` are
    attached (the local frame translating along the path, as in Figs. 8 and 9), with the limit
    curve of the current configuration and the force ``T`` that keeps the grain sliding, both
    scaled by ``scale`` (diameters per unit of ``T/Q``; by default the largest that keeps
    neighbouring curves apart). A scale bar under the axes gives the force scale.

    When ``ax`` is omitted the figure has a second panel, ``force_ax``, with the companion
    plot of ``|T|/Q`` against the distance travelled (:func:`path_force`), as tall as the
    first; pass both ``ax`` and ``force_ax`` to draw the pair on given axes. Returns ``ax``.
    """
    import matplotlib.pyplot as plt

    res = model.displacement_path(path)
    d, Q = model.diameter, model.Q
    idx = _stations(res, points)
    direction = float(np.arctan2(*(res.position[-1] - res.position[0])[::-1]))
    curves = [model.limit_curve(model.state_at(res.position[i], direction)) / Q for i in idx]
    origins = res.position[idx] / d
    if scale is None:
        step = np.hypot(*(origins[1] - origins[0]))
        scale = _apart_scale(origins, curves, cap=2.0 * step / max(np.ptp(c, axis=0).max()
                                                                     for c in curves))
    force = res.force / Q
    if ax is None:                      # the left panel as tall as its data at equal aspect
        drawn = np.concatenate([res.position / d] + [o + scale * c for o, c in zip(origins, curves)]
                               + [origins + scale * force[idx]])
        ratio = np.ptp(drawn[:, 1]) / np.ptp(drawn[:, 0])
        height = float(np.clip(5.2 * ratio, 2.6, 6.0))     # the left box is about 5.2 in wide
        fig, (ax, force_ax) = plt.subplots(1, 2, figsize=(12.0, height + 1.3),
                                           gridspec_kw={"width_ratios": (1.35, 1.0), "wspace": 0.28})
        ax.set_aspect("equal", adjustable="datalim")
    else:
        ax.set_aspect("equal")
    ax.plot(res.position[:, 0] / d, res.position[:, 1] / d, "k-", lw=1.0,
            label="trajectory $u/d$ of the centre")
    colours = _colours(points)
    numbers = []
    for m, (i, col, curve, o) in enumerate(zip(idx, colours, curves, origins), start=1):
        ax.plot(o[0] + scale * curve[:, 0], o[1] + scale * curve[:, 1], color=col, lw=1.4,
                label=f"{m}: $f = 0$ at $\\alpha$ = {np.degrees(res.alpha[i]) + 0.0:.1f}°"
                      + ("" if model.layer.cylindrical
                         else f", $\\psi$ = {np.degrees(res.psi[i]) + 0.0:.0f}°"))
        arrow(ax, o, o + scale * force[i], col,
              label="force $T/Q$ that keeps the grain sliding" if m == 1 else None)
        ax.plot(*o, "o", color=col, ms=4, label="stations 1–6: origins of the force axes" if m == 1 else None)
        numbers.append(label(ax, str(m), o, fontsize=9))
    ax.margins(0.08)
    ax.set_xlabel("displacement $u_x/d$; force $T_x/Q$ about each station")
    ax.set_ylabel("displacement $u_y/d$; force $T_y/Q$\nabout each station")
    ax.set_title(title or "limit curves along the path", fontsize=10)
    ax.grid(alpha=0.3)
    place_labels(ax, numbers)
    _force_scale_bar(ax, scale, max(np.abs(np.concatenate(curves)).max(), 1e-300))
    _stations_legend(ax)
    if force_ax is not None:
        path_force(model, path, ax=force_ax, points=points, result=res)
    return ax


def _stations_legend(ax):
    """Legend under the axes: the marks first, then the limit curves of the stations in order."""
    handles, labels = ax.get_legend_handles_labels()
    order = sorted(range(len(labels)), key=lambda k: (labels[k][:1].isdigit(), k))
    return legend_beside(ax, "below", ncol=2, handles=[handles[k] for k in order],
                         labels=[labels[k] for k in order])


def _force_scale_bar(ax, scale: float, fmax: float):
    """A bar under the axes whose length is a round force in the data units of the plot."""
    from matplotlib.offsetbox import AnchoredOffsetbox, AuxTransformBox, HPacker, TextArea
    from matplotlib.patches import Rectangle

    F = _nice(0.5 * fmax)
    fig = ax.figure
    fig.draw_without_rendering()
    box = ax.get_tightbbox(fig.canvas.get_renderer())
    y0 = ax.transAxes.inverted().transform((box.x0, box.y0))[1]
    bar = AuxTransformBox(ax.transData)
    bar.add_artist(Rectangle((0, 0), scale * F, 0, ec="k", lw=2.5))
    packed = HPacker(children=[TextArea(f"force scale: |T|/Q = {F:g}", textprops={"size": 8}), bar],
                     align="center", pad=0, sep=8)
    anchored = AnchoredOffsetbox(loc="upper right", child=packed, frameon=False, pad=0.1,
                                 bbox_to_anchor=(1.0, y0 - 0.01), bbox_transform=ax.transAxes)
    ax.add_artist(anchored)
    # the legend goes below the bar: make the bar part of the axes' tight box
    anchored.set_in_layout(True)
    return anchored


def path_force(model, path, ax=None, points: int = 6, result=None):
    """Companion of :func:`limit_evolution`: the force ``|T|/Q`` that keeps the grain sliding
    along ``path`` (and its component along the motion) against the distance travelled
    ``|u|/d``, with the stations 1, 2, ... of the limit-curve plot marked in their colours.

    Contact softening (§3): climbing the neighbour flattens the contact plane, so ``|T|``
    falls as ``|u|`` grows."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5.5, 4.2))
    res = model.displacement_path(path) if result is None else result
    d, Q = model.diameter, model.Q
    u, T = res.distance / d, res.force_magnitude / Q
    ax.plot(u, T, "k-", lw=1.2, label="$|T|/Q$ to keep sliding")
    e = (res.position[-1] - res.position[0]) / max(np.hypot(*(res.position[-1] - res.position[0])), 1e-300)
    ax.plot(u, res.force @ e / Q, "k--", lw=0.9, label="$T \\cdot e/Q$ along the motion $e$")
    numbers = []
    for m, (i, col) in enumerate(zip(_stations(res, points), _colours(points)), start=1):
        ax.plot(u[i], T[i], "o", color=col, ms=6, label="stations 1–6 of the left panel" if m == 1 else None)
        numbers.append(label(ax, str(m), (u[i], T[i]), fontsize=9))
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.margins(x=0.04, y=0.12)
    ax.set_xlabel("distance travelled $|u|/d$")
    ax.set_ylabel("force to keep sliding $|T|/Q$, $T \\cdot e/Q$")
    ax.set_title("force along the path: contact softening", fontsize=10)
    ax.grid(alpha=0.3)
    place_labels(ax, numbers)
    legend_beside(ax, "below", ncol=1)
    return ax


def cylinder_limit_evolution(ax=None, mu: float = 0.3):
    """Fig. 8: a cylinder pushed obliquely (20 deg to x) from the groove to the top of its
    neighbour; the limit ellipses (2.2) shrink towards the circle ``|T| = mu Q`` and their
    centre ``Q tan(alpha)`` moves to the origin: contact softening. Diameter d = 1, Q = 1."""
    from ..configuration import CylinderOnLayer

    cyl = CylinderOnLayer(diameter=_D, mu=mu)
    th = np.radians(20.0)
    path = cyl.straight_path(th, 0.5 / np.cos(th), 201)
    return limit_evolution(cyl, path, ax, title=f"Fig. 8  cylinder sliding on a layer of cylinders, "
                                                 f"pushed at 20° to $x$\n$d$ = 1, $Q$ = 1, $\\mu$ = {mu:g}")


def sphere_limit_evolution(ax=None, mu: float = 0.3):
    """Fig. 9: a sphere pushed along a straight line (30 deg to x) that passes beside the top of
    the layer sphere; the limit curves translate, shrink and rotate with ``psi``. Diameter
    d = 1, Q = 1."""
    from ..configuration import SphereOnLayer

    sph = SphereOnLayer(diameter=_D, mu=mu)
    path = sph.straight_path(np.radians(30.0), 1.0, 201)
    ax = limit_evolution(sph, path, ax, title=f"Fig. 9  sphere sliding on a layer sphere, pushed at "
                                              f"30° to $x$\n$d$ = 1, $Q$ = 1, $\\mu$ = {mu:g}")
    # the layer sphere's centre, at (d / sqrt(3), 0) from the pocket (the "single" layer)
    ax.plot(1.0 / np.sqrt(3.0), 0.0, "k+", ms=10, label="top of the layer sphere")  # (d/√3, 0)/d
    _stations_legend(ax)
    return ax


def softening_curve(ax=None, mu: float = 0.3):
    """T(|u|): the force component along the motion that keeps a grain sliding, exact (lines)
    and from the incremental rate form with 40 explicit Euler steps (markers), for a cylinder
    over two neighbours and a sphere over the top of the single layer sphere and beside it."""
    import matplotlib.pyplot as plt

    from ..configuration import CylinderOnLayer, SphereOnLayer

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4.5))
    cyl = CylinderOnLayer(diameter=_D, mu=mu)
    sph = SphereOnLayer(diameter=_D, mu=mu)
    cases = [(cyl, 0.0, 1.999, "cylinder over two neighbours", "C0"),
             (sph, 0.0, 1.0, "sphere, over the top", "C1"),
             (sph, np.radians(30.0), 1.0, "sphere, 30° beside the top", "C2")]
    for model, th, length, text, col in cases:
        e = np.array([np.cos(th), np.sin(th)])
        ex = model.displacement_path(model.straight_path(th, length, 401))
        ax.plot(*_jumps_apart(ex, ex.force @ e), color=col, label=f"{text} (exact)")
        inc = model.displacement_path(model.straight_path(th, length, 41), "incremental")
        ax.plot(inc.distance, inc.force @ e, "o", color=col, ms=3.5, mfc="none",
                label=f"{text} (incremental, 40 Euler steps)")
    ax.axhline(mu, color="0.5", ls="--", lw=0.8, label="$T \\cdot e/Q = \\mu$: on the top of a neighbour")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("distance travelled $|u|/d$")
    ax.set_ylabel("force along the motion $T \\cdot e/Q$")
    ax.set_title(f"contact softening: force to keep sliding, exact and incremental (3.3)–(3.13), "
                 f"$\\mu$ = {mu:g}", fontsize=10)
    ax.grid(alpha=0.3)
    legend_beside(ax, "right")
    return ax


def _jumps_apart(result, values):
    """``(distance, values)`` of a path with a gap (NaN) where the grain moves onto another
    support (no contact shared by consecutive points): the force jumps there, and a line drawn
    across the jump would show forces never reached."""
    cut = [i for i in range(1, len(result.contacts))
           if not set(result.contacts[i]) & set(result.contacts[i - 1])]
    u = np.insert(np.asarray(result.distance, dtype=float), cut, np.nan)
    return u, np.insert(np.asarray(values, dtype=float), cut, np.nan)


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
        sph = SphereOnLayer(diameter=_D, mu=mu, packing=packing)
        bo = sph.breakout_force(th)
        ax.plot(th, bo.peak, color=col, lw=1.0, label=f"{packing}: force direction, climbing over one")
        ax.plot(th, np.where(bo.count == 2, bo.peak, np.nan), color=col, lw=3.5, alpha=0.7,
                label=f"{packing}: force direction, climbing over two (ridge)")
        pk = sph.peak_force(th[::4], n=61)
        ax.plot(pk.direction, pk.peak, "--", color=col, lw=0.8,
                label=f"{packing}: displacement direction")
    ax.set_title(f"peak force $|T|/Q$ to leave a pocket of the layer, against the direction "
                 f"(degrees from $x$)\n$d$ = 1, $\\mu$ = {mu:g}", fontsize=10, pad=14)
    legend_beside(ax, "below", ncol=2)
    ax.set_rticks([0.5, 1.0, 1.5])       # the curves lie at 0.8-1.9: few labels, clear of them
    polar_radius_labels(ax, pad=6.0)
    return ax
