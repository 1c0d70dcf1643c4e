"""Benchmark: random packings in axisymmetric compression to 25 % strain, the DEM engine beside
YADE on the same samples.

One command: ``python benchmarks/assembly_yade.py [--quick] [--seeds 1,2,3 | 1-12] [--mu 0.3,0.5]
[--laws coulomb,user,orthotropic,dilatant] [--preparation cloud|scaled] [--rerun-yade]
[--reuse-ours] [--threads 1] [--figure FILE] [--ensemble-figure FILE]``.

* Preparations: "cloud" (both codes consolidate the loose cloud) or "scaled" (the cloud
  compacted frictionless to p by our engine, scaled up to zero overlap, then consolidated by
  both codes).
* Ensembles (``results/assembly_yade_ensemble[_scaled].md``, rewritten after each sample):
  each code's mean with its 95 % interval (Student's t) and the mean of the paired differences
  (the same sample in both codes) with its interval, for the statistics below, ε_v at 2–20 %
  and Z at the start of the shear.
* Screening (one thing of ours changed at run time, the runs tagged with it):
  ``--ours-preload`` (``triaxial(..., preload=X)``), ``--ours-dt-safety``, ``--ours-servo-rate``; ``--strain`` below
  ``--yade-strain`` compares short runs of ours with YADE's kept ones at ``--strain``.

* Samples: 400 spheres, radii 1 ± 20 %, made by YADE's own generator (``makeCloud``, periodic,
  a loose cloud) with the given seeds; both codes start from the same positions and radii.
* Both codes: frictionless isotropic compression to p = 1 (until the stress holds and the
  unbalanced-force ratio is below 1e-4), then Coulomb μ at every contact, kn = kt = 1e4
  (kn/(p d) = 5e3), axisymmetric compression at σxx = σyy = p and the inertial number
  I = ε̇ d √(ρ/p) = 4e-4, local damping 0.2, ρ = 1, to 25 % axial strain, a record every 0.1 %.
  Ours: ``triaxial(..., method="dem")`` on ``NUMBA_NUM_THREADS`` threads (``--threads``, 1 by
  default); YADE: ``yade -j1`` (see ``_yade_triaxial.py``).
* Statistics (``_dem_compare.statistics``): the peak friction angle on a ±0.25 % running mean of
  asin((σ1 − σ3)/(σ1 + σ3)), the angle and the coordination Z averaged over 20–25 %, the
  volumetric strain at 25 %, per run and averaged over the samples, ours beside YADE, with the
  differences against the tolerances (means: 1.5°, 2°, 0.008, 0.15; each run: 2°, 3°, 0.012,
  0.2) → ``results/assembly_yade.md``.
* Cost: wall and CPU seconds per run (preparation + shear), steps and time step of both codes,
  and ours over YADE's (goal ≤ 0.5) → ``results/assembly_yade_times.md``.
* Laws: a ``UserLaw`` written for Coulomb (the same statistics as the built-in), an elliptic
  orthotropic law and a dilatant non-associated user law through the same protocol, with the
  energy balance of each run → ``results/assembly_yade_laws.md``.

YADE's raw outputs are kept under ``results/assembly_yade/`` and reused for the same job
(``--rerun-yade`` runs them again). ``--quick``: one sample, μ = 0.3, 3 % strain.
"""

from __future__ import annotations

import argparse
import inspect
import json
import math
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _dem_compare import (STORE, Protocol, Run, Stats, have_yade, protocol_notes, scaled_sample,  # noqa: E402
                          statistics, within, yade_sample, yade_triaxial)
from _table import write_table  # noqa: E402

LAWS = ("coulomb", "user", "orthotropic", "dilatant")
LAW_TEXT = {
    "coulomb": "Coulomb(μ)",
    "user": 'UserLaw("sqrt(T1**2 + T2**2) - mu*N", potential="sqrt(T1**2 + T2**2)")',
    "orthotropic": "EllipticOrthotropic(mu_x=μ, mu_y=μ/2)",
    "dilatant": 'UserLaw("sqrt(T1**2 + T2**2) - mu*N", potential="sqrt(T1**2 + T2**2) - beta*N"), β = μ/3',
}


def make_law(name: str, mu: float):
    """The contact law ``name`` of the comparison at friction ``mu``."""
    import frictionrules as fr
    if name == "coulomb":
        return fr.Coulomb(mu)
    if name == "user":
        return fr.UserLaw("sqrt(T1**2 + T2**2) - mu*N", potential="sqrt(T1**2 + T2**2)",
                          params={"mu": mu})
    if name == "orthotropic":
        return fr.EllipticOrthotropic(mu_x=mu, mu_y=mu / 2)
    if name == "dilatant":
        return fr.UserLaw("sqrt(T1**2 + T2**2) - mu*N", potential="sqrt(T1**2 + T2**2) - beta*N",
                          params={"mu": mu, "beta": mu / 3})
    raise ValueError(f"law {name!r}: one of {', '.join(LAWS)}")


def ours_available() -> bool:
    """True where this checkout's ``triaxial`` has the DEM engine (``method="dem"``)."""
    from frictionrules import triaxial
    return "method" in inspect.signature(triaxial).parameters


def _triaxial_dem(sample: dict, law, protocol: Protocol, axial_strain: float,
                  preload: float | None = None):
    from frictionrules import Assembly, ContactModel, triaxial
    p = protocol
    assembly = Assembly(sample["positions"], sample["radii"], sample["cell"],
                        ContactModel(law, kn=p.kn, kt=p.kt))
    # the preload of the frictionless consolidation: triaxial's own default unless screened
    extra = {} if preload is None else {"preload": preload}
    return triaxial(assembly, "axisymmetric", pressure=p.pressure, axial_strain=axial_strain,
                    method="dem", inertial_number=p.inertial_number, damping=p.damping,
                    density=p.density, record_every=p.record_every, consolidation="frictionless",
                    **extra)


def energy_error(result) -> float:
    """The largest energy imbalance of the shearing stage over its largest boundary work
    (``EnergyTerms.relative_error``: boundary work against the elastic energy, the laws'
    dissipation, the kinetic energy and the damping's loss); NaN without energy records."""
    energy = getattr(result, "energy", None)
    return math.nan if energy is None else float(energy.relative_error)


def _steps_and_dt(result) -> tuple[int, float]:
    """Time steps of the whole run and their mean length (the consolidation's FIRE steps grow to
    1.5 times the dynamic step), from the engine's meters."""
    engine = getattr(result, "engine", None)
    if engine is None:
        return -1, math.nan
    m = engine.meters[0]
    steps = int(m["steps"])
    return steps, float(m["time"]) / steps if steps else math.nan


def run_ours(sample: dict, mu: float, protocol: Protocol, law: str = "coulomb",
             tag: str = "", preload: float | None = None) -> Run:
    """Our DEM run of the protocol on ``sample`` with the law ``law`` at friction ``mu``
    (``preload``: triaxial's option, its default where None)."""
    cpu0, t0 = time.process_time(), time.perf_counter()
    r = _triaxial_dem(sample, make_law(law, mu), protocol, protocol.axial_strain, preload)
    wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    steps, dt = _steps_and_dt(r)
    run = Run(axial_strain=np.asarray(r.strain)[:, 2, 2], volumetric_strain=np.asarray(r.volumetric_strain),
              stress=np.asarray(r.stress), coordination=np.asarray(r.coordination), wall=wall,
              cpu=cpu, steps=steps, dt=dt,
              info={"energy_error": energy_error(r), "message": r.message})
    _keep(run, f"seed{sample['seed']}{tag}_mu{mu:g}_{law}_{100 * protocol.axial_strain:g}pc")
    return run


def _keep(run: Run, name: str) -> None:
    """Our records beside YADE's raw outputs (for a later look), written atomically."""
    folder = STORE / "ours"
    folder.mkdir(parents=True, exist_ok=True)
    tmp = folder / f".{name}.npz"
    with open(tmp, "wb") as f:
        np.savez(f, axial_strain=run.axial_strain, volumetric_strain=run.volumetric_strain,
                 stress=run.stress, coordination=run.coordination,
                 cost=json.dumps({"wall": run.wall, "cpu": run.cpu, "steps": run.steps,
                                  "dt": run.dt, **run.info}))
    tmp.replace(folder / f"{name}.npz")


def warm_up(sample: dict, protocol: Protocol, laws) -> dict:
    """Compile each law's kernels once, before any timed run (a short run): seconds per law."""
    seconds = {}
    for law in laws:
        t0 = time.perf_counter()
        _triaxial_dem(sample, make_law(law, 0.3), protocol, 2 * protocol.record_every)
        seconds[law] = time.perf_counter() - t0
    return seconds


# ---- tables ---------------------------------------------------------------------------------

def _f(x, digits=2):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}f}"


def _stat_cells(ours, yade, key, digits, mean):
    a = getattr(ours, key) if ours else math.nan
    b = getattr(yade, key)
    d = a - b
    return [_f(a, digits), _f(b, digits), f"{_f(d, digits)} {within(d, key, mean)}"]


def mean_stats(runs, side: str) -> Stats:
    """The statistics averaged over ``runs`` (one code: ``side``)."""
    return Stats(*(float(np.mean([getattr(v[side], key) for v in runs]))
                   for key in ("peak", "end", "ev", "z", "reached")))


def comparison_table(results, mus, protocol, notes, suffix=""):
    rows = []
    for mu in mus:
        runs = [v for (s, m, law), v in results.items() if m == mu and law == "coulomb"]
        for (seed, m, law), v in results.items():
            if m == mu and law == "coulomb":
                rows.append([seed, mu] + sum((_stat_cells(v["ours_stats"], v["yade_stats"], k, d, False)
                                              for k, d in (("peak", 2), ("end", 2), ("ev", 4), ("z", 2))), []))
        have_ours = all(v["ours_stats"] is not None for v in runs)
        rows.append([f"**mean of {len(runs)}**", mu] + sum(
            (_stat_cells(mean_stats(runs, "ours_stats") if have_ours else None,
                         mean_stats(runs, "yade_stats"), k, d, True)
             for k, d in (("peak", 2), ("end", 2), ("ev", 4), ("z", 2))), []))
    head = ["seed", "μ"]
    for name in ("peak φ (°)", "end φ (°)", "ε_v", "Z"):
        head += [f"ours: {name}", f"YADE: {name}", "ours − YADE"]
    write_table("assembly_yade" + suffix, "Random packings to critical state: the DEM engine beside YADE",
                head, rows, notes)


def times_table(results, notes, suffix=""):
    rows, ratios_wall, ratios_cpu = [], [], []
    for (seed, mu, law), v in results.items():
        if law != "coulomb":
            continue
        o, y = v["ours"], v["yade"]
        rw = o.wall / y.wall if o else math.nan
        rc = o.cpu / y.cpu if o else math.nan
        ratios_wall.append(rw)
        ratios_cpu.append(rc)
        rows.append([seed, mu,
                     _f(o.wall, 1) if o else "–", _f(o.cpu, 1) if o else "–",
                     f"{o.steps} × {o.dt:.3g}" if o else "–",
                     _f(1e6 * o.cpu / o.steps, 0) if o and o.steps > 0 else "–",
                     _f(y.wall, 1), _f(y.cpu, 1),
                     f"{y.info['consolidation_steps']} + {y.info['shear_steps']} × {y.dt:.3g}",
                     _f(1e6 * y.info["cpu_inside"] / y.steps, 0),
                     f"{y.info['loadavg']:.1f}" + (" (kept)" if v["reused"] else ""),
                     _f(rw), _f(rc)])
    rows.append(["**median**", "", "", "", "", "", "", "", "", "", "", _f(float(np.median(ratios_wall))),
                 _f(float(np.median(ratios_cpu)))])
    write_table("assembly_yade_times" + suffix, "Cost per run (preparation + shear): the DEM engine beside YADE -j1",
                ["seed", "μ", "ours: wall s", "ours: CPU s", "ours: steps × mean dt", "ours: CPU µs/step",
                 "YADE: wall s", "YADE: CPU s", "YADE: steps (consolidation + shear) × dt",
                 "YADE: CPU µs/step (inside)",
                 "load during YADE", "wall ratio ours/YADE (goal ≤ 0.5)", "CPU ratio ours/YADE"],
                rows, notes)


def laws_table(results, notes, suffix=""):
    rows = []
    for (seed, mu, law), v in results.items():
        s = v["ours_stats"]
        ref = results.get((seed, mu, "coulomb"), {}).get("ours_stats")
        d = (lambda key: getattr(s, key) - getattr(ref, key)) if ref else (lambda key: math.nan)  # noqa: E731
        rows.append([law, seed, mu, _f(s.peak), _f(s.end), _f(s.ev, 4), _f(s.z),
                     _f(d("peak")), _f(d("end")), _f(d("ev"), 4), _f(d("z")),
                     _f(100 * v["ours"].info["energy_error"], 3), _f(v["ours"].wall, 1),
                     _f(v["ours"].cpu, 1), _f(100 * s.reached, 1)])
    write_table("assembly_yade_laws" + suffix, "Any law at every contact: the same protocol, ours only",
                ["law", "seed", "μ", "peak φ (°)", "end φ (°)", "ε_v", "Z", "Δ peak vs Coulomb",
                 "Δ end", "Δ ε_v", "Δ Z", "energy balance error (% of boundary work)", "wall s",
                 "CPU s", "reached %"], rows, notes)


ENSEMBLE_KEYS = (("peak", "peak φ (°)", 2), ("end", "20–25 % φ (°)", 2), ("ev", "ε_v at the end", 4),
                 ("z", "Z (20–25 %)", 2))


#: Axial strains the ensemble table gives ε_v at, besides the end.
EV_STRAINS = (0.02, 0.05, 0.1, 0.15, 0.2)


def _ci(values, digits):
    from frictionrules.assembly._statistics import interval
    ci = interval([v for v in values if not math.isnan(v)])
    if ci.n == 0:
        return ci, "–"
    if ci.n == 1:
        return ci, f"{ci.mean:.{digits}f} (n = 1)"
    return ci, f"{ci.mean:.{digits}f} ± {ci.half_width:.{digits}f}"


def _ensemble_row(mu, name, digits, a, b, n):
    """One statistic: each code's mean and interval, whether they overlap, the paired
    difference's interval and whether it holds 0."""
    ca, ta = _ci(a, digits)
    cb, tb = _ci(b, digits)
    cd, td = _ci([x - y for x, y in zip(a, b)], digits)
    overlap = "yes" if ca.n > 1 and ca.low <= cb.high and cb.low <= ca.high else (
        "no" if ca.n > 1 else "–")
    zero = "–" if cd.n < 2 else ("no" if cd.low > 0 or cd.high < 0 else "yes")
    return [mu, name, n, ta, tb, overlap, td, zero, _f(ca.std, digits), _f(cb.std, digits)]


def ensemble_table(results, mus, notes, suffix=""):
    """Means over the samples with their 95 % confidence intervals (Student's t), ours beside
    YADE, and the mean of the paired differences (the same sample in both codes) with its
    interval: a difference whose interval excludes 0 is one the samples do not explain."""
    rows = []
    for mu in mus:
        runs = [v for (s, m, law), v in sorted(results.items())
                if m == mu and law == "coulomb" and v.get("ours_stats") is not None]
        for key, name, digits in ENSEMBLE_KEYS:
            a = [getattr(v["ours_stats"], key) for v in runs]
            b = [getattr(v["yade_stats"], key) for v in runs]
            rows.append(_ensemble_row(mu, name, digits, a, b, len(runs)))
        final = min(float(v[side].axial_strain[-1]) for v in runs for side in ("ours", "yade")) \
            if runs else 0.0
        extra = [("Z at the start of the shear", 2, lambda r: float(r.coordination[0]))]
        extra += [(f"ε_v at {100 * e:g} %", 4,
                   lambda r, e=e: float(np.interp(e, r.axial_strain, r.volumetric_strain)))
                  for e in EV_STRAINS if e <= final + 1e-9]   # where the trajectories part
        for name, digits, value in extra:
            a = [value(v["ours"]) for v in runs]
            b = [value(v["yade"]) for v in runs]
            rows.append(_ensemble_row(mu, name, digits, a, b, len(runs)))
    write_table("assembly_yade_ensemble" + suffix,
                "Ensembles: the DEM engine beside YADE on the same samples (means, 95 % intervals)",
                ["μ", "statistic", "samples", "ours: mean ± 95 %", "YADE: mean ± 95 %",
                 "intervals overlap", "ours − YADE (paired): mean ± 95 %", "0 inside",
                 "ours: std", "YADE: std"], rows, notes)


def figure(results, path: str) -> None:
    """The mobilized angle, the volumetric strain and Z against the axial strain: ours solid,
    YADE dashed, a colour per μ."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from _dem_compare import mobilized_angle
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    mus = sorted({mu for (_, mu, _) in results})
    for (seed, mu, law), v in results.items():
        if law != "coulomb":
            continue
        colour = f"C{mus.index(mu)}"
        for side, style in (("ours", "-"), ("yade", "--")):
            run = v.get(side)
            if run is None:
                continue
            e = 100 * run.axial_strain
            label = f"{'ours' if side == 'ours' else 'YADE'} μ = {mu:g}" if seed == min(
                s for (s, m, x) in results if m == mu) else None
            for ax, y in zip(axes, (mobilized_angle(run.stress), run.volumetric_strain,
                                    run.coordination)):
                ax.plot(e, y, style, color=colour, lw=0.8, alpha=0.8, label=label)
    for ax, name in zip(axes, ("mobilized angle asin((σ1 − σ3)/(σ1 + σ3)) (°)",
                               "volumetric strain (compression +)", "coordination Z")):
        ax.set_xlabel("axial strain (%)")
        ax.set_ylabel(name)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


def ensemble_figure(results, path: str, final_strain: float) -> None:
    """The mean mobilized angle and volumetric strain against the axial strain over the
    samples, with their 95 % bands (Student's t, point by point), ours solid, YADE dashed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from _dem_compare import mobilized_angle
    from frictionrules.assembly._statistics import interval
    grid = np.linspace(0.0, final_strain, int(round(final_strain / 1e-3)) + 1)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    mus = sorted({mu for (_, mu, law), v in results.items() if law == "coulomb"})
    for mu in mus:
        runs = [v for (s, m, law), v in results.items()
                if m == mu and law == "coulomb" and v.get("ours") is not None]
        for side, style in (("ours", "-"), ("yade", "--")):
            curves = [[np.interp(grid, r[side].axial_strain, y) for r in runs
                       for y in [mobilized_angle(r[side].stress)]],
                      [np.interp(grid, r[side].axial_strain, r[side].volumetric_strain) for r in runs]]
            for ax, ys in zip(axes, curves):
                ys = np.array(ys)
                cis = [interval(col) for col in ys.T]
                mean = np.array([c.mean for c in cis])
                colour = f"C{2 * mus.index(mu) + (side == 'yade')}"
                ax.plot(100 * grid, mean, style, color=colour,
                        label=f"{'ours' if side == 'ours' else 'YADE'} μ = {mu:g} (n = {len(runs)})")
                if len(runs) > 1:
                    ax.fill_between(100 * grid, [c.low for c in cis], [c.high for c in cis],
                                    color=colour, alpha=0.2, lw=0)
    for ax, name in zip(axes, ("mobilized angle asin((σ1 − σ3)/(σ1 + σ3)) (°)",
                               "volumetric strain (compression +)")):
        ax.set_xlabel("axial strain (%)")
        ax.set_ylabel(name)
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


# ---- main -----------------------------------------------------------------------------------

PREPARATIONS = ("cloud", "scaled")
PREPARATION_TEXT = {
    "cloud": " Preparation 'cloud': both codes consolidate the loose makeCloud cloud.",
    "scaled": (" Preparation 'scaled': the makeCloud cloud compacted without friction to p by our "
               "engine, then scaled up by the least factor that leaves no overlap; both codes "
               "consolidate (frictionless, to p) from that packing."),
}


def ensemble_notes(protocol: Protocol, preparation: str) -> str:
    return (protocol_notes(protocol) + PREPARATION_TEXT[preparation] + " Intervals: "
            "mean ± t(0.975, n−1) s/√n over the samples (frictionrules.assembly._statistics."
            "interval); the paired difference is taken sample by sample. 'intervals overlap': "
            "the two codes' intervals of the mean share a value; '0 inside': the paired "
            "difference's interval holds 0.")


def screening(args) -> str:
    """Patch our engine's constants for a screening run (one thing changed at a time, at run
    time; the preload is triaxial's public option ``preload``, passed by :func:`run_ours`);
    the tag the runs and tables are named with ('' for none)."""
    from frictionrules.assembly._dem import _engine, _protocol
    tag = ""
    if args.ours_preload is not None:
        tag += f"_preload{args.ours_preload:g}"
    if args.ours_dt_safety is not None:
        _engine.SAFETY = args.ours_dt_safety
        tag += f"_safety{args.ours_dt_safety:g}"
    if args.ours_servo_rate is not None:
        _protocol.SERVO_RATE = args.ours_servo_rate
        tag += f"_servo{args.ours_servo_rate:g}"
    return tag


def parse_seeds(text: str) -> list[int]:
    """``"1,2,3"`` or ``"1-10"`` (or a mix, ``"1-3,7"``) as a list of seeds."""
    seeds = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        seeds += list(range(int(a), int(b) + 1)) if b else [int(a)]
    return seeds


def kept_ours(seed: int, mu: float, law: str, protocol: Protocol, tag: str):
    """Our kept record of the same run (``_keep``), or None."""
    path = STORE / "ours" / f"seed{seed}{tag}_mu{mu:g}_{law}_{100 * protocol.axial_strain:g}pc.npz"
    if not path.exists():
        return None
    with np.load(path) as f:
        cost = json.loads(str(f["cost"]))
        info = {k: v for k, v in cost.items() if k not in ("wall", "cpu", "steps", "dt")}
        return Run(axial_strain=f["axial_strain"], volumetric_strain=f["volumetric_strain"],
                   stress=f["stress"], coordination=f["coordination"], wall=cost["wall"],
                   cpu=cost["cpu"], steps=cost["steps"], dt=cost["dt"], info=info)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="1,2,3",
                        help="makeCloud seeds, one sample each: 1,2,3 or a range 1-10")
    parser.add_argument("--preparation", choices=PREPARATIONS, default="cloud",
                        help="cloud: both codes consolidate the loose makeCloud cloud; scaled: "
                             "the cloud compacted frictionless to p by our engine and scaled to "
                             "zero overlap, then both codes consolidate that")
    parser.add_argument("--yade-strain", type=float,
                        help="the final axial strain of YADE's runs (kept ones are reused), when "
                             "ours stop earlier (--strain): screening runs compare at --strain")
    parser.add_argument("--ours-preload", type=float,
                        help="screening: our frictionless consolidation's preload, triaxial(..., "
                             "preload=X) (a multiple of p; 1: none, compressed from below as YADE "
                             "does)")
    parser.add_argument("--ours-dt-safety", type=float,
                        help="screening: our time step's safety factor on √(m_min/k_max)")
    parser.add_argument("--ours-servo-rate", type=float,
                        help="screening: our servo's largest lateral strain rate during the "
                             "shear, a multiple of the axial rate")
    parser.add_argument("--reuse-ours", action="store_true",
                        help="reuse our kept records of the same run (seed, μ, law, strain, "
                             "preparation) instead of running it again")
    parser.add_argument("--mu", default="0.3,0.5")
    parser.add_argument("--strain", type=float, default=0.25, help="final axial strain")
    parser.add_argument("--laws", default=",".join(LAWS),
                        help=f"ours: laws to run ({', '.join(LAWS)}); coulomb is compared with YADE")
    parser.add_argument("--law-samples", type=int, default=1,
                        help="samples the laws other than coulomb and user run on")
    parser.add_argument("--quick", action="store_true", help="one sample, μ = 0.3, 3 %% strain")
    parser.add_argument("--rerun-yade", action="store_true", help="run YADE even where kept")
    parser.add_argument("--yade-only", action="store_true", help="skip ours")
    parser.add_argument("--threads", type=int, default=1, help="NUMBA_NUM_THREADS for ours")
    parser.add_argument("--figure", help="angle, ε_v and Z against the axial strain (.png)")
    parser.add_argument("--ensemble-figure",
                        help="mean angle and ε_v with their 95 %% bands, ours beside YADE (.png)")
    args = parser.parse_args(argv)
    os.environ["NUMBA_NUM_THREADS"] = str(args.threads)   # before anything imports numba
    seeds = parse_seeds(args.seeds)
    mus = [float(m) for m in args.mu.split(",")]
    laws = [law for law in args.laws.split(",") if law]
    if any(law not in LAWS for law in laws):
        parser.error(f"--laws {args.laws}: each one of {', '.join(LAWS)}")
    protocol = Protocol(axial_strain=args.strain)
    yade_protocol = replace(protocol, axial_strain=args.yade_strain or args.strain)
    if args.quick:
        seeds, mus, protocol = seeds[:1], mus[:1], replace(protocol, axial_strain=0.03)
    if not have_yade():
        print("YADE is not installed (Debian: apt-get install yade): kept outputs only", file=sys.stderr)
    with_ours = not args.yade_only and ours_available()
    if not args.yade_only and not with_ours:
        print("this checkout's triaxial has no method='dem': YADE only", file=sys.stderr)

    samples = {seed: yade_sample(seed, protocol) for seed in seeds}
    tag = ("" if args.preparation == "cloud" else f"_{args.preparation}") + screening(args)
    if args.preparation == "scaled":
        samples = {seed: scaled_sample(s, protocol) for seed, s in samples.items()}
    missing = not args.reuse_ours or any(kept_ours(seed, mu, law, protocol, tag) is None
                                         for seed in seeds for mu in mus for law in laws)
    warm = warm_up(samples[seeds[0]], protocol, laws) if with_ours and missing else {}
    results = {}
    for seed in seeds:
        for mu in mus:
            yade, reused = yade_triaxial(samples[seed], mu, yade_protocol, reuse=not args.rerun_yade)
            entry = {"yade": yade, "yade_stats": statistics(yade, protocol.axial_strain),
                     "reused": reused, "ours": None, "ours_stats": None}
            print(f"seed {seed}, μ = {mu}: YADE {entry['yade_stats']}, {yade.cpu:.1f} s CPU"
                  + (" (kept)" if reused else ""), flush=True)
            results[(seed, mu, "coulomb")] = entry
            for law in laws if with_ours else ():
                if law not in ("coulomb", "user") and seeds.index(seed) >= args.law_samples:
                    continue
                ours = (kept_ours(seed, mu, law, protocol, tag) if args.reuse_ours else None) \
                    or run_ours(samples[seed], mu, protocol, law, tag, args.ours_preload)
                e = results.setdefault((seed, mu, law), {"reused": False})
                e.update(ours=ours, ours_stats=statistics(ours, protocol.axial_strain))
                print(f"  ours {law}: {e['ours_stats']}, {ours.wall:.1f} s wall, {ours.cpu:.1f} s CPU",
                      flush=True)
        if with_ours:     # after each sample: the partial ensemble is kept
            ensemble_table(results, mus, ensemble_notes(protocol, args.preparation), tag)

    notes = protocol_notes(protocol) + PREPARATION_TEXT[args.preparation]
    threads = f"ours on {args.threads} thread(s) (NUMBA_NUM_THREADS)"
    comparison_table(results, mus, protocol,
                     notes + " ✓/✗: within the tolerance of a run (rows) or of the means." +
                     ("" if with_ours else " Ours not run: no DEM engine in this checkout."), tag)
    times_table(results, f"{threads}, after a warm-up that compiled each law's kernels "
                f"({', '.join(f'{k} {v:.1f} s' for k, v in warm.items()) or 'none'}); wall times "
                f"on {os.cpu_count()} cores (the load is the 1-minute load average when YADE ran; "
                "'kept': YADE's output of an earlier run of the same job). CPU: our process time; "
                "YADE's subprocess (RUSAGE_CHILDREN), start-up included.", tag)
    if with_ours:
        ensemble_table(results, mus, ensemble_notes(protocol, args.preparation), tag)
    if args.figure:
        figure(results, args.figure)
    if args.ensemble_figure and with_ours:
        ensemble_figure(results, args.ensemble_figure, protocol.axial_strain)
    if with_ours:
        laws_table({k: v for k, v in results.items() if v.get("ours_stats") is not None},
                   f"{threads}. Laws: " + "; ".join(f"{k}: {LAW_TEXT[k]}" for k in laws) +
                   ". Energy balance: boundary work against dissipation + elastic + kinetic + damping "
                   "at the end of the run.", tag)


if __name__ == "__main__":
    main()
