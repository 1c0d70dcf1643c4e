"""Fig. 10 of §4: the ellipsoidal cap in (T1, T2, N) (a), its hardening function A(κ, β) (b)
and the tangential force–displacement curves at fixed N (c), computed with the parameters
:data:`frictionrules.contact.summary.FIG10`."""

from __future__ import annotations

import numpy as np

from ._layout import label, legend_beside, place_labels

__all__ = ["cap_surface", "cap_hardening", "cap_shear_curves", "drive_curves"]

_COLOURS = {"A": "C0", "B": "C3"}


def _axes(ax, projection=None, size=(5.5, 4.2)):
    if ax is None:
        import matplotlib.pyplot as plt
        ax = plt.figure(figsize=size).add_subplot(111, projection=projection)
    return ax


def _peak_line(tests):
    """Slope and intercept of the straight line through the peaks A′ and B′ in (N, T1)."""
    (Na, Ta), (Nb, Tb) = ((t.N, t.T[t.peak]) for t in tests)
    slope = (Tb - Ta) / (Nb - Na)
    return slope, Ta - slope * Na


def cap_surface(ax=None):
    """Fig. 10a: the yield surface (4.9) in the space (T1, T2, N), with the two shear tests of
    Fig. 10c.

    The initial surface (the rotational ellipsoid ``A = A0``, its half ``T1 >= 0``) is shaded;
    in the plane ``T2 = 0`` are drawn its meridian, the meridians of the final surfaces of both
    tests, the stress paths at fixed N from A and B, the peaks A′, B′ and the asymptotic points
    A_c, B_c, the line through the peaks and the line through the asymptotic points (the
    critical-state line ``T = mN``, the locus of the tops of all the ellipsoids).
    """
    from ..contact.summary import FIG10, fig10c_results

    ax = _axes(ax, "3d", size=(8.0, 6.4))
    tests = fig10c_results()
    cap = FIG10.model().law
    m, A0 = FIG10.m, FIG10.A0
    n_max = 1.1 * max(2.0 * A0, max(t.N for t in tests))
    # initial surface: N = A(1 - cos phi), |T| = m A sin phi, rotated by omega about the N axis
    phi, omega = np.meshgrid(np.linspace(0.0, np.pi, 41), np.linspace(-np.pi / 2, np.pi / 2, 31))
    rho = m * A0 * np.sin(phi)
    ax.plot_surface(A0 * (1 - np.cos(phi)), rho * np.sin(omega), rho * np.cos(omega), color="0.6",
                    alpha=0.25, linewidth=0.2, edgecolor="0.5", rstride=3, cstride=3)

    def meridian(A, **kw):          # the part inside the box N <= n_max (3-D lines are not clipped)
        p = np.linspace(0.0, np.arccos(max(1.0 - n_max / A, -1.0)), 200)
        ax.plot(A * (1 - np.cos(p)), 0.0 * p, m * A * np.sin(p), **kw)

    meridian(A0, color="k", lw=1.6, label=f"initial surface $A = A_0$ = {A0:g} and its meridian $T_2 = 0$")
    for t in tests:
        col = _COLOURS[t.name]
        A_end = float(cap.A(t.result.kappa[-1], t.result.beta[-1]))
        meridian(A_end, color=col, lw=1.0, ls="--", label=f"final surface of test {t.name} (meridian)")
        k = t.peak
        ax.plot([t.N, t.N], [0, 0], [0, t.T[k]], color=col, lw=1.2,
                label=f"test {t.name}: stress path at $N$ = {t.N:g}")
        ax.scatter([t.N], [0], [t.T[k]], color=col, marker="o", s=30, depthshade=False)
        ax.scatter([t.N], [0], [t.T[-1]], color=col, marker="s", s=30, depthshade=False)
        ax.scatter([t.N], [0], [0], color=col, marker="^", s=30, depthshade=False)
        # labels on the free side of the lines: the peak line and the critical-state line rise
        # to the right, so A′, B′ go up-left and A_c, B_c down-right
        ax.text(t.N - 0.03, 0, t.T[k] + 0.06, f"{t.name}′", color=col, fontsize=11, ha="right",
                va="bottom")
        ax.text(t.N + 0.05, 0, t.T[-1] - 0.03, f"{t.name}$_c$", color=col, fontsize=11, ha="left",
                va="top")
        ax.text(t.N, 0, -0.06, t.name, color=col, fontsize=11, ha="center", va="top")
    n = np.array([0.0, n_max])
    ax.plot(n, 0 * n, m * n, color="0.2", lw=1.2,
            label=f"through $A_c$, $B_c$: critical state $T_1 = mN$, $m$ = {m:g}")
    slope, icpt = _peak_line(tests)
    ax.plot(n, 0 * n, icpt + slope * n, color="0.2", lw=1.2, ls="-.",
            label=f"through the peaks $A'$, $B'$: $T_1$ = {icpt:.2f} + {slope:.2f} $N$")
    ax.scatter([], [], [], color="0.3", marker="o", label="peaks $A'$, $B'$")
    ax.scatter([], [], [], color="0.3", marker="s", label="asymptotic points $A_c$, $B_c$")
    ax.scatter([], [], [], color="0.3", marker="^", label="$A$, $B$: the fixed normal forces")
    ax.set_xlim(0.0, n_max)
    ax.set_ylim(-0.8 * n_max / 2, 0.8 * n_max / 2)
    ax.set_zlim(0.0, 1.15 * max(t.T.max() for t in tests))
    ax.set_box_aspect((n_max, 0.8 * n_max, 1.15 * max(t.T.max() for t in tests)))
    ax.set_xticks(np.arange(0.0, n_max, 0.5))
    ax.set_yticks([-0.5, 0.0, 0.5])
    ax.set_xlabel("normal force $N$ (compression)")
    ax.set_ylabel("$T_2$")
    ax.set_zlabel("$T_1$")
    ax.view_init(elev=18, azim=-62)
    ax.set_title("Fig. 10a  yield surface (4.9) in $(T_1, T_2, N)$ and the tests of Fig. 10c\n"
                 + FIG10.describe("\n", math=True), fontsize=9)
    legend_beside(ax, "below", ncol=2)
    return ax


def cap_hardening(ax=None):
    """Fig. 10b: A(κ, β) of the Fig. 10 parameters against β for several accumulated slips κ."""
    from ..contact.summary import FIG10

    ax = _axes(ax)
    A = FIG10.model().law.A
    beta = np.linspace(0.0, 1.0, 101)
    for kappa in (0.0, A.kappa_h, 3 * A.kappa_h, np.inf):
        text = r"$\kappa\to\infty$" if np.isinf(kappa) else rf"$\kappa = {kappa:g}$"
        ax.plot(beta, A(1e300 if np.isinf(kappa) else kappa, beta), label=text)
    ax.set_xlabel(r"fraction of real contact area $\beta$")
    ax.set_ylabel(r"$A(\kappa, \beta)$")
    ax.set_title(rf"Fig. 10b  $A(\kappa, \beta) = p\beta[1 + h(1 - e^{{-\kappa/\kappa_h}})]$"
                 f"\n$p$ = {A.p:g}, $h$ = {A.h:g}, $\\kappa_h$ = {A.kappa_h:g}", fontsize=10)
    ax.grid(alpha=0.3)
    legend_beside(ax, "right")
    return ax


def cap_shear_curves(ax=None):
    """Fig. 10c: T1 against δt1 at the two fixed normal forces of Fig. 10a, with the peaks A′,
    B′, the asymptotic points A_c, B_c and the asymptotes ``T = mN``.

    Test A (``N < A0``) dilates, loses contact area and falls after the peak A′; test B
    (``N > A0``) rises to the peak B′ and then slowly diminishes to B_c.
    """
    from ..contact.summary import FIG10, fig10c_results

    ax = _axes(ax, size=(7.0, 4.4))
    m = FIG10.m
    names = []
    for t in fig10c_results():
        col = _COLOURS[t.name]
        d, T = t.slip, t.T
        side = "N < A_0" if t.N < FIG10.A0 else "N > A_0"
        ax.plot(d, T, color=col, label=f"test {t.name}: $N$ = {t.N:g} (${side}$)")
        ax.axhline(m * t.N, color=col, ls=":", lw=1)
        k = t.peak
        ax.plot(d[k], T[k], "o", color=col)
        ax.plot(d[-1], T[-1], "s", color=col)
        names += [label(ax, f"{t.name}′", (d[k], T[k]), col, fontsize=11),
                  label(ax, f"{t.name}$_c$", (d[-1], T[-1]), col, fontsize=11)]
    ax.plot([], [], "k:", lw=1, label="asymptotes $T_1 = mN$")
    ax.plot([], [], "ko", label="peaks $A'$, $B'$")
    ax.plot([], [], "ks", label="asymptotic points $A_c$, $B_c$")
    ax.set_xlim(0.0, None)
    ax.set_ylim(0.0, 1.12 * max(t.T.max() for t in fig10c_results()))
    ax.margins(x=0.06)
    ax.set_xlabel(r"tangential displacement $\delta_{t1}$")
    ax.set_ylabel(r"tangential force $T_1$")
    ax.set_title("Fig. 10c  tangential force–displacement curves at fixed $N$\n"
                 + FIG10.describe("\n", math=True), fontsize=9)
    ax.grid(alpha=0.3)
    place_labels(ax, names)
    legend_beside(ax, "right")
    return ax


def drive_curves(result, title: str = "", axes=None):
    """The force–displacement curves of a driven contact (:func:`frictionrules.drive`), one
    panel per direction: ``T1`` against ``δt1``, ``T2`` against ``δt2`` and ``N`` against
    ``δn`` (compression and opening positive, ``docs/conventions.md``), under ``title`` (each
    of its lines wrapped at 120 characters).

    ``axes`` are three Axes to draw on (a new figure when omitted); returns them.
    """
    import textwrap

    from matplotlib.ticker import MaxNLocator
    if axes is None:
        import matplotlib.pyplot as plt
        _, axes = plt.subplots(1, 3, figsize=(11.0, 3.8))
    panels = ((0, r"$\delta_{t1}$", r"$T_1$"), (1, r"$\delta_{t2}$", r"$T_2$"),
              (2, r"$\delta_n$ (opening > 0)", r"$N$ (compression > 0)"))
    for ax, (k, x, y) in zip(axes, panels):
        ax.plot(result.displacement[:, k], result.force[:, k], color="C0")
        ax.plot(result.displacement[-1, k], result.force[-1, k], "o", color="C0", ms=4)
        ax.set_xlabel(f"displacement {x}")
        ax.set_ylabel(f"force {y}")
        ax.xaxis.set_major_locator(MaxNLocator(4, steps=[1, 2, 5, 10]))
        ax.grid(alpha=0.3)
    fig = axes[0].figure
    if title:
        fig.suptitle("\n".join(textwrap.fill(line, 120) for line in title.splitlines()),
                     fontsize=9)
    fig.tight_layout()
    return axes
