"""Figures of §2 for asperity mechanisms: Figs. 5, 6 (a, b), 7 and a polar mu(theta) of a
height map."""

from __future__ import annotations

import numpy as np

from ..asperities import TwoFlankAsperity, from_heightmap
from ..asperities.surfaces import machined_surface
from ._layout import label, legend_beside, place_labels, polar_radius_labels

FIG5 = dict(alpha1=np.pi / 3, alpha2=5 * np.pi / 6, mu=1.0)
#: Fig. 7 needs delta + rho < pi/2 for the associated two-flank mechanism; mu = 1 of Fig. 5 is
#: the degenerate limit (see docs/asperities.md), so mu = 0.5 is used.
FIG7 = dict(alpha1=np.pi / 3, alpha2=5 * np.pi / 6, mu=0.5)
_COLORS = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown")


def _axes(ax, projection=None, size=(5.5, 5.0)):
    import matplotlib.pyplot as plt
    if ax is not None:
        return ax
    fig = plt.figure(figsize=size)
    return fig.add_subplot(111, projection=projection)


def _pieces(curve, box):
    """Runs of consecutive finite points with the same mechanism, clipped to ``|T| <= box``."""
    lab = curve.labels
    ok = np.isfinite(curve.load) & (np.max(np.abs(curve.T), axis=-1, initial=0.0) <= box)
    runs, start = [], None
    n = len(lab)
    for i in range(n + 1):
        same = i < n and ok[i] and start is not None and lab[i] == lab[start]
        if start is not None and not same:
            runs.append((lab[start], np.arange(start, i)))
            start = None
        if i < n and ok[i] and start is None:
            start = i
    return runs


def limit_curve(law, Q: float = 1.0, ax=None, box: float = 4.0, potentials: bool = True,
                corners: bool = True, style: str = "-", label_prefix: str = "", n: int = 1440,
                lw: float = 1.8, alpha: float = 1.0):
    """Limit curve of a facet law at fixed Q, coloured by mechanism, with the concave corners
    and (optionally) the potential of each mechanism through a point of its piece ((2.14),
    (2.15): ellipses for one facet, straight lines for two), drawn with the line ``style``,
    width ``lw`` and opacity ``alpha``."""
    ax = _axes(ax)
    curve = law.limit_curve(Q, n=n)
    mechs = sorted({lab for lab, _ in _pieces(curve, box)})
    color = {m: _COLORS[i % len(_COLORS)] for i, m in enumerate(mechs)}
    seen, drawn = set(), set()
    for lab, idx in _pieces(curve, box):
        ax.plot(*curve.T[idx].T, style, color=color[lab], lw=lw, alpha=alpha,
                label=None if lab in seen else label_prefix + law.mechanism_name(lab))
        mid = idx[len(idx) // 2]
        # one potential per mechanism (the two-facet one per sliding sense: g = +-Ty (2.15))
        key = (lab, tuple(np.sign(np.round(curve.velocity[mid], 9))) if "+" in lab else ())
        if potentials and key not in drawn:
            _potential(ax, law, curve, mid, Q, box, color[lab])
            drawn.add(key)
        seen.add(lab)
    if corners:
        for c in curve.concave_corners:
            if np.max(np.abs(c.T)) <= box:
                ax.plot(*c.T, "ko", ms=5, mfc="none")
                label(ax, f"{np.rad2deg(c.interior):.1f}°", c.T)
    ax.plot(0, 0, "k+")
    ax.set_xlim(-box, box)
    ax.set_ylim(-box, box)
    ax.set_aspect("equal")
    ax.set_xlabel("tangential force " + ("$T_x/Q$" if Q == 1 else "$T_x$"))
    ax.set_ylabel("tangential force " + ("$T_y/Q$" if Q == 1 else "$T_y$"))
    ax.grid(alpha=0.3)
    place_labels(ax, ax.texts)
    return ax


#: Mechanism families of :func:`surface_limit_curve`: number of sliding facets -> (name, colour).
_FAMILIES = {1: ("one facet slides", "tab:blue"),
             2: ("two facets slide, along their common edge", "tab:red")}


def surface_limit_curve(curve, ax=None, box: float | None = None, labels: int = 8):
    """Limit curve of a facet set with many facets (a measured surface), at the ``Q`` of
    ``curve`` (a :class:`~frictionrules.LimitCurve`, e.g. ``law.limit_curve(Q).merged()``).

    Drawn for hundreds of facets: the curve is coloured by mechanism family (one facet
    sliding, or two along their common edge; a legend of two entries, not one per facet), the
    concave corners of ``curve`` are marked and the ``labels`` most re-entrant ones carry their
    interior angle where the label fits clear of the curve and of the other labels (every
    corner is in the corners table of ``frictionrules asperity --out``). No potentials: one
    per facet would cross the frame. Only the part of the curve with ``|Tx|, |Ty| <= box`` is
    drawn (default: all of it), in limits that fit it and the origin. Returns the Axes.
    """
    ax = _axes(ax, size=(6.0, 6.0))
    T, Q = curve.T, curve.Q
    fin = np.all(np.isfinite(T), axis=-1)
    if box is None:
        box = 1.1 * float(np.abs(T[fin]).max()) if fin.any() else 1.0
    count = np.sum(curve.facets >= 0, axis=-1)
    shown = fin & (np.max(np.abs(np.where(fin[:, None], T, 0.0)), axis=-1) <= box)
    for k, (name, colour) in _FAMILIES.items():
        mask = shown & (count == k)
        mask |= np.roll(mask, 1) & shown    # and the segment to the next family: no gap
        xy = np.where(mask[:, None], T, np.nan)
        ax.plot(*np.concatenate((xy, xy[:1])).T, "-", color=colour, lw=2.0, label=name)
    corners = [c for c in curve.concave_corners if np.max(np.abs(c.T)) <= box]
    if corners:
        xy = np.array([c.T for c in corners])
        ax.plot(*xy.T, "ko", ms=4.5, mfc="none", label="concave corners (interior angle: the "
                "most re-entrant,\nwhere readable; every corner in the corners table)")
    ax.plot(0, 0, "k+", label="origin $T = 0$")
    seen = np.vstack((T[shown], np.zeros((1, 2))))      # the curve and the origin, with margins
    lo, hi = seen.min(axis=0), seen.max(axis=0)
    pad = 0.08 * max(float(np.max(hi - lo)), 1e-300)
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("tangential force " + ("$T_x/Q$" if Q == 1 else "$T_x$"))
    ax.set_ylabel("tangential force " + ("$T_y/Q$" if Q == 1 else "$T_y$"))
    ax.grid(alpha=0.3)
    legend_beside(ax, "below", ncol=1)
    if corners:                             # last: the layout is final
        worst = sorted(corners, key=lambda c: -c.interior)[:labels]
        place_labels(ax, [label(ax, f"{np.rad2deg(c.interior):.1f}°", c.T) for c in worst],
                     drop=True)
    return ax


def _normals(law) -> np.ndarray:
    """Unit facet normals ``(K, 3)`` of a facet law (a method of a two-flank asperity, an
    attribute of a facet set)."""
    n = law.normals
    return np.asarray(n() if callable(n) else n, dtype=float)


def _potential(ax, law, curve, i, Q, box, color):
    """Level set of the mechanism's potential at fixed Q through the limit point ``i``."""
    T = curve.T[i]
    ids = [int(k) for k in curve.facets[i] if k >= 0]
    if len(ids) == 2:                       # g = V.F: a straight line V_h.T = V_z Q + C
        V = curve.velocity[i]
        C = V[:2] @ T - V[2] * Q
        e = np.array([-V[1], V[0]]) / np.hypot(V[0], V[1])
        p0 = V[:2] * (C + V[2] * Q) / (V[:2] @ V[:2])
        s = np.linspace(-3 * box, 3 * box, 2)
        ax.plot(*(p0 + s[:, None] * e).T, ":", color=color, lw=1)
        return
    n = _normals(law)[ids[0]]
    # g = |F_t| = C: an ellipse about the load with F parallel to n (no in-plane force)
    centre = -Q * n[:2] / n[2]
    F = np.array([*T, -Q])
    C = np.linalg.norm(F - (F @ n) * n)
    psi = np.linspace(0, 2 * np.pi, 361)
    e = np.stack((np.cos(psi), np.sin(psi), 0 * psi), axis=-1)
    r = C / np.linalg.norm(e - (e @ n)[:, None] * n, axis=-1)
    ax.plot(*(centre + r[:, None] * e[:, :2]).T, ":", color=color, lw=1)


def fig5_two_flank(ax=None):
    """Fig. 5: limit curve f = 0 ((2.9), (2.12)) and potentials g = 0 ((2.14), (2.15)) of the
    two-flank asperity, alpha1 = pi/3, alpha2 = 5 pi/6, mu = 1, with its concave corners."""
    law = TwoFlankAsperity(**FIG5)
    ax = limit_curve(law, ax=ax, box=4.0)
    ax.plot([], [], "k:", lw=1, label="potentials $g = 0$ through a point of each piece,\n"
            "ellipses (2.14), lines $T_y = \\pm C$ (2.15)")
    ax.plot([], [], "ko", mfc="none", label="concave corners (interior angle)")
    ax.plot([], [], "k+", label="origin $T = 0$")
    ax.set_title("Fig. 5  limit curve $f = 0$ (2.9), (2.12) and potentials $g = 0$, $Q$ = 1\n"
                 "two flanks $\\alpha_1 = \\pi/3$, $\\alpha_2 = 5\\pi/6$, $\\mu$ = 1", fontsize=10)
    legend_beside(ax, "right")
    return ax


def _section(curve, box):
    """The finite part of a limit curve within ``|T| <= box`` as one run ordered by direction
    (rolled so that a locked or clipped gap, if any, falls at the ends): ``(T, labels)``."""
    ok = np.isfinite(curve.load) & (np.max(np.abs(curve.T), axis=-1, initial=0.0) <= box)
    shift = -int(np.argmin(ok)) if not ok.all() else 0
    keep = np.roll(ok, shift)
    return np.roll(curve.T, shift, axis=0)[keep], np.roll(np.array(curve.labels), shift)[keep]


def _pockets(T):
    """Pieces of the polygon ``T`` (ordered along the curve) that lie inside its convex hull:
    where the section is concave. Each is the run of points the hull skips, closed by the hull
    chord; slivers of the discretization (area < 1e-4 of the hull) are dropped."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(T)
    out = []
    for a, b in zip(*(lambda v: (v[:-1], v[1:]))(np.sort(hull.vertices))):
        poly = T[a:b + 1]
        area = 0.5 * abs(poly[:, 0] @ np.roll(poly[:, 1], 1) - poly[:, 1] @ np.roll(poly[:, 0], 1))
        if b - a > 1 and area > 1e-4 * hull.volume:
            out.append(poly)
    return out


def fig6a_limit_surface(ax=None, q_max: float = 1.0, box: float = 4.0):
    """Fig. 6a: the limit surface f = 0 in (Tx, Ty, Q): a cone over the Fig. 5 curve.

    Seen from above, with the section at ``Q = q_max`` drawn: where the section falls short of
    its convex hull (shaded) the surface is concave; the generators through the concave corners
    of Fig. 5 are its concave edges.
    """
    from matplotlib.colors import LightSource, to_rgb
    from matplotlib.patches import Patch
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax = _axes(ax, "3d", size=(7.5, 6.0))
    law = TwoFlankAsperity(**FIG5)
    curve = law.limit_curve(1.0, n=360)
    T, labels = _section(curve, box / q_max)
    T = q_max * T
    color = {"0": _COLORS[0], "0+1": _COLORS[1], "1": _COLORS[2]}   # as in Fig. 5
    s = np.linspace(0.0, 1.0, 13)[:, None]
    rgb = 0.4 + 0.6 * np.array([to_rgb(color[lab]) for lab in labels])
    faces = np.concatenate((np.broadcast_to(rgb[None, :-1], (len(s) - 1, len(T) - 1, 3)),
                            np.full((len(s) - 1, len(T) - 1, 1), 0.8)), axis=-1)
    ax.plot_surface(s * T[:, 0], s * T[:, 1], np.broadcast_to(s * q_max, (len(s), len(T))),
                    facecolors=faces, shade=True, lightsource=LightSource(azdeg=315, altdeg=65),
                    linewidth=0, rstride=1, cstride=1)
    ax.plot(T[:, 0], T[:, 1], q_max, "k", lw=1.2, label=f"section $Q$ = {q_max:g} (Fig. 5)")
    for poly in _pockets(T):
        ax.add_collection3d(Poly3DCollection([np.column_stack((poly, np.full(len(poly), q_max)))],
                                             facecolor="gold", edgecolor="k", linestyle="--",
                                             lw=0.8, alpha=0.55))
    for k, c in enumerate(curve.concave_corners):
        ax.plot([0.0, q_max * c.T[0]], [0.0, q_max * c.T[1]], [0.0, q_max], "k-", lw=1.8,
                label=None if k else "concave edges (through the corners of Fig. 5)")
    handles = [Patch(color=0.4 + 0.6 * np.array(to_rgb(color[k])), label=name)
               for k, name in (("0", "flank 1 slides"), ("0+1", "both flanks slide"),
                               ("1", "flank 2 slides"))]
    handles.append(Patch(facecolor="gold", edgecolor="k", linestyle="--",
                         label="between the section and its convex hull: concave"))
    ax.set_xlabel("$T_x$")
    ax.set_ylabel("$T_y$")
    ax.set_zlabel("$Q$")
    ax.set_box_aspect((1.0, 1.0, 0.5))
    ax.set_zticks([0.0, 0.5 * q_max, q_max])     # the Q axis is short seen from above
    ax.view_init(elev=60, azim=-105)
    ax.set_title(f"Fig. 6a  limit surface $f = 0$ in $(T_x, T_y, Q)$: a cone over the limit curve "
                 f"of Fig. 5\n$\\alpha_1 = \\pi/3$, $\\alpha_2 = 5\\pi/6$, $\\mu$ = 1, "
                 f"$|T_x|, |T_y| \\leq$ {box:g} shown", fontsize=9)
    legend_beside(ax, "below", handles=ax.get_legend_handles_labels()[0] + handles, ncol=2)
    return ax


def fig6b_potential_surface(ax=None, C: float = 1.0, q_max: float = 1.0):
    """Fig. 6b: the potential surfaces g = C in (Tx, Ty, Q): the climbing halves of the
    elliptic cylinders (2.14) of the flanks joined by the planes Ty = +-C (2.15)."""
    ax = _axes(ax, "3d")
    law = TwoFlankAsperity(**FIG5)
    Qs = np.linspace(0.0, q_max, 12)
    psi = np.linspace(-np.pi / 2, np.pi / 2, 61)
    for k, a in enumerate((law.alpha1, law.alpha2)):
        # in-plane load C (cos psi, sin psi), T1 >= 0 (climbing); Tx from (2.1)
        T1, T2 = C * np.cos(psi), C * np.sin(psi)
        X = (T1[None, :] + Qs[:, None] * np.sin(a)) / np.cos(a)
        Y = np.broadcast_to(T2[None, :], X.shape)
        Z = np.broadcast_to(Qs[:, None], X.shape)
        ax.plot_surface(X, Y, Z, color=_COLORS[2 * k], alpha=0.45, linewidth=0)
    s = np.linspace(0.0, 1.0, 2)
    for sign in (1.0, -1.0):
        t1, t2 = np.tan(law.alpha1), np.tan(law.alpha2)
        X = Qs[:, None] * (t2 + s[None, :] * (t1 - t2))
        ax.plot_surface(X, np.full(X.shape, sign * C), np.broadcast_to(Qs[:, None], X.shape),
                        color=_COLORS[1], alpha=0.45, linewidth=0)
    from matplotlib.patches import Patch
    ax.set_xlabel("$T_x$")
    ax.set_ylabel("$T_y$")
    ax.set_zlabel("$Q$")
    ax.set_yticks([-C, 0.0, C])
    ax.set_title(f"Fig. 6b  potential surfaces $g = C$ in $(T_x, T_y, Q)$, $C$ = {C:g}\n"
                 "$\\alpha_1 = \\pi/3$, $\\alpha_2 = 5\\pi/6$, $\\mu$ = 1", fontsize=10)
    ax.view_init(elev=25, azim=-60)
    legend_beside(ax, "below", ncol=2, handles=[
        Patch(color=_COLORS[0], alpha=0.45, label="flank 1: elliptic cylinder (2.14)"),
        Patch(color=_COLORS[2], alpha=0.45, label="flank 2: elliptic cylinder (2.14)"),
        Patch(color=_COLORS[1], alpha=0.45, label="both flanks: planes $T_y = \\pm C$ (2.15)")])
    return ax


def fig7_associated(ax=None):
    """Fig. 7: limit curves for the associated local rule (1.6) (solid, convex and smooth) and
    the non-associated one (broken, concave corners), alpha1 = pi/3, alpha2 = 5 pi/6, mu = 0.5."""
    ax = _axes(ax)
    # the associated curve wide and pale under the narrow dashed one: where they coincide
    # (one flank sliding) both stay visible
    for local, style, lw, alpha in (("associated", "-", 4.0, 0.4),
                                    ("non-associated", "--", 1.5, 1.0)):
        law = TwoFlankAsperity(**FIG7, local=local)
        limit_curve(law, ax=ax, box=6.0, potentials=False, corners=local == "non-associated",
                    style=style, label_prefix=f"{local}: ", lw=lw, alpha=alpha)
    ax.set_xlim(-2.0, 4.0)                 # the corners and the both-flank lines, enlarged
    ax.set_ylim(-2.5, 2.5)
    ax.plot([], [], "ko", mfc="none", label="concave corners, non-associated\n(interior angle)")
    ax.plot([], [], "k+", label="origin $T = 0$")
    ax.set_title("Fig. 7  limit curves $f = 0$: associated local rule (1.6) (solid, wide) and\n"
                 "non-associated (1.5) (broken), $\\alpha_1 = \\pi/3$, $\\alpha_2 = 5\\pi/6$, "
                 "$\\mu$ = 0.5, $Q$ = 1", fontsize=10)
    place_labels(ax, ax.texts)
    legend_beside(ax, "right")
    return ax


def heightmap_polar(ax=None, mu: float = 0.2, n: int = 512):
    """Polar mu(theta) of a synthetic machined 512 x 512 height map (grooves along y plus
    roughness), from :func:`frictionrules.from_heightmap`; mu(theta) is the coefficient for
    sliding at theta."""
    import matplotlib.pyplot as plt
    if ax is None:
        ax = plt.figure(figsize=(5.5, 5.0)).add_subplot(111, projection="polar")
    h = machined_surface(n)
    law = from_heightmap(h, 1.0, 1.0, mu)
    theta = np.linspace(-np.pi, np.pi, 721)
    m = law.friction_coefficient(theta)
    ax.plot(theta, m, "k", label=f"machined map, {len(law.normals)} facet groups")
    ax.plot(theta, np.full_like(theta, mu), "k:", lw=0.8, label=f"local $\\mu$ = {mu:g}")
    ax.set_title(f"friction coefficient $\\mu(\\theta)$ for sliding at $\\theta$ of a synthetic "
                 f"machined\n{n} x {n} height map (grooves along $y$ plus roughness)", fontsize=10, pad=14)
    legend_beside(ax, "below", ncol=2)
    polar_radius_labels(ax)
    return ax
