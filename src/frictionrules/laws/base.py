r"""The law protocol: what every friction law, built-in or user-defined, offers.

A law is a frozen dataclass of parameters. Its history — the internal variables ``q`` of a
hardening law, e.g. the accumulated slip κ and the real-contact-area fraction β of §4 — is a
separate :class:`LawState` passed in and returned, never stored in the law. All methods are pure
and vectorized over leading dimensions: ``T`` has shape ``(..., 2)`` (tangential force in the
contact frame), ``N`` shape ``(...)`` (normal force, compression positive), ``q`` a
:class:`LawState` of shape ``(...)`` (``None``: the law's initial state; ignored by laws without
internal variables) and a slip ``v`` shape ``(..., 3)`` ``(v1, v2, vn)`` or ``(..., 2)``, with
``vn > 0`` on opening (see ``docs/conventions.md``).

The generalized force conjugate to the generalized slip ``(v1, v2, vn)`` is ``(T1, T2, -N)``,
so the power of the contact forces is :math:`D = T\cdot v - N v_n` ((1.7), (1.12)) and the
sliding rule ((1.1)–(1.2), (2.7), (4.3)) with the evolution of the internal variables (4.5) reads

.. math:: v = \dot\lambda\,\Bigl(\frac{\partial g}{\partial T_1},
          \frac{\partial g}{\partial T_2}, -\frac{\partial g}{\partial N}\Bigr),
          \qquad \dot q = \dot\lambda\, h(T, N, q), \qquad \dot\lambda \ge 0 .

A potential is defined up to an additive constant (the paper's ``- C`` in (2.6), (2.14)):
only its gradient matters, and ``potential`` returns it without the constant.

**Capabilities.** What a consumer needs beyond f and g is declared by the law in
:attr:`FrictionLaw.capabilities` and checked where the law enters (a contact model, a
multi-contact problem, an exporter) by :func:`require`:

* ``"symbolic"`` — :meth:`FrictionLaw.symbolic_form`: f, g and the evolution of q as SymPy
  expressions; derived Hessians, the compiled return mapping and generated code follow;
* ``"cone"`` — :meth:`FrictionLaw.cone`: the law is an elliptic cone (Coulomb-like) with a
  constant dilatancy ratio, as the many-contact solvers need;
* ``"closed_form_return"`` — :meth:`FrictionLaw.closed_form_return`: a hand-written compiled
  return mapping, a fast path used instead of the generated one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite, check_nonnegative, check_vectors
from ._params import Parameterized
from ._records import Cone, InverseRelation
from ._state import LawState
from ._traits import LawTraits

__all__ = ["FrictionLaw", "RuleComparison", "compare_rules", "InverseRelation", "Cone",
           "require", "CAPABILITIES"]

#: The capabilities a law can declare, and what each gives.
CAPABILITIES = {
    "symbolic": "a symbolic form (f, g and the evolution of its internal variables as SymPy "
                "expressions), from which Hessians, the compiled return mapping and exported "
                "code are derived",
    "cone": "an elliptic-cone form with a constant dilatancy ratio (Coulomb, elliptic "
            "orthotropic, dilatant Coulomb), as the many-contact solvers need",
    "closed_form_return": "a hand-written compiled return mapping (a fast path)",
}


def require(law, capability: str, where: str) -> None:
    """Raise :class:`FrictionRulesError` unless ``law`` declares ``capability``.

    ``where`` names the consumer in the message, e.g. ``"ContactModel(law=...)"``.
    """
    if capability not in CAPABILITIES:
        raise ValueError(f"unknown capability {capability!r}")
    caps = getattr(law, "capabilities", None)
    if caps is None:
        raise FrictionRulesError(f"{where}: law = {law!r} violates: must be a friction law of "
                                 "frictionrules (a FrictionLaw)")
    if capability not in caps:
        have = ", ".join(sorted(caps)) or "none"
        raise FrictionRulesError(
            f"{where}: law = {_short(law)} lacks the capability {capability!r} "
            f"({CAPABILITIES[capability]}); it declares: {have}")


def _short(law) -> str:
    text = repr(law)
    return text if len(text) <= 120 else text[:117] + "..."


def safe_ratio(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a / b`` where ``b > 0`` and 0 where ``b == 0``: the minimal-norm subgradient at a kink."""
    a, b = np.broadcast_arrays(a, b)
    return np.divide(a, b, out=np.zeros(a.shape), where=b > 0)


def as_force(T) -> np.ndarray:
    return check_vectors("T", T, (2,))


def as_slip(v) -> np.ndarray:
    v = check_vectors("v", v, (2, 3))
    if np.any(np.hypot(v[..., 0], v[..., 1]) == 0):
        raise FrictionRulesError("v has a zero tangential part: the slip direction is undefined "
                                 "(constraint: v1**2 + v2**2 > 0)")
    return v


def unit3(grad: np.ndarray) -> np.ndarray:
    """Generalized slip direction from a gradient ``(dg/dT1, dg/dT2, dg/dN)``, normalized.

    Returns zeros where the gradient vanishes: the minimal-norm subgradient at a kink such as
    the apex ``T = 0`` of a cone without normal slip, where no direction is preferred.
    """
    v = np.stack((grad[..., 0], grad[..., 1], 0.0 - grad[..., 2]), axis=-1)
    norm = np.sqrt(v[..., 0] ** 2 + v[..., 1] ** 2 + v[..., 2] ** 2)
    v *= safe_ratio(1.0, norm)[..., None]
    return v


class FrictionLaw(Parameterized):
    """Interface of a friction law: limit condition f, sliding potential g and what follows.

    Subclasses are frozen dataclasses holding parameters only. A law either gives its
    symbolic form (:meth:`symbolic_form`, capability ``"symbolic"``), from which every function
    here is derived, or overrides :meth:`limit`, :meth:`potential` and their gradients. Closed
    forms replace the derived functions where a law has them (the tests compare the two).

    Notes
    -----
    ``limit`` is negative inside (stick), zero on the limit surface, positive outside.
    The normal argument is called ``N``; for laws in external loads (e.g. the wedge asperity)
    the vertical load ``Q`` takes its place with the same sign convention.
    """

    #: Name of the normal-force argument in messages (``"N"`` or ``"Q"``).
    normal_name = "N"
    #: Names of the internal variables q (empty: perfectly plastic).
    state_names: tuple[str, ...] = ()
    #: The capabilities the law declares (see :data:`CAPABILITIES`).
    capabilities: frozenset = frozenset()
    #: True when f and g are defined for N < 0 as well (otherwise N >= 0 is required).
    defined_in_tension: bool = False

    # ---- internal variables ----------------------------------------------------------------
    def initial_values(self) -> dict[str, float]:
        """Values of the internal variables of a virgin contact (override with state)."""
        return {}

    def initial_state(self, shape=(), **values) -> LawState:
        """The state of virgin contacts, ``shape`` of them; ``values`` override the defaults."""
        shape = (int(shape),) if np.ndim(shape) == 0 else tuple(int(k) for k in shape)
        base = self.initial_values()
        unknown = sorted(set(values) - set(self.state_names))
        if unknown:
            raise FrictionRulesError(f"initial state {unknown} violates: the law's internal "
                                     f"variables are {list(self.state_names)}")
        base.update(values)
        state = LawState.of(self.state_names, shape, **base)
        self._check_state(state.values)
        return state

    def _check_state(self, q: np.ndarray) -> None:
        """Raise where the internal variables are out of their domain (override with state)."""

    def _state(self, q, shape=()) -> np.ndarray:
        """The values ``(..., nq)`` of ``q`` (``None``: the initial state)."""
        nq = len(self.state_names)
        if q is None:
            return np.broadcast_to(self.initial_state().values, tuple(shape) + (nq,))
        if isinstance(q, LawState):
            if q.names != self.state_names:
                raise FrictionRulesError(f"q has the variables {list(q.names)}; constraint: the "
                                         f"law's internal variables {list(self.state_names)}")
            values = q.values
        else:
            values = check_finite("q", q)
            if values.ndim == 0 or values.shape[-1] != nq:
                raise FrictionRulesError(f"q must be a LawState or an array of shape (..., {nq}) "
                                         f"({list(self.state_names)}), got shape {values.shape}")
        if nq:
            self._check_state(values)
        return values

    # ---- parameters ------------------------------------------------------------------------
    @property
    def parameters(self) -> dict[str, float]:
        """The law's numeric parameters, name -> value (what :func:`frictionrules.fit` fits)."""
        return {k: v for k, v in self.arguments().items() if isinstance(v, float)}

    def parameter_info(self) -> dict:
        """:class:`~frictionrules.laws.Parameter` (meaning, unit, bounds) of each numeric
        parameter that the law's table declares."""
        table = self.parameter_table()
        return {k: table[k] for k in self.parameters if k in table}

    @property
    def parameter_descriptions(self) -> dict[str, str]:
        """The law's own words for its parameters, name -> text (a user law's; the built-in
        laws' parameters are described by their classes' docstrings): empty by default."""
        return {}

    def replace(self, **changes) -> "FrictionLaw":
        """A copy of the law with some parameters changed (validated like the constructor)."""
        unknown = sorted(set(changes) - set(self.parameters))
        if unknown:
            raise FrictionRulesError(f"parameters {unknown} violate: the law's parameters are "
                                     f"{sorted(self.parameters)}")
        return type(self).from_parameters(**{**self.arguments(), **changes})

    # ---- the symbolic form -----------------------------------------------------------------
    def symbolic_form(self):
        """f, g and the evolution of q as SymPy expressions (:class:`SymbolicLaw`).

        Raises :class:`FrictionRulesError` for a law without the capability ``"symbolic"``.
        """
        require(self, "symbolic", f"{type(self).__name__}.symbolic_form()")
        raise NotImplementedError  # pragma: no cover - a law declaring "symbolic" overrides this

    def symbolic(self):
        """``(f, g)`` as SymPy expressions with the parameter values put in.

        The symbols are ``T1, T2, N`` of :mod:`frictionrules` and, for laws with internal
        variables, the state symbols of :meth:`symbolic_form`.
        """
        from ._symbolic import form_of
        f, g, _ = form_of(self).substituted()
        return f, g

    def _derived(self):
        from ._symbolic import derived
        require(self, "symbolic", f"{type(self).__name__}")
        return derived(self)

    def _values(self) -> tuple[float, ...]:
        from ._symbolic import form_of
        return form_of(self).values

    def _call(self, name: str, T, N, q):
        T, N = self._inputs(T, N)
        shape = np.broadcast_shapes(T.shape[:-1], N.shape)
        qv = self._state(q, shape)
        return getattr(self._derived(), name)(T[..., 0], T[..., 1], N, qv, self._values())

    def _finite(self, what: str, out: np.ndarray) -> np.ndarray:
        if not np.all(np.isfinite(out)):
            f, g = self.symbolic()
            raise FrictionRulesError(
                f"the law's {what} is not finite at some of the given points (T, N); f = {f}, "
                f"g = {g}: evaluate it away from its singular points")
        return out

    @staticmethod
    def _subgradient(out: np.ndarray) -> np.ndarray:
        """Derivatives at a kink (0/0, e.g. the apex of a cone): the minimal-norm subgradient 0."""
        return np.where(np.isfinite(out), out, 0.0)

    # ---- f, g and their derivatives (derived from the symbolic form unless overridden) -----
    def limit(self, T, N, q=None) -> np.ndarray:
        """Limit condition f(T, N, q): < 0 stick, 0 limit surface, > 0 inadmissible."""
        return self._finite("limit condition", self._call("f", T, N, q))

    def potential(self, T, N, q=None) -> np.ndarray:
        """Sliding potential g(T, N, q), up to an additive constant."""
        return self._finite("sliding potential", self._call("g", T, N, q))

    def limit_gradient(self, T, N, q=None) -> np.ndarray:
        """``(df/dT1, df/dT2, df/dN)``, shape ``(..., 3)``."""
        return self._subgradient(self._call("grad_f", T, N, q))

    def potential_gradient(self, T, N, q=None) -> np.ndarray:
        """``(dg/dT1, dg/dT2, dg/dN)``, shape ``(..., 3)``."""
        return self._subgradient(self._call("grad_g", T, N, q))

    def limit_hessian(self, T, N, q=None) -> np.ndarray:
        """Second derivatives of f in ``(T1, T2, N)``, shape ``(..., 3, 3)``, derived symbolically.

        Undefined (non-finite) at kinks of f such as the cone apex ``T = 0``.
        """
        return self._call("hess_f", T, N, q)

    def potential_hessian(self, T, N, q=None) -> np.ndarray:
        """Second derivatives of g in ``(T1, T2, N)``, shape ``(..., 3, 3)``, derived symbolically."""
        return self._call("hess_g", T, N, q)

    def local_derivatives(self, T, N, q=None):
        """Everything the return mapping needs at ``(T, N, q)`` (:class:`LocalDerivatives`)."""
        from ._symbolic import LocalDerivatives
        return LocalDerivatives(*self._call("local", T, N, q))

    def state_rates(self, T, N, q=None) -> np.ndarray:
        r"""Evolution of the internal variables per unit multiplier, :math:`h = \dot q/\dot\lambda`
        ((4.5)), shape ``(..., nq)``."""
        return self.local_derivatives(T, N, q).h

    def hardening_modulus(self, T, N, q=None) -> np.ndarray:
        r"""H of (4.7): :math:`H = -\partial f/\partial q \cdot h` (0 for a perfectly plastic law).

        With :math:`\dot f = \nabla_\sigma f\cdot\dot\sigma - H\dot\lambda` the consistency
        condition gives the plastic multiplier (4.7).
        """
        loc = self.local_derivatives(T, N, q)
        return -np.sum(loc.dfq * loc.h, axis=-1)

    # ---- properties ----------------------------------------------------------------------
    @property
    def associated(self) -> bool:
        """True when g = f in the full space (T1, T2, N): normality including the normal slip."""
        return False

    @property
    def tangentially_associated(self) -> bool:
        """True when the tangential slip is normal to the limit curve at fixed N (a trait)."""
        return self.traits.tangentially_associated

    @property
    def traits(self) -> LawTraits:
        """What the layers above ask of the law (:class:`LawTraits`: homogeneity, normal slip,
        normality in the sliding plane, coupling through the internal variables, convexity),
        declared in closed form by the built-in laws, otherwise derived once from the symbolic
        form; cached per law."""
        from ._traits import traits_of
        return traits_of(self)

    def declared_traits(self) -> LawTraits | None:
        """The law's traits in closed form, or ``None`` (then derived from the symbolic form).

        A law that declares them has a test comparing them with the derived ones."""
        return None

    def cone(self, q=None) -> Cone:
        """The elliptic-cone form of the law (capability ``"cone"``) at the state ``q``."""
        require(self, "cone", f"{type(self).__name__}.cone()")
        raise NotImplementedError  # pragma: no cover - a law declaring "cone" overrides this

    def closed_form_return(self):
        """The hand-written compiled return mapping (capability ``"closed_form_return"``).

        Returns a record the contact integration runs (see :mod:`frictionrules.contact`).
        """
        require(self, "closed_form_return", f"{type(self).__name__}.closed_form_return()")
        raise NotImplementedError  # pragma: no cover

    # ---- derived quantities --------------------------------------------------------------
    def slip_direction(self, T, N, q=None) -> np.ndarray:
        r"""Unit generalized slip ``(v1, v2, vn)`` of the sliding rule at ``(T, N)``.

        .. math:: v = \frac{(g_{,T_1},\, g_{,T_2},\, -g_{,N})}{|(g_{,T_1},\, g_{,T_2},\, -g_{,N})|}

        ((1.2), (2.7)); ``vn > 0`` is opening (dilatancy). Where g has a kink its minimal-norm
        subgradient is used; where that vanishes (``T = 0`` of a cone with no normal slip) no
        direction is preferred and the result is the zero vector.
        """
        return unit3(self.potential_gradient(T, N, q))

    def normal_direction(self, T, N, q=None) -> np.ndarray:
        """Unit outward normal of the limit surface in ``(T1, T2, -N)``: the associated slip."""
        return unit3(self.limit_gradient(T, N, q))

    def inverse_relation(self, theta, N=1.0, q=None) -> InverseRelation:
        """Forces on the limit surface that slide at the tangential angles ``theta`` (radians).

        The inverse of the sliding rule ((1.8), (1.13)); where more than one point slides in a
        direction (possible for non-associated or non-convex laws) the smallest ``|T|``. Locked
        directions (no finite force) are flagged, with ``inf`` forces.
        """
        theta = check_finite("theta", theta)
        N = self._normal(N)
        theta, N = np.broadcast_arrays(theta, N)
        return self._inverse_relation(theta, N, q)

    def force_for_slip(self, v, N, q=None) -> np.ndarray:
        """Tangential force on the limit surface whose slip is along the tangential part of ``v``.

        The inverse of the sliding rule ((1.8), (1.13)). For associated-in-plane laws it is
        ``dD/dv``. Laws without a closed form scan the limit curve at fixed ``N`` (star-shaped
        about :meth:`centre`) for the points whose tangential slip direction equals that of
        ``v`` and refine them by bracketing; when more than one point slides in that direction
        (possible for non-associated or non-convex laws) the one with the smallest ``|T|`` is
        returned. Raises :class:`FrictionRulesError` where no point slides that way.

        Parameters
        ----------
        v : array (..., 2) or (..., 3)
            Slip; only its tangential direction is used.
        N : array (...)
            Normal force (compression positive).

        Returns
        -------
        T : array (..., 2)
        """
        v = as_slip(v)
        theta = np.arctan2(v[..., 1], v[..., 0])
        inv = self.inverse_relation(theta, N, q)
        if np.any(inv.locked):
            first = tuple(np.argwhere(np.atleast_1d(inv.locked))[0])
            raise FrictionRulesError(
                f"no force on the limit surface slides at theta = "
                f"{float(np.atleast_1d(theta)[first])!r} rad ({self.normal_name} = "
                f"{float(np.atleast_1d(np.broadcast_to(self._normal(N), theta.shape))[first])!r})"
                ": the law locks in that direction")
        return inv.force

    def dissipation(self, v, N, q=None) -> np.ndarray:
        r"""Power of the contact forces on the slip ``v``: :math:`D = T\cdot v_t - N v_n`.

        ``T = force_for_slip(v, N)`` ((1.7), (1.12)). For a 2-component ``v`` the normal slip is
        the one the sliding rule implies at ``T``; for a 3-component ``v`` its ``vn`` is used.
        """
        v = as_slip(v)
        N = self._normal(N)
        T = self.force_for_slip(v, N, q)
        vt = v[..., :2]
        if v.shape[-1] == 3:
            vn = v[..., 2]
        else:
            s = self.slip_direction(T, N, q)
            vn = np.hypot(vt[..., 0], vt[..., 1]) * safe_ratio(s[..., 2], np.hypot(s[..., 0], s[..., 1]))
        return np.sum(T * vt, axis=-1) - N * vn

    def friction_coefficient(self, theta, N=1.0, q=None) -> np.ndarray:
        r"""Directional friction coefficient :math:`\mu(\theta) = |T|/N` ((1.15)).

        ``T`` is the force on the limit surface that makes the contact slide at angle
        ``theta`` (radians, from the x axis). Returns ``inf`` where no finite force slides
        that way (self-locking; :meth:`inverse_relation` flags those directions).
        """
        inv = self.inverse_relation(theta, N, q)
        N = np.broadcast_to(self._normal(N), inv.locked.shape)
        with np.errstate(divide="ignore", invalid="ignore"):
            mu = np.hypot(inv.force[..., 0], inv.force[..., 1]) / N
        return np.where(inv.locked, np.inf, mu)

    def force_angle(self, theta, N=1.0, q=None) -> np.ndarray:
        """Angle beta of the force that makes the contact slide at angle ``theta`` ((1.14))."""
        theta = check_finite("theta", theta)
        T = self.force_for_slip(np.stack((np.cos(theta), np.sin(theta)), axis=-1), N, q)
        return np.arctan2(T[..., 1], T[..., 0])

    def centre(self, N, q=None) -> np.ndarray:
        """A point inside the limit curve at fixed N, about which the curve is star-shaped."""
        N = np.asarray(N, dtype=float)
        return np.zeros(N.shape + (2,))

    # ---- helpers for subclasses ----------------------------------------------------------
    def _normal(self, N) -> np.ndarray:
        return check_nonnegative(self.normal_name, N)

    def _inputs(self, T, N) -> tuple[np.ndarray, np.ndarray]:
        return as_force(T), self._normal(N)

    def _inverse_relation(self, theta: np.ndarray, N: np.ndarray, q) -> InverseRelation:
        """Forces on the limit surface sliding at ``theta``; the numeric default."""
        from ._inverse import inverse_relation
        return inverse_relation(self, theta, N, q)


@dataclass(frozen=True)
class RuleComparison:
    """Associated direction (normal to f) against a law's actual slip, at the same forces.

    Attributes
    ----------
    associated : (..., 3) unit normal of f in ``(T1, T2, -N)`` ((2.5) in the sliding plane).
    actual : (..., 3) unit slip of the law's potential g ((2.4)).
    angle : (...) angle between the two 3-vectors, radians.
    tangential_angle : (...) angle between their tangential parts (the sliding plane).
    """

    associated: np.ndarray
    actual: np.ndarray
    angle: np.ndarray
    tangential_angle: np.ndarray


def _angle_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    cross = np.linalg.norm(np.cross(a, b), axis=-1) if a.shape[-1] == 3 else np.abs(
        a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0])
    return np.arctan2(cross, np.sum(a * b, axis=-1))


def compare_rules(law: FrictionLaw, T, N, q=None) -> RuleComparison:
    """Compare the associated direction (normal to f) with the law's slip at ``(T, N)``.

    For the wedge asperity this is (2.5) against (2.4): the associated ratio ``Vx/Vy`` and the
    actual one differ unless ``mu = 0``.
    """
    assoc = law.normal_direction(T, N, q)
    actual = law.slip_direction(T, N, q)
    return RuleComparison(assoc, actual, _angle_between(assoc, actual),
                          _angle_between(assoc[..., :2], actual[..., :2]))
