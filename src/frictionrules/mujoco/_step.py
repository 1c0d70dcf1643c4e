r"""One MuJoCo step with the library's contact solve: :func:`step` and :class:`Simulator`.

The stages of a step (MuJoCo's own functions, the contact solve replaced):

1. ``mj_fwdPosition``, ``mj_fwdVelocity``, ``mj_fwdActuation``, ``mj_fwdAcceleration``:
   collision, the contacts' constraint rows, the smooth acceleration :math:`\ddot q_{smooth}`;
   during these calls ``opt.cone`` is elliptic, so that each contact has the three rows of its
   frame, and ``opt.solver`` Newton (a primal solver: ``mj_fwdPosition`` then skips the
   dual solvers' ``efc_AR``, which the step does not need); both are restored (a pyramidal
   model steps the same way);
2. the problem :math:`u = W r + q` of the contacts in the laws' frames (:mod:`._assemble`);
3. the solve from the previous step's impulses (warm start): non-smooth Gauss–Seidel on the
   factored operator (:func:`frictionrules.multicontact.factored.solve_factored`, W not
   formed), :func:`frictionrules.solve` on W where that does not apply or converge; where the
   first sweeps stall, on ``q`` less the part of its gap term that no motion produces
   (:mod:`._consistent`, :func:`_solve`);
4. :math:`\ddot q = \ddot q_{smooth} + M^{-1}J^T r/h` (from the blocks) and MuJoCo's integrator
   (``mj_Euler`` for ``opt.integrator="Euler"``, ``mj_implicit`` for ``"implicit"`` and
   ``"implicitfast"``; ``"RK4"`` is refused: it would call MuJoCo's solver at its stages).

``data.qacc``, ``data.qfrc_constraint`` and the contacts' ``data.efc_force`` hold the step's
values (``efc_force`` in the elliptic layout, (N, T1, T2) of MuJoCo's contact frame: what
``mj_contactForce`` reads for an elliptic-cone model). Sensors are not evaluated.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, field

import numpy as np

from .._optional import require
from ..errors import FrictionRulesError, check_scalar
from ..multicontact import METHODS, ContactLaws, FrictionContactProblem, solve, solve_factored
from ._assemble import assemble
from ._scene import Scene

__all__ = ["step", "Simulator", "StepResult"]


def _mujoco():
    return require("mujoco", extra="mujoco")


@dataclass(frozen=True)
class StepResult:
    r"""The contacts of one step and their solve.

    Attributes
    ----------
    time : float
        ``data.time`` after the step.
    r : (nc, 3) array
        Impulse of each contact over the step in its law frame ``(N, T1, T2)``: ``r_N >= 0``
        pushes geom 2 away from geom 1; the tangential impulse on geom 2 is ``r_T``
        (the laws' ``T = -r_T``, ``docs/conventions.md``).
    frames : (nc, 3, 3) array
        Rows ``n, t1, t2`` in world coordinates: ``n`` from geom 1 to geom 2, ``t1`` the law's
        direction 1 (the geom's axis projected on the plane, else MuJoCo's ``frame``).
    force : (nc, 3) array
        Mean contact force on geom 2 over the step in world coordinates, ``r @ frames / h`` (N).
    pos : (nc, 3) array
        Contact points (MuJoCo's ``contact.pos``).
    geom1, geom2 : (nc,) int arrays
    gap : (nc,) array
        MuJoCo's ``contact.dist`` (negative: penetration).
    solution : Solution or None
        The solve (None without contacts): ``error``, ``iterations``, ``converged``, ``method``.
    warm_started : int
        Contacts whose initial impulse came from the previous step.
    axis_fallback : int
        Contacts whose geom's axis was normal to the contact plane (MuJoCo's frame kept).
    """

    time: float
    r: np.ndarray = field(repr=False)
    frames: np.ndarray = field(repr=False)
    force: np.ndarray = field(repr=False)
    pos: np.ndarray = field(repr=False)
    geom1: np.ndarray = field(repr=False)
    geom2: np.ndarray = field(repr=False)
    gap: np.ndarray = field(repr=False)
    solution: object = field(repr=False, default=None)
    warm_started: int = 0
    axis_fallback: int = 0

    @property
    def nc(self) -> int:
        """Number of contacts."""
        return int(self.r.shape[0])

    @property
    def converged(self) -> bool:
        """Whether the solve reached its tolerance (True without contacts)."""
        return self.solution is None or bool(self.solution.converged)


def _warm_start(previous: StepResult | None, A, h: float, ngeom: int, distance: float):
    """Initial impulses ``(3 nc,)``: each contact takes the world force of the previous step's
    contact of the same geom pair nearest to it, within ``distance``, in its own frame
    (:func:`._kernels.warm_start`, compiled: the previous contacts sorted by pair, each new
    contact compared with the few previous ones of its pair)."""
    nc = A.pos.shape[0]
    if previous is None or previous.nc == 0 or nc == 0:
        return None, 0
    from ._kernels import warm_start
    r0 = np.empty((nc, 3))
    count = warm_start(A.geom1.astype(np.int64) * ngeom + A.geom2, np.ascontiguousarray(A.pos, dtype=float),
                       np.ascontiguousarray(A.frames), previous.geom1.astype(np.int64) * ngeom + previous.geom2,
                       np.ascontiguousarray(previous.pos, dtype=float), np.ascontiguousarray(previous.force),
                       float(h), float(distance), r0)
    if count == 0:
        return None, 0
    return r0.ravel(), int(count)


class _Params:
    __slots__ = ("baumgarte", "method", "tol", "max_iter", "warm_distance")

    def __init__(self, baumgarte, method, tol, max_iter, warm_distance):
        self.baumgarte = check_scalar("baumgarte", baumgarte, lo=0.0, hi=1.0)
        self.tol = check_scalar("tol", tol, lo=0.0)
        self.max_iter = max_iter
        self.method = method
        self.warm_distance = check_scalar("warm_distance", warm_distance, lo=0.0)


#: MuJoCo's warnings that mean contacts or their rows were dropped for want of memory.
_FULL = ("mjWARN_CONTACTFULL", "mjWARN_CNSTRFULL")

_INTEGRATORS = {0: "mj_Euler", 2: "mj_implicit", 3: "mj_implicit"}


@functools.cache
def _full_warnings(mujoco) -> tuple:
    """The indices of :data:`_FULL` in ``data.warning``."""
    return tuple(int(getattr(mujoco.mjtWarning, name)) for name in _FULL)


def _forward(mujoco, model, data):
    if int(model.opt.integrator) not in _INTEGRATORS:
        raise FrictionRulesError("model.opt.integrator = RK4 is refused (its stages call MuJoCo's "
                                 "solver); use Euler, implicit or implicitfast")
    opt = model.opt
    full = _full_warnings(mujoco)
    before = [int(data.warning[i].number) for i in full]
    solver, cone = int(opt.solver), int(opt.cone)
    opt.solver = mujoco.mjtSolver.mjSOL_NEWTON  # no efc_AR (a dual solver's): W is kept by its factors from efc_J
    opt.cone = mujoco.mjtCone.mjCONE_ELLIPTIC   # rows N, T1, T2 of each contact's frame
    try:
        mujoco.mj_fwdPosition(model, data)
        mujoco.mj_fwdVelocity(model, data)
        mujoco.mj_fwdActuation(model, data)
        mujoco.mj_fwdAcceleration(model, data)
    finally:
        opt.solver, opt.cone = solver, cone
    for name, i, n in zip(_FULL, full, before):
        if int(data.warning[i].number) > n:
            raise FrictionRulesError(f"MuJoCo's arena was full ({name}): contacts or their rows were dropped; "
                                     "give the model more memory (<size memory=\"64M\"/>)")


#: Sweeps of the factored NSGS on ``q`` as assembled, and (``method`` "auto") on ``q`` with its
#: gap term made consistent, before the step builds W and hands the problem to
#: :func:`frictionrules.solve` (the cone path's "auto" probes as many NSGS sweeps).
FACTORED_SWEEPS = 50
#: Newton steps on the law path's natural map (``method="polish"`` on W) after the factored
#: sweeps of "auto" have not converged, before the law path's own "auto" takes the rest.
POLISH_STEPS = 20


def _contact_laws(scene: Scene, geom1, geom2):
    """The contacts' :class:`~frictionrules.multicontact.factored.ContactLaws`, reduced again
    only when the contacts' laws change (the tuple :meth:`Scene.laws_of` returns)."""
    laws = scene.laws_of(geom1, geom2)
    last = scene.problem
    if last is not None and last[0] is laws:
        return last[1]
    reduced = ContactLaws(laws)
    scene.problem = (laws, reduced)
    return reduced


def _solve(A, claws, r0, p: _Params, h: float):
    """The step's solve: the factored sweeps (:func:`~frictionrules.multicontact.factored.solve_factored`,
    W not formed) for ``method`` "nsgs" and "auto", at most :data:`FACTORED_SWEEPS` of them on
    ``q`` as assembled. Where they have not converged, ``q`` loses the part of its gap term that
    no motion produces (:func:`._consistent.consistent_q`: the stalls of bodies on several
    contacts, whose W is singular) and the solve goes on from the sweeps' impulses: "nsgs"
    sweeps on; "auto" sweeps :data:`FACTORED_SWEEPS` more, then, where still above ``tol``,
    and for the other methods and elliptic cones with turned frames, :func:`frictionrules.solve`
    on W (:meth:`TreeBlocks.delassus`)."""
    from ._consistent import consistent_q, gap_term
    limit = METHODS[p.method].max_iter if p.max_iter is None else int(p.max_iter)
    stages = []
    q = A.q
    factored = p.method in ("auto", "nsgs") and (claws.path == "law" or claws.frames is None)
    if factored:
        first = solve_factored(claws, A.blocks, q, r0, tol=p.tol, max_iter=min(limit, FACTORED_SWEEPS))
        stages.append(first)
        if first.converged or first.reason == "unbounded" or first.iterations >= limit:
            return first
        r0 = first.r
    q = consistent_q(A.blocks, A.q, gap_term(A.gap, p.baumgarte, h))
    done = sum(s.iterations for s in stages)
    if factored:
        budget = limit - done if p.method == "nsgs" else min(limit - done, FACTORED_SWEEPS)
        second = solve_factored(claws, A.blocks, q, r0, tol=p.tol, max_iter=budget)
        stages.append(second)
        done += second.iterations
        if second.converged or second.reason == "unbounded" or done >= limit:
            return _joined(stages)
        r0 = second.r
    problem = FrictionContactProblem(A.blocks.delassus(), q, claws.laws)
    if factored and claws.path == "law" and p.method == "auto":
        # the sweeps have run: Newton's steps on the law path's natural map first (the law
        # path's "auto" would sweep AUTO_SWEEPS times more before its first one)
        polished = solve(problem, "polish", p.tol, min(POLISH_STEPS, limit - done), r0=r0)
        stages.append(polished)
        done += polished.iterations
        if polished.converged or done >= limit:
            return _joined(stages)
        r0 = polished.r
    stages.append(solve(problem, p.method, p.tol, limit - done, r0=r0))
    return _joined(stages)


def _joined(stages):
    """One :class:`~frictionrules.Solution` of the solves run one after the other (the last
    one's impulses and error; iterations, histories and times summed)."""
    last = stages[-1]
    if len(stages) == 1:
        return last
    its = np.cumsum([0] + [s.iterations for s in stages])
    return dataclasses.replace(
        last, iterations=int(its[-1]), method="+".join(s.method for s in stages),
        history=np.concatenate([s.history for s in stages]),
        history_iterations=np.concatenate([k + s.history_iterations for k, s in zip(its, stages)]),
        seconds=sum(s.seconds for s in stages), cpu_seconds=sum(s.cpu_seconds for s in stages))


def _advance(mujoco, model, data, scene: Scene, previous, p: _Params) -> StepResult:
    import scipy.sparse as sp

    _forward(mujoco, model, data)
    h = float(model.opt.timestep)
    A = assemble(sp, mujoco, model, data, scene, p.baumgarte)
    nc = A.pos.shape[0]
    sol, warm = None, 0
    if nc == 0:
        r = np.zeros((0, 3))
        data.qacc[:] = data.qacc_smooth
        data.qfrc_constraint[:] = 0.0
    else:
        claws = _contact_laws(scene, A.geom1, A.geom2)
        r0, warm = _warm_start(previous, A, h, scene.ngeom, p.warm_distance)
        sol = _solve(A, claws, r0, p, h)
        r = sol.r.reshape(nc, 3)
    force = np.einsum("ki,kij->kj", r, A.frames) / h
    if nc:
        # the impulses in MuJoCo's frames are its efc_force times h; J^T of them by MuJoCo
        efc = np.zeros(int(data.nefc))
        # the law frames are MuJoCo's where no geom has axes: r / h is then efc_force already
        efc[A.rows] = (r / h if A.frames is A.mj_frames else np.einsum("kij,kj->ki", A.mj_frames, force)).ravel()
        data.efc_force[:] = efc
        mujoco.mj_mulJacTVec(model, data, data.qfrc_constraint, efc)
        # qacc = qacc_smooth + M^-1 J^T r / h, M^-1 J^T r from the blocks
        np.add(data.qacc_smooth, A.blocks.impulse_velocity(sol.r) / h, out=data.qacc)
    getattr(mujoco, _INTEGRATORS[int(model.opt.integrator)])(model, data)
    return StepResult(time=float(data.time), r=r, frames=A.frames, force=force, pos=A.pos, geom1=A.geom1,
                      geom2=A.geom2, gap=A.gap, solution=sol, warm_started=warm, axis_fallback=A.axis_fallback)


def step(model, data, laws, axes=None, *, default=None, previous: StepResult | None = None,
         baumgarte: float = 0.2, method: str = "auto", tol: float = 1e-10, max_iter: int | None = 1000,
         warm_distance: float = 0.01) -> StepResult:
    r"""Advance ``data`` by one ``model.opt.timestep`` with the contacts solved by the library.

    MuJoCo keeps the model, collision, mass matrix and integration; the contact impulses are
    the solution of :class:`~frictionrules.FrictionContactProblem` :math:`u = W r + q` built
    from MuJoCo's own ``efc_J`` and ``mj_solveM`` (see ``docs/mujoco.md``).

    Parameters
    ----------
    model : mujoco.MjModel
        Contact-only (no equality constraints, joint or tendon limits, friction loss), every
        contact ``condim=3``, integrator Euler, implicit or implicitfast.
    data : mujoco.MjData
        Advanced in place (``qpos``, ``qvel``, ``act``, ``time``; ``qacc``,
        ``qfrc_constraint`` and ``efc_force`` hold the step's values).
    laws : mapping
        Geom name, or pair of geom names (order-free), to a law that
        :class:`~frictionrules.FrictionContactProblem` accepts or a number (Coulomb ``mu``).
        A contact takes its pair's law, else the single entry of one of its geoms (both
        geoms' entries must then agree), else ``default``.
    axes : mapping, optional
        Geom name to a direction ``(3,)`` in that geom's frame: projected on each contact
        plane, the law's direction 1 (an orthotropic law's ``angle`` is measured from it).
    default : law or number, optional
        The law of contacts that no entry covers (without it such a contact is an error).
    previous : StepResult, optional
        The previous step's result: its contact forces warm-start the solve.
    baumgarte : float
        :math:`\beta \in [0, 1]`: a penetration ``dist < 0`` is removed at the rate
        :math:`\beta\,|dist|/h`; a contact at ``0 < dist < margin`` may close within the step.
    method, tol, max_iter
        As in :func:`frictionrules.solve`; ``tol`` is 1e-10 here (at 1e-8, three stacked boxes
        crept 0.13 mm in 1 s of resting, measured; at 1e-10, 4e-13 m) and ``max_iter`` 1000
        (a solve that stalls above ``tol`` would otherwise run the method's own limit,
        100,000 NSGS sweeps: seconds per step). Where the first sweeps stall, the part of
        the gap term that no motion produces is dropped from ``q`` (bodies on several
        contacts at different heights: no stick solution otherwise; ``docs/mujoco.md``). A
        solve stopped above ``tol`` is applied all the same; ``StepResult`` and
        ``Simulator.unconverged`` say so.
    warm_distance : float
        A contact is warm-started from the previous step's contact of the same geom pair
        nearest to it within this distance (model length units).

    Returns
    -------
    StepResult
    """
    mujoco = _mujoco()
    p = _Params(baumgarte, method, tol, max_iter, warm_distance)
    return _advance(mujoco, model, data, Scene(mujoco, model, laws, axes, default), previous, p)


class Simulator:
    """A MuJoCo model stepped by :func:`step`, keeping the warm start and the statistics.

    Parameters
    ----------
    model : mujoco.MjModel
    laws, axes, default, baumgarte, method, tol, max_iter, warm_distance
        As in :func:`step` (names resolved once).
    data : mujoco.MjData, optional
        The state to advance (a fresh ``MjData`` by default).

    Attributes
    ----------
    model, data
    last : StepResult or None
        The last step's result.
    steps : int
        Steps taken.
    unconverged : int
        Steps whose solve stopped above ``tol`` (their impulses were applied all the same).
    max_error : float
        Largest final error of a solve so far.
    """

    def __init__(self, model, laws, axes=None, *, data=None, default=None, baumgarte: float = 0.2,
                 method: str = "auto", tol: float = 1e-10, max_iter: int | None = 1000,
                 warm_distance: float = 0.01):
        self._mujoco = _mujoco()
        self.model = model
        self.data = self._mujoco.MjData(model) if data is None else data
        self._scene = Scene(self._mujoco, model, laws, axes, default)
        self._params = _Params(baumgarte, method, tol, max_iter, warm_distance)
        self.last: StepResult | None = None
        self.steps = 0
        self.unconverged = 0
        self.max_error = 0.0

    def step(self, n: int = 1) -> StepResult:
        """Advance ``n`` steps; returns the last one's :class:`StepResult`."""
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise FrictionRulesError(f"n = {n!r} violates: an integer >= 1")
        for _ in range(int(n)):
            self.last = _advance(self._mujoco, self.model, self.data, self._scene, self.last, self._params)
            self.steps += 1
            sol = self.last.solution
            if sol is not None:
                self.unconverged += not sol.converged
                self.max_error = max(self.max_error, float(sol.error))
        return self.last
