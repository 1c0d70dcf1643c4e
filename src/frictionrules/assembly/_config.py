"""Assembly runs described in TOML (``frictionrules assembly CONFIG.toml``).

::

    [sample]
    lattice = "fcc"            # "fcc", "sc", "hex2d", "square2d"; or random = true
    frame = "cube"             # fcc: "cube" or "layer"
    cells = 1                  # or [nx, ny, nz]
    radius = 1.0
    reference_axis = [1.0, 0.0, 0.0]
    # random = true; n = 400; dim = 3; polydispersity = 0.2; seed = 1
    # seeds = [1, 2, 3]        # random samples: an ensemble, one run per seed (not with seed)
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
    increments = 100           # the implicit method's
    # consolidation = "frictionless"   # random packings' default ("auto"); or "stress"
    # preload = 10.0           # frictionless: settle at 10 p, then unload (1: from below)
    # method = "dem"           # the dynamic engine ("Dynamic runs"), with its options:
    # inertial_number = 4e-4; damping = 0.2; density = 1.0; record_every = 1e-3
    # peak_window = 2.5e-3
    # cell = "rectangular"     # or "flexible" (shear stresses held at zero instead)
    # engine = "lammps"        # method "dem" in LAMMPS (docs/assembly.md, "LAMMPS"), with
    # ranks = 2                # its MPI ranks
    # restart_every = 0.05     # and a restart file every 5 % of axial strain (resumable)
"""

from __future__ import annotations

from pathlib import Path

from ..contact import ContactModel
from ..errors import FrictionRulesError, check_scalar
from ..laws import law_from_mapping
from ._geometry import Assembly

__all__ = ["read_config", "read_samples"]

_SAMPLE = {"lattice", "frame", "cells", "radius", "reference_axis", "tolerance", "random", "n",
           "dim", "polydispersity", "seed", "seeds", "solid_fraction"}
#: The dynamic engine's own keys of [loading] (``triaxial(..., method="dem")``).
_DEM = ("inertial_number", "damping", "density", "record_every", "peak_window")
_LOADING = {"kind", "pressure", "axial_strain", "increments", "consolidation_increments",
            "rtol", "max_cuts", "failure_slope", "consolidation", "method", "cell", "engine",
            "ranks", "restart_every", "preload", *_DEM}


def _table(doc, name, file) -> dict:
    value = doc.get(name, {})
    if not isinstance(value, dict):
        raise FrictionRulesError(f"{file}: [{name}] must be a table")
    return dict(value)


def _check_loading(loading: dict, file) -> None:
    """The method, the cell, the preload and the dynamic engine's options, checked before the
    sample is built."""
    from ._loading import check_cell, check_engine, check_method
    try:
        if "preload" in loading:
            check_scalar("preload", loading["preload"], lo=1.0)
        check_method(loading.get("method", "implicit"))
        check_engine(loading.get("engine", "frictionrules"), loading.get("method", "implicit"),
                     None, loading.get("ranks", 1), None, loading.get("restart_every"))
        if "cell" in loading:
            check_cell(loading["cell"])
        dem = {k: loading[k] for k in _DEM if k in loading}
        if loading.get("method", "implicit") != "dem":
            if dem:
                raise FrictionRulesError(f"{', '.join(sorted(dem))} violates: options of "
                                         f"method = \"dem\" only (method = "
                                         f"{loading.get('method', 'implicit')!r})")
            return
        from ._dem import check_dem_options
        defaults = {name: p.default for name, p in _triaxial_parameters().items() if name in _DEM}
        check_dem_options(**{**defaults, **dem})
    except FrictionRulesError as exc:
        raise FrictionRulesError(f"{file}: [loading] {exc}") from None


def _triaxial_parameters():
    import inspect

    from ._loading import triaxial
    return inspect.signature(triaxial).parameters


def read_config(path, progress=None) -> tuple[Assembly, dict]:
    """The assembly and the keyword arguments of :func:`triaxial` of a TOML file;
    ``progress`` (with a method ``phase(text)``) hears how a random packing is made. A file
    with ``seeds`` describes an ensemble (:func:`read_samples`)."""
    assemblies, seeds, loading = read_samples(path, progress=progress)
    if seeds is not None:
        raise FrictionRulesError(f"{path}: [sample] seeds = {seeds!r} describes an ensemble; "
                                 "constraint: one sample (seed) for a single run")
    return assemblies[0], loading


def _check_seeds(seeds, where: str) -> list:
    if (not isinstance(seeds, (list, tuple)) or not seeds
            or any(isinstance(s, bool) or not isinstance(s, int) or s < 0 for s in seeds)):
        raise FrictionRulesError(f"{where} = {seeds!r} violates: a non-empty list of integers >= 0")
    if len(set(seeds)) != len(seeds):
        raise FrictionRulesError(f"{where} = {list(seeds)!r} violates: distinct seeds")
    return [int(s) for s in seeds]


def read_samples(path, seeds=None, progress=None) -> tuple[list, list | None, dict]:
    """``(assemblies, seeds, loading)`` of a TOML file: one random sample per seed where
    ``seeds`` (the argument, else ``[sample] seeds``) is given, else the file's one sample
    (``seeds`` None); ``loading`` the keyword arguments of :func:`triaxial`."""
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
    _check_loading(loading, file)
    if "seeds" in sample:
        if "seed" in sample:
            raise FrictionRulesError(f"{file}: [sample] seed and seeds violates: one of them")
        listed = _check_seeds(sample.pop("seeds"), f"{file}: [sample] seeds")
        seeds = listed if seeds is None else seeds
    if seeds is not None:
        seeds = _check_seeds(seeds, "seeds")
        if not sample.get("random", False):
            raise FrictionRulesError(f"seeds = {seeds!r} violates: random = true in [sample] of "
                                     f"{file} (a lattice has no seed)")
    law = law_from_mapping(model_t.pop("law"), where=f"{file}: [model.law]")
    try:
        model = ContactModel(law, **model_t)
    except TypeError as exc:
        raise FrictionRulesError(f"{file}: [model]: {exc}") from None
    if "kind" not in loading or "pressure" not in loading:
        raise FrictionRulesError(f"{file}: [loading] needs kind and pressure")
    common = {k: sample[k] for k in ("reference_axis", "tolerance") if k in sample}
    if sample.get("random", False):
        for key in ("n", "dim"):
            if key not in sample:
                raise FrictionRulesError(f"{file}: [sample] random = true needs {key}")
        opts = {k: sample[k] for k in ("radius", "polydispersity", "seed", "solid_fraction") if k in sample}
        if seeds is None:
            return [Assembly.random(sample["n"], sample["dim"], model, **opts, **common,
                                    progress=progress)], None, loading
        return [Assembly.random(sample["n"], sample["dim"], model, **opts, **common, seed=s,
                                progress=progress) for s in seeds], seeds, loading
    if "lattice" not in sample:
        raise FrictionRulesError(f"{file}: [sample] needs lattice = NAME or random = true")
    opts = {k: sample[k] for k in ("frame", "cells", "radius") if k in sample}
    return [Assembly.lattice(sample["lattice"], model, **opts, **common)], None, loading
