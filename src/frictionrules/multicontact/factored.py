r"""Many-contact problems whose Delassus operator is given by its factors, :math:`W = J M^{-1}
J^T`, as a multibody engine holds it: non-smooth Gauss–Seidel without forming W.

A multibody engine (MuJoCo: ``efc_J`` and ``mj_solveM``) has the contacts' Jacobian J and the
mass matrix M, which couples only the dofs of one kinematic tree. Per contact ``a`` and tree
``t`` it touches (at most two), the dense blocks :math:`J_{a,t}` (3 x n_t) and
:math:`B_{a,t} = J_{a,t} M_t^{-1}` give

.. math:: W_{ac} = \sum_t J_{a,t} B_{c,t}^T, \qquad
          (W r + q)_a = J_a v + q_a, \quad v = M^{-1} J^T r = \sum_c B_c^T r_c ,

so a Gauss–Seidel sweep keeps ``v`` (one vector of the dofs) and updates it by
:math:`B_a^T \Delta r_a` after each contact: its cost is the contacts' dofs, not nnz(W), and W
is not built (the sweeps of physics engines, e.g. Erleben 2007, *Velocity-based shock
propagation*; Siconos' global formulation). The local solvers, the checks of the error and its
measure are those of :func:`~frictionrules.solve`'s ``"nsgs"`` (Siconos' error on the cone
path, the laws' natural map on the law path: :mod:`frictionrules.multicontact.problem`), so a
sweep here is the same sweep as on W, to rounding.

:class:`ContactLaws` is the laws' reduction (done once, kept while the contacts' laws are the
same), :class:`TreeBlocks` the operator, :func:`solve_factored` the sweeps. Elliptic cones
with turned frames (``frames`` not None: :class:`~frictionrules.EllipticOrthotropic` through
its capability "cone") are not taken here: build :meth:`TreeBlocks.delassus` and use
:func:`~frictionrules.solve`.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..errors import FrictionRulesError, check_finite
from ._law_path import LOCAL_ITER, LOCAL_TOL
from ._methods import options_for
from .problem import Solution, _contact_states, _parameters

__all__ = ["ContactLaws", "TreeBlocks", "solve_factored"]

_TINY = np.finfo(float).tiny


class ContactLaws:
    r"""The contacts' laws reduced once, for any operator: what
    :class:`~frictionrules.FrictionContactProblem` derives from its ``mu`` argument.

    Parameters
    ----------
    laws : sequence
        One law (or Coulomb coefficient) per contact, as ``FrictionContactProblem``'s ``mu``
        (its laws' initial states).

    Attributes
    ----------
    laws : tuple
    nc : int
    mu_bar, dilatancy : (nc,) arrays
        As :class:`~frictionrules.FrictionContactProblem` (NaN on the law path's contacts).
    frames : (nc, 2, 2) array or None
    path : {"cone", "law"}
    """

    def __init__(self, laws):
        laws = tuple(laws)
        nc = len(laws)
        if nc == 0:
            raise FrictionRulesError("laws has 0 entries; constraint: nc >= 1")
        mbar, dil, frames, general = _parameters(laws, _contact_states(None, laws), nc)
        self.laws = tuple(float(x) if isinstance(x, (int, float, np.floating, np.integer)) else x
                          for x in laws)
        self.nc = nc
        self.mu_bar = np.ascontiguousarray(mbar, dtype=float)
        self.dilatancy = np.ascontiguousarray(dil, dtype=float)
        self.frames = None if general else frames
        self.path = "law" if general else "cone"


class TreeBlocks:
    r""":math:`W = J M^{-1} J^T` by blocks per contact and kinematic tree (module docstring).

    Parameters
    ----------
    tree : (nc, 2) int array
        The trees each contact touches (-1: none).
    offset : (nc, 2) int array
        Where each block starts in ``J`` and ``B``.
    J, B : 1-D float arrays
        The blocks :math:`J_{a,t}` and :math:`B_{a,t} = J_{a,t}M_t^{-1}`, each ``3 x n_t``
        row-major (rows N, T1, T2 of the contact's frame; columns the tree's dofs).
    dofadr, dofnum : (ntree,) int arrays
        First dof and dof count of each tree (dofs of a tree contiguous).
    D : (nc, 3, 3) array
        The diagonal blocks :math:`W_{aa} = \sum_t J_{a,t} B_{a,t}^T`.
    nv : int
        Dofs.

    The arrays are taken as they are (a builder such as :mod:`frictionrules.mujoco` fills
    them in compiled code each step), not checked.
    """

    __slots__ = ("tree", "offset", "J", "B", "dofadr", "dofnum", "D", "nv")

    def __init__(self, tree, offset, J, B, dofadr, dofnum, D, nv: int):
        self.tree, self.offset, self.J, self.B = tree, offset, J, B
        self.dofadr, self.dofnum, self.D, self.nv = dofadr, dofnum, D, int(nv)

    @property
    def nc(self) -> int:
        """Number of contacts."""
        return int(self.tree.shape[0])

    def impulse_velocity(self, r) -> np.ndarray:
        r""":math:`M^{-1} J^T r` (nv,): the velocity change of the impulses ``r`` (3 nc,)."""
        from ._factored import impulse_velocity
        v = np.empty(self.nv)
        impulse_velocity(self.tree, self.offset, self.B, self.dofadr, self.dofnum,
                         np.ascontiguousarray(r, dtype=float), v)
        return v

    def velocity(self, v, q) -> np.ndarray:
        """:math:`J v + q` (3 nc,) for a velocity of the dofs ``v`` (nv,)."""
        from ._factored import contact_velocity
        u = np.empty(3 * self.nc)
        contact_velocity(self.tree, self.offset, self.J, self.dofadr, self.dofnum,
                         np.ascontiguousarray(v, dtype=float), np.ascontiguousarray(q, dtype=float), u)
        return u

    def delassus(self):
        r""":math:`W = J M^{-1} J^T` as a SciPy CSR matrix (3 nc x 3 nc, columns sorted): the
        blocks :math:`W_{ac}` of the contacts sharing a tree."""
        import scipy.sparse as sp

        from ._factored import delassus_csr
        n = 3 * self.nc
        indptr, indices, data = delassus_csr(self.tree, self.offset, self.J, self.B, self.dofadr,
                                             self.dofnum)
        W = sp.csr_matrix((data, indices, indptr), shape=(n, n))
        W.has_sorted_indices = True
        return W


def solve_factored(laws: ContactLaws, blocks: TreeBlocks, q, r0=None, *, tol: float = 1e-8,
                   max_iter: int = 1000, max_check_interval: int | None = None) -> Solution:
    r"""Non-smooth Gauss–Seidel sweeps on :math:`u = J M^{-1} J^T r + q` (module docstring).

    Parameters
    ----------
    laws : ContactLaws
        The contacts' laws (``frames`` None: isotropic cones, or the law path).
    blocks : TreeBlocks
    q : (3 nc,) array
        Free velocity, FCLIB's convention (``u_N > 0`` separates).
    r0 : (3 nc,) array, optional
        Initial impulses (zero by default).
    tol : float
        Stop when the error (Siconos' on the cone path, :func:`~frictionrules.multicontact.law_error`'s
        on the law path) is at most ``tol``.
    max_iter : int
        Sweeps at most.
    max_check_interval : int, optional
        At most this many sweeps between two evaluations of the error
        (:class:`~frictionrules.NSGSOptions`' default).

    Returns
    -------
    Solution
        ``method`` ``"nsgs"``; ``error_measure`` ``"fc3d"`` or ``"law"``.
    """
    t0, c0 = time.perf_counter(), time.thread_time()
    if not isinstance(laws, ContactLaws):
        raise FrictionRulesError(f"laws = {laws!r} is not a ContactLaws")
    if laws.path == "cone" and laws.frames is not None:
        raise FrictionRulesError("laws = elliptic cones with turned frames violates: solve_factored "
                                 "takes isotropic cones and the law path (use TreeBlocks.delassus and solve)")
    nc = laws.nc
    if blocks.nc != nc:
        raise FrictionRulesError(f"blocks has {blocks.nc} contacts; constraint: nc = {nc}")
    q = np.ascontiguousarray(check_finite("q", q), dtype=float).ravel()
    if q.size != 3 * nc:
        raise FrictionRulesError(f"q has {q.size} entries; constraint: 3 nc = {3 * nc}")
    if r0 is None:
        r = np.zeros(3 * nc)
    else:
        from ._frame import initial_reactions
        r = initial_reactions(r0, 3 * nc)
    max_iter = int(max_iter)
    if max_iter < 1:
        raise FrictionRulesError(f"max_iter = {max_iter} violates: an integer >= 1")
    interval = (options_for("nsgs", None).max_check_interval if max_check_interval is None
                else int(max_check_interval))
    from . import _factored as K
    b = blocks
    v, u = np.empty(b.nv), np.empty(3 * nc)
    K.impulse_velocity(b.tree, b.offset, b.B, b.dofadr, b.dofnum, r, v)
    hist_err, hist_it = np.empty(max_iter), np.empty(max_iter, dtype=np.int64)
    norm_q = math.sqrt(q @ q)
    if laws.path == "cone":
        it, err, nh = K.factored_nsgs(b.tree, b.offset, b.J, b.B, b.dofadr, b.dofnum, b.D, q, laws.mu_bar,
                                      laws.dilatancy, r, v, u, float(tol), max_iter, hist_err, hist_it,
                                      norm_q, interval)
        measure = "fc3d"
    else:
        from ._law_path import law_set
        ls = law_set(laws)
        it, err, nh = K.factored_law_nsgs(b.tree, b.offset, b.J, b.B, b.dofadr, b.dofnum, b.D, q, ls.fn,
                                          ls.rows, ls.ell, ls.dilatant, r, v, u, float(tol), max_iter,
                                          hist_err, hist_it, norm_q, interval, LOCAL_ITER, LOCAL_TOL)
        measure = "law"
    from ._frame import UNBOUNDED
    bounded = bool(math.sqrt(r @ r) <= UNBOUNDED * max(norm_q, _TINY) / K.mean_diagonal(b.D))
    reason = "converged" if err <= tol and bounded else ("max_iter" if bounded else "unbounded")
    return Solution._record(r, u, float(err), int(it), reason == "converged", hist_err[:nh].copy(),
                            hist_it[:nh].copy(), "nsgs", time.perf_counter() - t0, reason,
                            time.thread_time() - c0, measure)
