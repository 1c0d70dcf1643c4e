"""Shared by ``assembly_yade.py``: the protocol of the DEM comparison, the YADE side (samples
and runs, each in its own ``yade -j1`` subprocess, their raw outputs kept under
``benchmarks/results/assembly_yade/``) and the statistics both codes are compared on.

Sign conventions: stresses and strains compression positive; the axial strain is the
logarithmic (Hencky) strain of the cell since the end of the consolidation; the volumetric
strain is ``−ln det F`` (dilation negative).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import resource
import shutil
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
YADE_SCRIPT = HERE / "_yade_triaxial.py"
STORE = HERE / "results" / "assembly_yade"

PEAK_WINDOW = 0.0025     # ± axial strain of the running mean the peak angle is taken on
END_FRACTION = 0.8       # the end window: from 0.8 × the final axial strain (20 % of 25 %)

# (means over the samples, each run): allowed |ours − YADE|
TOLERANCES = {"peak": (1.5, 2.0), "end": (2.0, 3.0), "ev": (0.008, 0.012), "z": (0.15, 0.2)}


@dataclass(frozen=True)
class Protocol:
    """The settings both codes run with (lengths in units of the mean radius)."""

    n: int = 400
    radius: float = 1.0
    fuzz: float = 0.2                 # radii uniform in radius (1 ± fuzz)
    cloud_fraction: float = 0.3       # solid fraction of the loose cloud the samples start from
    kn: float = 1e4
    kt: float = 1e4
    pressure: float = 1.0
    inertial_number: float = 4e-4     # I = ε̇ d √(ρ/p)
    damping: float = 0.2
    density: float = 1.0
    axial_strain: float = 0.25
    record_every: float = 0.001
    stress_tol: float = 1e-3          # consolidation: |σii − p| ≤ stress_tol p ...
    unbalanced_tol: float = 1e-4      # ... and unbalanced-force ratio below this
    yade_dt_safety: float = 0.5       # YADE's time step: this × PWaveTimeStep()
    yade_consolidation_rate: float = 2e-3   # YADE: the cell's largest strain rate while consolidating
    yade_lateral_rate_cap: float = 10.0     # YADE: lateral strain rate ≤ this × the axial rate
    yade_cell_mass: float = 0.01      # YADE: the cell's inertia, a fraction of the grains' mass
    yade_cell_damping: float = 0.8    # YADE: PeriTriaxController.growDamping

    @property
    def strain_rate(self) -> float:
        """ε̇ = I √(p/ρ) / d, d = 2 × radius (the mean diameter)."""
        return self.inertial_number * math.sqrt(self.pressure / self.density) / (2 * self.radius)


# ---- records and statistics ----------------------------------------------------------------

@dataclass(frozen=True)
class Run:
    """One run of one code: its records and its cost."""

    axial_strain: np.ndarray        # (k,)
    volumetric_strain: np.ndarray   # (k,)
    stress: np.ndarray              # (k, 3, 3)
    coordination: np.ndarray        # (k,)
    wall: float                     # seconds, preparation + shear
    cpu: float                      # seconds of CPU, preparation + shear
    steps: int                      # time steps, preparation + shear
    dt: float
    info: dict                      # anything else worth a column (per code)


@dataclass(frozen=True)
class Stats:
    peak: float        # degrees: the largest ±PEAK_WINDOW running mean of the mobilized angle
    end: float         # degrees: the mobilized angle averaged over the end window
    ev: float          # volumetric strain at the final axial strain
    z: float           # coordination averaged over the end window
    reached: float     # the axial strain the run reached


def mobilized_angle(stress: np.ndarray) -> np.ndarray:
    """Degrees, ``asin((σ1 − σ3)/(σ1 + σ3))`` of the principal stresses of each (3, 3) row."""
    s = np.linalg.eigvalsh(0.5 * (stress + np.swapaxes(stress, -1, -2)))
    return np.degrees(np.arcsin((s[:, -1] - s[:, 0]) / (s[:, -1] + s[:, 0])))


def statistics(run: Run, final_strain: float) -> Stats:
    """The comparison's statistics of one run compressed to ``final_strain``.

    Peak: the largest running mean of the mobilized angle over the records within
    ``±PEAK_WINDOW`` of axial strain; end: its mean over ``[0.8, 1] × final_strain``; ``ε_v``
    interpolated at ``final_strain``; ``Z`` averaged over the end window. A run that stopped
    short gives NaN for what it did not reach.
    """
    e = np.asarray(run.axial_strain, dtype=float)
    phi = mobilized_angle(np.asarray(run.stress, dtype=float))
    inside = np.abs(e[:, None] - e[None, :]) <= PEAK_WINDOW + 1e-9
    running = (inside @ phi) / inside.sum(axis=1)
    reached = float(e[-1])
    end = (e >= END_FRACTION * final_strain - 1e-9) & (e <= final_strain + 1e-9)
    done = reached >= final_strain - 1e-6
    return Stats(peak=float(running.max()),
                 end=float(phi[end].mean()) if done else math.nan,
                 ev=float(np.interp(final_strain, e, run.volumetric_strain)) if done else math.nan,
                 z=float(np.mean(np.asarray(run.coordination)[end])) if done else math.nan,
                 reached=reached)


def within(diff: float, key: str, mean: bool) -> str:
    """``|diff|`` against the tolerance of ``key`` (the means' or each run's): '✓' or '✗'."""
    tol = TOLERANCES[key][0 if mean else 1]
    return "✓" if abs(diff) <= tol else ("–" if math.isnan(diff) else "✗")


# ---- YADE ------------------------------------------------------------------------------------

def have_yade() -> bool:
    return shutil.which("yade") is not None


def _key(data: dict) -> str:
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:10]


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _run_yade(job: dict, folder: Path) -> tuple[float, float]:
    """Run one YADE job (``yade -j1 -n -x``); its wall and CPU seconds (the whole process)."""
    yade = shutil.which("yade")
    if yade is None:
        raise SystemExit("YADE is needed for this (Debian: apt-get install yade)")
    folder.mkdir(parents=True, exist_ok=True)
    job_file = folder / f".job-{os.getpid()}.json"
    job_file.write_text(json.dumps(job))
    env = dict(os.environ, FR_YADE_JOB=str(job_file), OMP_NUM_THREADS="1")
    cpu0, t0 = _children_cpu(), time.perf_counter()
    done = subprocess.run([yade, "-j1", "-n", "-x", str(YADE_SCRIPT)], env=env, cwd=folder,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall, cpu = time.perf_counter() - t0, _children_cpu() - cpu0
    job_file.unlink()
    if done.returncode != 0 or not Path(job["out"]).exists():
        tail = "\n".join(done.stdout.splitlines()[-15:])
        raise RuntimeError(f"YADE failed (exit {done.returncode}) on {job['task']}:\n{tail}")
    return wall, cpu


def yade_sample(seed: int, protocol: Protocol) -> dict:
    """A loose periodic cloud by YADE's ``makeCloud`` with ``seed`` (kept and reused):
    ``{"positions", "radii", "cell", "path"}``, the cell's columns its vectors."""
    spec = {"task": "sample", "seed": seed, "n": protocol.n, "radius": protocol.radius,
            "fuzz": protocol.fuzz, "solid_fraction": protocol.cloud_fraction}
    path = STORE / "samples" / f"seed{seed}_{_key(spec)}.json"
    if not path.exists():
        _run_yade(dict(spec, out=str(path)), path.parent)
    data = json.loads(path.read_text())
    return {"positions": np.array(data["positions"]), "radii": np.array(data["radii"]),
            "cell": np.array(data["cell"]).T, "path": str(path), "seed": seed}


def scaled_sample(cloud: dict, protocol: Protocol) -> dict:
    """The cloud ``cloud`` (:func:`yade_sample`) compacted without friction to the pressure
    (our engine's frictionless compression, normal springs ``kn``, unbalanced-force ratio below
    ``unbalanced_tol``), then its positions and cell scaled up by the least factor that leaves
    no overlap (kept and reused): the same dictionary, its ``path`` the scaled sample's file.

    Both codes then consolidate from this dense, stress-free packing, so that neither one's
    compaction of the loose cloud decides the sample."""
    spec = {"task": "scaled", "cloud": Path(cloud["path"]).name, "kn": protocol.kn,
            "pressure": protocol.pressure, "unbalanced_tol": protocol.unbalanced_tol,
            "density": protocol.density}
    path = STORE / "samples" / f"seed{cloud['seed']}_scaled_{_key(spec)}.json"
    if not path.exists():
        from frictionrules.assembly._dem import frictionless_compression
        radii = cloud["radii"]
        x, cell = frictionless_compression(cloud["positions"], radii, cloud["cell"], protocol.kn,
                                           protocol.pressure, density=protocol.density,
                                           unbalanced_tol=protocol.unbalanced_tol)
        x, cell = _scale_to_contact(x, radii, cell)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps({"positions": x.tolist(), "radii": radii.tolist(),
                                   "cell": cell.T.tolist(), "seed": cloud["seed"],
                                   "generator": "makeCloud, frictionless compression, scaled",
                                   "spec": spec}))
        tmp.replace(path)
    data = json.loads(path.read_text())
    return {"positions": np.array(data["positions"]), "radii": np.array(data["radii"]),
            "cell": np.array(data["cell"]).T, "path": str(path), "seed": cloud["seed"]}


def _scale_to_contact(x, radii, cell):
    """``x``, ``cell`` times the least factor ``s`` that leaves no overlap: the largest
    ``(ri + rj)/|xi − xj|`` over pairs (minimum images of a rectangular cell), all pairs."""
    L = np.diag(cell)
    if not np.allclose(cell, np.diag(L)):
        raise ValueError("a rectangular cell is expected")
    d = x[:, None, :] - x[None, :, :]
    d -= L * np.round(d / L)
    dist = np.linalg.norm(d, axis=-1)
    np.fill_diagonal(dist, np.inf)
    s = float(np.max((radii[:, None] + radii[None, :]) / dist))
    s = max(s, 1.0) * (1 + 1e-12)
    return x * s, cell * s


def yade_job(sample: dict, mu: float, protocol: Protocol) -> dict:
    p = protocol
    return {"task": "triaxial", "sample": sample["path"], "mu": mu, "kn": p.kn, "kt": p.kt,
            "pressure": p.pressure, "inertial_number": p.inertial_number, "damping": p.damping,
            "density": p.density, "axial_strain": p.axial_strain, "record_every": p.record_every,
            "stress_tol": p.stress_tol, "unbalanced_tol": p.unbalanced_tol,
            "dt_safety": p.yade_dt_safety, "consolidation_rate": p.yade_consolidation_rate,
            "lateral_rate_cap": p.yade_lateral_rate_cap, "cell_mass": p.yade_cell_mass,
            "cell_damping": p.yade_cell_damping, "max_consolidation_steps": 5_000_000}


def yade_output_path(sample: dict, mu: float, protocol: Protocol) -> Path:
    job = yade_job(sample, mu, protocol)
    job["sample"] = Path(job["sample"]).name
    return STORE / "yade" / f"seed{sample['seed']}_mu{mu:g}_{_key(job)}.json"


def yade_triaxial(sample: dict, mu: float, protocol: Protocol, *, reuse: bool = True) -> tuple[Run, bool]:
    """YADE's run of the protocol on ``sample`` at friction ``mu``; True when it was reused
    from an earlier run's output (the same job) rather than run now."""
    path = yade_output_path(sample, mu, protocol)
    reused = reuse and path.exists()
    if not reused:
        wall, cpu = _run_yade(dict(yade_job(sample, mu, protocol), out=str(path)), path.parent)
        out = json.loads(path.read_text())
        out["process"] = {"wall": wall, "cpu": cpu, "loadavg": os.getloadavg()[0]}
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps(out))
        tmp.replace(path)
    out = json.loads(path.read_text())
    rec, cons, shear = out["records"], out["consolidation"], out["shear"]
    info = {"consolidation_steps": cons["steps"], "shear_steps": shear["steps"],
            "cpu_inside": cons["cpu"] + shear["cpu"], "wall_inside": cons["wall"] + shear["wall"],
            "solid_fraction": cons["solid_fraction"], "z0": cons["coordination"],
            "loadavg": out["process"]["loadavg"], "output": str(path)}
    run = Run(axial_strain=np.array(rec["axial_strain"]),
              volumetric_strain=np.array(rec["volumetric_strain"]),
              stress=np.array(rec["stress"]), coordination=np.array(rec["coordination"]),
              wall=out["process"]["wall"], cpu=out["process"]["cpu"],
              steps=cons["steps"] + shear["steps"], dt=out["dt"], info=info)
    return run, reused


def protocol_notes(protocol: Protocol) -> str:
    p = protocol
    return (f"Protocol: {p.n} spheres, radii {p.radius:g}(1 ± {p.fuzz:g}) (YADE's makeCloud, a "
            f"periodic cloud at solid fraction {p.cloud_fraction:g}, the same positions and radii "
            f"for both codes), kn = {p.kn:g}, kt = {p.kt:g}, density {p.density:g}; frictionless "
            f"isotropic compression to p = {p.pressure:g} until |σii − p| ≤ {p.stress_tol:g} p "
            f"and unbalanced-force ratio < {p.unbalanced_tol:g}; then axisymmetric compression "
            f"(σxx = σyy = p) at I = {p.inertial_number:g} (ε̇ = {p.strain_rate:.4g}), local "
            f"damping {p.damping:g}, to {100 * p.axial_strain:g} % axial (Hencky) strain, a "
            f"record every {100 * p.record_every:g} %. Peak: the largest ±{100 * PEAK_WINDOW:g} % "
            f"running mean of asin((σ1 − σ3)/(σ1 + σ3)); end angle and Z: means over "
            f"{100 * END_FRACTION * p.axial_strain:g}–{100 * p.axial_strain:g} %; ε_v at "
            f"{100 * p.axial_strain:g} % (compression positive). YADE: FrictMat per sphere "
            f"(young = kn/r, poisson = kt/kn: kn, ks exact for every pair), CundallStrack, "
            f"PeriTriaxController with cell inertia {p.yade_cell_mass:g} × the grains' mass and damping "
            f"{p.yade_cell_damping:g} (normal stresses only; the lateral stress held within ±0.3 %), NewtonIntegrator, "
            f"dt = {p.yade_dt_safety:g} × PWaveTimeStep, `yade -j1`.")

