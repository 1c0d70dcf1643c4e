"""The law table: every law of frictionrules by name, with its parameters.

The command line (``frictionrules law NAME``, ``export``), law files (``type = ...``, see
:mod:`._layout`) and the API read this one table, so a law added here appears everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

from ..errors import FrictionRulesError
from .cap import EllipsoidCap
from .coulomb import Coulomb
from .orthotropic import EllipticOrthotropic, Huber, TransformedCoulomb
from .user import UserLaw
from .wedge import WedgeAsperity

__all__ = ["LawEntry", "LAWS", "law_entry"]


@dataclass(frozen=True)
class LawEntry:
    """One law of the table.

    Attributes
    ----------
    name : str
        Its short name: ``frictionrules law NAME``.
    cls : type
        The law's class; ``cls.__name__`` is its ``type`` in a law file.
    aliases : tuple of str
        Other names accepted for it.
    """

    name: str
    cls: type
    aliases: tuple = ()

    @property
    def type(self) -> str:
        """The class name: ``type = "..."`` in a law file."""
        return self.cls.__name__

    @property
    def parameters(self) -> dict:
        """The law's parameters by name (:class:`~frictionrules.laws.Parameter`: meaning,
        unit, bounds, default)."""
        return self.cls.parameter_table()

    @property
    def summary(self) -> str:
        """The first line of the class docstring."""
        return (self.cls.__doc__ or "").strip().splitlines()[0]


#: The laws by short name (read-only).
LAWS = MappingProxyType({e.name: e for e in (
    LawEntry("coulomb", Coulomb),
    LawEntry("elliptic", EllipticOrthotropic, ("orthotropic",)),
    LawEntry("huber", Huber),
    LawEntry("transformed", TransformedCoulomb),
    LawEntry("wedge", WedgeAsperity),
    LawEntry("cap", EllipsoidCap),
    LawEntry("user", UserLaw),
)})


def _key(text: str) -> str:
    return text.lower().replace("-", "").replace("_", "")


_LOOKUP = MappingProxyType({_key(n): e for e in LAWS.values()
                            for n in (e.name, e.type, *e.aliases)})


def law_entry(name, where: str = "law") -> LawEntry:
    """The entry of a short name, a class name or an alias (case, ``-`` and ``_`` ignored)."""
    entry = _LOOKUP.get(_key(name)) if isinstance(name, str) else None
    if entry is None:
        raise FrictionRulesError(
            f"unknown law {name!r} ({where}); constraint: one of {', '.join(LAWS)} (or the "
            f"class names {', '.join(e.type for e in LAWS.values())})")
    return entry
