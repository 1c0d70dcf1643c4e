"""Assembly runs described in TOML (``frictionrules assembly CONFIG.toml``).

::

    [sample]
    lattice = "fcc"            # "fcc", "sc", "hex2d", "square2d"; or random = true
    frame = "cube"             # fcc: "cube" or "layer"
    cells = 1                  # or [nx, ny, nz]
    radius = 1.0
    reference_axis = [1.0, 0.0, 0.0]
    # random = true; n = 400; dim = 3; polydispersity = 0.2; seed = 1
    [model]
    kn = 1e6
    kt = 1e6
    [model.law]                # a law in the one layout (frictionrules.read_law)
    type = "Coulomb"           # any law of frictionrules.LAWS, "UserLaw" included
    mu = 0.3
    [loading]
    kind = "axisymmetric"      # "plane_strain", "biaxial" (2-D)
    pressure = 1.0
    axial_strain = 0.01
    increments = 100
"""

from __future__ import annotations

from pathlib import Path

from ..contact import ContactModel
from ..errors import FrictionRulesError
from ..laws import law_from_mapping
from ._geometry import Assembly

__all__ = ["read_config"]

_SAMPLE = {"lattice", "frame", "cells", "radius", "reference_axis", "tolerance", "random", "n",
           "dim", "polydispersity", "seed", "solid_fraction"}
_LOADING = {"kind", "pressure", "axial_strain", "increments", "consolidation_increments",
            "rtol", "max_cuts", "failure_slope", "consolidation"}


def _table(doc, name, file) -> dict:
    value = doc.get(name, {})
    if not isinstance(value, dict):
        raise FrictionRulesError(f"{file}: [{name}] must be a table")
    return dict(value)


def read_config(path) -> tuple[Assembly, dict]:
    """The assembly and the keyword arguments of :func:`triaxial` of a TOML file."""
    from .._toml import load_toml
    file = Path(path)
    doc = load_toml(file)
    unknown = sorted(set(doc) - {"sample", "model", "loading"})
    if unknown:
        raise FrictionRulesError(f"{file}: unknown tables {unknown}; known: sample, model, loading")
    sample, model_t, loading = (_table(doc, k, file) for k in ("sample", "model", "loading"))
    for name, table, known in (("sample", sample, _SAMPLE), ("loading", loading, _LOADING)):
        extra = sorted(set(table) - known)
        if extra:
            raise FrictionRulesError(f"{file}: [{name}] unknown keys {extra}; known: {sorted(known)}")
    if "law" not in model_t or not isinstance(model_t["law"], dict):
        raise FrictionRulesError(f"{file}: missing [model.law] table")
    law = law_from_mapping(model_t.pop("law"), where=f"{file}: [model.law]")
    try:
        model = ContactModel(law, **model_t)
    except TypeError as exc:
        raise FrictionRulesError(f"{file}: [model]: {exc}") from None
    common = {k: sample[k] for k in ("reference_axis", "tolerance") if k in sample}
    if sample.get("random", False):
        for key in ("n", "dim"):
            if key not in sample:
                raise FrictionRulesError(f"{file}: [sample] random = true needs {key}")
        opts = {k: sample[k] for k in ("radius", "polydispersity", "seed", "solid_fraction") if k in sample}
        assembly = Assembly.random(sample["n"], sample["dim"], model, **opts, **common)
    else:
        if "lattice" not in sample:
            raise FrictionRulesError(f"{file}: [sample] needs lattice = NAME or random = true")
        opts = {k: sample[k] for k in ("frame", "cells", "radius") if k in sample}
        assembly = Assembly.lattice(sample["lattice"], model, **opts, **common)
    if "kind" not in loading or "pressure" not in loading:
        raise FrictionRulesError(f"{file}: [loading] needs kind and pressure")
    return assembly, loading
