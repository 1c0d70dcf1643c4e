"""Figures of §2 for asperity mechanisms: Figs. 5, 6 (a, b), 7 and a polar mu(theta) of a
height map."""

from __future__ import annotations

import numpy as np

from ..asperities import TwoFlankAsperity, from_heightmap
from ..asperities.surfaces import machined_surface

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
                corners: bool = True, style: str = "-", label_prefix: str = "", n: int = 1440):
    """Limit curve of a facet law at fixed Q, coloured by mechanism, with the concave corners
    and (optionally) the potential of each mechanism through a point of its piece ((2.14),
    (2.15): ellipses for one facet, straight lines for two)."""
    ax = _axes(ax)
    curve = law.limit_curve(Q, n=n)
    mechs = sorted({lab for lab, _ in _pieces(curve, box)})
    color = {m: _COLORS[i % len(_COLORS)] for i, m in enumerate(mechs)}
    seen, drawn = set(), set()
    for lab, idx in _pieces(curve, box):
        if isinstance(law, TwoFlankAsperity):
            name = {"0": "flank 1", "1": "flank 2", "0+1": "both flanks"}[lab]
        else:
            name = f"facet{'s' if '+' in lab else ''} {lab}"
        ax.plot(*curve.T[idx].T, style, color=color[lab], lw=1.8,
                label=None if lab in seen else label_prefix + name)
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
                ax.annotate(f"{np.rad2deg(c.interior):.1f}°", c.T, textcoords="offset points",
                            xytext=(6, -12 if c.T[1] < 0 else 6), fontsize=8)
    ax.plot(0, 0, "k+")
    ax.set_xlim(-box, box)
    ax.set_ylim(-box, box)
    ax.set_aspect("equal")
    ax.set_xlabel("$T_x/Q$" if Q == 1 else "$T_x$")
    ax.set_ylabel("$T_y/Q$" if Q == 1 else "$T_y$")
    ax.grid(alpha=0.3)
    return ax


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
    n = law._facets.normal_array[ids[0]]
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
    ax.plot([], [], "k:", lw=1, label="potentials (2.14), (2.15)")
    ax.plot([], [], "ko", mfc="none", label="concave corners (interior angle)")
    ax.set_title("Fig. 5  two flanks: $\\alpha_1 = \\pi/3$, $\\alpha_2 = 5\\pi/6$, $\\mu$ = 1")
    ax.legend(loc="lower left", fontsize=7)
    return ax


def fig6a_limit_surface(ax=None, q_max: float = 1.0, box: float = 3.0):
    """Fig. 6a: the limit surface f = 0 in (Tx, Ty, Q): a cone over the Fig. 5 curve."""
    ax = _axes(ax, "3d")
    law = TwoFlankAsperity(**FIG5)
    curve = law.limit_curve(1.0, n=1440)
    Qs = np.linspace(0.0, q_max, 12)
    color = {"0": _COLORS[0], "0+1": _COLORS[1], "1": _COLORS[2]}   # as in Fig. 5
    for lab, idx in _pieces(curve, box / q_max):
        P = curve.T[idx]
        X, Y = Qs[:, None] * P[None, :, 0], Qs[:, None] * P[None, :, 1]
        Z = np.broadcast_to(Qs[:, None], X.shape)
        ax.plot_surface(X, Y, Z, color=color[lab], alpha=0.45, linewidth=0)
    ax.set_xlabel("$T_x$")
    ax.set_ylabel("$T_y$")
    ax.set_zlabel("$Q$")
    ax.set_title("Fig. 6a  limit surface $f = 0$\n(blue: flank 1, red: both flanks, "
                 "green: flank 2)", fontsize=9)
    ax.view_init(elev=25, azim=-60)
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
    ax.set_xlabel("$T_x$")
    ax.set_ylabel("$T_y$")
    ax.set_zlabel("$Q$")
    ax.set_title("Fig. 6b  potential surfaces $g = C$ (2.14), (2.15)")
    ax.view_init(elev=25, azim=-60)
    return ax


def fig7_associated(ax=None):
    """Fig. 7: limit curves for the associated local rule (1.6) (solid, convex and smooth) and
    the non-associated one (broken, concave corners), alpha1 = pi/3, alpha2 = 5 pi/6, mu = 0.5."""
    ax = _axes(ax)
    for local, style in (("associated", "-"), ("non-associated", "--")):
        law = TwoFlankAsperity(**FIG7, local=local)
        limit_curve(law, ax=ax, box=6.0, potentials=False, corners=local == "non-associated",
                    style=style, label_prefix=f"{local}: ")
    ax.set_xlim(-2.0, 4.0)                 # the corners and the both-flank lines, enlarged
    ax.set_ylim(-2.5, 2.5)
    ax.set_title("Fig. 7  associated (solid) and non-associated (broken), $\\mu$ = 0.5")
    ax.legend(loc="lower left", fontsize=7)
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
    ax.set_title("$\\mu(\\theta)$ of a 512 x 512 height map", fontsize=10)
    ax.legend(loc="lower left", fontsize=7, bbox_to_anchor=(-0.1, -0.12))
    return ax
