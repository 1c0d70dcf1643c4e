r"""The files of a triaxial test in LAMMPS: the data file and the input script
(``docs/assembly.md``, "LAMMPS").

**Data file** (``atom_style sphere``, ``units lj``: any consistent units): the periodic box
``[0, Lx] × [0, Ly] × [0, Lz]`` of the assembly's (rectangular) cell, one atom type, each grain
its diameter, the density and its centre wrapped into the box.

**Input script**, the stages of our engine (:mod:`.._dem._protocol`) in LAMMPS's commands:

* ``fix nve/sphere`` (velocity Verlet for positions and spins), ``fix damping/cundall λ λ``:
  each component of a grain's force (moment) times ``1 - λ sgn(F v)`` (``F·ω``), with ``v``
  the half-step velocity LAMMPS holds after the force pass; ours takes the sign of ``F`` times
  the velocity extrapolated to the force's time, ``v_{n-1/2} + a dt/2``
  (:func:`.._dem._passes._damped_step`): the same rule half a step apart;
* the time step of our engine, ``dt = SAFETY √(m_min/k_max)``;
* the consolidation: ``fix deform/pressure`` on x, y and z at the target (virial) stress, the
  box's strain rate ``k (σ - p)/p`` bounded by ``CONSOLIDATION_RATE ε̇``, under damped dynamics
  until every normal stress is within ``STRESS_TOL`` of the pressure and the unbalanced-force
  ratio below ``UNBALANCED_TOL`` (``fix halt``); "frictionless" settles first at ``preload``
  times the pressure with the friction coefficient 0 (the option of ``triaxial``; none where
  it is 1), then at the pressure, and the laws come in with virgin tangential histories (our
  engine relaxes these stages by FIRE);
* the shear: ``fix deform/pressure`` with x and y (plane strain: x only) at the pressure and z
  at the true strain rate ``-ε̇`` (``trate``), ``ε̇ = I √(p/ρ)/d``; the gain ``k`` is that of
  our servo, ``p/(S dt)`` with ``S`` the affine stiffness of an isotropic packing
  (:func:`servo_gain`), the rate bounded by ``SERVO_RATE ε̇``;
* a record every ``record_every`` of axial strain (``fix print``): the box, the virial stress
  (``compute pressure NULL virial``: no kinetic part, compression positive as ours), the
  coordination: the force-carrying contacts (N > 0) the exported pair style counts per atom
  (``fix property/atom i_fr_carrying``), as ours, open contacts of the skin pushing after a
  plastic opening included; with LAMMPS's own styles the overlapping pairs (``compute
  contact/atom``, the same for them: an open contact carries no force); the unbalanced-force
  ratio (the forces before the
  damping, ``fix store/force``), the kinetic energy; with a pair style that offers them
  (``compute pair/local p3 p4``), the sliding fraction and the laws' dissipation.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import FrictionRulesError
from .._consolidation import PRELOAD

__all__ = ["data_file", "input_script", "resume_script", "steps_of", "servo_gain",
           "time_step_of", "RECORD_COLUMNS", "RECORDS", "POSITIONS", "HALT_EVERY", "STAGES",
           "RESTART_PREFIX", "SHEAR0", "check_cell_rectangular"]

#: The records file's name and columns (one line per record).
RECORDS = "records.txt"
RECORD_COLUMNS = ("step", "time", "lx", "ly", "lz", "pxx", "pyy", "pzz", "pxy", "pxz", "pyz",
                  "contacts2", "n0", "n1", "sliding", "dissipation", "unbalanced", "kinetic")
#: The stages' ends, one line each.
STAGES = "stages.txt"
#: The line's words in ``STAGES`` that say the shear ran to its end.
SHEAR_DONE = "shear done"
#: The dump of the grains' unwrapped centres at the records.
POSITIONS = "positions.dump"
#: The restart files of the shear's segments (``shear.<step>.restart``).
RESTART_PREFIX = "shear."
#: The shear's start values (time, dissipation) as LAMMPS commands, for a resumed run.
SHEAR0 = "shear0.lmp"
#: Steps between two looks at the consolidation's end condition.
HALT_EVERY = 100
#: The isotropic packing whose affine stiffness sets the servo's gain: coordination, solid
#: fraction.
_Z, _PHI = 6.0, 0.64


def time_step_of(radii: np.ndarray, density: float, k_max: float) -> float:
    """Our engine's time step ``SAFETY √(m_min/k_max)``, ``m = ρ (4/3) π r³``."""
    from .._dem._engine import SAFETY
    m_min = density * 4.0 / 3.0 * math.pi * float(np.min(radii)) ** 3
    return SAFETY * math.sqrt(m_min / k_max)


def servo_gain(pressure: float, kn: float, kt: float, radius: float, dt: float) -> float:
    r"""The gain ``k`` (1/time) of ``fix deform/pressure ... normalize/pressure yes``:
    ``p/(S dt)``, our servo's rate ``(σ - p)/(S dt)`` (:mod:`.._dem._engine`) with ``S`` the
    affine stiffness of a normal component of an isotropic packing of coordination ``Z`` and
    solid fraction ``φ``, ``S = (Z/2)(kn/5 + 2 kt/15) 3φ/(π r̄)`` (``⟨n_x⁴⟩ = 1/5``,
    ``⟨n_x²(1 - n_x²)⟩ = 2/15``, branch ``2 r̄``)."""
    stiffness = 0.5 * _Z * (kn / 5.0 + 2.0 * kt / 15.0) * 3.0 * _PHI / (math.pi * radius)
    return pressure / (stiffness * dt)


def data_file(path, positions: np.ndarray, radii: np.ndarray, cell: np.ndarray,
              density: float) -> None:
    """The LAMMPS data file (``atom_style sphere``) of the grains in the rectangular ``cell``."""
    lengths = np.diag(cell).astype(float)
    x = np.mod(positions, lengths)
    x = np.where(x >= lengths, 0.0, x)  # mod can round up to the length itself
    lines = ["frictionrules assembly (atom_style sphere: id type diameter density x y z)", "",
             f"{len(radii)} atoms", "1 atom types", ""]
    for name, length in zip("xyz", lengths):
        lines.append(f"0 {float(length)!r} {name}lo {name}hi")
    lines += ["", "Atoms # sphere", ""]
    lines += [f"{k + 1} 1 {float(2 * r)!r} {float(density)!r} {float(p[0])!r} {float(p[1])!r} "
              f"{float(p[2])!r}" for k, (r, p) in enumerate(zip(radii, x))]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def _settle(pressure: float, gain: float, max_rate: float, unbalanced_tol: float,
            label: str) -> list[str]:
    """A consolidation stage: the three normal stresses driven to ``pressure`` until they hold
    with the forces balanced (``fix halt``)."""
    from .._dem._protocol import CONSOLIDATION_STEPS, STRESS_TOL
    p = repr(float(pressure))
    return [
        f"# {label}",
        f"fix servo all deform/pressure 1 x pressure {p} {gain!r} y pressure {p} {gain!r} "
        f"z pressure {p} {gain!r} normalize/pressure yes max/rate {max_rate!r} remap x",
        "fix_modify servo press stress",
        f"variable settled equal (abs(c_stress[1]/{p}-1)<{STRESS_TOL!r})*"
        f"(abs(c_stress[2]/{p}-1)<{STRESS_TOL!r})*(abs(c_stress[3]/{p}-1)<{STRESS_TOL!r})*"
        f"(v_unbalanced<{unbalanced_tol!r})",
        f"fix halt all halt {HALT_EVERY} v_settled == 1 error continue",
        "variable start equal $(step)",
        f"run {CONSOLIDATION_STEPS}",
        f'if "$(step-v_start) >= {CONSOLIDATION_STEPS}" then &',
        f'  "print \'stage {label} did not settle within {CONSOLIDATION_STEPS} steps\' '
        f'append {STAGES} screen no" "quit 3"',
        "unfix halt",
        "unfix servo",
        f'print "stage {label} settled at step $(step)" append {STAGES} screen no',
    ]


def _settings(*, law_active: bool, law_outputs: bool, normal: str, skin: float, damping: float,
              record_steps: int) -> list[str]:
    """The fixes, computes and variables of every stage (the integrator, the damping, the
    records' quantities); ``law_active``: the laws' pair style runs (not the frictionless
    stage's)."""
    return [
        f"neighbor {skin!r} bin",
        "neigh_modify delay 0 every 1 check yes",
        "fix store all store/force",
        f"fix damping all damping/cundall {float(damping)!r} {float(damping)!r}",
        "fix integrate all nve/sphere",
        "compute stress all pressure NULL virial",
        "compute contacts all contact/atom",
        *(["fix carrying all property/atom i_fr_carrying"] if law_outputs else []),
        f"variable contacts atom {'i_fr_carrying' if law_outputs and law_active else 'c_contacts'}",
        "variable none atom v_contacts==0",
        "variable one atom v_contacts==1",
        "compute counts all reduce sum v_contacts v_none v_one",
        f"compute normal all pair/local {normal}",
        "compute forces all reduce sum c_normal inputs local",
        "variable force atom sqrt(f_store[1]^2+f_store[2]^2+f_store[3]^2)",
        "compute grainforce all reduce ave v_force",
        "compute spin all erotate/sphere",
        "compute motion all ke",
        "variable closed equal c_counts[1]/2",
        "variable unbalanced equal c_grainforce*v_closed/(c_forces+(c_forces<=0)*1e-300)",
        "thermo_style custom step time lx ly lz c_stress[1] c_stress[2] c_stress[3] v_unbalanced",
        f"thermo {10 * record_steps}",
        "thermo_modify norm no flush yes",
    ]


def _law_outputs(law_outputs: bool) -> list[str]:
    if law_outputs:
        return ["compute law all pair/local p3 p4",
                "compute laws all reduce sum c_law[1] c_law[2] inputs local",
                "variable sliding equal c_laws[1]/(v_closed+(v_closed<=0))",
                "variable dissipation equal c_laws[2]-v_dissipation0"]
    return ["variable sliding equal NULL", "variable dissipation equal NULL"]


def _shear(*, law_outputs, kind, p, gain, rate, record_steps, total, restart_steps,
           positions_every_record, append) -> list[str]:
    """The shear's fixes, dumps and runs (in segments of ``restart_steps`` with a restart file
    after each, or one run)."""
    from .._dem._protocol import SERVO_RATE
    servo = f"x pressure {p} {gain!r}" + ("" if kind == "plane_strain" else f" y pressure {p} {gain!r}")
    fields = " ".join(["$(step)", "$(time-v_time0:%.17g)", "$(lx:%.17g)", "$(ly:%.17g)",
                       "$(lz:%.17g)"] + [f"$(c_stress[{k}]:%.17g)" for k in range(1, 7)]
                      + ["$(c_counts[1]:%.17g)", "$(c_counts[2]:%.17g)", "$(c_counts[3]:%.17g)",
                         "$(v_sliding:%.17g)" if law_outputs else "nan",
                         "$(v_dissipation:%.17g)" if law_outputs else "nan",
                         "$(v_unbalanced:%.17g)", "$(c_motion+c_spin:%.17g)"])
    lines = [
        f"fix servo all deform/pressure 1 {servo} z trate {-float(rate)!r} "
        f"normalize/pressure yes max/rate {SERVO_RATE * rate!r} remap x",
        "fix_modify servo press stress",
        # fix print writes the record at a run's first step (0) and every record_steps
        f'fix records all print {record_steps} "{fields}" append {RECORDS} screen no title "#"',
        f"dump positions all custom {record_steps if positions_every_record else total} "
        f"{POSITIONS} id xu yu zu",
        "dump_modify positions sort id format float %.17g" + (" append yes" if append else ""),
    ]
    if restart_steps is None:
        lines.append(f"run {total}")
    else:    # segments: a run that starts again repeats a record and a dump (the reader
        # keeps the first of each step); the last one ends at the shear's last step
        lines += ["label segment", f"run $(({total}-step>{restart_steps})*{restart_steps}+({total}-step<={restart_steps})"
                  f"*({total}-step):%.0f)",
                  f"write_restart {RESTART_PREFIX}*.restart",
                  f'if "$(step) < {total}" then "jump SELF segment"']
    lines.append(f'print "stage {SHEAR_DONE} at step $(step)" append {STAGES} screen no')
    return lines


def input_script(*, pair_frictionless: list[str], pair_law: list[str], law_outputs: bool,
                 normal_law: str,
                 kind: str, pressure: float, rate: float, axial_strain: float, record_every: float,
                 damping: float, dt: float, gain: float, skin: float, frictionless: bool,
                 positions_every_record: bool, restart_steps: int | None = None,
                 preload: float = PRELOAD) -> str:
    """The input script (module docstring). ``pair_*``: the pair lines of the frictionless
    stage and of the laws; ``law_outputs``: the pair style offers ``compute pair/local p3 p4``
    (sliding flag, dissipation); ``normal_law``: its ``compute pair/local`` value of the normal
    force ("force" for LAMMPS's own styles); ``restart_steps``: the shear runs in segments of
    that many steps, each followed by a restart file (:func:`resume_script`); ``preload``: the
    frictionless consolidation's (1: none)."""
    from .._dem._protocol import CONSOLIDATION_RATE, UNBALANCED_TOL
    record_steps, total = steps_of(rate, dt, record_every, axial_strain)
    p = repr(float(pressure))
    lines = [
        "# frictionrules: a triaxial test (docs/assembly.md, \"LAMMPS\")",
        "units lj",
        "atom_style sphere",
        "boundary p p p",
        "newton on",
        "comm_modify vel yes",
        "read_data grains.data",
        "atom_modify sort 0 0.0",    # the atoms in one order: a restart repeats the run exactly
        f"timestep {dt!r}",
        *(pair_frictionless if frictionless else pair_law),
        *_settings(law_active=not frictionless, law_outputs=law_outputs,
                   normal="force" if frictionless else normal_law, skin=skin, damping=damping,
                   record_steps=record_steps),
    ]
    if frictionless:
        if preload > 1.0:
            lines += _settle(preload * pressure, gain, CONSOLIDATION_RATE * rate,
                             preload * UNBALANCED_TOL, "consolidation (frictionless, preload)")
        lines += _settle(pressure, gain, CONSOLIDATION_RATE * rate, UNBALANCED_TOL,
                         "consolidation (frictionless)")
        lines += ["# the laws take over: virgin tangential histories", *pair_law,
                  "uncompute normal", f"compute normal all pair/local {normal_law}"]
        if law_outputs:    # the exported style counts force-carrying contacts per atom
            lines.append("variable contacts atom i_fr_carrying")
    else:
        lines += _settle(pressure, gain, CONSOLIDATION_RATE * rate, UNBALANCED_TOL,
                         "consolidation")
    lines += _law_outputs(law_outputs)
    lines += [
        "# the shear: lateral stresses held, axial true strain rate -rate",
        "reset_timestep 0",
        "run 0",
        "variable time0 equal $(time:%.17g)",
        f'print "variable time0 equal $(time:%.17g)" file {SHEAR0} screen no',
    ]
    if law_outputs:
        lines += ["variable dissipation0 equal $(c_laws[2]:%.17g)",
                  f'print "variable dissipation0 equal $(c_laws[2]:%.17g)" append {SHEAR0} '
                  "screen no"]
    lines.append(f'print "# {" ".join(RECORD_COLUMNS)}" file {RECORDS} screen no')
    lines += _shear(law_outputs=law_outputs, kind=kind, p=p, gain=gain, rate=rate,
                    record_steps=record_steps, total=total, restart_steps=restart_steps,
                    positions_every_record=positions_every_record, append=False)
    return "\n".join(lines) + "\n"


def resume_script(*, plugin: str | None, law_outputs: bool, normal_law: str, kind: str,
                  pressure: float, rate: float, axial_strain: float, record_every: float,
                  damping: float, dt: float, gain: float, skin: float,
                  positions_every_record: bool, restart_steps: int) -> str:
    """The script that goes on with the shear from one of its restart files (``lmp -in
    in.resume -var restart FILE``): the plugin loaded, ``read_restart`` (the box, the grains,
    the pair style with its coefficients and every contact's history, the servo's state), the
    same settings and the remaining segments; the records and centres appended. Run from a
    restart file of the same folder it repeats the run that wrote it, bit for bit on one rank
    (``docs/assembly.md``, "LAMMPS")."""
    record_steps, total = steps_of(rate, dt, record_every, axial_strain)
    lines = ["# frictionrules: the triaxial test resumed from a restart file of its shear",
             *([plugin] if plugin else []),
             "read_restart ${restart}",
             "comm_modify vel yes",
             *_settings(law_active=True, law_outputs=law_outputs, normal=normal_law, skin=skin,
                        damping=damping, record_steps=record_steps),
             f"include {SHEAR0}",
             *_law_outputs(law_outputs)]
    lines += _shear(law_outputs=law_outputs, kind=kind, p=repr(float(pressure)), gain=gain,
                    rate=rate, record_steps=record_steps, total=total,
                    restart_steps=restart_steps, positions_every_record=positions_every_record,
                    append=True)
    return "\n".join(lines) + "\n"


def steps_of(rate: float, dt: float, record_every: float, axial_strain: float) -> tuple[int, int]:
    """Steps between two records and steps of the shear (a whole number of records)."""
    record_steps = max(1, int(round(record_every / rate / dt)))
    total = int(math.ceil(axial_strain / rate / dt - 1e-9))
    return record_steps, -(-total // record_steps) * record_steps


def check_cell_rectangular(cell: np.ndarray) -> None:
    """LAMMPS's orthogonal box: the assembly's cell must be diagonal."""
    off = cell - np.diag(np.diag(cell))
    if np.any(off != 0.0):
        raise FrictionRulesError(f"assembly.cell = {cell.tolist()!r} violates: a diagonal "
                                 "(rectangular) cell for engine = 'lammps'")
