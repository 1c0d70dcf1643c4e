"""Reproduce the paper: every figure the library can make, an index of them, and a table of
key numbers.

:data:`FIGURES` registers each figure by the import path of the function that draws it
(``"module:function"``), so that nothing is imported or computed until the figure is made. A
figure function takes ``ax=None`` and returns the Axes it drew on. The paper's figures go to
the folder ``paper/`` (file stems ``fig1a_...`` numbered as in the paper), the figures beyond
the paper to ``extra/``; ``index.md`` lists every figure written with its caption.

:data:`KEY_NUMBERS` registers the key-number tables; each returns a list of
``(quantity, value, reference)`` rows. Making figures never computes them: call
:func:`key_numbers`.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path

from ._optional import require_all
from ._output import FIGURE_SUFFIXES, provenance, write_figure, write_text
from .contact.summary import FIG10

#: What the figures and key numbers import beyond NumPy: the packages of the ``paper`` extra.
REQUIRES: tuple[str, ...] = ("matplotlib", "numba", "scipy", "sympy")


def check_requirements() -> None:
    """Raise one :class:`~frictionrules.FrictionRulesError` line naming every missing package
    of :data:`REQUIRES` and the ``paper`` extra, before any work starts."""
    require_all(REQUIRES, extra="paper", purpose="frictionrules paper")


#: Folder of the paper's figures and of the figures beyond the paper, under the output folder.
PAPER, EXTRA = "paper", "extra"


@dataclass(frozen=True)
class Figure:
    """One registered figure: ``folder/stem.<format>`` drawn by ``target`` (``"module:function"``)."""

    folder: str
    stem: str
    target: str
    caption: str

    @property
    def name(self) -> str:
        """``folder/stem``, the figure's path under the output folder without a suffix."""
        return f"{self.folder}/{self.stem}"


_P = "frictionrules.plot."

#: Every figure, the paper's in its order, then ours.
FIGURES: tuple[Figure, ...] = (
    Figure(PAPER, "fig1a_coulomb_cone", _P + "laws:coulomb_cone",
           "FIG. 1a. Coulomb limit condition (1.4) in the force space Tx, Ty, N (μ = 0.5), with "
           "the slip without normal component (1.5) and the associated, dilatant slip (1.6) at one "
           "limit force."),
    Figure(PAPER, "fig1b_orthotropic_ellipse", _P + "laws:orthotropic_ellipse",
           "FIG. 1b. Orthotropic friction condition (1.9) in the plane N = const (μx = 0.6, "
           "μy = 0.3, N = 1): forces T at the angle β and the slips V at the angle α, normal to "
           "the ellipse (1.10), (1.14)."),
    Figure(PAPER, "fig1c_dissipation", _P + "laws:dissipation_function",
           "FIG. 1c. Dissipation function (1.12) in the plane Vx, Vy (level lines, μx = 0.6, "
           "μy = 0.3, N = 1); its gradient is the force (1.13)."),
    Figure(PAPER, "fig3a_wedge_elliptic", _P + "laws:wedge_elliptic",
           "FIG. 3a. Elliptical yield condition f = 0 (2.2) and velocity potential g = 0 (2.6) of "
           "a block on a plane inclined at α = 30°, μ = 0.5: the point R of the potential on the "
           "ray from its centre through P gives the slip at P (2.4), which differs from the "
           "associated normal (2.5)."),
    Figure(PAPER, "fig3b_wedge_parabolic", _P + "laws:wedge_parabolic",
           "FIG. 3b. Parabolic yield condition f = 0 (α + ϱ = π/2, μ = 0.5) and velocity "
           "potential g = 0, with the same construction."),
    Figure(PAPER, "fig5_two_flank", _P + "asperities:fig5_two_flank",
           "FIG. 5. Limit condition f = 0 (2.9), (2.12) and velocity potential g = 0 (2.14), "
           "(2.15) of a single asperity with two flanks, α1 = π/3, α2 = 5π/6, μ = 1, Q = 1; the "
           "concave corners are marked with their interior angles."),
    Figure(PAPER, "fig6a_limit_surface", _P + "asperities:fig6a_limit_surface",
           "FIG. 6a. Limit surface f = 0 in the space Tx, Ty, Q of the asperity of Fig. 5, seen "
           "from above: a cone over the limit curve. Shaded: where its section Q = 1 lies inside "
           "its convex hull (the surface is concave there); black lines: the concave edges "
           "through the corners of Fig. 5."),
    Figure(PAPER, "fig6b_potential_surface", _P + "asperities:fig6b_potential_surface",
           "FIG. 6b. Velocity potential g = C in the space Tx, Ty, Q: elliptic cylinders (2.14) "
           "of the flanks joined by the planes Ty = ±C (2.15)."),
    Figure(PAPER, "fig7_associated", _P + "asperities:fig7_associated",
           "FIG. 7. Limit condition f = 0 for the associated local sliding rule (1.6) (solid, "
           "convex) and the non-associated one (1.5) (broken, concave corners), α1 = π/3, "
           "α2 = 5π/6, μ = 0.5 (the associated two-flank mechanism needs δ + ϱ < π/2; μ = 1 of "
           "Fig. 5 is its degenerate limit)."),
    Figure(PAPER, "fig8_cylinder_limit_evolution", _P + "configuration:cylinder_limit_evolution",
           "FIG. 8. Evolution of limit conditions in the displacement plane for a cylinder "
           "sliding on the layer of cylinders (d = 1, Q = 1, μ = 0.3, pushed at 20° to x from "
           "the groove to the top of its neighbour): the force axes translate with the stations "
           "1–6, a bar gives the force scale; right, the force T against the displacement |u|."),
    Figure(PAPER, "fig9_sphere_limit_evolution", _P + "configuration:sphere_limit_evolution",
           "FIG. 9. Evolution of limit conditions in the displacement plane for a sphere sliding "
           "on a layer sphere (d = 1, Q = 1, μ = 0.3, the layer sphere at (d/√3, 0), the path at "
           "30° to x beside its top): the limit curves translate, shrink and rotate with ψ; "
           "right, the force T against the displacement |u|."),
    Figure(PAPER, "fig10a_cap_surface", _P + "contact:cap_surface",
           "FIG. 10a. Yield surface (4.9) in the space T1, T2, N, with the stress paths from A "
           "and B, the peaks A′, B′, the asymptotic points A_c, B_c and the lines through them "
           f"({FIG10.describe()})."),
    Figure(PAPER, "fig10b_cap_hardening", _P + "contact:cap_hardening",
           "FIG. 10b. Variation of the characteristic contact function A(κ, β) with β and κ "
           f"(p = {FIG10.p:g}, h = {FIG10.h:g}, κh = {FIG10.kappa_h:g})."),
    Figure(PAPER, "fig10c_cap_shear_curves", _P + "contact:cap_shear_curves",
           "FIG. 10c. Tangential force–displacement curves for fixed values of N: test A "
           f"(N = {FIG10.normal_forces[0]:g} < A0) peaks at A′ and softens to A_c, test B "
           f"(N = {FIG10.normal_forces[1]:g} > A0) rises to B′ and slowly diminishes to B_c "
           f"({FIG10.describe()})."),
    Figure(EXTRA, "orthotropic_friction_polar", _P + "laws:directional_friction",
           "Friction coefficient μ(θ) for sliding at θ of the three orthotropic rules: elliptic "
           "with normality (1.15), Huber (1.16) and transformed Coulomb (1.17), μx = 0.6, μy = 0.3."),
    Figure(EXTRA, "heightmap_friction_polar", _P + "asperities:heightmap_polar",
           "Friction coefficient μ(θ) of a synthetic machined 512 × 512 height map (grooves along "
           "y plus roughness) as a facet set with local μ = 0.2."),
    Figure(EXTRA, "softening_exact_vs_incremental", _P + "configuration:softening_curve",
           "Contact softening: the force along the motion that keeps a grain sliding against the "
           "distance travelled, exact and from the incremental rate form (3.3)–(3.13) with 40 "
           "Euler steps, for a cylinder over two neighbours and a sphere over and beside the top "
           "of a layer sphere (μ = 0.3)."),
    Figure(EXTRA, "pocket_breakout_force_polar", _P + "configuration:pocket_peak_force",
           "Peak force |T|/Q to push a sphere out of a square or hexagonal pocket against the "
           "direction of the force (thick: riding the ridge between two layer spheres) and of a "
           "straight displacement (dashed), μ = 0.3."),
)

#: "module:function" of every key-number table.
KEY_NUMBERS: tuple[str, ...] = (
    "frictionrules.laws.summary:key_numbers",
    "frictionrules.asperities.summary:key_numbers",
    "frictionrules.configuration.summary:key_numbers",
    "frictionrules.contact.summary:key_numbers",
)

def _resolve(target: str):
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def select(names=None, argument: str = "names") -> tuple[Figure, ...]:
    """The registered figures named in ``names`` (stems or ``folder/stem``), all when ``None``.

    Raises :class:`FrictionRulesError` naming ``argument`` for a name that is not a figure.
    """
    if names is None:
        return FIGURES
    from .errors import FrictionRulesError
    known = {f.stem: f for f in FIGURES} | {f.name: f for f in FIGURES}
    for name in names:
        if name not in known:
            raise FrictionRulesError(f"{argument} {name!r} is not a figure; choose from "
                                     f"{', '.join(f.stem for f in FIGURES)}")
    wanted = {known[name] for name in names}
    return tuple(f for f in FIGURES if f in wanted)


def save_figure(fig, path, figure: Figure | None = None) -> Path:
    """Save ``fig`` to ``path`` (PNG, SVG or PDF by the suffix) atomically, with the umask's
    permissions and the same bytes on every run (fixed SVG ids, no dates); the metadata name
    the package version and, when given, the registered ``figure`` and its caption."""
    meta = provenance(figure=figure.name, caption=figure.caption) if figure else provenance()
    return write_figure(fig, path, metadata=meta, bbox_inches="tight")


def make_figures(out_dir, formats=("png", "svg"), names=None, progress=None) -> list[Path]:
    """Draw the registered figures (or those in ``names``), save them under ``out_dir``
    (``paper/`` and ``extra/``) in each of ``formats``, update ``out_dir/index.md`` and return
    the paths of the figure files.

    ``progress``, if given, is called as ``progress(done, total)`` after each figure.
    """
    check_requirements()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = Path(out_dir)
    chosen = select(names)
    written = []
    for k, figure in enumerate(chosen, start=1):
        ax = _resolve(figure.target)()
        for fmt in formats:
            written.append(save_figure(ax.figure, out_dir / f"{figure.name}.{fmt}", figure))
        plt.close(ax.figure)
        if progress is not None:
            progress(k, len(chosen))
    write_index(out_dir)
    return written


def write_index(out_dir) -> Path:
    """Write ``out_dir/index.md``: every registered figure found in ``out_dir``, with its files
    and caption, the paper's first."""
    out_dir = Path(out_dir)
    from ._version import __version__
    lines = ["# Figures", "",
             f"Made by `frictionrules paper` (frictionrules {__version__}). `{PAPER}/`: the figures "
             "of Michałowski & Mróz (1978), numbered as in the paper, computed by the library; "
             f"`{EXTRA}/`: figures beyond the paper.", ""]
    for folder, heading in ((PAPER, "The paper's figures"), (EXTRA, "Beyond the paper")):
        rows = []
        for f in FIGURES:
            files = sorted(p.name for p in (out_dir / f.folder).glob(f"{f.stem}.*")
                           if p.suffix in FIGURE_SUFFIXES)
            if f.folder == folder and files:
                links = ", ".join(f"[{p.rsplit('.', 1)[-1]}]({folder}/{p})" for p in files)
                caption = f.caption.replace("|", "\\|")          # a pipe would end the cell
                rows.append(f"| `{f.stem}` ({links}) | {caption} |")
        if rows:
            lines += [f"## {heading} (`{folder}/`)", "", "| figure | caption |", "|---|---|", *rows, ""]
    return write_text(out_dir / "index.md", "\n".join(lines) + "\n")


def key_numbers() -> list[tuple[str, str, str]]:
    """Rows ``(quantity, value, reference)`` from every registered table."""
    check_requirements()
    rows = []
    for target in KEY_NUMBERS:
        rows.extend(_resolve(target)())
    return rows


#: Widest line of :func:`format_table` (a terminal of 100 columns shows it unwrapped).
TABLE_WIDTH = 100


def format_table(rows, width: int = TABLE_WIDTH) -> str:
    """Plain-text table of ``(quantity, value, reference)`` rows, no line wider than ``width``.

    Consecutive rows whose quantities start with the same subject (``"wedge alpha=30 deg, mu=0.5:
    limit curve"``) are listed under that subject; a cell too long for its column continues on
    the next lines of its row.
    """
    import textwrap
    head = ("quantity", "value", "paper")
    rows = [tuple(map(str, r)) for r in rows]
    entries = []                                    # (heading or None, row)
    for k, (quantity, value, ref) in enumerate(rows):
        subject, sep, rest = quantity.partition(": ")
        shared = sep and any(rows[j][0].startswith(subject + ": ") for j in (k - 1, k + 1)
                             if 0 <= j < len(rows))
        entries.append((subject if shared else None, ("  " + rest if shared else quantity, value, ref)))
    natural = [max(len(r[i]) for r in [head, *(row for _, row in entries)]) for i in range(3)]
    value_w, ref_w = min(natural[1], 30), min(natural[2], 18)
    widths = [min(natural[0], width - value_w - ref_w - 4), value_w, ref_w]
    line = "  ".join("{:<%d}" % w for w in widths)
    out = [line.format(*head), line.format(*("-" * w for w in widths))]
    previous = None
    for heading, row in entries:
        if heading is not None and heading != previous:
            out.append(textwrap.shorten(heading, width))
        previous = heading
        indent = "    " if row[0].startswith("  ") else "  "
        cells = [textwrap.wrap(cell, w, subsequent_indent=indent if i == 0 else "  ") or [""]
                 for i, (cell, w) in enumerate(zip(row, widths))]
        for j in range(max(map(len, cells))):
            out.append(line.format(*(c[j] if j < len(c) else "" for c in cells)))
    return "\n".join(r.rstrip() for r in out)
