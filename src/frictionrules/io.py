r"""Read and write frictional contact problems in the FCLIB HDF5 format.

FCLIB (https://frictionalcontactlibrary.github.io) stores 3-D frictional contact problems.
Per contact the components are ordered ``(N, T1, T2)``; ``r`` is the reaction (``r_N >= 0``
in compression) and ``u`` the relative velocity (``u_N >= 0`` separating).

* Local problem, group ``/fclib_local``: :math:`u = W r + q` with the Coulomb cone law at
  every contact (datasets ``W`` (sparse), ``vectors/q``, ``vectors/mu``).
* Global problem, group ``/fclib_global``: :math:`M v = H r + f`, :math:`u = H^T v + w`
  (datasets ``M``, ``H`` (sparse), ``vectors/f``, ``vectors/w``, ``vectors/mu``). It is
  condensed to a local problem with a sparse LU factorization of ``M``:

  .. math:: W = H^T M^{-1} H, \qquad q = H^T M^{-1} f + w .

A sparse matrix group holds ``m, n, nz, nzmax`` (int32[1]) and ``p, i, x``: ``nz >= 0`` is a
triplet matrix (``i`` row, ``p`` column, the CSparse convention), ``nz == -1`` CSC (``p``
column pointers), ``nz == -2`` CSR (``p`` row pointers, ``i`` column indices).

A missing, mis-shaped or truncated dataset raises :class:`FrictionRulesError` naming it.
Writes are atomic (a temporary file renamed onto the target).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ._optional import require
from .errors import FrictionRulesError

__all__ = ["GlobalProblem", "read_fclib", "read_fclib_global", "write_fclib", "write_fclib_global",
           "read_guess", "read_solution", "write_solution"]


#: Largest number of rows of M that :meth:`GlobalProblem.condense` solves dense (a dense LU of
#: this size takes a few milliseconds).
DENSE_CONDENSE_MAX = 400


@dataclass(frozen=True)
class GlobalProblem:
    r"""A global FCLIB problem :math:`M v = H r + f`, :math:`u = H^T v + w`, Coulomb ``mu``.

    Attributes
    ----------
    M : scipy.sparse.csc_matrix (ndof, ndof)
    H : scipy.sparse.csc_matrix (ndof, 3 nc)
    f : (ndof,) array
    w : (3 nc,) array
    mu : (nc,) array
    title, description : str
    """

    M: object
    H: object
    f: np.ndarray
    w: np.ndarray
    mu: np.ndarray
    title: str = ""
    description: str = ""

    def condense(self):
        r"""The local problem :math:`W = H^T M^{-1} H`, :math:`q = H^T M^{-1} f + w`.

        ``M`` is factorized once (sparse LU, SuperLU); ``M^{-1} H`` is solved column block by
        column block and the product is kept sparse. Where ``M`` has at most
        ``DENSE_CONDENSE_MAX`` rows, it is solved dense instead (LAPACK's LU through NumPy: the
        same W to round-off, without importing SciPy's sparse solvers: about 40 ms of a small
        file's whole call).

        Returns
        -------
        FrictionContactProblem
        """
        sp = require("scipy.sparse", extra="solvers")

        from .multicontact.problem import FrictionContactProblem
        H = sp.csc_matrix(self.H)
        f = np.asarray(self.f, dtype=float)
        singular = "fclib_global/M is singular: cannot condense ({})"
        if self.M.shape[0] <= DENSE_CONDENSE_MAX:
            try:
                X = np.linalg.solve(sp.csc_matrix(self.M).toarray(),
                                    np.column_stack([H.toarray(), f]))
            except np.linalg.LinAlgError as exc:
                raise FrictionRulesError(singular.format(exc)) from exc
            MinvH, Minvf = sp.csc_matrix(X[:, :-1]), X[:, -1]
        else:
            import scipy.sparse.linalg as spla
            try:
                lu = spla.splu(sp.csc_matrix(self.M))
            except RuntimeError as exc:
                raise FrictionRulesError(singular.format(exc)) from exc
            blocks = []
            for start in range(0, H.shape[1], 256):  # M^-1 H by column blocks, kept sparse
                X = lu.solve(H[:, start:start + 256].toarray())
                blocks.append(sp.csc_matrix(np.where(np.abs(X) > 0.0, X, 0.0)))
            MinvH = sp.hstack(blocks, format="csc") if blocks else sp.csc_matrix(H.shape)
            Minvf = lu.solve(f)
        W = sp.csr_matrix(H.T @ MinvH)
        W.eliminate_zeros()
        q = H.T @ Minvf + self.w
        return FrictionContactProblem(W, q, self.mu, title=self.title)


# ---- reading ---------------------------------------------------------------------------------
def _dataset(h5, path: str, *, dtype=float, size=None) -> np.ndarray:
    if path not in h5:
        raise FrictionRulesError(f"dataset {path!r} is missing from the FCLIB file")
    try:
        arr = np.asarray(h5[path][()], dtype=dtype).ravel()
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise FrictionRulesError(f"dataset {path!r} cannot be read (truncated file?): {exc}") from exc
    if size is not None and arr.size != size:
        raise FrictionRulesError(f"dataset {path!r} has {arr.size} entries; constraint: {size}")
    if dtype is float and not np.all(np.isfinite(arr)):
        raise FrictionRulesError(f"dataset {path!r} has non-finite entries")
    return arr


def _int(h5, path: str) -> int:
    arr = _dataset(h5, path, dtype=np.int64)
    if arr.size != 1:
        raise FrictionRulesError(f"dataset {path!r} has {arr.size} entries; constraint: 1")
    return int(arr[0])


def _text(h5, path: str) -> str:
    if path not in h5:
        return ""
    value = h5[path][()]
    if isinstance(value, bytes):
        return value.decode("utf-8", errors="replace").strip()
    return str(value).strip()


def _read_sparse(h5, group: str):
    sp = require("scipy.sparse", extra="solvers")
    m, n, nz = _int(h5, f"{group}/m"), _int(h5, f"{group}/n"), _int(h5, f"{group}/nz")
    if m < 0 or n < 0:
        raise FrictionRulesError(f"dataset {group}/m, n = {m}, {n}; constraint: >= 0")
    p = _dataset(h5, f"{group}/p", dtype=np.int64)
    i = _dataset(h5, f"{group}/i", dtype=np.int64)
    x = _dataset(h5, f"{group}/x")
    if nz >= 0:  # triplet: i = row, p = column (CSparse)
        if min(p.size, i.size, x.size) < nz:
            raise FrictionRulesError(f"dataset {group}/p, i or x is shorter than nz = {nz}")
        rows, cols, vals = i[:nz], p[:nz], x[:nz]
        if nz and (rows.min() < 0 or rows.max() >= m or cols.min() < 0 or cols.max() >= n):
            raise FrictionRulesError(f"dataset {group}/i or {group}/p has an index out of range")
        return sp.csr_matrix(sp.coo_matrix((vals, (rows, cols)), shape=(m, n)))
    if nz not in (-1, -2):
        raise FrictionRulesError(f"dataset {group}/nz = {nz}; constraint: >= 0, -1 (CSC) or -2 (CSR)")
    major = n if nz == -1 else m
    minor = m if nz == -1 else n
    if p.size != major + 1:
        raise FrictionRulesError(f"dataset {group}/p has {p.size} entries; constraint: {major + 1}")
    nnz = int(p[-1])
    if nnz < 0 or np.any(np.diff(p) < 0) or i.size < nnz or x.size < nnz:
        raise FrictionRulesError(f"dataset {group}/p, i or x is inconsistent (nnz = {nnz})")
    idx = i[:nnz]
    if nnz and (idx.min() < 0 or idx.max() >= minor):
        raise FrictionRulesError(f"dataset {group}/i has an index out of range")
    cls = sp.csc_matrix if nz == -1 else sp.csr_matrix
    return sp.csr_matrix(cls((x[:nnz], idx, p), shape=(m, n)))


def _open(path):
    h5py = require("h5py", extra="hdf5")
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such FCLIB file: {path}")
    try:
        return h5py.File(path, "r")
    except OSError as exc:
        raise FrictionRulesError(f"{path} is not a readable HDF5 file (truncated?): {exc}") from exc


def read_fclib_global(path) -> GlobalProblem:
    """Read the global problem ``/fclib_global`` of an FCLIB file (without condensing it)."""
    with _open(path) as h5:
        if "fclib_global" not in h5:
            raise FrictionRulesError(f"group 'fclib_global' is missing from {path}")
        g = "fclib_global"
        M = _read_sparse(h5, f"{g}/M")
        H = _read_sparse(h5, f"{g}/H")
        ndof, m3 = H.shape
        if M.shape != (ndof, ndof):
            raise FrictionRulesError(f"dataset {g}/M has shape {M.shape}; constraint: ({ndof}, {ndof})")
        if m3 % 3:
            raise FrictionRulesError(f"dataset {g}/H has {m3} columns; constraint: a multiple of 3")
        return GlobalProblem(M, H, _dataset(h5, f"{g}/vectors/f", size=ndof),
                             _dataset(h5, f"{g}/vectors/w", size=m3),
                             _dataset(h5, f"{g}/vectors/mu", size=m3 // 3),
                             _text(h5, f"{g}/info/title"), _text(h5, f"{g}/info/description"))


def read_fclib(path):
    """Read an FCLIB file as a local :class:`~frictionrules.FrictionContactProblem`.

    A local problem (``/fclib_local``) is read as it is; a global one (``/fclib_global``) is
    condensed, :math:`W = H^T M^{-1} H`, :math:`q = H^T M^{-1} f + w` (see
    :meth:`GlobalProblem.condense`). Mixed local problems (``V, R, s``) are refused.

    Raises
    ------
    FrictionRulesError
        Missing, mis-shaped or unreadable dataset (the message names it).
    FileNotFoundError
        No such file.
    """
    from .multicontact.problem import FrictionContactProblem
    with _open(path) as h5:
        if "fclib_local" in h5:
            g = "fclib_local"
            if f"{g}/V" in h5 or f"{g}/R" in h5:
                raise FrictionRulesError(f"{path}: mixed local problems ({g}/V, {g}/R) are not supported")
            W = _read_sparse(h5, f"{g}/W")
            if W.shape[0] != W.shape[1] or W.shape[0] % 3:
                raise FrictionRulesError(f"dataset {g}/W has shape {W.shape}; constraint: square, 3 nc")
            n = W.shape[0]
            q = _dataset(h5, f"{g}/vectors/q", size=n)
            mu = _dataset(h5, f"{g}/vectors/mu", size=n // 3)
            return FrictionContactProblem(W, q, mu, title=_text(h5, f"{g}/info/title"))
        if "fclib_global" not in h5:
            raise FrictionRulesError(f"{path} has neither group 'fclib_local' nor 'fclib_global'")
    return read_fclib_global(path).condense()


# ---- writing ---------------------------------------------------------------------------------
def _write_sparse(h5, group: str, A, fmt: str = "csr") -> None:
    sp = require("scipy.sparse", extra="solvers")
    A = sp.csr_matrix(A) if fmt == "csr" else sp.csc_matrix(A)
    A.sort_indices()
    g = h5.create_group(group)
    m, n = A.shape
    g["m"], g["n"] = np.array([m], np.int32), np.array([n], np.int32)
    g["nz"] = np.array([-2 if fmt == "csr" else -1], np.int32)
    g["nzmax"] = np.array([A.nnz], np.int32)
    g["p"], g["i"], g["x"] = A.indptr.astype(np.int32), A.indices.astype(np.int32), A.data.astype(float)


def _write_info(h5, group: str, title: str, description: str) -> None:
    h5[f"{group}/info/title"] = np.bytes_(str(title).encode("utf-8"))
    h5[f"{group}/info/description"] = np.bytes_(str(description).encode("utf-8"))
    h5[f"{group}/info/math_info"] = np.bytes_(b"")


def _write_solution(h5, solution) -> None:
    if solution is not None:
        h5["solution/r"] = np.asarray(solution.r, dtype=float)
        h5["solution/u"] = np.asarray(solution.u, dtype=float)


def write_fclib(path, problem, *, solution=None, title: str = "", description: str = "") -> Path:
    """Write a local problem (``/fclib_local``, W in CSR) atomically; return the path.

    Only problems whose every contact is isotropic Coulomb can be written (FCLIB has no other
    law). ``solution`` (a :class:`~frictionrules.Solution`) goes to ``/solution/{r,u}``.
    """
    h5py = require("h5py", extra="hdf5")

    from ._output import atomic_path
    mu = problem.coulomb_mu()
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        g = "fclib_local"
        h5[f"{g}/spacedim"] = np.array([3], np.int32)
        _write_sparse(h5, f"{g}/W", problem.W, "csr")
        h5[f"{g}/vectors/q"] = np.asarray(problem.q, dtype=float)
        h5[f"{g}/vectors/mu"] = mu
        _write_info(h5, g, title or problem.title, description)
        _write_solution(h5, solution)
    return Path(path)


def write_fclib_global(path, problem: GlobalProblem, *, solution=None) -> Path:
    """Write a :class:`GlobalProblem` (``/fclib_global``, M and H in CSC) atomically."""
    h5py = require("h5py", extra="hdf5")

    from ._output import atomic_path
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        g = "fclib_global"
        h5[f"{g}/spacedim"] = np.array([3], np.int32)
        _write_sparse(h5, f"{g}/M", problem.M, "csc")
        _write_sparse(h5, f"{g}/H", problem.H, "csc")
        h5[f"{g}/vectors/f"] = np.asarray(problem.f, dtype=float)
        h5[f"{g}/vectors/w"] = np.asarray(problem.w, dtype=float)
        h5[f"{g}/vectors/mu"] = np.asarray(problem.mu, dtype=float)
        _write_info(h5, g, problem.title, problem.description)
        _write_solution(h5, solution)
    return Path(path)


# ---- warm starts and saved solutions ---------------------------------------------------------
def read_guess(path, number: int = 1):
    """The reactions ``/guesses/<number>/r`` of an FCLIB file (a simulation's previous step),
    or None when the file holds no guess.

    Raises
    ------
    FrictionRulesError
        A guess of the wrong size or with non-finite entries (the message names it).
    """
    with _open(path) as h5:
        group = f"guesses/{int(number)}/r"
        if group not in h5:
            return None
        g = "fclib_local" if "fclib_local" in h5 else "fclib_global"
        size = None
        if f"{g}/vectors/mu" in h5:
            size = 3 * h5[f"{g}/vectors/mu"].shape[0]
        return _dataset(h5, group, size=size)


def write_solution(path, solution, *, source: str = "", tol: float | None = None) -> Path:
    """Write a :class:`~frictionrules.Solution` to an HDF5 file atomically: ``/solution/r``,
    ``/solution/u`` and attributes ``error, iterations, converged, reason, method, seconds``
    (and ``source``, ``tol`` when given). :func:`read_solution` reads it back, and
    ``frictionrules solve --warm-start`` starts from it.
    """
    import h5py

    from ._output import atomic_path
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        _write_solution(h5, solution)
        attrs = h5["solution"].attrs
        attrs["error"], attrs["iterations"] = float(solution.error), int(solution.iterations)
        attrs["converged"], attrs["reason"] = bool(solution.converged), str(solution.reason)
        attrs["method"], attrs["seconds"] = str(solution.method), float(solution.seconds)
        attrs["source"] = str(source)
        if tol is not None:
            attrs["tol"] = float(tol)
        from ._output import provenance
        attrs["software"] = provenance()["software"]
    return Path(path)


def read_solution(path, size: int | None = None) -> np.ndarray:
    """The reactions ``/solution/r`` of a file written by :func:`write_solution` (or any FCLIB
    file's ``/solution/r``); ``size`` checks their number."""
    with _open(path) as h5:
        return _dataset(h5, "solution/r", size=size)
