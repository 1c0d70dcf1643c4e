"""Figures of §1–2: Fig. 1 (a, b, c), Fig. 3 (a, b) and the polar mu(theta) comparison."""

from __future__ import annotations

import numpy as np

from ..laws import Coulomb, EllipticOrthotropic, Huber, TransformedCoulomb, WedgeAsperity
from ._layout import arrow, label, legend_beside, place_labels, polar_radius_labels


def _axes(ax, projection=None):
    import matplotlib.pyplot as plt
    if ax is not None:
        return ax
    fig = plt.figure(figsize=(5.5, 5.0))
    return fig.add_subplot(111, projection=projection)


def coulomb_cone(ax=None, mu: float = 0.5, n_max: float = 1.0):
    """Fig. 1a: the Coulomb cone (1.4) in (Tx, Ty, N) with the slips (1.5) and (1.6) at a point."""
    ax = _axes(ax, "3d")
    law = Coulomb(mu)
    phi, n = np.meshgrid(np.linspace(0, 2 * np.pi, 61), np.linspace(0, n_max, 12))
    ax.plot_surface(mu * n * np.cos(phi), mu * n * np.sin(phi), n, alpha=0.25, color="tab:blue",
                    linewidth=0)
    N0 = 0.8 * n_max
    T0 = np.array([mu * N0 * np.cos(0.6), mu * N0 * np.sin(0.6)])
    L = 0.35 * n_max
    for dilatant, color, text in ((False, "tab:red", "(1.5) no normal slip"),
                                   (True, "tab:green", "(1.6) associated, dilatant")):
        v = Coulomb(mu, dilatant).slip_direction(T0, N0)
        # a slip (v1, v2, vn) is drawn in force space as (v1, v2, -vn): conjugate to (T, -N)
        ax.quiver(T0[0], T0[1], N0, L * v[0], L * v[1], -L * v[2], color=color, label=text)
    ax.scatter(*T0, N0, color="k", label="a limit force $(T, N)$ on the cone")
    ax.set_xlabel("$T_x$")
    ax.set_ylabel("$T_y$")
    ax.set_zlabel("$N$")
    ax.set_title(f"Fig. 1a  Coulomb cone $|T| = \\mu N$, $\\mu$ = {law.mu:g}")
    legend_beside(ax, "below", ncol=2)
    return ax


def orthotropic_ellipse(ax=None, mu_x: float = 0.6, mu_y: float = 0.3, N: float = 1.0):
    """Fig. 1b: the orthotropic limit ellipse (1.9) at fixed N with force T and slip V at angles
    beta and alpha, (1.10), (1.14)."""
    ax = _axes(ax)
    law = EllipticOrthotropic(mu_x, mu_y)
    phi = np.linspace(0, 2 * np.pi, 361)
    ax.plot(mu_x * N * np.cos(phi), mu_y * N * np.sin(phi), "k", label="$f = 0$ (1.9)")
    for k, theta in enumerate(np.deg2rad([20.0, 50.0, 75.0, 130.0, 250.0])):
        T = law.force_for_slip([np.cos(theta), np.sin(theta)], N)
        v = law.slip_direction(T, N)
        arrow(ax, np.zeros(2), T, "tab:blue", label=None if k else "force $T$ at angle $\\beta$")
        arrow(ax, T, T + 0.25 * N * v[:2], "tab:red",
              label=None if k else "slip $V$ at angle $\\alpha$ (normal to $f$, (1.10))")
    ax.set_aspect("equal")
    ax.set_xlabel("tangential force " + ("$T_x/N$" if N == 1 else "$T_x$"))
    ax.set_ylabel("tangential force " + ("$T_y/N$" if N == 1 else "$T_y$"))
    ax.set_title(f"Fig. 1b  orthotropic limit, $\\mu_x$ = {mu_x:g}, $\\mu_y$ = {mu_y:g}, $N$ = {N:g}")
    legend_beside(ax, "below", ncol=2)
    ax.grid(alpha=0.3)
    return ax


def dissipation_function(ax=None, mu_x: float = 0.6, mu_y: float = 0.3, N: float = 1.0):
    """Fig. 1c: level lines of the dissipation function (1.12) in the (Vx, Vy) plane.

    :math:`D = N\\sqrt{(\\mu_x V_x)^2 + (\\mu_y V_y)^2}`; its gradient is the force (1.13).
    """
    ax = _axes(ax)
    law = EllipticOrthotropic(mu_x, mu_y)
    vx, vy = np.meshgrid(np.linspace(-2, 2, 201), np.linspace(-2, 2, 201))
    ax.set_xlim(-2, 2)
    ax.set_ylim(-2, 2)
    v = np.stack((vx, vy), axis=-1)
    D = np.zeros(vx.shape)
    nz = np.hypot(vx, vy) > 0
    D[nz] = law.dissipation(v[nz], N)
    cs = ax.contour(vx, vy, D, levels=np.linspace(0.1, 1.0, 10) * N * max(mu_x, mu_y), cmap="viridis")
    ax.clabel(cs, fontsize=7, fmt="%.2f")
    theta = np.deg2rad(35.0)
    V = 1.2 * np.array([np.cos(theta), np.sin(theta)])
    T = law.force_for_slip(V, N)
    arrow(ax, V, V + T, "tab:blue")
    ax.plot(*V, "ko")
    ax.set_xlim(-2, 2)
    ax.set_ylim(-2, 2)
    place_labels(ax, [label(ax, "$T = \\partial D/\\partial V$ (1.13)", V + T, "tab:blue")])
    ax.set_aspect("equal")
    ax.set_xlabel("$V_x$")
    ax.set_ylabel("$V_y$")
    ax.set_title("Fig. 1c  dissipation $D(V_x, V_y)$ (1.12)")
    return ax


def directional_friction(ax=None, mu_x: float = 0.6, mu_y: float = 0.3):
    """Polar plot of the directional friction coefficient of the three orthotropic rules:
    elliptic (1.15), Huber (1.16) and transformed Coulomb (1.17)."""
    ax = _axes(ax, "polar")
    theta = np.linspace(0, 2 * np.pi, 721)
    for law, name in ((EllipticOrthotropic(mu_x, mu_y), "elliptic, normality (1.15)"),
                      (Huber(mu_x, mu_y), "Huber (1.16)"),
                      (TransformedCoulomb(mu_x, mu_y), "transformed (1.17)")):
        ax.plot(theta, law.friction_coefficient(theta), label=name)
    ax.set_title(f"friction coefficient $\\mu(\\theta)$ for sliding at $\\theta$: three orthotropic "
                 f"rules,\n$\\mu_x$ = {mu_x:g}, $\\mu_y$ = {mu_y:g}", fontsize=10, pad=14)
    legend_beside(ax, "below", ncol=2)
    polar_radius_labels(ax)
    return ax


def wedge_limit_curve(law: WedgeAsperity, Q: float = 1.0, phi_P: float = 0.9, ax=None,
                      max_load: float = 4.0):
    """Limit curve f = 0 of a wedge asperity at fixed Q with the potential ellipse g = 0 (2.6) and
    the construction of Fig. 3: the ray from the ellipse centre through P meets the potential at
    R, where the slip is normal to g; it differs from the associated normal to f at P ((2.4) vs
    (2.5)).

    ``phi_P`` is the in-plane force angle of the point P.
    """
    ax = _axes(ax)
    curve = law.limit_curve(Q, max_load=max_load)
    ax.plot(curve[:, 0], curve[:, 1], "k", label="limit $f = 0$ (2.2)")
    c = np.cos(law.alpha)
    P = law.limit_point(phi_P, Q)
    centre = law.centre(Q)
    C = 0.5 * float(law.potential(P, Q))
    psi = np.linspace(0, 2 * np.pi, 361)
    ax.plot(centre[0] + C * np.cos(psi) / c, C * np.sin(psi), "tab:orange", ls="--",
            label="potential $g = 0$ (2.6)")
    R = centre + (P - centre) * C / float(law.potential(P, Q))
    ax.plot(*np.stack((centre, P)).T, color="0.5", lw=0.8, label="ray O'P from the centre of $g$")
    scale = 0.35 * max(Q, float(np.hypot(*(P - centre))))
    for point, v, color, text in (
            (R, law.slip_direction(R, Q), "tab:orange", "slip at R, normal to $g$ (2.4)"),
            (P, law.slip_direction(P, Q), "tab:red", "actual slip at P (parallel to that at R)"),
            (P, law.normal_direction(P, Q), "tab:blue", "associated normal to $f$ at P (2.5)")):
        arrow(ax, point, point + scale * v[:2] / np.hypot(*v[:2]), color, label=text)
    names = []
    for point, name in ((P, "P"), (R, "R"), (centre, "O'")):
        ax.plot(*point, "ko", ms=3)
        names.append(label(ax, name, point, fontsize=10))
    ax.set_aspect("equal")
    ax.set_xlabel("tangential force " + ("$T_x/Q$" if Q == 1 else "$T_x$"))
    ax.set_ylabel("tangential force " + ("$T_y/Q$" if Q == 1 else "$T_y$"))
    legend_beside(ax, "below", ncol=2)
    ax.grid(alpha=0.3)
    place_labels(ax, names)
    return ax


def wedge_elliptic(ax=None, alpha: float = np.pi / 6, mu: float = 0.5):
    """Fig. 3a: elliptic limit curve (alpha + rho < pi/2) and the potential ellipse."""
    law = WedgeAsperity(alpha, mu)
    ax = wedge_limit_curve(law, ax=ax)
    ax.set_title(f"Fig. 3a  {law.conic()}: $\\alpha$ = {np.rad2deg(alpha):.0f}°, $\\mu$ = {mu:g}")
    return ax


def wedge_parabolic(ax=None, mu: float = 0.5):
    """Fig. 3b: parabolic limit curve (alpha + rho = pi/2) and the potential ellipse."""
    alpha = np.pi / 2 - np.arctan(mu)
    law = WedgeAsperity(alpha, mu)
    ax = wedge_limit_curve(law, phi_P=2.2, ax=ax, max_load=6.0)
    ax.set_title(f"Fig. 3b  {law.conic()}: $\\alpha + \\varrho = \\pi/2$, $\\mu$ = {mu:g}")
    return ax
