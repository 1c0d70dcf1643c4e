r"""Internal variables of a law: the record ``q`` of f(T, N, q), g(T, N, q).

A perfectly plastic law has no internal variables (``q`` is empty). A hardening law carries,
e.g., the accumulated tangential plastic slip κ and the fraction of real contact area β of §4,
evolving by (4.5) :math:`\dot q = \dot\lambda\, h(T, N, q)`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FrictionRulesError, check_finite

__all__ = ["LawState"]


@dataclass(frozen=True, eq=False)
class LawState:
    """The internal variables of a law at a batch of points (read-only).

    Attributes
    ----------
    names : tuple of str
        Variable names, in the law's order (``law.state_names``).
    values : array (..., len(names))
        Their values; one row per point of the batch.

    Each variable is also an attribute: ``q.kappa`` is ``q.values[..., q.names.index("kappa")]``.
    """

    names: tuple[str, ...]
    values: np.ndarray

    def __post_init__(self):
        names = tuple(str(n) for n in self.names)
        if len(set(names)) != len(names):
            raise FrictionRulesError(f"state names = {names!r} violates: names must be distinct")
        v = check_finite("state values", self.values)
        if v.ndim == 0 or v.shape[-1] != len(names):
            raise FrictionRulesError(
                f"state values must have shape (..., {len(names)}) for the variables {names}, got "
                f"shape {v.shape}")
        v = np.array(v, dtype=float)
        v.flags.writeable = False
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "values", v)

    @classmethod
    def empty(cls, shape=()) -> "LawState":
        """The state of a law without internal variables, for a batch of ``shape``."""
        return cls((), np.zeros(tuple(shape) + (0,)))

    @classmethod
    def of(cls, names, shape=(), **values) -> "LawState":
        """A state of ``shape`` with each variable broadcast from ``values`` (all required)."""
        names = tuple(names)
        missing = [n for n in names if n not in values]
        extra = sorted(set(values) - set(names))
        if missing or extra:
            raise FrictionRulesError(
                f"state values {sorted(values)} violate: exactly the variables {list(names)} "
                f"(missing {missing}, unknown {extra})")
        shape = tuple(shape)
        cols = [np.broadcast_to(check_finite(n, values[n]), shape) for n in names]
        return cls(names, np.stack(cols, axis=-1) if cols else np.zeros(shape + (0,)))

    def __getattr__(self, name):
        names = object.__getattribute__(self, "names")
        if name in names:
            return object.__getattribute__(self, "values")[..., names.index(name)]
        raise AttributeError(f"the law state has no variable {name!r} (it has {list(names)})")

    @property
    def shape(self) -> tuple[int, ...]:
        return self.values.shape[:-1]

    def as_dict(self) -> dict[str, np.ndarray]:
        return {n: self.values[..., i] for i, n in enumerate(self.names)}

    def __repr__(self) -> str:
        inner = ", ".join(f"{n}={np.array2string(self.values[..., i], threshold=6)}"
                          for i, n in enumerate(self.names))
        return f"LawState({inner})"
