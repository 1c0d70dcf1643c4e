"""Fig. 10 of §4: the ellipsoidal cap (a), its hardening function A(β, κ) (b) and the
tangential force–displacement curves at fixed N (c)."""

from __future__ import annotations

import numpy as np

__all__ = ["cap_surface", "cap_hardening", "cap_shear_curves"]


def _axes(ax):
    if ax is None:
        import matplotlib.pyplot as plt
        _, ax = plt.subplots(figsize=(5.5, 4.2))
    return ax


def cap_surface(ax=None):
    """Fig. 10a: meridian section (T2 = 0) of the cap (4.9) at the start and at the end of the
    two shear tests of Fig. 10c, their stress paths, peaks and asymptotes on ``T = mN``."""
    from ..contact.summary import FIG10, fig10_model, fig10c_results
    ax = _axes(ax)
    model = fig10_model()
    cap, m = model.law, FIG10["m"]
    phi = np.linspace(0, np.pi, 200)

    def meridian(A, **kw):
        ax.plot(A - A * np.cos(phi), m * A * np.sin(phi), **kw)

    meridian(float(cap.A(0.0, FIG10["beta"])), color="k", lw=1.5, label="initial surface")
    res = fig10c_results()
    for (N, r), col, lab in zip(res.items(), ("C0", "C3"), ("A", "B")):
        A_end = float(cap.A(r.kappa[-1], r.beta[-1]))
        meridian(A_end, color=col, lw=1, ls="--", label=f"final surface, test {lab}")
        T = r.force[:, 0]
        k = int(np.argmax(T))
        ax.plot([N, N], [0, T.max() * 1.05], color=col, lw=0.8, alpha=0.6)
        if k < len(T) - 1:  # a peak before the asymptote (test A); test B rises monotonically
            ax.plot(N, T[k], "o", color=col)
            ax.annotate(f"{lab}'", (N, T[k]), textcoords="offset points", xytext=(5, 3), color=col)
        ax.plot(N, T[-1], "s", color=col)
        ax.annotate(f"{lab}$_c$", (N, T[-1]), textcoords="offset points", xytext=(5, -12), color=col)
    n_max = 2.2
    ax.plot([0, n_max], [0, m * n_max], color="0.4", lw=1, label="critical state $T = mN$")
    ax.set_xlabel("normal force $N$ (compression)")
    ax.set_ylabel("tangential force $T_1$")
    ax.set_title("Fig. 10a: ellipsoidal cap (4.9), section $T_2 = 0$")
    ax.set_aspect("equal")
    ax.set_xlim(0, n_max)
    ax.set_ylim(0, None)
    ax.legend(fontsize=7, loc="upper left")
    return ax


def cap_hardening(ax=None):
    """Fig. 10b: the default A(κ, β) against β for several accumulated slips κ."""
    from ..laws import AreaHardening
    ax = _axes(ax)
    A = AreaHardening()
    beta = np.linspace(0.0, 1.0, 101)
    for kappa in (0.0, A.kappa_h, 3 * A.kappa_h, 1e9):
        lab = r"$\kappa\to\infty$" if kappa > 1 else rf"$\kappa = {kappa:g}$"
        ax.plot(beta, A(kappa, beta), label=lab)
    ax.set_xlabel(r"fraction of real contact area $\beta$")
    ax.set_ylabel(r"$A(\kappa, \beta)$")
    ax.set_title(r"Fig. 10b: $A = p\beta[1 + h(1 - e^{-\kappa/\kappa_h})]$")
    ax.legend(fontsize=8)
    return ax


def cap_shear_curves(ax=None):
    """Fig. 10c: T1 against δt1 at the two fixed normal forces, with the asymptotes ``mN``."""
    from ..contact.summary import FIG10, fig10c_results
    ax = _axes(ax)
    m = FIG10["m"]
    for (N, r), col, lab in zip(fig10c_results().items(), ("C0", "C3"), ("A", "B")):
        d, T = r.displacement[:, 0], r.force[:, 0]
        ax.plot(d, T, color=col, label=f"test {lab}: N = {N:g}")
        ax.axhline(m * N, color=col, ls=":", lw=1)
        k = int(np.argmax(T))
        ax.plot(d[k], T[k], "o", color=col)
    ax.set_xlabel(r"tangential displacement $\delta_{t1}$")
    ax.set_ylabel(r"tangential force $T_1$")
    ax.set_title("Fig. 10c: shear at fixed N (dotted: asymptotes $T = mN$)")
    ax.legend(fontsize=8)
    return ax
