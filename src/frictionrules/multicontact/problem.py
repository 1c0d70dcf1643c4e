r"""The multi-contact frictional problem :math:`u = W r + q` with a friction law at every contact.

Per contact ``a`` the components are ordered ``(N, T1, T2)`` as in FCLIB: ``r_a`` is the reaction
(``r_N >= 0`` compression), ``u_a`` the relative velocity (``u_N >= 0`` separating). In the
force/slip variables of the laws (``docs/conventions.md``) ``T = -r_T``, ``N = r_N``,
``v_t = u_T``, ``v_n = u_N``.

Every law accepted at a contact is reduced to an isotropic cone with a *dilatancy ratio*
:math:`d_a` in a local frame where the cone is circular:

.. math::

    r_T = A_a \tilde r_T, \qquad \tilde u_T = A_a^T u_T, \qquad
    \tilde K_a = \{|\tilde r_T| \le \bar\mu_a r_N\},

so that :math:`\tilde r\cdot\tilde u = r\cdot u` (``A_a = I`` for Coulomb). The sliding rule
:math:`v = \dot\lambda(\partial g/\partial T, -\partial g/\partial N)` of a cone-shaped
potential g that is associated in the sliding plane (its tangential gradient is normal to the
limit curve) then reads :math:`\tilde u_T = \lambda\,\tilde r_T/|\tilde r_T|` reversed,
:math:`u_N = \bar\mu_a d_a |\tilde u_T|`, and the whole contact law is De Saxcé's
complementarity with the *generalized modified velocity*

.. math::

    \hat u_a = \tilde u_a + \bar\mu_a (1 - d_a)\,|\tilde u_{aT}|\,e_N, \qquad
    \tilde K_a \ni \tilde r_a \perp \hat u_a \in \tilde K_a^* ,

with :math:`d_a = -g_{,N}/(\bar\mu_a |A_a^T \nabla_T g|)` (constant on a cone).
``d = 0`` is Coulomb without normal slip (De Saxcé's original modified velocity, FCLIB),
``d = 1`` the associated (dilatant) rule g = f, ``d = tan(psi)/mu`` a dilatancy angle psi.

Accepted laws: a number (Coulomb ``mu``) and every law that declares the capability
``"cone"`` (:meth:`~frictionrules.FrictionLaw.cone` gives ``mu_x, mu_y, angle`` and ``d``;
``A = R(angle) diag(mu_x, mu_y)/sqrt(mu_x mu_y)``): :class:`~frictionrules.Coulomb`
(``dilatant`` gives ``d = 1``), :class:`~frictionrules.EllipticOrthotropic` (``d = 0``), a
law with slip hardening of these (at each contact's state κ) and a user law whose symbolic
form is such a cone.

**The law path.** A law without the capability ``"cone"`` whose limit condition f and
potential g are cones in (T, N) — homogeneous of degree one (the traits ``degree`` and
``slip_degree`` derived from its symbolic form) — without internal variables is accepted too:
:class:`~frictionrules.TransformedCoulomb` (1.17)–(1.18), :class:`~frictionrules.Huber`
(1.16), a :class:`~frictionrules.UserLaw` with g ≠ f, dilatant or not. A problem with such a
contact (``path == "law"``) is solved contact by contact with each law's own return map
along its potential (:mod:`frictionrules.multicontact._law_path`: the fixed point
:math:`r = P(r - K u)`), every contact of it, floats as ``Coulomb(mu)``. Any other law is
refused with an error naming the missing property.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._optional import require
from .._rotation import rotation
from ..errors import FrictionRulesError, check_finite

__all__ = ["FrictionContactProblem", "Solution"]


def _coerce_matrix(W):
    sp = require("scipy.sparse", extra="solvers")
    if type(W) is sp.csr_matrix and W.dtype == np.float64:
        pass                        # its arrays are shared all the same: no new wrapper (a time step's W)
    elif sp.issparse(W):
        W = sp.csr_matrix(W, dtype=float)
    else:
        arr = check_finite("W", W)
        if arr.ndim != 2:
            raise FrictionRulesError(f"W must be a 2-D matrix, got shape {arr.shape}")
        W = sp.csr_matrix(arr)
    if W.shape[0] != W.shape[1] or W.shape[0] % 3 or W.shape[0] == 0:
        raise FrictionRulesError(f"W has shape {W.shape}; constraint: square, 3 nc x 3 nc, nc >= 1")
    if not np.all(np.isfinite(W.data)):
        raise FrictionRulesError("W has non-finite entries; constraint: finite")
    W.sum_duplicates()
    W.sort_indices()
    return W


def _ellipse_frame(mu_x: float, mu_y: float, angle: float):
    mbar = float(np.sqrt(mu_x * mu_y))
    A = rotation(angle) @ np.diag([mu_x, mu_y]) / mbar
    return mbar, A


def _law_params(law, index: int, q=None):
    """``(mu_bar, d, A)`` of the law at contact ``index`` through its "cone" capability
    (``A`` None for an isotropic cone); None for a law of the law path (checked)."""
    from ..laws import FrictionLaw
    if not isinstance(law, FrictionLaw):
        try:
            mu = float(law)
        except (TypeError, ValueError):
            raise FrictionRulesError(f"mu[{index}] = {law!r} is not a friction law or a "
                                     "coefficient") from None
        if not np.isfinite(mu) or mu < 0:
            raise FrictionRulesError(f"mu[{index}] = {mu!r} violates mu >= 0 (finite)")
        return mu, 0.0, None
    if "cone" not in law.capabilities:
        from ._law_check import check_law
        check_law(law, index)
        return None
    cone = law.cone(q)
    if cone.mu_x == cone.mu_y:
        return cone.mu_x, cone.dilatancy, None
    mbar, A = _ellipse_frame(cone.mu_x, cone.mu_y, cone.angle)
    return mbar, cone.dilatancy, A


def _contact_states(state, laws):
    """Per-contact law states from ``state``: None, one LawState of shape ``(nc,)`` (all
    contacts with the same variables) or a sequence of per-contact states."""
    from ..laws import LawState
    nc = len(laws)
    if state is None:
        return (None,) * nc
    if isinstance(state, LawState):
        if state.shape != (nc,):
            raise FrictionRulesError(f"state has shape {state.shape}; constraint: (nc,) = ({nc},)")
        return tuple(LawState(state.names, state.values[a]) for a in range(nc))
    states = tuple(state)
    if len(states) != nc:
        raise FrictionRulesError(f"state has {len(states)} entries; constraint: nc = {nc}")
    return states


def _parameters(laws, states, nc: int):
    """``(mu_bar, dilatancy, frames or None, general)`` of the contacts: each distinct law
    object (and each distinct number) reduced once, its values spread to its contacts by index.
    A contact with a state of its own is reduced at that state."""
    from ._law_check import check_law
    index = np.empty(nc, dtype=np.intp)
    params, first, seen = [], [], {}
    for a, (law, qa) in enumerate(zip(laws, states)):
        key = (id(law), type(law)) if qa is None else a
        j = seen.get(key)
        if j is None:
            j = seen[key] = len(params)
            params.append(_law_params(law, a, qa))
            first.append(a)
        index[a] = j
    general = any(x is None for x in params)
    if general:
        for x, a in zip(params, first):
            if not isinstance(laws[a], (int, float, np.floating, np.integer)):
                check_law(laws[a], a)
    m = np.array([np.nan if x is None else x[0] for x in params])
    d = np.array([np.nan if x is None else x[1] for x in params])
    frames = None
    if not general and any(x[2] is not None for x in params):
        A = np.empty((len(params), 2, 2))
        A[:] = np.eye(2)
        for j, x in enumerate(params):
            if x[2] is not None:
                A[j] = x[2]
        frames = A[index]
    return m[index], d[index], frames, general


class FrictionContactProblem:
    r"""Find ``r, u`` with :math:`u = W r + q` and the friction law of every contact.

    Parameters
    ----------
    W : (3 nc, 3 nc) sparse matrix or array
        Delassus operator (converted to CSR). It need not be symmetric.
    q : (3 nc,) array
        Free velocity.
    mu : float, (nc,) array, FrictionLaw or sequence of laws/floats
        Per-contact law: a number is isotropic Coulomb without normal slip (FCLIB); a law
        declares the capability ``"cone"`` or has f and g cones in (T, N) without internal
        variables (the law path; see the module docstring).
    title : str
        A label (read from FCLIB ``info/title``).
    state : LawState or sequence of LawState, optional
        The internal variables of the contacts' laws (e.g. the accumulated slip κ of a law
        with slip hardening), one state per contact or one of shape ``(nc,)``; the cone of
        each contact is taken at its state. None: the laws' initial states.

    Attributes
    ----------
    W, q, nc, title
    laws : tuple
        The per-contact laws as given (floats for plain Coulomb).
    states : tuple
        The per-contact law states (None: initial).
    mu_bar : (nc,) array
        Isotropic coefficient of each contact in its circular frame.
    dilatancy : (nc,) array
        Dilatancy ratio ``d`` of each contact.
    frames : (nc, 2, 2) array or None
        ``A_a`` with :math:`r_T = A_a\tilde r_T`; None when every contact is isotropic (and on
        the law path).
    path : {"cone", "law"}
        ``"cone"``: every contact reduced to an elliptic cone (the solvers of
        :data:`~frictionrules.METHODS`); ``"law"``: some law is not (see the module docstring;
        ``mu_bar`` and ``dilatancy`` are NaN at its contacts).
    """

    def __init__(self, W, q, mu, *, title: str = "", state=None):
        self.W = _coerce_matrix(W)
        n = self.W.shape[0]
        self.nc = n // 3
        self.q = check_finite("q", q).ravel()
        if self.q.size != n:
            raise FrictionRulesError(f"q has {self.q.size} entries; constraint: 3 nc = {n}")
        if np.ndim(mu) == 0 and not isinstance(mu, (list, tuple)):
            laws = (mu,) * self.nc
        else:
            laws = tuple(np.asarray(mu, dtype=object).ravel()) if isinstance(mu, np.ndarray) else tuple(mu)
        if len(laws) != self.nc:
            raise FrictionRulesError(f"mu has {len(laws)} entries; constraint: nc = {self.nc}")
        states = _contact_states(state, laws)
        mbar, dil, frames, general = _parameters(laws, states, self.nc)
        self.laws = tuple(float(x) if isinstance(x, (int, float, np.floating, np.integer)) else x
                          for x in laws)
        self.states = states
        self.mu_bar = mbar
        self.dilatancy = dil
        self.frames = None if general else frames
        self.path = "law" if general else "cone"
        self.title = str(title)

    def __repr__(self) -> str:
        return (f"FrictionContactProblem(nc={self.nc}, nnz(W)={self.W.nnz}"
                + (f", title={self.title!r}" if self.title else "") + ")")

    def coulomb_mu(self) -> np.ndarray:
        """The Coulomb coefficients; raises if a contact has another law (FCLIB cannot store it)."""
        if self.path != "cone" or self.frames is not None or np.any(self.dilatancy != 0):
            raise FrictionRulesError("only problems with plain Coulomb contacts (no dilatancy, "
                                     "isotropic) can be written to FCLIB")
        return self.mu_bar.copy()

    def associated(self) -> "FrictionContactProblem":
        r"""The associated (dilatant, convex) relaxation: every contact with the sliding rule
        normal to its own cone, ``g = f`` (the paper's (1.6): :math:`V_z = -\dot\lambda\mu`
        in the paper's sign, the block separating at :math:`u_N = \bar\mu|\tilde u_T|`).

        Same ``W``, ``q``, cones and frames, dilatancy ratio ``d = 1`` everywhere, so that
        :math:`\hat u = u` and the problem is the convex cone complementarity problem
        :math:`K \ni r \perp W r + q \in K^*` (the optimality conditions of
        :math:`\min \tfrac12 r^T W r + q^T r`, :math:`r \in K`, for a symmetric W) that
        convex solvers and most physics engines solve. ``laws`` keeps the given laws;
        ``dilatancy`` is what the solvers use.
        """
        import copy
        if self.path != "cone":
            raise FrictionRulesError("problem = the law path (a law that is not an elliptic cone) "
                                     "violates: associated() needs every contact's law to declare "
                                     "the capability 'cone'")
        out = copy.copy(self)
        out.dilatancy = np.ones(self.nc)
        out.title = f"{self.title} (associated)" if self.title else "associated"
        return out

    def renewed(self, W, q) -> "FrictionContactProblem":
        """The same contacts and laws with another ``W`` and ``q`` (a time step's next problem).

        The laws' reduction (``mu_bar``, ``dilatancy``, ``frames``, the law path's compiled
        set) is kept, not recomputed; ``W`` and ``q`` are checked as in the constructor and
        must have the same size.
        """
        import copy
        W = _coerce_matrix(W)
        if W.shape[0] != 3 * self.nc:
            raise FrictionRulesError(f"W has shape {W.shape}; constraint: 3 nc x 3 nc = {3 * self.nc} x {3 * self.nc}")
        q = check_finite("q", q).ravel()
        if q.size != 3 * self.nc:
            raise FrictionRulesError(f"q has {q.size} entries; constraint: 3 nc = {3 * self.nc}")
        out = copy.copy(self)
        out.W, out.q = W, q
        return out

    def velocity(self, r) -> np.ndarray:
        """:math:`u = W r + q`."""
        return self.W @ np.asarray(r, dtype=float) + self.q

    # ---- the circular frame the solvers work in ------------------------------------------
    def _transform(self):
        """Sparse block-diagonal ``P`` with :math:`r = P\\tilde r`, or None (identity)."""
        if self.frames is None:
            return None
        import scipy.sparse as sp
        blocks = np.zeros((self.nc, 3, 3))
        blocks[:, 0, 0] = 1.0
        blocks[:, 1:, 1:] = self.frames
        return sp.bsr_matrix((blocks, np.arange(self.nc), np.arange(self.nc + 1)),
                             shape=(3 * self.nc, 3 * self.nc)).tocsr()

    def _solver_frame(self):
        """``(W~, q~, P)`` with :math:`\\tilde W = P^T W P`, :math:`\\tilde q = P^T q`."""
        P = self._transform()
        if P is None:
            return self.W, self.q, None
        import scipy.sparse as sp
        Wt = sp.csr_matrix(P.T @ self.W @ P)
        Wt.sort_indices()
        return Wt, P.T @ self.q, P


@dataclass(frozen=True)
class Solution:
    """Result of :func:`~frictionrules.solve`.

    Attributes
    ----------
    r : (3 nc,) array
        Reactions, per contact ``(r_N, r_T1, r_T2)``.
    u : (3 nc,) array
        Relative velocities :math:`u = W r + q`.
    error : float
        Final error (:func:`~frictionrules.multicontact.fc3d_error`, Siconos' measure; on the
        law path :func:`~frictionrules.multicontact.law_error`: see ``error_measure``).
    iterations : int
    converged : bool
        ``error <= tol`` (and the reactions bounded: see ``reason``).
    reason : str
        Why the run stopped: ``"converged"``, ``"max_iter"``, ``"time_limit"``,
        ``"callback"`` (the callback asked to stop), ``"unbounded"`` (the reactions grow
        without bound: no bounded solution, an infeasible problem) or ``"stalled"`` (the
        polish found no step lowering the error: the active set has not settled). Only
        ``"converged"`` has ``converged`` true.
    history : array
        Error after the iterations ``history_iterations`` (every iteration for ``newton`` and
        ``prox``; the sweeps where NSGS evaluated it; for ``admm``, the iterations where it
        was measured, :attr:`ADMMOptions.max_check_interval`).
    history_iterations : array of int
    method : str
        The method that ran (for ``"auto"``, the stages joined by ``+``, e.g. ``"nsgs+prox"``).
    seconds : float
        Wall time of the call (compilation of the kernels excluded when cached).
    error_measure : str
        What ``error`` measures: ``"fc3d"`` Siconos' (:func:`~frictionrules.multicontact.fc3d_error`),
        ``"law"`` the natural map of the contacts' own laws
        (:func:`~frictionrules.multicontact.law_error`, the law path).
    cpu_seconds : float
        CPU time of the call in the calling thread (``time.thread_time``): the solver's own
        work, BLAS included (it runs in that thread under ``blas_threads=1``), other jobs on
        the machine and other threads of the process excluded. On the small-problem path (at
        most 16 contacts, ``nsgs``, ``polish`` or ``auto``) the wall time of the call, which
        a call of microseconds spends on one processor (more when the thread was preempted):
        the CPU clock's system call would cost a sixth of such a call.
    """

    r: np.ndarray
    u: np.ndarray
    error: float
    iterations: int
    converged: bool
    history: np.ndarray = field(repr=False)
    history_iterations: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0, int))
    method: str = ""
    seconds: float = 0.0
    reason: str = ""
    cpu_seconds: float = 0.0
    error_measure: str = "fc3d"

    @classmethod
    def _record(cls, r, u, error, iterations, converged, history, history_iterations, method, seconds, reason,
                cpu_seconds, error_measure="fc3d") -> "Solution":
        """The same frozen record, every field given in order, built without the generated
        ``__init__`` (its per-field ``object.__setattr__`` was 1.1 µs of a 5 µs small solve)."""
        self = object.__new__(cls)
        d = self.__dict__           # item by item: 0.1 µs less than dict.update's keywords
        d["r"], d["u"], d["error"], d["iterations"], d["converged"] = r, u, error, iterations, converged
        d["history"], d["history_iterations"], d["method"] = history, history_iterations, method
        d["seconds"], d["reason"], d["cpu_seconds"] = seconds, reason, cpu_seconds
        d["error_measure"] = error_measure
        return self
