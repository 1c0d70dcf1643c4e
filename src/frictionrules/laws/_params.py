"""The parameters of a law as data: name, meaning, unit and bounds, declared once on the
dataclass field and read by the constructor's check, the law table, the command line, TOML
files and the exporters' README tables."""

from __future__ import annotations

import dataclasses
import functools
import numbers
from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_scalar

__all__ = ["Parameter", "parameter", "Parameterized"]


@dataclass(frozen=True)
class Parameter:
    """One parameter of a law (or of a part of one, such as a hardening function).

    Attributes
    ----------
    name : str
    meaning : str
        What it is, in a few words (help texts, README tables of exported code).
    unit : str
        ``"1"`` (dimensionless), ``"rad"``, ``"length"``, ``"force"``, ...
    kind : type
        ``float``, ``bool`` or ``str`` (then ``choices``); ``dict`` for a table of named
        numbers (a user law's ``params``) or of expressions.
    lo, hi, lo_open, hi_open : bounds of a number (``None``: unbounded).
    choices : tuple of str
    required : bool
        It has no default.
    default : the value when not given.
    """

    name: str
    meaning: str
    unit: str = "1"
    kind: type = float
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple = ()
    required: bool = False
    default: object = None

    @property
    def constraint(self) -> str:
        """The constraint a value must satisfy, as the error message states it."""
        n = self.name
        if self.kind is float:
            parts = ([f"{n} {'>' if self.lo_open else '>='} {self.lo}"] if self.lo is not None
                     else []) + ([f"{n} {'<' if self.hi_open else '<='} {self.hi}"]
                                 if self.hi is not None else [])
            return " and ".join(parts) or f"{n} a finite number"
        if self.kind is bool:
            return f"{n} true or false"
        if self.choices:
            return f"{n} in {self.choices}"
        return f"{n} a {self.kind.__name__}"

    def check(self, value):
        """``value`` converted (a float, a bool) where it satisfies :attr:`constraint`, else
        :class:`FrictionRulesError` naming the parameter, the value and the constraint (for a
        number, the bound it violates)."""
        if self.kind is float:  # the message states the bound violated
            return check_scalar(self.name, value, lo=self.lo, hi=self.hi, lo_open=self.lo_open,
                                hi_open=self.hi_open)
        if self.kind is bool:
            if isinstance(value, (bool, np.bool_)) or (isinstance(value, numbers.Integral)
                                                       and value in (0, 1)):
                return bool(value)
        elif self.choices:
            if isinstance(value, str) and value in self.choices:
                return value
        elif isinstance(value, self.kind):
            return value
        raise FrictionRulesError(f"{self.name} = {value!r} violates {self.constraint}")


def parameter(meaning: str, unit: str = "1", *, kind: type = float, lo=None, hi=None,
              lo_open: bool = False, hi_open: bool = False, choices: tuple = (),
              default=dataclasses.MISSING, nested: bool = False):
    """A dataclass field declared as a checked parameter (see :class:`Parameterized`).

    ``nested=True`` marks a field holding a :class:`Parameterized` part (the hardening functions
    of the cap): its parameters count as the law's own, under their own names, and ``default``
    is then the part's class (its defaults make the default part).
    """
    if nested:
        return dataclasses.field(default_factory=default, metadata={"nested": True})
    spec = Parameter("", meaning, unit, kind, lo, hi, lo_open, hi_open, tuple(choices))
    return dataclasses.field(default=default, metadata={"parameter": spec})


@functools.cache
def _table(cls) -> dict[str, Parameter]:
    """The declared parameters of a dataclass ``cls`` by name, nested parts' included."""
    out = {}
    for f in dataclasses.fields(cls) if dataclasses.is_dataclass(cls) else ():
        if f.metadata.get("nested"):
            out.update(_table(f.default_factory))
        elif "parameter" in f.metadata:
            out[f.name] = dataclasses.replace(
                f.metadata["parameter"], name=f.name, required=f.default is dataclasses.MISSING,
                default=None if f.default is dataclasses.MISSING else f.default)
    return out


class Parameterized:
    """A frozen dataclass whose fields declared with :func:`parameter` are checked where the
    object is made, and which can be rebuilt from its parameters by name."""

    def __post_init__(self):
        table = _table(type(self))
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.metadata.get("nested") and not isinstance(value, f.default_factory):
                raise FrictionRulesError(f"{f.name} = {value!r} violates: must be of type "
                                         f"{f.default_factory.__name__}")
            if f.name in table:
                object.__setattr__(self, f.name, table[f.name].check(value))

    @classmethod
    def parameter_table(cls) -> dict[str, Parameter]:
        """The declared parameters by name (those of nested parts included), in order."""
        return dict(_table(cls))

    def arguments(self) -> dict:
        """The values of every field by name, nested parts flattened: what
        :meth:`from_parameters` takes back."""
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.metadata.get("nested"):
                out.update(value.arguments())
            else:
                out[f.name] = value
        return out

    @classmethod
    def from_parameters(cls, **values):
        """The object of the given parameters by name (nested parts built from theirs);
        :class:`FrictionRulesError` for an unknown or a missing one."""
        table = cls.parameter_table()
        unknown = sorted(set(values) - set(table) - {f.name for f in dataclasses.fields(cls)})
        if unknown:
            raise FrictionRulesError(f"unknown parameters {unknown}; constraint: parameters "
                                     f"in {list(table)}")
        missing = [n for n, p in table.items() if p.required and n not in values]
        if missing:
            raise FrictionRulesError(f"the parameters {missing} are missing; constraint: "
                                     f"{cls.__name__} needs {missing}")
        kwargs = {}
        for f in dataclasses.fields(cls):
            if f.metadata.get("nested"):
                part = f.default_factory
                kwargs[f.name] = part.from_parameters(**{
                    k: values.pop(k) for k in part.parameter_table() if k in values})
            elif f.name in values:
                kwargs[f.name] = values.pop(f.name)
        return cls(**kwargs)
