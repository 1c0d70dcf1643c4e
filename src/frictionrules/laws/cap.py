r"""The ellipsoidal cap (4.9) of §4 and its hardening functions A(κ, β) and B(β).

Yield surface (4.9), a rotational ellipsoid through the origin of the ``(T1, T2, N)`` space:

.. math:: f(T, N, \kappa, \beta) = (N - A)^2 + \frac{T_1^2 + T_2^2}{m^2} - A^2

with semi-axes ``A`` along N and ``m A`` along T (``m = c/a = tan ϱ``). Its top
``N = A, |T| = m A`` lies on the line ``|T| = m N``: there the associated normal slip vanishes
(``∂f/∂N = 0``), so this line is the *critical-state* line on which the surface stops moving.

Default hardening (our choice; the paper only sketches A in Fig. 10b):

* :class:`AreaHardening`, :math:`A(\kappa, \beta) = p\,\beta\,[1 + h(1 - e^{-\kappa/\kappa_h})]`.
  A is half the normal force the contact layer carries at yield in pure compression
  (the ellipsoid spans ``0 <= N <= 2A``). Following Bowden–Tabor, that force is the asperity
  hardness times the real contact area ``β A_total``, hence ``A ∝ β``: ``p`` is
  hardness × total area / 2. Tangential slip grows the junctions (Tabor's junction growth)
  and work-hardens the asperity tips, a gain that saturates after a slip of a few ``κ_h``:
  the factor ``1 + h(1 - e^{-κ/κ_h})``.
* :class:`AreaGrowth`, :math:`B(\beta) = b\,\beta(1 - \beta)` in (4.5),
  :math:`\dot\beta = B(\beta)\,\dot\delta^p_{closure}`. Plastic closure (compaction)
  flattens asperities and grows the real contact area, plastic opening (dilatancy) lets
  asperities ride over each other and shrinks it; the logistic form keeps ``0 < β < 1`` and
  makes ``ln(β/(1-β))`` linear in the plastic closure, the contact analogue of the
  Cam-clay/Calladine law in which the size of the yield locus is exponential in the plastic
  volumetric strain.

With these, a contact sheared at fixed N below ``A0 = A(0, β0)`` dilates, loses area and
softens after a peak; above ``A0`` it compacts and hardens. Both end on the critical-state
line ``|T| = m N`` (Fig. 10c), where ``A(κ, β) = N``.

Sign convention: in frictionrules the normal plastic displacement is positive on *opening*
(``docs/conventions.md``); the sliding rule gives it as ``-λ̇ ∂g/∂N``, so the paper's
``β̇ = B(β) δ̇ₙᵖ`` (closure positive) reads ``β̇ = B(β) λ̇ ∂g/∂N`` here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite
from ._params import Parameterized, parameter
from ._state import LawState
from ._traits import LawTraits
from .base import FrictionLaw

__all__ = ["AreaGrowth", "AreaHardening", "EllipsoidCap", "state_symbols"]


@dataclass(frozen=True)
class AreaHardening(Parameterized):
    r"""Default :math:`A(\kappa, \beta) = p\,\beta\,[1 + h(1 - e^{-\kappa/\kappa_h})]`.

    Parameters
    ----------
    p : float
        Force scale, ``p > 0``: ``A`` at full contact (``β = 1``) and no slip.
    h : float
        Relative slip hardening at saturation, ``h > -1`` (``h < 0`` is slip softening).
    kappa_h : float
        Slip length over which the slip hardening saturates, ``> 0``.
    """

    p: float = parameter("force scale of the cap", "force", lo=0.0, lo_open=True, default=2.0)
    h: float = parameter("relative slip hardening at saturation", lo=-1.0, lo_open=True,
                         default=0.25)
    kappa_h: float = parameter("slip scale of the hardening", "length", lo=0.0, lo_open=True,
                               default=0.05)

    def __call__(self, kappa, beta):
        kappa, beta = np.asarray(kappa, dtype=float), np.asarray(beta, dtype=float)
        return self.p * beta * (1.0 + self.h * (1.0 - np.exp(-kappa / self.kappa_h)))

    def symbolic(self, kappa, beta):
        import sympy
        p, h, kh = (sympy.Float(x) for x in (self.p, self.h, self.kappa_h))
        return p * beta * (1 + h * (1 - sympy.exp(-kappa / kh)))


@dataclass(frozen=True)
class AreaGrowth(Parameterized):
    r"""Default :math:`B(\beta) = b\,\beta(1 - \beta)` of (4.5).

    Parameters
    ----------
    b : float
        Rate of area growth per unit plastic closure (1/length), ``b > 0``.
    """

    b: float = parameter("rate of area growth per unit plastic closure", "1/length", lo=0.0,
                         lo_open=True, default=20.0)

    def __call__(self, beta):
        beta = np.asarray(beta, dtype=float)
        return self.b * beta * (1.0 - beta)

    def derivative(self, beta):
        beta = np.asarray(beta, dtype=float)
        return self.b * (1.0 - 2.0 * beta)

    def symbolic(self, beta):
        import sympy
        return sympy.Float(self.b) * beta * (1 - beta)


@dataclass(frozen=True)
class EllipsoidCap(FrictionLaw):
    r"""Ellipsoidal yield surface (4.9) with hardening by slip (κ) and contact area (β).

    .. math:: f = (N - A(\kappa,\beta))^2 + |T|^2/m^2 - A(\kappa,\beta)^2, \qquad
              g = \omega\,(N - A)^2 + |T|^2/m^2

    ``normal_ratio`` :math:`\omega = 1` is the associated rule (4.8); ``ω < 1`` scales the
    normal slip (dilatancy and compaction) down. ``ω = 0`` is excluded: without normal slip
    β never changes and a normal force beyond ``2A`` could not be accommodated. The internal
    variables ``q = (kappa, beta)`` evolve by (4.5): :math:`\dot\kappa = \dot\lambda\,|\partial
    g/\partial T|`, :math:`\dot\beta = B(\beta)\,\dot\lambda\,\partial g/\partial N`
    (compaction positive, see the module notes); a virgin contact has ``κ = 0, β = 0.5``. The
    hardening modulus is (4.7)/(4.11).

    Parameters
    ----------
    m : float
        Ratio of the semi-axes, ``m = tan ϱ > 0``: the slope of the critical-state line.
    A : AreaHardening
        A(κ, β), the semi-axis along N.
    B : AreaGrowth
        B(β) of (4.5).
    normal_ratio : float
        ω > 0 (1: associated).

    Notes
    -----
    The methods take the state as ``q`` (a :class:`LawState` of ``kappa, beta``, or an array
    ``(..., 2)``); the form ``limit(T, N, kappa, beta)`` with the two variables as separate
    arguments is also accepted.
    """

    m: float = parameter("slope of the critical-state line, tan(rho)", lo=0.0, lo_open=True)
    A: AreaHardening = parameter("A(kappa, beta)", default=AreaHardening, nested=True)
    B: AreaGrowth = parameter("B(beta)", default=AreaGrowth, nested=True)
    normal_ratio: float = parameter("weight of the normal part of g", lo=0.0, lo_open=True,
                                    default=1.0)
    state_names = ("kappa", "beta")
    capabilities = frozenset({"symbolic"})
    defined_in_tension = True

    @property
    def associated(self) -> bool:
        return self.normal_ratio == 1.0

    def declared_traits(self) -> LawTraits:
        """An ellipsoid (convex, not a cone) with normal slip off the critical-state line; g
        differs from f by a function of N and q only, and κ̇ = λ̇|∂g/∂T| couples the
        tangential directions."""
        return LawTraits(degree=None, slip_degree=None, normal_slip=True,
                         tangentially_associated=True, tangent_coupling=True, convex=True)

    def initial_values(self) -> dict[str, float]:
        return {"kappa": 0.0, "beta": 0.5}

    def _check_state(self, q):
        if np.any(q[..., 0] < 0):
            raise FrictionRulesError("kappa violates kappa >= 0 (accumulated slip)")
        if np.any((q[..., 1] <= 0) | (q[..., 1] >= 1)):
            raise FrictionRulesError("beta violates 0 < beta < 1 (fraction of real contact area)")

    def symbolic_form(self):
        """``(f, g)`` of (4.9) and the rates (4.5) in ``T1, T2, N, kappa, beta``."""
        import sympy

        from ._symbolic import SymbolicLaw, slip_rate
        from .symbols import N, T1, T2
        kappa, beta = state_symbols()
        m, om, p, h, kh, b = sympy.symbols("m normal_ratio p h kappa_h b", positive=True)
        h = sympy.Symbol("h", real=True)
        A = p * beta * (1 + h * (1 - sympy.exp(-kappa / kh)))
        t2 = (T1**2 + T2**2) / m**2
        f = (N - A) ** 2 + t2 - A**2
        g = om * (N - A) ** 2 + t2
        rates = (slip_rate(g), b * beta * (1 - beta) * sympy.diff(g, N))
        return SymbolicLaw(f, g, state=(kappa, beta), rates=rates, params=(m, om, p, h, kh, b),
                           values=(self.m, self.normal_ratio, self.A.p, self.A.h, self.A.kappa_h,
                                   self.B.b))

    def _cap_state(self, q, beta):
        """``q`` as given, or the separate ``(kappa, beta)`` arguments as a state."""
        if beta is None and (q is None or isinstance(q, LawState) or np.ndim(q) and
                             np.shape(q)[-1] == 2):
            return q
        kappa = 0.0 if q is None else q
        beta = 0.5 if beta is None else beta
        kappa, beta = np.broadcast_arrays(check_finite("kappa", kappa), check_finite("beta", beta))
        return np.stack((kappa, beta), axis=-1)

    def limit(self, T, N, q=None, beta=None):
        """f of (4.9): < 0 inside, 0 on the surface."""
        return super().limit(T, N, self._cap_state(q, beta))

    def potential(self, T, N, q=None, beta=None):
        """g = ω (N - A)^2 + |T|^2/m^2 (= f + A^2 when associated)."""
        return super().potential(T, N, self._cap_state(q, beta))

    def limit_gradient(self, T, N, q=None, beta=None):
        """``(df/dT1, df/dT2, df/dN)``, shape ``(..., 3)``."""
        return super().limit_gradient(T, N, self._cap_state(q, beta))

    def potential_gradient(self, T, N, q=None, beta=None):
        """``(dg/dT1, dg/dT2, dg/dN)``, shape ``(..., 3)``."""
        return super().potential_gradient(T, N, self._cap_state(q, beta))

    def hardening_modulus(self, T, N, q=None, beta=None):
        r"""H of (4.7): :math:`H = -[f_{,\kappa}|g_{,T}| + f_{,\beta} B(\beta) g_{,N}]`.

        For the associated cap this is (4.11),
        :math:`H = 2[f_{,\beta}(A - N)B - f_{,\kappa}(|T|^2/m^4)^{1/2}]`.
        """
        return super().hardening_modulus(T, N, self._cap_state(q, beta))

    def centre(self, N, q=None) -> np.ndarray:
        N = np.asarray(N, dtype=float)
        return np.zeros(N.shape + (2,))

    def _normal(self, N) -> np.ndarray:
        """The cap is defined for every N (it closes at N = 0 and N = 2A)."""
        return check_finite("N", N)


def state_symbols():
    """The SymPy symbols ``kappa, beta`` of the hardening variables."""
    import sympy
    return sympy.Symbol("kappa", nonnegative=True), sympy.Symbol("beta", positive=True)
