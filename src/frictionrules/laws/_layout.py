"""The one layout of a law in a file: a TOML table read by every command and by the API.

.. code-block:: toml

    [law]
    type = "EllipticOrthotropic"   # a name of the law table (frictionrules.LAWS)
    mu_x = 0.6                     # the law's parameters by name
    mu_y = 0.3
    angle = 0.2

    [law.hardening]                # optional slip hardening of a law without internal variables
    h = 0.2
    kappa_h = 0.05

A user law (``type = "UserLaw"``, or no ``type``) has ``limit``, ``potential``, ``params``,
``state`` and ``rates``; the cap (``type = "EllipsoidCap"``) the parameters of A and B under
their own names (``m, p, h, kappa_h, b, normal_ratio``). Drive and assembly files hold the same
table as ``[model.law]``.
"""

from __future__ import annotations

import json

from ..errors import FrictionRulesError
from .hardening import HardenedLaw, SlipHardening
from ._table import LAWS, law_entry

__all__ = ["law_from_mapping", "law_to_mapping", "law_to_toml", "read_law"]


def law_from_mapping(table, *, where: str = "[law]"):
    """The law of a table in the one layout (a dict, e.g. a table of a TOML file).

    ``where`` names the table in error messages (e.g. ``"run.toml: [model.law]"``).
    """
    if not hasattr(table, "keys"):
        raise FrictionRulesError(f"{where} = {table!r} violates: a table (type and the law's "
                                 "parameters)")
    table = dict(table)
    entry = law_entry(table.pop("type", "UserLaw"), where=f"{where} type")
    hardening = table.pop("hardening", None)
    try:
        law = entry.cls.from_parameters(**table)
        if hardening is not None:
            if not hasattr(hardening, "keys"):
                raise FrictionRulesError(f"hardening = {hardening!r} violates: a table "
                                         "(h, kappa_h)")
            law = HardenedLaw(law, SlipHardening.from_parameters(**hardening))
    except FrictionRulesError as exc:
        raise FrictionRulesError(f"{where} ({entry.type}): {exc}") from None
    return law


def law_to_mapping(law) -> dict:
    """The table of ``law`` in the one layout (the inverse of :func:`law_from_mapping`)."""
    if isinstance(law, HardenedLaw):
        return {**law_to_mapping(law.law), "hardening": law.hardening.arguments()}
    entry = next((e for e in LAWS.values() if type(law) is e.cls), None)
    if entry is None:
        raise FrictionRulesError(f"law = {type(law).__name__}(...) violates: a law of the law "
                                 f"table ({', '.join(e.type for e in LAWS.values())}) or one "
                                 "of them with slip hardening")
    return {"type": entry.type, **law.arguments()}


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, str):
        return json.dumps(v)
    return repr(float(v))


def law_to_toml(law, table: str = "law") -> str:
    """``law`` as the text of a TOML table ``[table]`` in the one layout (what
    :func:`read_law` reads back)."""
    lines = [f"[{table}]"]
    lines += [f"{k} = {_value(v)}" for k, v in law_to_mapping(law).items()]
    return "\n".join(lines) + "\n"


def read_law(path, table: str = "law"):
    """The law of the table ``[law]`` (or ``table``, dotted: ``"model.law"``) of a TOML file.

    A top-level ``[hardening]`` beside ``[law]`` is read as ``[law.hardening]``.
    """
    from .._toml import load_toml
    doc = load_toml(path)
    *outer, last = table.split(".")
    for name in outer:
        doc = doc.get(name) if isinstance(doc, dict) else None
    if not isinstance(doc, dict) or last not in doc:
        raise FrictionRulesError(f"{path}: no [{table}] table; constraint: a law file has a "
                                 f"[{table}] table (type and the law's parameters)")
    law_table = doc[last]
    if table == "law":
        unknown = sorted(set(doc) - {"law", "hardening"})
        if unknown:
            raise FrictionRulesError(f"{path}: unknown tables {unknown}; known: law, hardening")
        if "hardening" in doc and hasattr(law_table, "keys"):
            if "hardening" in law_table:
                raise FrictionRulesError(f"{path}: [hardening] and [law.hardening] violate: "
                                         "give one")
            law_table = {**law_table, "hardening": doc["hardening"]}
    return law_from_mapping(law_table, where=f"{path}: [{table}]")
