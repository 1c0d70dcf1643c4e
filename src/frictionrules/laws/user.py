r"""A law written by the user: f and g (and the evolution of internal variables) as expressions.

Expressions are SymPy expressions or strings in the force symbols ``T1, T2, N``, the names of
the law's parameters and of its internal variables. Strings are read by a whitelist parser
(numbers, those names, ``+ - * / **``, parentheses and a fixed list of functions): they are
never evaluated as code.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import FrictionRulesError, check_finite
from .base import FrictionLaw

__all__ = ["UserLaw"]

#: Names a rate expression may use for the gradient of g (replaced by the derivatives).
GRADIENT_NAMES = ("dg_dT1", "dg_dT2", "dg_dN")
#: A rate given as this string is the accumulated-slip rate |dg/dT| ((4.5)).
SLIP = "slip"
_RESERVED = ("T1", "T2", "N") + GRADIENT_NAMES


def _symbol(name: str):
    import sympy
    return sympy.Symbol(name, real=True)


def _check_name(kind: str, name) -> str:
    if not isinstance(name, str) or not name.isidentifier() or name.startswith("_"):
        raise FrictionRulesError(f"{kind} name {name!r} violates: an identifier not starting "
                                 "with '_'")
    if name in _RESERVED:
        raise FrictionRulesError(f"{kind} name {name!r} violates: reserved names {_RESERVED}")
    return name


def _parse(text: str, symbols: dict, name: str):
    """A law string as a SymPy expression, by the whitelist parser."""
    from ._expr import parse_expression
    return parse_expression(text, symbols, name=name)


def _expression(name: str, value, symbols: dict):
    """``value`` (string or SymPy expression) in the allowed ``symbols`` (name -> Symbol)."""
    import sympy

    if isinstance(value, str):
        expr = _parse(value, symbols, name)
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        expr = sympy.Float(check_finite(name, value).item())
    elif isinstance(value, sympy.Basic):
        # symbols the user made with other assumptions are matched by name
        expr = value.xreplace({s: symbols[s.name] for s in value.free_symbols
                               if getattr(s, "name", None) in symbols})
    else:
        raise FrictionRulesError(f"{name} = {value!r} violates: a string or a SymPy expression")
    unknown = expr.free_symbols - set(symbols.values())
    if unknown:
        raise FrictionRulesError(
            f"{name} = {expr} uses the symbols {sorted(map(str, unknown))}; constraint: only "
            f"{', '.join(symbols)} (declare parameters in params=, internal variables in state=)")
    if expr.has(sympy.zoo, sympy.nan, sympy.oo, -sympy.oo):
        raise FrictionRulesError(f"{name} = {expr} violates: must be finite")
    return expr


def _items(name: str, value) -> tuple:
    if value is None:
        return ()
    if isinstance(value, dict):
        return tuple(value.items())
    try:
        return tuple((k, v) for k, v in value)
    except (TypeError, ValueError):
        raise FrictionRulesError(f"{name} = {value!r} violates: a mapping name -> value") from None


@dataclass(frozen=True, init=False)
class UserLaw(FrictionLaw):
    r"""A friction law given by its limit condition f and sliding potential g.

    Parameters
    ----------
    limit : str or sympy.Expr
        f(T1, T2, N, params, state): negative inside, zero on the limit surface.
    potential : str or sympy.Expr, optional
        g; the law is associated (g = f) when omitted.
    params : dict, optional
        Named parameters and their values, e.g. ``{"mu": 0.3}``; in the expressions they are
        symbols, so :func:`frictionrules.fit`, equality, hashing, TOML files and code generation
        treat them like the parameters of a built-in law.
    state : dict, optional
        Named internal variables and their values in a virgin contact, e.g. ``{"kappa": 0.0}``.
    rates : dict, optional
        Their evolution per unit plastic multiplier, :math:`h = \dot q/\dot\lambda` ((4.5)),
        one expression per internal variable; it may use ``dg_dT1, dg_dT2, dg_dN`` for the
        gradient of g, and the string ``"slip"`` stands for the accumulated-slip rate
        :math:`|\partial g/\partial T|`.
    descriptions : dict, optional
        What each parameter means, in the user's words, e.g. ``{"mu_x": "friction along the
        grooves"}``: exported code and READMEs quote it (a parameter without one is a "user
        parameter"; its meaning is never guessed from its name). Not part of the law's identity
        (equality, hashing).

    Gradients and Hessians are derived symbolically; at a kink (the apex of a cone) the
    minimal-norm subgradient is used. The inverse relation is solved numerically.

    Examples
    --------
    >>> from frictionrules import UserLaw
    >>> law = UserLaw("sqrt(T1**2 + T2**2) - mu*N", potential="sqrt(T1**2 + T2**2)",
    ...               params={"mu": 0.3})
    >>> float(law.limit([0.3, 0.0], 1.0))
    0.0
    >>> law.replace(mu=0.4).parameters
    {'mu': 0.4}
    """

    limit_expr: object
    potential_expr: object
    params: tuple
    state: tuple
    rates: tuple
    descriptions: tuple = field(default=(), compare=False)

    def __init__(self, limit, potential=None, params=None, state=None, rates=None, *,
                 descriptions=None):
        from .._optional import require
        sympy = require("sympy", purpose="UserLaw")

        from .symbols import N, T1, T2
        params = tuple((_check_name("parameter", k), check_finite(k, v).item() if np.ndim(v) == 0
                        else _scalar_error(k, v)) for k, v in _items("params", params))
        state = tuple((_check_name("internal variable", k), check_finite(k, v).item()
                       if np.ndim(v) == 0 else _scalar_error(k, v)) for k, v in _items("state", state))
        names = [k for k, _ in params] + [k for k, _ in state]
        if len(set(names)) != len(names):
            raise FrictionRulesError(f"params and state names {names} violate: names must be distinct")
        symbols = {"T1": T1, "T2": T2, "N": N, **{k: _symbol(k) for k in names}}
        f = _expression("limit", limit, symbols)
        g = None if potential is None else _expression("potential", potential, symbols)
        rate_map = dict(_items("rates", rates))
        missing = [k for k, _ in state if k not in rate_map]
        extra = sorted(set(rate_map) - {k for k, _ in state})
        if missing or extra:
            raise FrictionRulesError(f"rates {sorted(rate_map)} violate: one rate per internal "
                                     f"variable {[k for k, _ in state]} (missing {missing}, "
                                     f"unknown {extra})")
        grad_syms = {n: _symbol(n) for n in GRADIENT_NAMES}
        rate_exprs = []
        for k, _ in state:
            r = rate_map[k]
            if isinstance(r, str) and r.strip() == SLIP:
                rate_exprs.append(sympy.Symbol(SLIP))
            else:
                rate_exprs.append(_expression(f"rates[{k!r}]", r, {**symbols, **grad_syms}))
        object.__setattr__(self, "limit_expr", f)
        object.__setattr__(self, "potential_expr", g)
        object.__setattr__(self, "params", params)
        object.__setattr__(self, "state", state)
        object.__setattr__(self, "rates", tuple(rate_exprs))
        texts = dict(_items("descriptions", descriptions))
        unknown = sorted(set(texts) - {k for k, _ in params})
        if unknown or not all(isinstance(t, str) for t in texts.values()):
            raise FrictionRulesError(f"descriptions = {texts!r} violates: texts for parameters "
                                     f"of the law ({[k for k, _ in params]}); unknown {unknown}")
        object.__setattr__(self, "descriptions",
                           tuple((k, " ".join(texts[k].split())) for k, _ in params if k in texts))

    # ---- protocol ----------------------------------------------------------------------------
    @property
    def capabilities(self) -> frozenset:
        from ._cone import cone_of
        return frozenset({"symbolic"} | ({"cone"} if cone_of(self) is not None else set()))

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(k for k, _ in self.state)

    def initial_values(self) -> dict[str, float]:
        return dict(self.state)

    @property
    def parameters(self) -> dict[str, float]:
        return dict(self.params)

    @property
    def parameter_descriptions(self) -> dict[str, str]:
        """Every parameter's description: the user's text, or ``"user parameter"``."""
        own = dict(self.descriptions)
        return {k: own.get(k, "user parameter") for k, _ in self.params}

    def parameter_info(self) -> dict:
        """A :class:`~frictionrules.laws.Parameter` per user parameter: its meaning is the
        user's description (never guessed from the name), its unit that of the law."""
        from ._params import Parameter
        return {k: Parameter(k, text, "as in the law")
                for k, text in self.parameter_descriptions.items()}

    def replace(self, **changes) -> "UserLaw":
        unknown = sorted(set(changes) - set(self.parameters))
        if unknown:
            raise FrictionRulesError(f"parameters {unknown} violate: the law's parameters are "
                                     f"{sorted(self.parameters)}")
        return UserLaw(self.limit_expr, self.potential_expr, {**self.parameters, **changes},
                       dict(self.state), dict(zip(self.state_names, self._rate_inputs())),
                       descriptions=dict(self.descriptions))

    def _rate_inputs(self):
        import sympy
        return [SLIP if r == sympy.Symbol(SLIP) else r for r in self.rates]

    @property
    def associated(self) -> bool:
        return self.potential_expr is None

    def symbolic_form(self):
        import sympy

        from ._symbolic import SymbolicLaw, slip_rate
        from .symbols import N, T1, T2
        f = self.limit_expr
        g = f if self.potential_expr is None else self.potential_expr
        grads = {_symbol(n): sympy.diff(g, s) for n, s in zip(GRADIENT_NAMES, (T1, T2, N))}
        grads[sympy.Symbol(SLIP)] = slip_rate(g)
        rates = tuple(r.xreplace(grads) for r in self.rates)
        return SymbolicLaw(f, g, state=tuple(_symbol(k) for k in self.state_names), rates=rates,
                           params=tuple(_symbol(k) for k, _ in self.params),
                           values=tuple(v for _, v in self.params))

    def cone(self, q=None):
        """The elliptic-cone form, when f and g have one (see :mod:`._cone`)."""
        from ._cone import cone_of
        from .base import require
        require(self, "cone", "UserLaw.cone()")
        return cone_of(self)

    # ---- as data (TOML files, the CLI) ------------------------------------------------------
    @classmethod
    def parameter_table(cls) -> dict:
        """What a user law is made of, as the law table lists it: the expressions and the
        tables of parameters, internal variables and their rates."""
        from ._params import Parameter
        return {"limit": Parameter("limit", "limit condition f (expression)", "", kind=str,
                                   required=True),
                "potential": Parameter("potential", "sliding potential g (expression; default f)",
                                       "", kind=str, default=None),
                "params": Parameter("params", "parameters of the expressions and their values",
                                    "", kind=dict, default=None),
                "state": Parameter("state", "internal variables and their virgin values", "",
                                   kind=dict, default=None),
                "rates": Parameter("rates", "evolution of each internal variable per unit "
                                   "multiplier (4.5): an expression or \"slip\"", "", kind=dict,
                                   default=None)}

    @classmethod
    def from_parameters(cls, **values) -> "UserLaw":
        return cls.from_mapping(values, name="UserLaw")

    def arguments(self) -> dict:
        return self.to_mapping()

    @classmethod
    def from_mapping(cls, table, *, name: str = "law") -> "UserLaw":
        """A user law from a mapping (e.g. a TOML table): ``limit`` (required), ``potential``,
        ``params``, ``state`` and ``rates`` (tables), as the constructor takes them. A
        parameter may be a table ``{ value = ..., description = "..." }``: the description is
        the parameter's meaning in exported code and READMEs.

        .. code-block:: toml

            [law]
            limit = "sqrt(T1**2 + T2**2) - mu*N"
            potential = "sqrt(T1**2 + T2**2) - psi*N"
            params = { mu = 0.5, psi = { value = 0.1, description = "dilatancy coefficient" } }
        """
        keys = list(cls.parameter_table())
        if not hasattr(table, "keys"):
            raise FrictionRulesError(f"{name} = {table!r} violates: a table with the keys "
                                     f"{', '.join(keys)}")
        unknown = sorted(set(table) - set(keys))
        if unknown:
            raise FrictionRulesError(f"{name} has the unknown keys {unknown}; constraint: keys in "
                                     f"{keys}")
        if "limit" not in table:
            raise FrictionRulesError(f"{name} has no 'limit'; constraint: the limit condition f "
                                     "is required")
        values, texts = {}, {}
        for key, value in _items(f"{name}: params", table.get("params")):
            if hasattr(value, "keys"):
                extra = sorted(set(value) - {"value", "description"})
                if "value" not in value or extra:
                    raise FrictionRulesError(
                        f"{name}: params.{key} = {dict(value)!r} violates: a number, or a table "
                        "with 'value' and an optional 'description'")
                if "description" in value:
                    texts[key] = value["description"]
                value = value["value"]
            values[key] = value
        return cls(table["limit"], table.get("potential"), values, table.get("state"),
                   table.get("rates"), descriptions=texts)

    def to_mapping(self) -> dict:
        """The inverse of :meth:`from_mapping` (expressions as strings)."""
        out = {"limit": str(self.limit_expr)}
        if self.potential_expr is not None:
            out["potential"] = str(self.potential_expr)
        if self.params:
            own = dict(self.descriptions)
            out["params"] = {k: {"value": v, "description": own[k]} if k in own else v
                             for k, v in self.params}
        if self.state:
            out["state"] = dict(self.state)
            out["rates"] = {k: str(r) for k, r in zip(self.state_names, self._rate_inputs())}
        return out

    def __repr__(self) -> str:
        parts = [f"limit={str(self.limit_expr)!r}"]
        if self.potential_expr is not None:
            parts.append(f"potential={str(self.potential_expr)!r}")
        if self.params:
            parts.append(f"params={dict(self.params)!r}")
        if self.state:
            parts.append(f"state={dict(self.state)!r}")
        return f"UserLaw({', '.join(parts)})"


def _scalar_error(name, value):
    raise FrictionRulesError(f"{name} = {value!r} violates: must be a real number")
