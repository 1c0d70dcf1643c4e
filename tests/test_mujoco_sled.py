r"""The sled of ``examples/mujoco_snake_sled.py``: a rigid body on three spherical feet, W of
rank 6 for its 9 rows, stepped by ``frictionrules.mujoco``.

The feet are pressed in by different depths, so the contact points lie at different heights,
and the gap term :math:`g = \gamma/h\,e_N` of ``q`` (normal rows only) is not in the range of
J: the rotation that meets those normal velocities moves the points tangentially. Then
:math:`u = Wr + q` keeps :math:`P_{null(J^T)}\,q \ne 0` whatever ``r`` and the stick phases
have no stick solution. The step drops that part where its sweeps stall
(:func:`frictionrules.mujoco._consistent.consistent_q`); checked here against the projector of
a dense SVD of J, and every solve of the sled's stick phases reaches ``tol``.

Without ``mujoco`` these tests skip, except in CI (``CI=true``), where they fail.
"""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import numpy as np
import pytest

import frictionrules as fr

if os.environ.get("CI") == "true":
    import mujoco  # noqa: F401  (CI installs the extra: a missing one fails here, loudly)
else:
    mujoco = pytest.importorskip("mujoco", reason="the extra mujoco is not installed")

from frictionrules.mujoco import Simulator  # noqa: E402

FLOOR_X = {"floor": (1.0, 0.0, 0.0)}


def _example():
    path = Path(__file__).resolve().parent.parent / "examples" / "mujoco_snake_sled.py"
    spec = importlib.util.spec_from_file_location("mujoco_snake_sled", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


EX = _example()
LAWS = {"sawtooth": fr.WedgeAsperity(alpha=EX.ALPHA, mu=EX.MU),
        "elliptic": fr.EllipticOrthotropic(EX.MU_X, EX.MU_Y)}


def _sled(law, steps, **kw):
    model = mujoco.MjModel.from_xml_string(EX.scene_xml())
    sim = Simulator(model, {"floor": law}, axes=FLOOR_X, **kw)
    for _ in range(steps):
        sim.data.ctrl[0] = EX.drive(sim.data.time)
        sim.step()
    return sim


@pytest.mark.parametrize("kind", sorted(LAWS))
@pytest.mark.parametrize("tol, max_iter", [(1e-8, 200), (1e-10, 1000)])
def test_sled_stick_phase_every_solve_reaches_tol(kind, tol, max_iter):
    """The first 220 steps (0.88 s): the sled settles and sticks on its three feet (steps
    9–27 of the wedge law stopped above 1e-8 after 200 iterations, and the elliptic law's
    10–26, while the gap term was kept whole), then slides (step 213 of the wedge law: the
    sweeps converge slowly there, about 900 of them, Newton's steps on W in a few): every
    solve ends at most ``tol``."""
    sim = _sled(LAWS[kind], 220, tol=tol, max_iter=max_iter)
    assert sim.steps == 220 and sim.last.nc == 3
    assert sim.unconverged == 0
    assert sim.max_error <= tol


def test_consistent_q_is_q_less_the_null_space_part_of_its_gap_term():
    r""":math:`q_c = q - P\,g`, :math:`P = I - U_6 U_6^T` the projector on the null space of
    :math:`J^T` from a dense SVD of J (rank 6: one rigid body), and :math:`P q_c = 0`; the
    sled's ``q`` itself has a null-space part of the size the stalls showed (about 1e-9 m/s,
    1e-8 of ``|q|``), all of it from the gap term."""
    import scipy.sparse as sp

    from frictionrules.mujoco import _assemble, _step
    from frictionrules.mujoco._consistent import consistent_q, gap_term
    sim = _sled(LAWS["sawtooth"], 15, tol=1e-8, max_iter=200)
    model, data = sim.model, sim.data
    data.ctrl[0] = EX.drive(data.time)
    _step._forward(mujoco, model, data)
    A = _assemble.assemble(sp, mujoco, model, data, sim._scene, 0.2)
    h = float(model.opt.timestep)
    nv = A.blocks.nv
    J = np.stack([A.blocks.velocity(e, np.zeros(A.q.size)) for e in np.eye(nv)], axis=1)
    U, s, _ = np.linalg.svd(J)
    assert np.sum(s > 1e-10 * s[0]) == 6
    P = np.eye(J.shape[0]) - U[:, :6] @ U[:, :6].T
    g = gap_term(A.gap, 0.2, h)
    vfree = data.qvel + h * data.qacc_smooth
    assert np.allclose(A.q, J @ vfree + g, rtol=0, atol=1e-15 * np.linalg.norm(A.q))
    null_q = np.linalg.norm(P @ A.q)
    assert 1e-10 < null_q < 1e-6 * np.linalg.norm(A.q)
    assert np.linalg.norm(P @ (J @ vfree)) < 1e-6 * null_q
    qc = consistent_q(A.blocks, A.q, g)
    assert np.linalg.norm(qc - (A.q - P @ g)) <= 1e-6 * null_q
    assert np.linalg.norm(P @ qc) <= 1e-6 * null_q


def test_consistent_q_without_gap_term_is_q():
    """No gap term, nothing to drop: the same array back."""
    from frictionrules.mujoco._consistent import consistent_q
    q = np.arange(9.0)
    assert consistent_q(None, q, np.zeros(9)) is q
