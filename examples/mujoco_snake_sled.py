"""A vibration-driven sled on a sawtooth surface: friction that differs forwards and backwards.

A MuJoCo sled (a 1 kg plate on three spherical feet) carries a 0.5 kg mass on a slide joint along its own x axis, driven
by a motor with the periodic force ``A sin(2 pi f t)`` (a spring centres it). Only internal
forces act: the sled moves when the floor's friction lets it slide one way more easily than
the other, as snake scales or the bristles of a vibration robot do. The sled is turned by 30
deg from the sawtooth's x axis.

Three runs of the same MuJoCo scene (same model, collision, integration):

* ``sawtooth``: :func:`frictionrules.mujoco.step` with the paper's wedge asperity (§2, (2.1)-
  (2.8)): :class:`~frictionrules.WedgeAsperity` ``(alpha = 10 deg, mu = 0.5)``, a block on the
  flanks of a sawtooth whose slope rises towards +x (``axes={"floor": (1, 0, 0)}``): pushing
  towards -x needs ``tan(rho - alpha) = 0.30`` of the load, towards +x ``tan(rho + alpha) =
  0.74``; its slip is the paper's non-associated rule (2.3), the block rising or sinking along
  the flank (the normal slip at the one step MuJoCo's flat floor allows, see docs/mujoco.md);
* ``elliptic (frictionrules)``: the symmetric elliptic law with the sawtooth's mean
  coefficient along x (0.52) and 0.49 across, also through ``frictionrules.mujoco``;
* ``elliptic (MuJoCo)``: MuJoCo's own solver with the same coefficients as a ``<pair>``
  with an elliptic cone (its anisotropy fixed to MuJoCo's contact frame of plane-box
  contacts, world y then -x: it cannot be turned with a surface, and it is the same
  forwards and backwards).

The sawtooth ratchets the sled towards -x; the two symmetric laws only rock it.

Run: ``python examples/mujoco_snake_sled.py`` (prints the displacements and saves the figure
of the trajectories in the current folder).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

ALPHA, MU = np.deg2rad(10.0), 0.5
MU_X = 0.5 * (np.tan(np.arctan(MU) - ALPHA) + np.tan(np.arctan(MU) + ALPHA))   # 0.52
MU_Y = MU * np.cos(ALPHA)                                                         # 0.49
FORCE, FREQ, H = 9.0, 2.0, 0.004


def scene_xml(mujoco_pair: bool = False, yaw_deg: float = 30.0) -> str:
    """The sled scene; ``mujoco_pair`` adds MuJoCo's own anisotropic elliptic friction."""
    pair = ("<contact>" + "".join(f'<pair geom1="floor" geom2="foot{i}" condim="3" '
                                  f'friction="{MU_Y:.6f} {MU_X:.6f} 0.005 0.0001 0.0001"/>' for i in (1, 2, 3))
            + "</contact>" if mujoco_pair else "")
    return f"""
<mujoco>
  <option timestep="{H}" cone="elliptic"/>
  <worldbody>
    <geom name="floor" type="plane" size="20 20 .1" margin="0.002"/>
    <body name="sled" pos="0 0 0.02" euler="0 0 {yaw_deg}">
      <freejoint/>
      <geom name="sled" type="box" size=".15 .1 .01" pos="0 0 0.01" mass="1" contype="0" conaffinity="0"/>
      <geom name="foot1" type="sphere" size=".02" pos=".12 0 0" mass="0.01" margin="0.002"/>
      <geom name="foot2" type="sphere" size=".02" pos="-.12 .08 0" mass="0.01" margin="0.002"/>
      <geom name="foot3" type="sphere" size=".02" pos="-.12 -.08 0" mass="0.01" margin="0.002"/>
      <body name="mover" pos="0 0 0.05">
        <joint name="slide" type="slide" axis="1 0 0" stiffness="200" damping="2"/>
        <geom name="mover" type="sphere" size="0.03" mass="0.5" contype="0" conaffinity="0"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor name="drive" joint="slide" gear="1"/></actuator>
  {pair}
</mujoco>"""


def drive(t: float) -> float:
    return FORCE * np.sin(2 * np.pi * FREQ * t)


def run(kind: str, seconds: float = 3.0) -> np.ndarray:
    """The sled's (t, x, y) every step for ``kind`` in ``"sawtooth"``,
    ``"elliptic (frictionrules)"``, ``"elliptic (MuJoCo)"``."""
    import mujoco

    import frictionrules as fr
    from frictionrules.mujoco import Simulator
    model = mujoco.MjModel.from_xml_string(scene_xml(mujoco_pair=kind == "elliptic (MuJoCo)"))
    data = mujoco.MjData(model)
    axes = {"floor": (1.0, 0.0, 0.0)}
    # the step's tol (1e-10): every solve reaches it. Three feet make W singular, and where
    # they are pressed in by different depths the gap term asks for normal velocities that no
    # rigid motion gives exactly (no stick solution); where its sweeps stall the step drops
    # that part, 1e-9 m/s here (docs/mujoco.md, "Bodies on several contacts")
    if kind == "sawtooth":
        sim = Simulator(model, {"floor": fr.WedgeAsperity(alpha=ALPHA, mu=MU)}, axes=axes, data=data)
    elif kind == "elliptic (frictionrules)":
        sim = Simulator(model, {"floor": fr.EllipticOrthotropic(MU_X, MU_Y)}, axes=axes, data=data)
    else:
        sim = None
    out, iterations = [], 0
    for _ in range(int(round(seconds / H))):
        data.ctrl[0] = drive(data.time)
        if sim is None:
            mujoco.mj_step(model, data)
        else:
            sol = sim.step().solution
            iterations += 0 if sol is None else sol.iterations
        out.append((data.time, *data.qpos[:2]))
    if sim is not None:
        print(f"{kind}: {sim.unconverged} of {sim.steps} solves stopped above tol (largest final "
              f"error {sim.max_error:.1e}), {iterations / sim.steps:.1f} iterations per step")
    return np.array(out)


KINDS = ("sawtooth", "elliptic (frictionrules)", "elliptic (MuJoCo)")


def visualize(paths: dict, ax=None):
    """The sled's path in the plane for each run; returns the Axes."""
    import matplotlib.pyplot as plt
    if ax is None:
        _, ax = plt.subplots(figsize=(6.0, 4.0))
    for (kind, p), style in zip(paths.items(), ("C3-", "C0-", "C2--")):
        ax.plot(p[:, 1], p[:, 2], style, lw=1.2, label=kind)
        ax.plot(p[-1, 1], p[-1, 2], style[:2] + "o", ms=4)
    ax.plot(0, 0, "ko", ms=4)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m): the sawtooth rises towards +x")
    ax.set_ylabel("y (m)")
    ax.set_title(f"sled turned 30°, internal drive {FORCE:g} N at {FREQ:g} Hz", fontsize=9)
    ax.legend(fontsize=8)
    return ax


def main(seconds: float = 3.0, out_dir=None) -> dict:
    """Run the three laws; print and return each final displacement (m); with ``out_dir``
    save the figure there."""
    paths = {kind: run(kind, seconds) for kind in KINDS}
    out = {}
    for kind, p in paths.items():
        out[kind] = (float(p[-1, 1]), float(p[-1, 2]))
        print(f"{kind:26s} after {p[-1, 0]:.2f} s: x = {p[-1, 1]:+.4f} m, y = {p[-1, 2]:+.4f} m")
    if out_dir is not None:
        import matplotlib.pyplot as plt
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(10.0, 4.0))
        visualize(paths, a1)
        for (kind, p), style in zip(paths.items(), ("C3-", "C0-", "C2--")):
            a2.plot(p[:, 0], p[:, 1], style, lw=1.2, label=kind)
        a2.set_xlabel("t (s)")
        a2.set_ylabel("x (m)")
        a2.set_title("x of the sled", fontsize=9)
        fig.tight_layout()
        path = Path(out_dir) / "mujoco_snake_sled.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        print(f"wrote {path}")
    return out


if __name__ == "__main__":
    main(out_dir=".")
