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

Accepted laws: a number (Coulomb ``mu``), :class:`~frictionrules.Coulomb` (``dilatant``
gives ``d = 1``), :class:`~frictionrules.EllipticOrthotropic` (``A = R(angle)
diag(mu_x, mu_y)/sqrt(mu_x mu_y)``, ``d = 0``), and any other law whose limit surface is a
cone with an elliptic section and whose potential is associated in the sliding plane with a
constant dilatancy ratio (checked numerically on 24 points of the limit curve).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._optional import require
from ..errors import FrictionRulesError, check_finite

__all__ = ["FrictionContactProblem", "Solution"]


def _coerce_matrix(W):
    sp = require("scipy.sparse", extra="solvers")
    if sp.issparse(W):
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
    c, s = np.cos(angle), np.sin(angle)
    A = np.array([[c, -s], [s, c]]) @ np.diag([mu_x, mu_y]) / mbar
    return mbar, A


def _probe_law(law, index: int):
    """(mu_bar, d, A) of a generic law: elliptic cone, tangential normality, constant d."""
    th = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    e = np.stack((np.cos(th), np.sin(th)), axis=-1)
    what = f"mu[{index}] = {law!r}"
    lo, hi = np.zeros(th.size), np.ones(th.size)
    N1 = np.ones(th.size)
    try:
        for _ in range(60):  # bracket the limit curve along rays (star-shaped about 0)
            out = law.limit(hi[:, None] * e, N1) < 0
            if not out.any():
                break
            hi = np.where(out, 2 * hi, hi)
        if np.any(law.limit(hi[:, None] * e, N1) < 0) or np.any(law.limit(0 * e, N1) >= 0):
            raise FrictionRulesError(f"{what}: the limit curve at N = 1 is not closed around T = 0")
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            inside = law.limit(mid[:, None] * e, N1) < 0
            lo, hi = np.where(inside, mid, lo), np.where(inside, hi, mid)
        T = 0.5 * (lo + hi)[:, None] * e
        # fit T^T Q T = 1 (ellipse through 0's centre)
        X = np.stack((T[:, 0] ** 2, 2 * T[:, 0] * T[:, 1], T[:, 1] ** 2), axis=-1)
        a, b, c = np.linalg.lstsq(X, np.ones(th.size), rcond=None)[0]
        Q = np.array([[a, b], [b, c]])
        ok_fit = np.max(np.abs(X @ [a, b, c] - 1)) < 1e-6 and np.all(np.linalg.eigvalsh(Q) > 0)
        ok_cone = np.max(np.abs(law.limit(2.5 * T, 2.5 * N1) / 2.5 - law.limit(T, N1))) < 1e-7
        if not (ok_fit and ok_cone):
            raise FrictionRulesError(
                f"{what}: constraint: the limit surface must be a cone with an elliptic section "
                "(Coulomb, EllipticOrthotropic or an equivalent law)")
        lam, V = np.linalg.eigh(Q)
        mu_x, mu_y = 1 / np.sqrt(lam)
        angle = float(np.arctan2(V[1, 0], V[0, 0]))
        mbar, A = _ellipse_frame(mu_x, mu_y, angle)
        gf = law.limit_gradient(T, N1)
        gg = law.potential_gradient(T, N1)
        cross = gf[:, 0] * gg[:, 1] - gf[:, 1] * gg[:, 0]
        dot = gf[:, 0] * gg[:, 0] + gf[:, 1] * gg[:, 1]
        if np.max(np.abs(cross)) > 1e-7 * np.max(np.abs(dot)) or np.any(dot <= 0):
            raise FrictionRulesError(
                f"{what}: constraint: the potential must be associated in the sliding plane "
                "(its tangential gradient normal to the limit curve)")
        gt = gg[:, :2] @ A  # A^T grad_T g, row-wise
        d = -gg[:, 2] / (mbar * np.hypot(gt[:, 0], gt[:, 1]))
        if np.ptp(d) > 1e-7 * max(1.0, np.max(np.abs(d))):
            raise FrictionRulesError(
                f"{what}: constraint: the dilatancy ratio -g_N/(mu |grad_T g|) must be constant "
                f"around the cone (found {d.min():.6g} .. {d.max():.6g})")
    except FrictionRulesError:
        raise
    except (TypeError, AttributeError) as exc:
        raise FrictionRulesError(f"{what} is not a friction law or a coefficient") from exc
    return mbar, float(np.mean(d)), A


def _law_params(law, index: int):
    from ..laws import Coulomb, EllipticOrthotropic, FrictionLaw
    if isinstance(law, Coulomb):
        return law.mu, (1.0 if law.dilatant else 0.0), None
    if isinstance(law, EllipticOrthotropic):
        mbar, A = _ellipse_frame(law.mu_x, law.mu_y, law.angle)
        return mbar, 0.0, A
    if isinstance(law, FrictionLaw):
        return _probe_law(law, index)
    try:
        mu = float(law)
    except (TypeError, ValueError) as exc:
        raise FrictionRulesError(f"mu[{index}] = {law!r} is not a friction law or a coefficient") from exc
    if not np.isfinite(mu) or mu < 0:
        raise FrictionRulesError(f"mu[{index}] = {mu!r} violates mu >= 0 (finite)")
    return mu, 0.0, None


class FrictionContactProblem:
    r"""Find ``r, u`` with :math:`u = W r + q` and the friction law of every contact.

    Parameters
    ----------
    W : (3 nc, 3 nc) sparse matrix or array
        Delassus operator (converted to CSR). It need not be symmetric.
    q : (3 nc,) array
        Free velocity.
    mu : float, (nc,) array, FrictionLaw or sequence of laws/floats
        Per-contact law: a number is isotropic Coulomb without normal slip (FCLIB); see the
        module docstring for the laws accepted.
    title : str
        A label (read from FCLIB ``info/title``).

    Attributes
    ----------
    W, q, nc, title
    laws : tuple
        The per-contact laws as given (floats for plain Coulomb).
    mu_bar : (nc,) array
        Isotropic coefficient of each contact in its circular frame.
    dilatancy : (nc,) array
        Dilatancy ratio ``d`` of each contact.
    frames : (nc, 2, 2) array or None
        ``A_a`` with :math:`r_T = A_a\tilde r_T`; None when every contact is isotropic.
    """

    def __init__(self, W, q, mu, *, title: str = ""):
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
        cache = {}
        mbar, dil, frames = np.empty(self.nc), np.zeros(self.nc), np.empty((self.nc, 2, 2))
        frames[:] = np.eye(2)
        any_frame = False
        for a, law in enumerate(laws):
            key = id(law) if not isinstance(law, (int, float, np.floating, np.integer)) else None
            if key is not None and key in cache:
                m, d, A = cache[key]
            else:
                m, d, A = _law_params(law, a)
                if key is not None:
                    cache[key] = (m, d, A)
            mbar[a], dil[a] = m, d
            if A is not None:
                frames[a] = A
                any_frame = True
        self.laws = tuple(float(x) if isinstance(x, (int, float, np.floating, np.integer)) else x
                          for x in laws)
        self.mu_bar = mbar
        self.dilatancy = dil
        self.frames = frames if any_frame else None
        self.title = str(title)

    def __repr__(self) -> str:
        return (f"FrictionContactProblem(nc={self.nc}, nnz(W)={self.W.nnz}"
                + (f", title={self.title!r}" if self.title else "") + ")")

    def coulomb_mu(self) -> np.ndarray:
        """The Coulomb coefficients; raises if a contact has another law (FCLIB cannot store it)."""
        if self.frames is not None or np.any(self.dilatancy != 0):
            raise FrictionRulesError("only problems with plain Coulomb contacts (no dilatancy, "
                                     "isotropic) can be written to FCLIB")
        return self.mu_bar.copy()

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
        Final error (:func:`~frictionrules.multicontact.fc3d_error`, Siconos' measure).
    iterations : int
    converged : bool
        ``error <= tol``.
    history : array
        Error after the iterations ``history_iterations`` (every iteration for ``newton`` and
        ``prox``; the sweeps where NSGS evaluated it).
    history_iterations : array of int
    method : str
    seconds : float
        Wall time of the solver (compilation of the kernels excluded when cached).
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
