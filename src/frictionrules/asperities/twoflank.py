r"""The paper's parallel wedge asperities (Fig. 4): two flanks, three mechanisms, (2.9)–(2.17).

Angle convention (the paper's, as in :class:`frictionrules.WedgeAsperity`): flank ``i`` has the
inclination ``alpha_i`` and the upward normal :math:`n_i = \sigma_i(-\sin\alpha_i, 0,
\cos\alpha_i)`, :math:`\sigma_i = \operatorname{sign}\cos\alpha_i`. With
``0 < alpha1 < pi/2 < alpha2 < pi`` this is

.. math:: n_1 = (-\sin\alpha_1, 0, \cos\alpha_1),\qquad n_2 = (\sin\alpha_2, 0, -\cos\alpha_2),

exactly the reactions of (2.10): :math:`T_x = N_1\sin\alpha_1 - N_2\sin\alpha_2`,
:math:`Q = N_1\cos\alpha_1 - N_2\cos\alpha_2`. Flank 1 rises towards +x at the slope
``alpha1``, flank 2 towards -x at the slope ``pi - alpha2``: a groove along y. The paper's
example ``alpha1 = pi/3, alpha2 = 5 pi/6`` is a right-angled groove with flanks at 60° and 30°.
(The quadric (2.9) is the same for ``alpha`` and ``alpha + pi``; only the sign of ``N`` picks
the nappe, ``N_1 = T_x\sin\alpha_1 + Q\cos\alpha_1``, ``N_2 = -(T_x\sin\alpha_2 +
Q\cos\alpha_2)``.)

Closed forms, with :math:`\tan\varphi = T_x/|T_y|` (``phi`` measured from the y axis):

* one flank (mechanisms i, ii): the cone (2.9);
* both flanks, non-associated (iii): the plane (2.12) written for either sign of ``Ty``,
  :math:`\mu T_x(\cos\alpha_1+\cos\alpha_2) + |T_y|\sin(\alpha_2-\alpha_1)
  - \mu Q(\sin\alpha_1+\sin\alpha_2) = 0`, for :math:`-\sin\alpha_2/\mu < \tan\varphi <
  \sin\alpha_1/\mu` (2.13), velocity :math:`\pm y`, potential :math:`g_3 = \pm T_y` (2.15);
* both flanks, associated (the corrected (2.16)–(2.17), see ``docs/errata.md``): with
  :math:`\delta = (\pi + \alpha_1 - \alpha_2)/2` (half the angle between the normals),
  :math:`m = (\alpha_1 + \alpha_2)/2`, :math:`b = (\cos m, 0, \sin m)` the bisector of the
  normals and :math:`c = (1 - \sin^2\varrho/\cos^2\delta)^{1/2}`, the velocity is
  :math:`V = (\sin\varrho/\cos\delta)\,b \pm c\,y` and the limit plane :math:`V\cdot F = 0`,

  .. math:: |T_y| = \kappa\,(Q\sin m - T_x\cos m),\qquad
            \kappa = \frac{\sin\varrho}{\sqrt{\cos^2\delta - \sin^2\varrho}},

  for :math:`-(\sin\alpha_2 - \sin^2\varrho\cos m/\cos\delta)/(c\sin\varrho) < \tan\varphi <
  (\sin\alpha_1 + \sin^2\varrho\cos m/\cos\delta)/(c\sin\varrho)`. It exists for
  :math:`\delta + \varrho < \pi/2`; at :math:`\delta + \varrho = \pi/2` (the paper's Fig. 5
  parameters) the two friction cones add up to a half-space and the groove locks in every
  direction but one.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_scalar
from ..laws.wedge import WedgeAsperity
from ._law import FacetLaw
from .facets import LOCALS, FacetSet, law_parameters, local_argument, replace_law

__all__ = ["TwoFlankAsperity"]


@dataclass(frozen=True, init=False)
class TwoFlankAsperity(FacetLaw):
    r"""The two-flank (groove) asperity of Fig. 4 as a facet set with its closed forms.

    Parameters
    ----------
    alpha1 : float
        Inclination of flank 1, in (0, pi/2): it rises towards +x.
    alpha2 : float
        Inclination of flank 2 in the paper's convention, in (pi/2, pi): it rises towards -x
        at the slope ``pi - alpha2``.
    mu : float, FrictionLaw, or a pair of those
        The flanks' local law: a number is the local Coulomb coefficient ``mu > 0``; a law
        (or one per flank) as for :class:`FacetSet`, in each flank's frame (``t1`` the
        up-slope direction of flank 1, ``(cos alpha1, 0, sin alpha1)``, and of flank 2 the
        direction towards +x, down its slope). ``law=`` is accepted as well.
    local : {"non-associated", "associated"}
        Local sliding rule, (1.5) or (1.6) for a number; for a law, its own rule or its
        associated twin (g = f), as for :class:`FacetSet`.

    Everything of :class:`FacetSet` is available (facet 0 is flank 1, facet 1 is flank 2); the
    closed forms (:meth:`closed_form_load`, :meth:`pair_range`, :meth:`flank`) need local
    Coulomb friction.
    """

    alpha1: float
    alpha2: float
    mu: object
    local: str = "non-associated"

    def __init__(self, alpha1, alpha2, mu=None, local: str = "non-associated", *, law=None):
        object.__setattr__(self, "alpha1", check_scalar("alpha1", alpha1, lo=0.0, hi=np.pi / 2,
                                                        lo_open=True, hi_open=True))
        object.__setattr__(self, "alpha2", check_scalar("alpha2", alpha2, lo=np.pi / 2,
                                                        hi=np.pi, lo_open=True, hi_open=True))
        if local not in LOCALS:
            raise FrictionRulesError(f"local = {local!r} violates local in {LOCALS}")
        # the keyword of a number is mu, of a law law; either takes either
        value = local_argument(law, mu, 2, "TwoFlankAsperity")
        object.__setattr__(self, "mu", value)
        object.__setattr__(self, "local", local)
        if not isinstance(value, float):
            self._facets                       # a local law is checked where it enters

    def mechanism_name(self, label: str) -> str:
        return {"0": "flank 1", "1": "flank 2", "0+1": "both flanks"}[label]

    @functools.cached_property
    def _facets(self) -> FacetSet:
        return FacetSet(self.normals(), self.mu, self.local)

    @property
    def law(self):
        """The local law argument (the same as :attr:`mu`)."""
        return self.mu

    @property
    def parameters(self) -> dict[str, float]:
        """``alpha1``, ``alpha2`` and the local law's parameters (``mu`` for a number)."""
        return {"alpha1": self.alpha1, "alpha2": self.alpha2, **law_parameters(self.mu)}

    def replace(self, **changes) -> "TwoFlankAsperity":
        """A copy with some of :attr:`parameters` changed (validated)."""
        geo = {k: changes.pop(k) for k in ("alpha1", "alpha2") if k in changes}
        return TwoFlankAsperity(geo.get("alpha1", self.alpha1), geo.get("alpha2", self.alpha2),
                                replace_law(self.mu, changes), self.local)

    @property
    def _mu(self) -> float:
        """The local Coulomb coefficient of the closed forms."""
        try:
            return self._facets.mu
        except FrictionRulesError:
            raise FrictionRulesError(
                f"the closed forms (2.9)-(2.17) are for local Coulomb friction; the flanks' law "
                f"is {self.mu!r}: use limit_load or limit_curve") from None

    def normals(self) -> np.ndarray:
        """``(2, 3)``: :math:`n_1 = (-\\sin\\alpha_1, 0, \\cos\\alpha_1)`,
        :math:`n_2 = (\\sin\\alpha_2, 0, -\\cos\\alpha_2)` ((2.10))."""
        a1, a2 = self.alpha1, self.alpha2
        return np.array([[-np.sin(a1), 0.0, np.cos(a1)], [np.sin(a2), 0.0, -np.cos(a2)]])

    def flank(self, i: int) -> WedgeAsperity:
        """Flank ``i`` (1 or 2) alone, as the wedge of (2.1)–(2.8)."""
        if i not in (1, 2):
            raise FrictionRulesError(f"i = {i!r} violates i in (1, 2)")
        return WedgeAsperity(self.alpha1 if i == 1 else self.alpha2, self._mu,
                             "associated" if self.associated else "non-associated")

    # ---- closed forms ------------------------------------------------------------------------
    @property
    def _assoc_pair(self):
        """``(delta, m, sin rho, c**2)`` of the associated two-flank mechanism, which exists
        for ``c**2 > 0`` (``delta + rho < pi/2``)."""
        delta = 0.5 * (np.pi + self.alpha1 - self.alpha2)
        m = 0.5 * (self.alpha1 + self.alpha2)
        sr = np.sin(np.arctan(self._mu))
        c2 = 1.0 - sr**2 / np.cos(delta) ** 2
        return delta, m, sr, c2

    def pair_range(self) -> tuple[float, float]:
        r"""Range of :math:`\tan\varphi = T_x/|T_y|` where both flanks slide.

        Non-associated: (2.13), :math:`(-\sin\alpha_2/\mu,\ \sin\alpha_1/\mu)`. Associated:
        the corrected (2.17) (module docstring). Raises :class:`FrictionRulesError` for the
        associated rule when :math:`\delta + \varrho \ge \pi/2` (no such mechanism).
        """
        s1, s2 = np.sin(self.alpha1), np.sin(self.alpha2)
        if not self.associated:
            return -s2 / self._mu, s1 / self._mu
        delta, m, sr, c2 = self._assoc_pair
        if c2 <= 1e-12:
            raise FrictionRulesError(
                f"the associated two-flank mechanism needs delta + rho < pi/2: delta = {delta!r}, "
                f"rho = {float(np.arctan(self._mu))!r}")
        c = np.sqrt(c2)
        shift = sr**2 * np.cos(m) / np.cos(delta)
        return -(s2 - shift) / (c * sr), (s1 + shift) / (c * sr)

    def closed_form_load(self, direction, Q=1.0):
        """Limit load factor and mechanism (1, 2 or 3; 0 locked) from the closed forms.

        One flank: smallest root ``t >= 0`` of the quadric (2.9) along ``T = t d`` with
        ``N_i > 0``; both flanks: the plane (2.12) (or its associated correction) in the range
        (2.13) (or (2.17)).

        Returns
        -------
        load : array (...)
        mechanism : int array (...)
        """
        d = check_finite("direction", direction)
        d = d / np.linalg.norm(d, axis=-1, keepdims=True)
        Q = check_scalar("Q", Q, lo=0.0)
        dx, dy = d[..., 0], np.abs(d[..., 1])
        lo, hi = self.pair_range()
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(dy > 0, dx / np.where(dy > 0, dy, 1.0), np.sign(dx) * np.inf)
        a1, a2, mu = self.alpha1, self.alpha2, self._mu
        if self.associated:
            delta, m, sr, c2 = self._assoc_pair
            kappa = sr / np.sqrt(np.cos(delta) ** 2 - sr**2)
            den3 = dy + kappa * np.cos(m) * dx
            num3 = kappa * Q * np.sin(m)
        else:
            den3 = mu * dx * (np.cos(a1) + np.cos(a2)) + dy * np.sin(a2 - a1)        # (2.12)
            num3 = mu * Q * (np.sin(a1) + np.sin(a2))
        pair = (ratio > lo) & (ratio < hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            t3 = np.where(den3 > 0, num3 / np.where(den3 > 0, den3, 1.0), np.inf)
        t1 = self._conic_root(a1, dx, dy, Q, 1.0)
        t2 = self._conic_root(a2, dx, dy, Q, -1.0)
        load = np.where(pair, t3, np.where(ratio >= hi, t1, t2))
        mech = np.where(pair, 3, np.where(ratio >= hi, 1, 2))
        return load, np.where(np.isfinite(load), mech, 0)

    def _conic_root(self, a, dx, dy, Q, sigma):
        r"""Smallest root ``t >= 0`` of (2.9) along ``(t dx, t dy)`` with ``N = sigma (Tx sin a +
        Q cos a) > 0`` where the block climbs the flank.

        Climbing: the in-plane load :math:`T_1 = T_x\cos a - Q\sin a` points up-slope,
        :math:`T_1 \ge 0` (non-associated; the other flank blocks a descent, since
        :math:`V\cdot n_{other} = T_1\sin(\alpha_2-\alpha_1)/|F_t|`), or
        :math:`T_1 \ge \mu^2\tan\delta\,N` (associated: :math:`V\cdot n_{other} \ge
        \sin\varrho`).
        """
        mu = self._mu
        climb = mu**2 * np.tan(self._assoc_pair[0]) if self.associated else 0.0
        A = dx**2 * (np.cos(a) ** 2 - mu**2 * np.sin(a) ** 2) + dy**2
        B = -dx * Q * np.sin(2 * a) * (1 + mu**2)
        C = Q**2 * (np.sin(a) ** 2 - mu**2 * np.cos(a) ** 2) + 0.0 * dx
        disc = B**2 - 4 * A * C
        best = np.full(np.shape(dx), np.inf)
        with np.errstate(divide="ignore", invalid="ignore"):
            sq = np.sqrt(np.where(disc >= 0, disc, 0.0))
            for sgn in (1.0, -1.0):
                t = np.where(np.abs(A) > 1e-14, (-B + sgn * sq) / (2 * A),
                             np.where(B != 0, -C / np.where(B != 0, B, 1.0), np.inf))
                N = sigma * (t * dx * np.sin(a) + Q * np.cos(a))
                T1 = t * dx * np.cos(a) - Q * np.sin(a)
                ok = (disc >= 0) & np.isfinite(t) & (t >= -1e-12) & (N > 0)
                ok &= T1 >= climb * N - 1e-12 * (1.0 + np.abs(N))
                best = np.where(ok & (t < best), np.clip(t, 0.0, None), best)
        return best
