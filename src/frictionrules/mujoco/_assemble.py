r"""The contact problem of one MuJoCo step in FCLIB's convention, from MuJoCo's own arrays.

After ``mj_fwdPosition``, ``mj_fwdVelocity``, ``mj_fwdActuation`` and ``mj_fwdAcceleration``
MuJoCo holds, for each active contact ``a`` (``dist < margin - gap``), three rows of the
constraint Jacobian ``efc_J`` at ``contact.efc_address``: the rows of its ``frame``
:math:`(n, t_1, t_2)`, with :math:`u = J\,\dot q` the velocity of geom 2 relative to geom 1
and ``n`` pointing from geom 1 to geom 2 (so ``u_N > 0`` separates: FCLIB's sign). With
:math:`h` the time step, the semi-implicit Euler step :math:`\dot q^+ = \dot q + h(\ddot
q_{smooth} + M^{-1}J^T r / h)` gives

.. math::

    u^+ = W r + q, \qquad W = J M^{-1} J^T, \qquad q = J(\dot q + h\,\ddot q_{smooth})
          + \tfrac1h\,\gamma\,e_N,

``r`` the contact impulses over the step (``r_N >= 0`` compression). ``W`` is kept by its
factors: per contact and kinematic tree the blocks :math:`J_{a,t}` of ``efc_J`` (sparse or
dense as the model's ``opt.jacobian`` makes it) and :math:`J_{a,t} M_t^{-1}`, the blocks of
:math:`M^{-1}` of every tree from one ``mj_solveM`` (:mod:`._kernels`,
:class:`~frictionrules.multicontact.factored.TreeBlocks`), so that
:math:`W_{ac} = \sum_t J_{a,t} M_t^{-1} J_{c,t}^T` is what MuJoCo's ``efc_AR - diag(efc_R)``
holds for its dual solvers, without setting ``opt.solver`` to one of them (which made
``mj_fwdPosition`` three times dearer). ``q`` is :math:`J_a(\dot q + h\ddot q_{smooth})`
from the same blocks. No product runs in a Python loop over contacts.

The gap term :math:`\gamma` (speculative contacts with a Baumgarte correction): a contact at
the distance ``dist > 0`` may close it within the step (:math:`\gamma = ` ``dist``), a
penetration ``dist < 0`` is pushed out at the rate :math:`\beta\,` ``dist`` ``/h``
(:math:`\gamma = \beta` ``dist``, ``baumgarte`` :math:`= \beta`).

Material axes: where a geom of the contact has an axis (``axes``), its direction
:math:`a = R_{geom} a_{local}` projected on the contact plane, :math:`t = a - (a\cdot n)n`,
is the law's direction 1: the rows T1, T2 are turned within the plane to
:math:`(t/|t|,\ n\times t/|t|)`. Where :math:`|t| <` :data:`AXIS_NORMAL_TOL` (the axis is
normal to the contact plane, within 1e-6 rad) the in-plane direction is undefined and the
contact keeps MuJoCo's frame (``StepResult.axis_fallback`` counts such contacts).
"""

from __future__ import annotations

import numpy as np

from ..errors import FrictionRulesError

__all__ = ["assemble", "AXIS_NORMAL_TOL", "Assembled", "Trees"]

#: Below this length of the unit axis projected on the contact plane, MuJoCo's frame is kept.
AXIS_NORMAL_TOL = 1e-6

#: MuJoCo's constraint types (``mjtConstraint``) that are not contacts, as users name them.
_NOT_CONTACT = {0: "an equality constraint", 1: "dof friction loss", 2: "tendon friction loss",
                3: "a joint limit", 4: "a tendon limit"}
_OBJECT = {0: "mjOBJ_EQUALITY", 1: "mjOBJ_DOF", 2: "mjOBJ_TENDON", 3: "mjOBJ_JOINT", 4: "mjOBJ_TENDON"}
_CONTACT_FRICTIONLESS = 5
#: The turn of the tangents where no contact has a material axis (not read).
_NO_TURN = np.zeros((1, 2, 2))


class Assembled:
    """The problem's pieces: ``blocks`` (:class:`~frictionrules.multicontact.factored.TreeBlocks`,
    rows in the law frames), ``q``; per
    contact the world frame rows ``frames`` (nc, 3, 3) of the law and ``mj_frames`` of
    MuJoCo, ``pos``, ``geom1``, ``geom2``, ``gap``; ``rows`` (3 nc,) the contacts' rows of
    MuJoCo's ``efc_*`` arrays; the count of axis fallbacks."""

    __slots__ = ("blocks", "q", "frames", "mj_frames", "rows", "pos", "geom1", "geom2", "gap", "axis_fallback")

    def __init__(self, blocks, q, frames, mj_frames, rows, pos, geom1, geom2, gap, axis_fallback):
        self.blocks, self.q, self.frames, self.mj_frames, self.rows = blocks, q, frames, mj_frames, rows
        self.pos, self.geom1, self.geom2, self.gap, self.axis_fallback = pos, geom1, geom2, gap, axis_fallback


def refuse_other_rows(mujoco, model, data) -> None:
    """One line naming the first constraint row that is not a contact (or a contact this
    bridge does not take: frictionless ``condim=1``, torsional or rolling ``condim`` 4, 6,
    flex contacts)."""
    nefc = int(data.nefc)
    if nefc == 0:
        return
    types = data.efc_type[:nefc]
    if types.min() > _CONTACT_FRICTIONLESS:      # contacts with friction only (one pass)
        return
    other = types < _CONTACT_FRICTIONLESS
    if other.any():
        i = int(np.flatnonzero(other)[0])
        t, oid = int(types[i]), int(data.efc_id[i])
        name = mujoco.mj_id2name(model, getattr(mujoco.mjtObj, _OBJECT[t]), oid) or f"#{oid}"
        raise FrictionRulesError(f"the model has {_NOT_CONTACT[t]} ({name!r}); frictionrules.mujoco "
                                 "steps contact-only models (remove it or step with mj_step)")
    if (types == _CONTACT_FRICTIONLESS).any():
        raise FrictionRulesError("the model has a frictionless contact (condim=1); frictionrules.mujoco "
                                 "takes condim=3 contacts only (the law gives the friction)")


class Trees:
    """A model's kinematic trees as :func:`._kernels.contact_blocks` takes them (built once):
    ``dof_tree`` (nv,), ``dofadr`` (ntree,), the right-hand sides ``rhs`` (m, nv) of the one
    ``mj_solveM`` that gives every block of :math:`M^{-1}`."""

    __slots__ = ("dof_tree", "dofadr", "dofnum", "rhs", "X")

    def __init__(self, model):
        from ._kernels import minv_rhs
        self.dof_tree = np.ascontiguousarray(model.dof_treeid, dtype=np.int64)
        self.dofadr = np.ascontiguousarray(model.tree_dofadr, dtype=np.int64)
        self.dofnum = num = np.ascontiguousarray(model.tree_dofnum, dtype=np.int64)
        c = np.arange(self.dof_tree.size)
        t = self.dof_tree
        if not (np.all(t >= 0) and np.all(c >= self.dofadr[t]) and np.all(c < self.dofadr[t] + num[t])):
            raise FrictionRulesError("the model's kinematic trees do not have contiguous dofs "
                                     "(dof_treeid, tree_dofadr); frictionrules.mujoco needs them")
        self.rhs = minv_rhs(self.dofadr, num, int(model.nv))
        self.X = np.empty_like(self.rhs)     # mj_solveM's answer, written each step


def _jacobian_csr(sp, mujoco, model, data):
    """``(rowadr, rownnz, colind, values)`` of ``efc_J`` (MuJoCo's own arrays for a sparse
    model; the dense ``efc_J`` converted, its zeros dropped)."""
    nefc, nv = int(data.nefc), int(model.nv)
    if mujoco.mj_isSparse(model):
        return data.efc_J_rowadr, data.efc_J_rownnz, data.efc_J_colind, data.efc_J
    J = sp.csr_matrix(np.asarray(data.efc_J[:nefc * nv]).reshape(nefc, nv))
    return J.indptr[:-1], np.diff(J.indptr), J.indices, J.data


def _law_frames(frames, owner, geom_xmat, axes):
    """Turn each contact's tangent rows to its owner geom's axis; returns the frames and the
    count of contacts whose axis was normal to the plane."""
    with_axis = np.flatnonzero(owner >= 0)
    if with_axis.size == 0:
        return frames, 0
    g = owner[with_axis]
    R = geom_xmat[g].reshape(-1, 3, 3)
    a = np.einsum("kij,kj->ki", R, axes[g])
    n = frames[with_axis, 0]
    t = a - np.einsum("ki,ki->k", a, n)[:, None] * n
    length = np.linalg.norm(t, axis=1)
    ok = length >= AXIS_NORMAL_TOL
    t = t[ok] / length[ok, None]
    rows = with_axis[ok]
    out = frames.copy()
    out[rows, 1] = t
    out[rows, 2] = np.cross(frames[rows, 0], t)
    return out, int((~ok).sum())


def assemble(sp, mujoco, model, data, scene, baumgarte: float) -> Assembled:
    """The problem of the current step (the forward stages have run). Contacts are those with
    constraint rows (``efc_address >= 0``), in MuJoCo's order."""
    from ..multicontact.factored import TreeBlocks
    from ._consistent import gap_term
    from ._kernels import contact_blocks
    refuse_other_rows(mujoco, model, data)
    ncon = int(data.ncon)
    con = data.contact
    addr = np.asarray(con.efc_address[:ncon]) if ncon else np.zeros(0, int)
    active = np.flatnonzero(addr >= 0)
    if active.size == 0:
        z = np.zeros(0)
        return Assembled(None, z, np.zeros((0, 3, 3)), np.zeros((0, 3, 3)), z.astype(int),
                         np.zeros((0, 3)), z.astype(int), z.astype(int), z, 0)
    whole = active.size == ncon
    dim = np.asarray(con.dim[:ncon])
    geom = np.asarray(con.geom[:ncon])
    if not whole:
        dim, geom = dim[active], geom[active]
    if (geom < 0).any():
        raise FrictionRulesError("the model has flex contacts; frictionrules.mujoco takes geom contacts only")
    if (dim != 3).any():
        j = int(np.flatnonzero(dim != 3)[0])
        raise FrictionRulesError(f"the contact of geoms {scene.names[geom[j, 0]]!r} and {scene.names[geom[j, 1]]!r} "
                                 f"has condim={int(dim[j])}; frictionrules.mujoco takes condim=3 only")
    geom1, geom2 = geom[:, 0].copy(), geom[:, 1].copy()
    start = addr if whole else addr[active]
    # copies: MuJoCo's contact arrays are views of its arena, rewritten by the next step (the
    # result keeps them for the next step's warm start)
    frames = np.array(con.frame[:ncon]).reshape(-1, 3, 3)
    gap = np.array(con.dist[:ncon])
    pos = np.array(con.pos[:ncon])
    if not whole:
        frames, gap, pos = frames[active], gap[active], pos[active]
    if scene.any_axis:
        owner = scene.axis_owner(geom1, geom2)
        law_frames, fallback = _law_frames(frames, owner, np.asarray(data.geom_xmat), scene.axes)
    else:
        law_frames, fallback = frames, 0
    if law_frames is frames:
        C, turned = _NO_TURN, np.zeros(active.size, dtype=np.bool_)
    else:
        # C[a, i, j] = t'_i . t_j: MuJoCo's tangents to the law's, within the contact plane
        C = np.einsum("kid,kjd->kij", law_frames[:, 1:], frames[:, 1:])
        turned = owner >= 0
    trees = scene.trees
    X = trees.X
    if X.size:
        mujoco.mj_solveM(model, data, X, trees.rhs)
    h = float(model.opt.timestep)
    vfree = np.asarray(data.qvel) + h * np.asarray(data.qacc_smooth)
    rowadr, rownnz, colind, values = _jacobian_csr(sp, mujoco, model, data)
    gap_velocity = gap_term(gap, float(baumgarte), h)[0::3].copy()
    tree, off, Jp, Bp, D, q = contact_blocks(start, rowadr, rownnz, colind, values, trees.dof_tree, trees.dofadr,
                                             trees.dofnum, X, C, turned, vfree, gap_velocity)
    blocks = TreeBlocks(tree, off, Jp, Bp, trees.dofadr, trees.dofnum, D, int(model.nv))
    rows = (start[:, None] + np.arange(3)).ravel()
    return Assembled(blocks, q, law_frames, frames, rows, pos, geom1, geom2, gap, fallback)
