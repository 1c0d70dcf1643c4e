"""Fig. 10 of §4 computed with the ellipsoidal cap, and its key numbers for ``frictionrules paper``.

The paper draws Fig. 10 schematically. Our parameters (:data:`FIG10`) are chosen so that both
behaviours it describes appear: below ``A0 = A(0, β0)`` (test A) the contact dilates and T
falls after the peak A′ to A_c; above ``A0`` (test B) T rises to an interior peak B′ and then
slowly diminishes to B_c. The peak B′ needs a slip hardening that outruns the area change near
the critical state (``h = 1`` over ``κ_h = 0.15``, with the area growth ``b = 15``); the soft
layer (``kt = 5``) makes the elastic branch readable next to the slip of 2.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Fig10Setup:
    """Parameters of the Fig. 10 reproduction.

    ``A(κ, β) = p β [1 + h(1 − e^{−κ/κ_h})]``, ``B(β) = b β(1 − β)`` (the cap's default forms),
    critical-state slope ``m``, layer stiffnesses ``kn, kt``, initial area fraction ``beta``,
    the fixed normal forces of tests A and B and the imposed tangential slip.
    """

    m: float = 0.6
    p: float = 2.0
    h: float = 1.0
    kappa_h: float = 0.15
    b: float = 15.0
    kn: float = 5.0
    kt: float = 5.0
    beta: float = 0.5
    normal_forces: tuple = (0.4, 1.6)
    slip: float = 2.0

    def model(self):
        """The :class:`ContactModel` with the cap (4.9) of these parameters."""
        from ..laws import AreaGrowth, AreaHardening, EllipsoidCap
        from . import ContactModel
        cap = EllipsoidCap(self.m, A=AreaHardening(p=self.p, h=self.h, kappa_h=self.kappa_h),
                           B=AreaGrowth(b=self.b))
        return ContactModel(cap, kn=self.kn, kt=self.kt)

    @property
    def A0(self) -> float:
        """``A(0, β0)``: the normal force at the top of the initial surface."""
        return self.p * self.beta

    def describe(self, sep: str = "; ", math: bool = False) -> str:
        """The parameters, for captions: two parts joined by ``sep``; in matplotlib's math text
        (for figure titles beside math-text axis labels) when ``math``."""
        if math:
            return (f"$m$ = {self.m:g}, $k_n$ = {self.kn:g}, $k_t$ = {self.kt:g}, $\\beta_0$ = "
                    f"{self.beta:g}{sep}$A = p\\beta[1 + h(1 - e^{{-\\kappa/\\kappa_h}})]$ with "
                    f"$p$ = {self.p:g}, $h$ = {self.h:g}, $\\kappa_h$ = {self.kappa_h:g}, "
                    f"$B = b\\beta(1 - \\beta)$ with $b$ = {self.b:g}")
        return (f"m = {self.m:g}, kn = {self.kn:g}, kt = {self.kt:g}, β0 = {self.beta:g}{sep}"
                f"A = pβ[1 + h(1 − exp(−κ/κh))] with p = {self.p:g}, h = {self.h:g}, "
                f"κh = {self.kappa_h:g}, B = bβ(1 − β) with b = {self.b:g}")


FIG10 = Fig10Setup()


@dataclass(frozen=True)
class ShearTest:
    """One curve of Fig. 10c: shear at the fixed normal force ``N``.

    ``name`` is "A" or "B" (the points of Fig. 10a); ``result`` the :class:`DriveResult`;
    ``peak`` the index of the largest T (A′, B′), the last row is the asymptotic point (A_c, B_c).
    """

    name: str
    N: float
    result: object

    @property
    def slip(self) -> np.ndarray:
        return self.result.displacement[:, 0]

    @property
    def T(self) -> np.ndarray:
        return self.result.force[:, 0]

    @property
    def peak(self) -> int:
        return int(np.argmax(self.T))


@functools.lru_cache(maxsize=1)
def fig10c_results() -> tuple[ShearTest, ...]:
    """The two shear tests of Fig. 10c at fixed N (points A and B of Fig. 10a): N is applied
    with no slip, then the slip ``δt1`` is imposed in steps of 0.0025 up to 0.2 and of 0.01
    beyond."""
    from . import drive
    model = FIG10.model()
    fine = 0.2
    out = []
    for name, N in zip("AB", FIG10.normal_forces):
        res = drive(model, [{"N": N, "dt1": 0.0, "T2": 0.0, "steps": 10},
                            {"dt1": fine, "steps": 80},
                            {"dt1": FIG10.slip, "steps": int(round((FIG10.slip - fine) / 0.01))}],
                    beta=FIG10.beta)
        out.append(ShearTest(name, N, res))
    return tuple(out)


def key_numbers() -> list[tuple[str, str, str]]:
    """Peaks and asymptotes of the T–δ curves of Fig. 10c (parameters :data:`FIG10`)."""
    rows = []
    for t in fig10c_results():
        k = t.peak
        rows.append((f"cap, test {t.name} (N = {t.N:g}): peak T{t.name}′ (at δt1)",
                     f"{t.T[k]:.4f} ({t.slip[k]:.4f})", "Fig. 10c"))
        rows.append((f"cap, test {t.name} (N = {t.N:g}): final T/N, {t.name}_c (asymptote m = {FIG10.m:g})",
                     f"{t.T[-1] / t.N:.4f}", "Fig. 10c, (4.9)"))
        rows.append((f"cap, test {t.name} (N = {t.N:g}): final β (β0 = {FIG10.beta:g})", f"{t.result.beta[-1]:.4f}", "(4.5)"))
    return rows
