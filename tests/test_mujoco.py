r"""frictionrules.mujoco: MuJoCo scenes stepped by the library's contact solve, against closed forms.

Without ``mujoco`` these tests skip, except in CI (``CI=true``), where they fail: the extra
``mujoco`` is part of the test setup.

The incline: a horizontal floor and gravity tilted by :math:`\theta` (the same as a plane
tilted by :math:`\theta`), its tangential part along :math:`s` at the angle :math:`\phi_s` from
the floor's x axis, the law's axis 1 along x. A box starting at rest slides with a constant
acceleration :math:`a` along a fixed unit direction :math:`e` (angle :math:`\beta` from axis 1)
when the net force per unit mass is parallel to :math:`e`:

.. math::

    g(\sin\theta\, s - \cos\theta\, \hat F(\beta)) \parallel e, \qquad
    |v(t)| = t\,|g(\sin\theta\, s - \cos\theta\, \hat F(\beta))|,

where :math:`N\hat F(\beta)` is the friction force of the law for the slip direction
:math:`e` (each corner of the box slides with the same velocity, so the box's total is the
one-contact force times the total normal force :math:`N = mg\cos\theta`). Semi-implicit Euler
is exact for a constant acceleration, so the step's velocities are the closed form's.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from scipy.optimize import brentq

import frictionrules as fr
from frictionrules.errors import FrictionRulesError

if os.environ.get("CI") == "true":
    import mujoco  # noqa: F401  (CI installs the extra: a missing one fails here, loudly)
else:
    mujoco = pytest.importorskip("mujoco", reason="the extra mujoco is not installed")

from frictionrules.mujoco import Simulator, StepResult, step  # noqa: E402

G = 9.81
MU = (0.2, 0.8)
THETA = np.pi / 4


def incline_xml(theta=THETA, slope=np.pi / 4, yaw=0.0, h=0.01, half=0.1):
    """A box (half size ``half``, 1 kg) resting on a horizontal floor, gravity tilted by
    ``theta`` towards ``slope`` (angle from x); the box turned by ``yaw`` about z."""
    gx, gy = G * np.sin(theta) * np.cos(slope), G * np.sin(theta) * np.sin(slope)
    gz = -G * np.cos(theta)
    return f"""
<mujoco>
  <option timestep="{h}" gravity="{gx:.17g} {gy:.17g} {gz:.17g}"/>
  <worldbody>
    <geom name="floor" type="plane" size="50 50 .1" margin="0.002"/>
    <body name="box" pos="0 0 {half}" euler="0 0 {np.degrees(yaw):.17g}">
      <freejoint/>
      <geom name="box" type="box" size="{half} {half} {half}" mass="1" margin="0.002"/>
    </body>
  </worldbody>
</mujoco>"""


#: The law's axis 1 along the floor's x axis (MuJoCo's own plane-box frame has t1 = world y).
FLOOR_X = {"floor": (1.0, 0.0, 0.0)}


def slide(law, t=0.5, axes=FLOOR_X, **kw):
    """Run the incline to ``t``; return the box's velocity (3,) and its height."""
    m = mujoco.MjModel.from_xml_string(incline_xml(**kw))
    sim = Simulator(m, {"floor": law}, axes=axes, tol=1e-10)
    sim.step(int(round(t / m.opt.timestep)))
    assert sim.unconverged == 0
    return sim.data.qvel[:3].copy(), float(sim.data.qpos[2])


def closed_form(F_hat, theta=THETA, slope=np.pi / 4, t=0.5):
    """``(beta, |v(t)|)`` of the condition in the module docstring, ``beta`` from axis 1 found
    by bracketing the sign change of the cross product on (0, pi/2)."""
    s = np.array([np.cos(slope), np.sin(slope)])

    def net(b):
        return G * (np.sin(theta) * s - np.cos(theta) * F_hat(b))

    def cross(b):
        n = net(b)
        return n[0] * np.sin(b) - n[1] * np.cos(b)

    grid = np.linspace(1e-6, np.pi / 2 - 1e-6, 2001)
    values = np.array([cross(b) for b in grid])
    k = np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))
    assert k.size == 1
    beta = brentq(cross, grid[k[0]], grid[k[0] + 1], xtol=1e-15)
    n = net(beta)
    assert n @ np.array([np.cos(beta), np.sin(beta)]) > 0        # it slides forwards along e
    return beta, t * float(np.linalg.norm(n))


def elliptic_force(b, mx=MU[0], my=MU[1]):
    """Associated elliptic law, the inverse relation (1.13): the force normal to whose
    ellipse the slip ``e`` is, :math:`(\\mu_x^2 c, \\mu_y^2 s)/\\sqrt{(\\mu_x c)^2 + (\\mu_y s)^2}`."""
    c, s = np.cos(b), np.sin(b)
    return np.array([mx**2 * c, my**2 * s]) / np.hypot(mx * c, my * s)


def direction(v):
    return np.arctan2(v[1], v[0])


# ---- closed forms on the anisotropic incline ------------------------------------------------
def test_incline_associated_elliptic_eq_1_13():
    r"""EllipticOrthotropic(0.2, 0.8), slope at 45 deg to its axes, theta = 45 deg.

    With :math:`\sin\theta = \cos\theta` the condition reads :math:`(s - \hat F)\times e = 0`;
    for :math:`\mu_x + \mu_y = 1` its root is :math:`\tan\beta = \mu_x/\mu_y`, i.e.
    14.04 deg from axis 1 (30.96 deg off the slope line, towards the easy axis), and
    :math:`|v(0.5)| = 2.0224`; the bracketed root is checked against that too.
    """
    beta, speed = closed_form(elliptic_force)
    assert beta == pytest.approx(np.arctan(MU[0] / MU[1]), abs=1e-12)
    assert np.degrees(beta) == pytest.approx(14.036, abs=1e-3) and speed == pytest.approx(2.0224, abs=1e-4)
    v, z = slide(fr.EllipticOrthotropic(*MU))
    assert direction(v) == pytest.approx(beta, abs=1e-7)
    assert np.linalg.norm(v[:2]) == pytest.approx(speed, rel=1e-7)
    assert abs(v[2]) < 1e-9 and z == pytest.approx(0.1, abs=1e-9)        # no normal motion


def test_incline_isotropic_coulomb_slides_down_the_slope():
    """Coulomb mu: straight down the slope at :math:`g t(\\sin\\theta - \\mu\\cos\\theta)`."""
    v, _ = slide(0.3, slope=0.7)
    assert direction(v) == pytest.approx(0.7, abs=1e-8)
    assert np.linalg.norm(v[:2]) == pytest.approx(0.5 * G * (np.sin(THETA) - 0.3 * np.cos(THETA)), rel=1e-8)


@pytest.mark.parametrize("turn", [0.3, -1.1])
def test_incline_turning_the_law_angle_turns_the_slip(turn):
    """The law's angle and the slope turned by the same angle: the slip turns by it, the
    speed is unchanged (frame invariance of (1.9)-(1.10))."""
    beta, speed = closed_form(elliptic_force)
    v, _ = slide(fr.EllipticOrthotropic(*MU, angle=turn), slope=np.pi / 4 + turn)
    assert direction(v) == pytest.approx(beta + turn, abs=1e-7)
    assert np.linalg.norm(v[:2]) == pytest.approx(speed, rel=1e-7)


@pytest.mark.parametrize("yaw", [0.4, 2.0])
def test_incline_axes_fixed_to_the_body_turn_with_it(yaw):
    """The law's axis 1 is the box's own x axis (``axes={"box": (1, 0, 0)}``): the box turned
    by ``yaw`` and the slope turned with it slide along the turned closed-form direction. The
    floor's axes are MuJoCo's frame (plane-box: t1 = world y), so without ``axes`` the
    direction would not turn."""
    beta, speed = closed_form(elliptic_force)
    v, _ = slide(fr.EllipticOrthotropic(*MU), axes={"box": (1.0, 0.0, 0.0)}, yaw=yaw, slope=np.pi / 4 + yaw)
    assert np.cos(direction(v) - beta - yaw) == pytest.approx(1.0, abs=1e-12)
    assert np.linalg.norm(v[:2]) == pytest.approx(speed, rel=1e-7)


def test_incline_axis_on_the_floor_frame():
    """Axes on the floor (a world direction): the same as the law's angle."""
    beta, speed = closed_form(elliptic_force)
    turn = 0.5
    v, _ = slide(fr.EllipticOrthotropic(*MU), axes={"floor": (np.cos(turn), np.sin(turn), 0.0)},
                 slope=np.pi / 4 + turn)
    assert direction(v) == pytest.approx(beta + turn, abs=1e-7)
    assert np.linalg.norm(v[:2]) == pytest.approx(speed, rel=1e-7)


def test_dilatant_rule_lifts_at_d_times_the_slip_speed():
    r"""A user law with the Coulomb limit and the potential :math:`g = |T| - dN`: the slip
    :math:`v = \dot\lambda(T/|T|, d)` lifts the block at :math:`v_n = d|v_t|`. On a flat
    floor the lift is one step's: at the next step the speculative gap term closes the gap
    the lift opened (the floor is flat: no asperity to climb), so the check is the velocity
    after the first step of a block already sliding at :math:`v_0 = 1` m/s.

    The step's impulses (per unit mass): the normal one :math:`r_N = gh + v_n` carries the
    weight and starts the lift, the tangential one is :math:`\mu r_N`, so
    :math:`v_t = v_0 - \mu(gh + d v_t)`, i.e. :math:`v_t = (v_0 - \mu g h)/(1 + \mu d)`."""
    d = 0.25
    law = fr.UserLaw("sqrt(T1**2 + T2**2) - mu*N", "sqrt(T1**2 + T2**2) - d*N", params={"mu": 0.3, "d": d})
    m = mujoco.MjModel.from_xml_string(incline_xml(theta=0.0))
    data = mujoco.MjData(m)
    data.qvel[0] = 1.0
    res = step(m, data, {"floor": law}, tol=1e-12)
    vt = np.hypot(*data.qvel[:2])
    assert vt == pytest.approx((1.0 - 0.3 * G * m.opt.timestep) / (1 + 0.3 * d), rel=1e-9)
    assert data.qvel[2] == pytest.approx(d * vt, rel=1e-8)
    assert res.converged and res.nc == 4


# ---- isotropic regression ---------------------------------------------------------------
def box_on_floor_xml(mu, h):
    return f"""
<mujoco>
  <option timestep="{h}"/>
  <worldbody>
    <geom name="floor" type="plane" size="50 50 .1" margin="0.002" friction="{mu} 0.005 0.0001"/>
    <body name="box" pos="0 0 0.1">
      <freejoint/>
      <geom name="box" type="box" size=".1 .1 .1" mass="1" margin="0.002" friction="{mu} 0.005 0.0001"/>
    </body>
  </worldbody>
</mujoco>"""


def test_pushed_box_speed_f_over_m_minus_mu_g_and_mujoco_within_3_percent():
    """A 1 kg box pushed by F = 8 N on mu = 0.5 reaches (F/m - mu g) t at t = 1 s exactly
    (constant acceleration: semi-implicit Euler is exact); MuJoCo's own (soft) solver within
    3 % of it at h = 2 ms with its default pyramidal cone. MuJoCo's own value moves with h,
    cone and margin (measured with mujoco 4.0.0: from -9 % to +6 % over h = 1, 2, 5 ms, both
    cones, margin 0 and 2 mm; docs/mujoco.md has the table); ours does not."""
    F, mu, h, n = 8.0, 0.5, 0.002, 500
    m = mujoco.MjModel.from_xml_string(box_on_floor_xml(mu, h))
    sim = Simulator(m, {"floor": mu}, tol=1e-10)
    ref = mujoco.MjData(m)
    for _ in range(n):
        sim.data.xfrc_applied[1, 0] = F
        ref.xfrc_applied[1, 0] = F
        sim.step()
        mujoco.mj_step(m, ref)
    exact = (F - mu * G) * n * h
    assert sim.data.qvel[0] == pytest.approx(exact, rel=1e-8)
    assert abs(sim.data.qvel[1]) < 1e-9 and abs(sim.data.qvel[2]) < 1e-9
    assert ref.qvel[0] == pytest.approx(exact, rel=0.03)
    assert sim.last.warm_started == 4


def test_launched_box_stops_at_v0_squared_over_2_mu_g():
    """Launched at v0 = 2 m/s on mu = 0.5: it stops after v0^2/(2 mu g) within one step's
    travel h v0 (semi-implicit Euler's position error for a constant deceleration, the
    stopping step included), and stays stopped."""
    v0, mu, h = 2.0, 0.5, 0.005
    m = mujoco.MjModel.from_xml_string(box_on_floor_xml(mu, h))
    sim = Simulator(m, {"floor": mu}, tol=1e-10)
    mujoco.mj_forward(m, sim.data)
    sim.data.qvel[0] = v0
    stop = v0 / (mu * G)
    sim.step(int(stop / h) + 20)
    assert abs(sim.data.qvel[0]) < 1e-9
    assert sim.data.qpos[0] == pytest.approx(v0**2 / (2 * mu * G), abs=h * v0)


# ---- resting, the Baumgarte term -----------------------------------------------------
def stack_xml(n=3, h=0.005):
    bodies = "".join(f"""
    <body name="b{i}" pos="{0.01 * (i % 2)} 0 {0.1 + 0.2 * i}" euler="0 0 {7 * i}">
      <freejoint/>
      <geom name="b{i}" type="box" size=".1 .1 .1" mass="1" margin="0.002"/>
    </body>""" for i in range(n))
    return f"""<mujoco><option timestep="{h}"/><worldbody>
    <geom name="floor" type="plane" size="5 5 .1" margin="0.002"/>{bodies}
    </worldbody></mujoco>"""


def test_a_stack_of_boxes_rests_without_drift():
    """Three boxes stacked (offset and turned) rest 1 s: no body moves by more than 1e-6 m
    (the Baumgarte term keeps penetration at zero: each contact starts at dist = 0)."""
    m = mujoco.MjModel.from_xml_string(stack_xml())
    sim = Simulator(m, {}, default=0.5)
    mujoco.mj_forward(m, sim.data)
    start = sim.data.xpos.copy()
    sim.step(200)
    assert np.abs(sim.data.xpos - start).max() < 1e-6
    assert sim.unconverged == 0 and sim.last.nc >= 12
    assert np.all(sim.last.gap > -1e-6)


def test_penetration_is_removed_at_the_baumgarte_rate():
    """A box started 1 mm into the floor: with beta the penetration falls by the factor
    (1 - beta) a step (q_N's term beta dist/h; gravity is carried by the impulse)."""
    m = mujoco.MjModel.from_xml_string(box_on_floor_xml(0.5, 0.005))
    data = mujoco.MjData(m)
    data.qpos[2] = 0.099
    res = step(m, data, {"floor": 0.5}, baumgarte=0.5)
    assert res.gap == pytest.approx(np.full(4, -1e-3), abs=1e-12)
    assert data.qpos[2] == pytest.approx(0.1 - 0.5e-3, abs=1e-12)


# ---- laws mapping, axes and refusals ----------------------------------------------------
def test_law_lookup_pair_then_single_then_default():
    m = mujoco.MjModel.from_xml_string(stack_xml(2))
    data = mujoco.MjData(m)
    law = fr.EllipticOrthotropic(0.3, 0.6)
    res = step(m, data, {("b1", "b0"): law, "floor": 0.4})
    assert res.nc > 4 and np.sum((res.geom1 == 0) | (res.geom2 == 0)) == 4
    with pytest.raises(FrictionRulesError, match="'b0' and 'b1' has no law"):
        step(m, mujoco.MjData(m), {"floor": 0.4})
    with pytest.raises(FrictionRulesError, match="two different single-geom laws"):
        step(m, mujoco.MjData(m), {"b0": 0.4, "b1": 0.3, "floor": 0.4})
    step(m, mujoco.MjData(m), {"b0": 0.4, "b1": 0.4})            # equal single entries agree


def test_bad_arguments_are_refused_in_one_line():
    m = mujoco.MjModel.from_xml_string(stack_xml(1))
    data = mujoco.MjData(m)
    with pytest.raises(FrictionRulesError, match="'nope' is not a geom of the model"):
        step(m, data, {"nope": 0.3})
    two_flank = fr.TwoFlankAsperity(np.pi / 3, 5 * np.pi / 6, 0.3)     # no symbolic form, no cone
    with pytest.raises(FrictionRulesError, match=r"laws\['floor'\]: FrictionContactProblem: .* violates"):
        step(m, data, {"floor": two_flank})
    with pytest.raises(FrictionRulesError, match="baumgarte = 2.0 violates"):
        step(m, data, {"floor": 0.3}, baumgarte=2.0)
    with pytest.raises(FrictionRulesError, match=r"axes\['b0'\].*non-zero 3-vector"):
        step(m, data, {"floor": 0.3}, axes={"b0": (0, 0, 0)})


def _refused(xml, match):
    m = mujoco.MjModel.from_xml_string(xml)
    with pytest.raises(FrictionRulesError, match=match):
        step(m, mujoco.MjData(m), {}, default=0.3)


def test_models_with_other_constraints_or_condims_are_refused():
    hinge = """<mujoco><worldbody><geom name="floor" type="plane" size="5 5 .1" margin="0.01"/>
      <body pos="0 0 0.1"><joint name="j" type="hinge" limited="true" range="0.1 0.2"/>
      <geom type="box" size=".1 .1 .1" margin="0.01"/></body></worldbody></mujoco>"""
    _refused(hinge, "a joint limit \\('j'\\)")
    for condim in (1, 4, 6):
        xml = box_on_floor_xml(0.5, 0.005).replace('margin="0.002"', f'margin="0.002" condim="{condim}"')
        _refused(xml, "condim=1" if condim == 1 else f"condim={condim}")
    rk4 = box_on_floor_xml(0.5, 0.005).replace("<option ", '<option integrator="RK4" ')
    _refused(rk4, "RK4 is refused")


def test_an_axis_normal_to_the_contact_plane_keeps_mujocos_frame():
    m = mujoco.MjModel.from_xml_string(incline_xml(theta=0.0))
    res = step(m, mujoco.MjData(m), {"floor": fr.EllipticOrthotropic(*MU)}, axes={"box": (0, 0, 1.0)})
    assert res.axis_fallback == 4
    assert res.frames[:, 1] == pytest.approx(np.tile([0.0, 1.0, 0.0], (4, 1)))


def test_step_result_records_forces_and_mujoco_reads_them():
    """The resting box: the contact forces sum to its weight, and ``mj_contactForce`` reads the
    same forces from ``efc_force`` in MuJoCo's frames (an elliptic-cone model: ``efc_force``
    holds each contact's (N, T1, T2), the elliptic layout, whatever the model's cone)."""
    m = mujoco.MjModel.from_xml_string(box_on_floor_xml(0.5, 0.005).replace("<option ", '<option cone="elliptic" '))
    data = mujoco.MjData(m)
    res = step(m, data, {"floor": 0.5}, tol=1e-12)
    assert isinstance(res, StepResult) and res.converged
    assert res.force.sum(axis=0) == pytest.approx([0.0, 0.0, G], abs=1e-8)
    out = np.zeros(6)
    total = np.zeros(3)
    for i in range(data.ncon):
        mujoco.mj_contactForce(m, data, i, out)
        total += data.contact[i].frame.reshape(3, 3).T @ out[:3]
    assert total == pytest.approx([0.0, 0.0, G], abs=1e-8)


# ---- the paper's non-associated rules on the incline (the law path of the problem) ------------
def coaxial_law(mx=MU[0], my=MU[1]):
    """The ellipse (1.9) as limit, ``g = |T|``: the slip follows the force."""
    return fr.UserLaw(f"sqrt((T1/{mx!r})**2 + (T2/{my!r})**2) - N", "sqrt(T1**2 + T2**2)")


def coaxial_force(b, mx=MU[0], my=MU[1]):
    r"""Slip along the force: :math:`\hat F = \mu(\beta) e` with the ellipse's radius
    :math:`\mu(\beta) = (\cos^2\beta/\mu_x^2 + \sin^2\beta/\mu_y^2)^{-1/2}`."""
    c, s = np.cos(b), np.sin(b)
    return np.array([c, s]) / np.hypot(c / mx, s / my)


def transformed_force(b, mx=MU[0], my=MU[1]):
    r"""(1.18): the slip is along :math:`(T'_1/\mu_x, T'_2/\mu_y)`; for the slip
    :math:`e = (c, s)` the force on the ellipse is :math:`\hat F = (\mu_x c, \mu_y s)`."""
    return np.array([mx * np.cos(b), my * np.sin(b)])


def test_incline_coaxial_rule_slides_straight_down():
    r"""Slip along the force: the net force is along e only for e = s, so the box slides
    straight down the slope (45 deg from axis 1) at :math:`|v| = g t(\sin\theta -
    \mu(45^\circ)\cos\theta)` = 2.517 at 0.5 s (:math:`\mu(45^\circ) = 0.2744`)."""
    beta, speed = closed_form(coaxial_force)
    assert beta == pytest.approx(np.pi / 4, abs=1e-12)
    mu45 = 1 / np.sqrt(0.5 / MU[0] ** 2 + 0.5 / MU[1] ** 2)
    assert speed == pytest.approx(0.5 * G * (np.sin(THETA) - mu45 * np.cos(THETA)), rel=1e-12)
    assert speed == pytest.approx(2.517, abs=1e-3)
    v, z = slide(coaxial_law())
    assert direction(v) == pytest.approx(beta, abs=1e-7)
    assert np.linalg.norm(v[:2]) == pytest.approx(speed, rel=1e-7)
    assert abs(v[2]) < 1e-9 and z == pytest.approx(0.1, abs=1e-9)


def test_incline_transformed_variable_rule_eq_1_18():
    r"""TransformedCoulomb(0.2, 0.8): with :math:`\hat F = (\mu_x c, \mu_y s)` the condition
    :math:`(s - \hat F)\times e = 0` at :math:`\theta = 45^\circ` reads
    :math:`(\sin\beta - \cos\beta)/\sqrt2 = (\mu_x - \mu_y)\sin\beta\cos\beta`, whose root
    in (0, 90 deg) is found by bracketing; the slip lies between the associated rule's and
    the slope."""
    beta, speed = closed_form(transformed_force)
    residual = (np.sin(beta) - np.cos(beta)) / np.sqrt(2) - (MU[0] - MU[1]) * np.sin(beta) * np.cos(beta)
    assert abs(residual) < 1e-14
    beta_assoc, _ = closed_form(elliptic_force)
    assert beta_assoc < beta < np.pi / 4
    assert np.degrees(beta) == pytest.approx(29.955, abs=1e-3) and speed == pytest.approx(2.1370, abs=1e-4)
    v, z = slide(fr.TransformedCoulomb(*MU))
    assert direction(v) == pytest.approx(beta, abs=1e-7)
    assert np.linalg.norm(v[:2]) == pytest.approx(speed, rel=1e-7)
    assert abs(v[2]) < 1e-9 and z == pytest.approx(0.1, abs=1e-9)


@pytest.mark.parametrize("yaw", [0.4])
def test_incline_transformed_rule_turns_with_the_body(yaw):
    beta, speed = closed_form(transformed_force)
    v, _ = slide(fr.TransformedCoulomb(*MU), axes={"box": (1.0, 0.0, 0.0)}, yaw=yaw, slope=np.pi / 4 + yaw)
    assert np.cos(direction(v) - beta - yaw) == pytest.approx(1.0, abs=1e-12)
    assert np.linalg.norm(v[:2]) == pytest.approx(speed, rel=1e-7)


# ---- MuJoCo's layouts and integrators give the same step ---------------------------------------
@pytest.mark.parametrize("option", ['jacobian="sparse"', 'integrator="implicitfast"', 'integrator="implicit"',
                                    'cone="elliptic"'])
def test_sparse_jacobian_implicit_integrators_and_cones_step_alike(option):
    """The stack with a turned top box and axes on it, 20 steps: MuJoCo's sparse layout of
    efc_J (the rows turned by sparse products), the implicit integrators (no damping
    here: the same update as Euler) and the elliptic cone give the default run's state."""
    def run(extra):
        xml = stack_xml(3).replace("<option ", f"<option {extra} ")
        m = mujoco.MjModel.from_xml_string(xml)
        sim = Simulator(m, {}, axes={"b2": (1.0, 1.0, 0.0)}, default=fr.EllipticOrthotropic(0.3, 0.6), tol=1e-12)
        mujoco.mj_forward(m, sim.data)
        sim.data.qvel[12:14] = 0.5, -0.2                  # the top box launched
        sim.step(20)
        return sim.data.qpos.copy(), sim.data.qvel.copy()
    q0, v0 = run("")
    q1, v1 = run(option)
    assert np.abs(v1 - v0).max() < 1e-9 and np.abs(q1 - q0).max() < 1e-11
    assert np.hypot(q0[14], q0[15]) > 0.01                 # the top box slid (from x = y = 0)


@pytest.mark.parametrize("jacobian", ["dense", "sparse"])
def test_W_from_efc_J_is_J_Minv_JT_and_q_is_the_free_velocity(jacobian):
    """Stage 2 against an independent product: ``J`` from ``mj_jac`` at each contact point in
    its frame (geom 2 minus geom 1), ``M^-1 J^T`` from ``mj_solveM``; ``W`` equals ``J M^-1 J^T``
    and ``q`` equals ``J (qvel + h qacc_smooth)`` plus the gap term."""
    import scipy.sparse as sp

    from frictionrules.mujoco import _assemble, _scene, _step
    m = mujoco.MjModel.from_xml_string(stack_xml(3).replace("<option ", f'<option jacobian="{jacobian}" '))
    data = mujoco.MjData(m)
    data.qvel[:] = np.random.default_rng(1).normal(scale=0.1, size=m.nv)
    _step._forward(mujoco, m, data)
    A = _assemble.assemble(sp, mujoco, m, data, _scene.Scene(mujoco, m, {}, default=0.5), 0.2)
    rows = []
    for i in range(data.ncon):
        c = data.contact[i]
        jac = []
        for g in (c.geom1, c.geom2):
            jp = np.zeros((3, m.nv))
            mujoco.mj_jac(m, data, jp, None, c.pos, m.geom_bodyid[g])
            jac.append(jp)
        rows.append(c.frame.reshape(3, 3) @ (jac[1] - jac[0]))
    J = np.vstack(rows)
    X = np.zeros_like(J)
    mujoco.mj_solveM(m, data, X, J.copy())
    W = A.blocks.delassus().toarray()
    assert np.abs(W - J @ X.T).max() < 1e-13 * np.abs(W).max()
    D = np.array([W[3 * a:3 * a + 3, 3 * a:3 * a + 3] for a in range(data.ncon)])
    assert np.abs(A.blocks.D - D).max() < 1e-13 * np.abs(W).max()
    gap = np.repeat(A.gap, 3) * np.tile([1.0, 0.0, 0.0], data.ncon)
    gap = np.where(gap > 0, gap, 0.2 * gap) / m.opt.timestep
    assert A.q == pytest.approx(J @ (data.qvel + m.opt.timestep * data.qacc_smooth) + gap, abs=1e-13)


def test_a_step_without_contacts_is_mujocos_free_step():
    """No contact (the box 1 m up): the step is MuJoCo's own free fall, v = -g h."""
    m = mujoco.MjModel.from_xml_string(box_on_floor_xml(0.5, 0.005).replace('pos="0 0 0.1"', 'pos="0 0 1"'))
    data, ref = mujoco.MjData(m), mujoco.MjData(m)
    res = step(m, data, {"floor": 0.5})
    mujoco.mj_step(m, ref)
    assert res.nc == 0 and res.converged and res.solution is None
    assert data.qvel == pytest.approx(ref.qvel, abs=1e-15) and data.qvel[2] == pytest.approx(-G * 0.005)


def articulated_xml():
    """A two-link arm (hinge, then a ball joint) whose tip box touches the floor, a free box
    beside it and a slider: kinematic trees of 4, 6 and 1 dofs (W's blocks from trees larger
    than a free body's and from a tree touched by two contacts of different bodies)."""
    return """
<mujoco><option timestep="0.002" jacobian="sparse"/><size memory="8M"/>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 .1" margin="0.002"/>
    <body pos="0 0 0.5"><joint type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 -0.2" size="0.03" mass="1"/>
      <body pos="0.3 0 -0.2"><joint type="ball"/>
        <geom name="tip" type="box" pos="0 0 -0.2" size="0.1 0.1 0.1" mass="1" margin="0.002"/>
      </body>
    </body>
    <body pos="0.5 0 0.1"><freejoint/><geom type="box" size="0.1 0.1 0.1" mass="1" margin="0.002"/></body>
    <body pos="-0.6 0 0.1"><joint type="slide" axis="1 0 0"/>
      <geom type="box" size="0.1 0.1 0.1" mass="1" margin="0.002"/></body>
  </worldbody>
</mujoco>"""


def test_W_tree_by_tree_equals_the_dense_J_Minv_JT_of_an_articulated_model():
    """:math:`W = J M^{-1} J^T` from the blocks per contact and tree (the blocks of
    :math:`M^{-1}` of each kinematic tree from one ``mj_solveM``) against the dense product of
    all of ``efc_J`` with ``mj_solveM`` of every row, on trees of 4 (hinge + ball), 6 (free) and
    1 (slide) dofs, for all the contacts and for a subset; ``M^-1 J^T r`` and ``J v + q`` of
    the blocks against the dense products."""
    import scipy.sparse as sp

    from frictionrules.mujoco import _assemble, _kernels, _scene, _step
    from frictionrules.multicontact.factored import TreeBlocks
    m = mujoco.MjModel.from_xml_string(articulated_xml())
    data = mujoco.MjData(m)
    data.qpos[0] = 0.3                      # lower the arm onto the floor
    mujoco.mj_forward(m, data)
    for _ in range(200):                    # let it settle so that several bodies touch
        mujoco.mj_step(m, data)
    _step._forward(mujoco, m, data)
    assert data.nefc >= 9 and m.ntree == 3
    J = np.zeros((data.nefc, m.nv))
    mujoco.mju_sparse2dense(J, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind)
    X = np.zeros_like(J)
    mujoco.mj_solveM(m, data, X, J.copy())
    dense = J @ X.T
    trees = _scene.Scene(mujoco, m, {}, default=0.5).trees
    mujoco.mj_solveM(m, data, trees.X, trees.rhs)
    rowadr, rownnz, colind, values = _assemble._jacobian_csr(sp, mujoco, m, data)
    addr = np.arange(0, data.nefc, 3)
    rng = np.random.default_rng(2)
    for some in (addr, addr[1:]):
        nc = some.size
        tree, off, Jp, Bp, D, q = _kernels.contact_blocks(
            some, rowadr, rownnz, colind, values, trees.dof_tree, trees.dofadr, trees.dofnum, trees.X,
            np.zeros((1, 2, 2)), np.zeros(nc, dtype=bool), np.zeros(m.nv), np.zeros(nc))
        blocks = TreeBlocks(tree, off, Jp, Bp, trees.dofadr, trees.dofnum, D, m.nv)
        rows = (some[:, None] + np.arange(3)).ravel()
        W = blocks.delassus().toarray()
        assert np.abs(W - dense[np.ix_(rows, rows)]).max() <= 1e-13 * np.abs(dense).max()
        r, v = rng.normal(size=3 * nc), rng.normal(size=m.nv)
        assert np.abs(blocks.impulse_velocity(r) - X[rows].T @ r).max() <= 1e-13 * np.abs(X).max() * np.abs(r).sum()
        assert blocks.velocity(v, q) == pytest.approx(J[rows] @ v + q, abs=1e-13 * np.abs(J).max() * np.abs(v).sum())


def test_warm_start_takes_the_nearest_previous_contact_of_the_pair_in_its_own_frame():
    """Two previous contacts of the pair (0, 1) at x = 0 and x = 1 and one of (0, 2); a new
    contact of (0, 1) at x = 0.9 takes the force of the one at x = 1, turned into its frame
    (rows n, t1, t2) and times h; a new contact farther than ``distance`` from all of its
    pair's gets nothing, and a tensile normal is cut to 0."""
    from frictionrules.mujoco import _kernels
    pos_old = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.9, 0, 0]])
    force_old = np.array([[1.0, 0, 0], [2.0, 3.0, 0], [5.0, 0, 0]])
    key_old = np.array([1, 1, 2])
    rot = np.array([[0.0, 1, 0], [0, 0, 1], [1, 0, 0]])        # n = world y, t1 = z, t2 = x
    frames = np.stack([rot, np.eye(3), -np.eye(3)])
    pos_new = np.array([[0.9, 0, 0], [5.0, 0, 0], [0.05, 0, 0]])
    r0 = np.full((3, 3), np.nan)
    count = _kernels.warm_start(np.array([1, 1, 1]), pos_new, frames, key_old, pos_old, force_old, 0.5, 0.2, r0)
    assert count == 2
    assert r0[0] == pytest.approx(0.5 * rot @ force_old[1])
    assert r0[1] == pytest.approx([0.0, 0.0, 0.0])
    assert r0[2] == pytest.approx([0.0, 0.0, 0.0])        # -h (1, 0, 0): tensile normal cut to 0
