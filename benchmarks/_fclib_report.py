"""Tables and figures of ``benchmarks/fclib.py``: the per-file summary, the Dolan–Moré
performance profiles and the time per iteration against nnz(W)."""

from __future__ import annotations

import csv
import io
import json
import shutil
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DOCS_FIGURES = ROOT / "docs" / "figures"
OURS = {"nsgs", "newton", "prox", "admm", "polish", "auto"}
#: Peer rows timing the whole Python call (tiny files only): compared apart, not in the profiles.
CALL_SUFFIX = "-call"


def _rows(csv_rows):
    return list(csv.DictReader(io.StringIO("\n".join(csv_rows))))


def summary(csv_rows) -> str:
    """Markdown: per file and target, our best and the best peer's time to the target."""
    rows = _rows(csv_rows)
    groups = {}
    for r in rows:
        groups.setdefault((r["file"], r["target"]), []).append(r)
    lines = ["| file | nc | target | best peer: solver, it, error, s, MB | ours best: method, it, error, s, MB "
             "| ours / peer |", "|---|---:|---|---|---|---:|"]
    for (f, target), runs in sorted(groups.items(), key=lambda kv: (int(kv[1][0]["contacts"]), kv[0][1])):
        cells, best = [], {}
        for side in ("peer", "ours"):
            mine = [r for r in runs if (r["solver"] in OURS) == (side == "ours") and r["reached"] == "1"
                    and not r["solver"].endswith(CALL_SUFFIX)]
            b = min(mine, key=lambda r: float(r["cpu_median"])) if mine else None
            best[side] = b
            if b:
                cells.append(f"{b['solver']}, {b['iterations']}, {float(b['error']):.1e}, "
                             f"{_s(b['cpu_median'])}, {float(b['peak_mb']):.0f}")
            else:
                tried = [r for r in runs if (r["solver"] in OURS) == (side == "ours")]
                known = [r for r in tried if np.isfinite(float(r["error"]))]
                low = min(known, key=lambda r: float(r["error"]), default=None)
                if low is not None:
                    cells.append(f"not reached (best {low['solver']} {float(low['error']):.1e})")
                elif tried:     # no run reported an error: each was stopped (time limit, crash)
                    stops = sorted({r["info"] or "stopped" for r in tried})
                    cells.append(f"not reached (no error reported: {', '.join(stops)})")
                else:
                    cells.append("none")
        a, b = best["peer"], best["ours"]
        ratio = f"{float(b['cpu_median']) / max(float(a['cpu_median']), 1e-7):.2f}" if a and b else "–"
        lines.append(f"| {f.replace('.hdf5', '')} | {runs[0]['contacts']} | {target} | {cells[0]} | {cells[1]} "
                     f"| {ratio} |")
    return "\n".join(lines) + "\n\n" + whole_calls(rows) + full_table(rows)


def whole_calls(rows) -> str:
    """Markdown: on the tiny files, our best against the fastest peer's whole Python call (its options
    and arrays made, the driver, the results read), the way ``solve`` is timed; empty when no
    such rows."""
    fastest = {}
    for r in rows:
        if r["solver"].endswith(CALL_SUFFIX) and r["reached"] == "1":
            key = (r["file"], r["target"])
            if key not in fastest or float(r["cpu_median"]) < float(fastest[key]["cpu_median"]):
                fastest[key] = r
    calls = list(fastest.values())
    if not calls:
        return ""
    out = ["The tiny files timed as whole Python calls (the peer's options and arrays made, its "
           "driver, its results read; ours: `solve` from its arguments to its `Solution`):", "",
           "| file | target | peer call: solver, s | peer driver alone, s | ours best: method, s | ours / call |",
           "|---|---|---|---|---|---:|"]
    for c in sorted(calls, key=lambda r: (int(r["contacts"]), r["file"], r["target"], r["solver"])):
        same = [r for r in rows if r["file"] == c["file"] and r["target"] == c["target"]]
        driver = next((r for r in same if r["solver"] == c["solver"][:-len(CALL_SUFFIX)]), None)
        mine = [r for r in same if r["solver"] in OURS and r["reached"] == "1"]
        if not mine or driver is None:
            continue
        b = min(mine, key=lambda r: float(r["cpu_median"]))
        out.append(f"| {c['file'].replace('.hdf5', '')} | {c['target']} | {c['solver']}, {_s(c['cpu_median'])} | "
                   f"{_s(driver['cpu_median'])} | {b['solver']}, {_s(b['cpu_median'])} | "
                   f"{float(b['cpu_median']) / max(float(c['cpu_median']), 1e-9):.2f} |")
    return "\n".join(out) + "\n\n"


def _s(x) -> str:
    """Seconds with three significant digits (tiny problems take microseconds)."""
    x = float(x)
    return "–" if not np.isfinite(x) else f"{x:.3g}"


def full_table(rows) -> str:
    """Markdown: every solver on every file, CPU seconds to 1e-8 and 1e-4 (median, with the
    spread), iterations and error at 1e-8, peak memory; "–" where the target was not reached."""
    out = ["| file | solver | 1e-8: s (min-max) | it | error | 1e-4: s | it | error | MB |",
           "|---|---|---|---:|---:|---|---:|---:|---:|"]
    by = {}
    for r in rows:
        by.setdefault((r["file"], r["solver"]), {})[r["target"]] = r
    files = sorted({r["file"] for r in rows}, key=lambda f: int(next(r["contacts"] for r in rows if r["file"] == f)))
    for f in files:
        for solver in sorted({s for (g, s) in by if g == f}, key=lambda s: (s not in OURS, s)):
            cells = []
            for target in ("1e-08", "1e-04"):
                r = by[(f, solver)].get(target)
                if r is None:
                    cells += ["", "", ""]
                    continue
                t = (f"{_s(r['cpu_median'])} ({_s(r['cpu_min'])}-{_s(r['cpu_max'])})" if target == "1e-08"
                     else _s(r["cpu_median"])) if r["reached"] == "1" else f"– ({r['info']})"
                cells += [t, r["iterations"], f"{float(r['error']):.1e}"]
            mb = max(float(r["peak_mb"]) for r in by[(f, solver)].values())
            out.append(f"| {f.replace('.hdf5', '')} | {solver} | " + " | ".join(cells) + f" | {mb:.0f} |")
    return "\n".join(out) + "\n"


def profiles(csv_rows, ax):
    """Dolan–Moré performance profiles: for every solver the fraction of (file, target) problems
    it solves within a factor tau of the fastest solver on that problem."""
    rows = [r for r in _rows(csv_rows) if not r["solver"].endswith(CALL_SUFFIX)]
    problems = sorted({(r["file"], r["target"]) for r in rows})
    solvers = sorted({r["solver"] for r in rows})
    T = np.full((len(problems), len(solvers)), np.inf)
    for r in rows:
        if r["reached"] == "1":
            T[problems.index((r["file"], r["target"])), solvers.index(r["solver"])] = max(float(r["cpu_median"]), 1e-6)
    best = T.min(axis=1, keepdims=True)
    ratio = T / best
    taus = np.logspace(0, 4, 400)
    for j, s in enumerate(solvers):
        frac = [(ratio[:, j] <= t).mean() for t in taus]
        ax.step(taus, frac, where="post", label=s, lw=2.2 if s in OURS else 1.2,
                ls="-" if s in OURS else "--")
    ax.set_xscale("log")
    ax.set_xlabel("tau: CPU time / the fastest solver's CPU time on the problem")
    ax.set_ylabel("fraction of problems solved within tau")
    ax.set_ylim(0, 1.02)
    ax.set_title(f"Performance profiles, {len(problems)} problems (FCLIB files x targets)")
    ax.legend(fontsize=7, ncol=2, loc="lower right")
    return ax


def scaling(per_iteration: dict, ax):
    """Seconds per iteration of each method against nnz(W), log-log, with the fitted slopes."""
    slopes = {}
    for method in ("nsgs", "newton", "prox", "admm", "polish"):
        pts = sorted((nnz, d[method]) for nnz, d in per_iteration.values() if method in d)
        x, y = np.array([p[0] for p in pts], float), np.array([p[1] for p in pts], float)
        ok = (x > 2000) & (y > 0)          # the small files time the Python overhead only
        slope = np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0] if ok.sum() >= 2 else float("nan")
        slopes[method] = slope
        ax.loglog(x, y, "o-", label=f"{method} (slope {slope:.2f} above nnz 2000)")
    xs = np.array([1e3, 1e6])
    ax.loglog(xs, 1e-7 * xs ** 1.2, "k:", label="nnz^1.2")
    ax.set_xlabel("nnz(W)")
    ax.set_ylabel("CPU seconds per iteration")
    ax.set_title("Time per iteration (nsgs: sweep; prox: outer iteration; polish: Newton step)")
    ax.legend(fontsize=7)
    return slopes


def figures(csv_rows, per_iteration_json: Path, outdir: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    written = []
    fig, ax = plt.subplots(figsize=(7.5, 5))
    profiles(csv_rows, ax)
    fig.tight_layout()
    path = outdir / "fclib_profiles.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    written.append(path)
    if per_iteration_json.is_file():
        fig, ax = plt.subplots(figsize=(7.5, 5))
        slopes = scaling(json.loads(per_iteration_json.read_text()), ax)
        fig.tight_layout()
        path = outdir / "fclib_scaling.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
        print("slopes of time per iteration against nnz(W):",
              ", ".join(f"{m} {s:.2f}" for m, s in slopes.items()))
    DOCS_FIGURES.mkdir(parents=True, exist_ok=True)
    for path in list(written):
        shutil.copyfile(path, DOCS_FIGURES / path.name)
        written.append(DOCS_FIGURES / path.name)
    return written
