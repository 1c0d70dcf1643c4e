"""Figures of grain assemblies: the response of a test (stress ratio and volumetric strain
against axial strain), the coordination and sliding fraction of a dynamic run, the
contact-force network, and the roses of contact normals and of mobilized friction. Each
function takes ``ax=None`` (or ``axes``) and returns what it drew on; :func:`plot_dem_run`
puts a dynamic run's four panels on one figure; :func:`plot_ensemble` draws the mean curves of
an ensemble with their confidence bands.
"""

from __future__ import annotations

import numpy as np

__all__ = ["plot_response", "plot_coordination", "force_network", "normal_rose", "friction_rose",
           "plot_dem_run", "plot_ensemble"]


_PLANES = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}


def _axes(ax, polar=False, size=(5.0, 4.0)):
    if ax is None:
        import matplotlib.pyplot as plt
        ax = plt.figure(figsize=size).add_subplot(111, projection="polar" if polar else None)
    return ax


def plot_response(result, axes=None, label=None, linestyle="-", title=None):
    r"""Stress ratio σ1/σ3 (left) and volumetric strain ε_v (right, compression positive)
    against the axial strain ε_a of a :class:`TriaxialResult`, both strains as fractions (as
    the result and the command line give them); the peak is marked with a circle (a dynamic
    run: a dotted line at the peak of the ratio's running mean), which the legend of the left
    Axes names. Returns the two Axes.

    ``title`` goes over the left Axes; by default it names the test and, for a single run
    (``label`` None), its peak and friction angle. Several runs on the same Axes: pass
    ``label`` for each (the legend lists them).
    """
    if axes is None:
        import matplotlib.pyplot as plt
        _, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    a, b = axes
    ok = result.converged
    x = result.axial_strain[ok]
    (line,) = a.plot(x, result.stress_ratio[ok], label=label, linestyle=linestyle)
    named = any(h.get_label() in (_PEAK, _PEAK_MEAN) for h in a.lines)
    if result.failed and getattr(result, "method", "implicit") == "dem":
        # the peak of a dynamic run is that of the running mean (the ratio fluctuates about it)
        a.axhline(result.peak_ratio, color=line.get_color(), lw=0.8, ls=":",
                  label="_" if named else _PEAK_MEAN)
    elif result.failed:
        k = int(np.argmax(np.where(ok, result.stress_ratio, -np.inf)))
        a.plot(result.axial_strain[k], result.stress_ratio[k], "o", color=line.get_color(), ms=4,
               label="_" if named else _PEAK)
    a.set_xlabel(r"axial strain $\varepsilon_a$ (compression > 0)")
    a.set_ylabel(r"stress ratio $\sigma_1/\sigma_3$")
    b.plot(x, result.volumetric_strain[ok], color=line.get_color(), label=label,
           linestyle=linestyle)
    b.set_xlabel(r"axial strain $\varepsilon_a$ (compression > 0)")
    b.set_ylabel(r"volumetric strain $\varepsilon_v$ (compression > 0)")
    for ax in axes:
        _strain_axis(ax)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3), useMathText=True)
    if title is None:
        title = f"{result.kind.replace('_', ' ')} test"
        if label is None:
            title += (rf": peak $\sigma_1/\sigma_3$ = {result.peak_ratio:.4g}, friction angle "
                      f"{result.peak_friction_angle:.3g}°" if result.failed else ": no failure")
    a.set_title(title, fontsize=9)
    if any(not h.get_label().startswith("_") for h in a.lines):
        a.legend(fontsize=7)
    return axes


#: Legend entries of the peak markers.
_PEAK = r"peak $\sigma_1/\sigma_3$"
_PEAK_MEAN = r"peak of the running mean"


def _strain_axis(ax) -> None:
    ax.set_xlabel(r"axial strain $\varepsilon_a$ (compression > 0)")
    ax.locator_params(axis="x", nbins=5)
    ax.ticklabel_format(axis="x", style="sci", scilimits=(-2, 3), useMathText=True)
    ax.grid(alpha=0.3)


def plot_coordination(result, ax=None):
    r"""A dynamic run's coordination against axial strain: ``Z = 2 N_c/N`` (force-carrying
    contacts per grain), ``Z`` without rattlers (the mechanical coordination
    ``(2 N_c - N_1)/(N - N_0 - N_1)``, ``N_0``, ``N_1`` grains with none or one force-carrying
    contact) on the left axis, and the fraction of the force-carrying contacts that slide on
    the right one. Returns ``(ax, right)``, the two Axes."""
    if result.coordination_without_rattlers is None:
        raise ValueError("plot_coordination draws a dynamic run (method='dem'): the implicit "
                         "path records no sliding fraction")
    ax = _axes(ax)
    x = result.axial_strain
    ax.plot(x, result.coordination, color="C0", label="$Z$")
    ax.plot(x, result.coordination_without_rattlers, color="C0", ls="--",
            label="$Z$ without rattlers")
    ax.set_ylabel("coordination $Z$", color="C0")
    right = ax.twinx()
    right.plot(x, result.sliding_fraction, color="C3", label="sliding fraction")
    right.set_ylabel("sliding fraction", color="C3")
    right.set_ylim(0, max(0.05, 1.15 * float(np.max(result.sliding_fraction))))
    _strain_axis(ax)
    lines = ax.lines + right.lines
    ax.legend(lines, [h.get_label() for h in lines], fontsize=7, loc="upper right")
    return ax, right


def _geometry(result, increment: int):
    """Grain centres and cell at an increment: a dynamic run has them at every record, the
    implicit path at its last increment only."""
    if result.positions is not None:
        return result.positions[increment], result.cells[increment]
    if increment not in (-1, len(result.contacts) - 1):
        raise ValueError("force_network draws the implicit path's last increment (the state it "
                         "has positions for)")
    return result.final.positions, result.final.cell


def _segments(snapshot, x, h, plane):
    """End points of the branch vectors of the contacts (grain ``i`` to the image of ``j``),
    centres wrapped into the cell, projected on ``plane``; and each branch's midpoint's
    distance from the cell's middle plane parallel to ``plane`` (3-D; zeros in 2-D)."""
    i, j, k = snapshot.grains[:, 0], snapshot.grains[:, 1], snapshot.shift
    wrapped = x - np.floor(np.linalg.solve(h, x.T).T) @ h.T
    start = wrapped[i]
    end = start + (x[j] + k @ h.T - x[i])
    axes = _PLANES[plane] if x.shape[1] == 3 else (0, 1)
    depth = np.zeros(len(i))
    if x.shape[1] == 3:
        (c,) = {0, 1, 2} - set(axes)
        a, b = h[:, axes[0]], h[:, axes[1]]
        across = abs(np.linalg.det(h)) / np.linalg.norm(np.cross(a, b))  # between the faces
        frac = np.linalg.solve(h, (0.5 * (start + end)).T)[c]
        depth = np.abs(frac - 0.5) * across
    return start[:, axes], end[:, axes], depth


def _slab_of(x, h, slab):
    """The slab's thickness drawn by :func:`force_network` (None: the whole sample)."""
    if x.shape[1] != 3:
        return None
    if slab is None:
        slab = 5.0 * (abs(np.linalg.det(h)) / len(x)) ** (1.0 / 3.0)
    elif not slab > 0:
        from ..errors import FrictionRulesError
        raise FrictionRulesError(f"slab = {slab!r} violates: > 0 (a length) or None")
    return float(slab)


def force_network(result, increment: int = -1, ax=None, plane: str = "xz", slab=None):
    """The contact-force network at an increment (a dynamic run: a record): the branch
    vectors of the force-carrying contacts, from grain ``i`` to the image of ``j`` across the
    periodic boundary, drawn with widths proportional to the normal force ``N``; the cell is
    outlined.

    In 3-D it draws the contacts whose branch midpoints lie in a slab of thickness ``slab``
    (a length) about the cell's middle plane parallel to ``plane``, projected on it: by
    default five mean grain spacings ``(V/n)^{1/3}`` (about five diameters), so that a large
    sample's network stays legible; the whole sample when it is thinner than the slab."""
    import matplotlib.collections as mc
    ax = _axes(ax)
    snap = result.contacts[increment]
    x, h = _geometry(result, increment)
    start, end, depth = _segments(snap, x, h, plane)
    thickness = _slab_of(x, h, slab)
    N = snap.force[:, 2]
    closed = N > 0
    if thickness is not None:
        closed &= depth <= 0.5 * thickness
    width = 3 * N[closed] / N[closed].max() if closed.any() else []
    ax.add_collection(mc.LineCollection(np.stack((start[closed], end[closed]), axis=1),
                                        linewidths=width, colors="k", capstyle="round"))
    axes = _PLANES[plane] if x.shape[1] == 3 else (0, 1)
    corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]], float)
    box = np.zeros((5, x.shape[1]))
    box[:, list(axes)] = corners
    outline = box @ h.T
    ax.plot(outline[:, axes[0]], outline[:, axes[1]], color="C0", lw=0.8, ls="--")
    ax.set_aspect("equal")
    ax.autoscale()
    names = plane if x.shape[1] == 3 else "xy"
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1])
    return ax


def _angles(snapshot, plane):
    n = snapshot.frame[:, 2, :]
    a, b = _PLANES[plane]
    ang = np.arctan2(n[:, b], n[:, a])
    return np.concatenate((ang, ang + np.pi))  # both directions of each normal


def normal_rose(result, increment: int = -1, ax=None, plane: str = "xz", bins: int = 36):
    """Rose (polar histogram) of the closed contacts' normals in ``plane`` at an increment."""
    ax = _axes(ax, polar=True)
    snap = result.contacts[increment]
    closed = snap.force[:, 2] > 0
    sub = type(snap)(snap.grains[closed], snap.shift[closed], snap.frame[closed], snap.force[closed],
                     snap.slip[closed], snap.status[closed], snap.states, snap.group[closed])
    ang = _angles(sub, plane)
    counts, edges = np.histogram(np.mod(ang, 2 * np.pi), bins=bins, range=(0, 2 * np.pi))
    ax.bar(edges[:-1], counts / max(counts.max(), 1), width=edges[1] - edges[0], align="edge",
           color="C0", alpha=0.7)
    ax.set_yticklabels([])
    ax.set_title(f"contact normals ({plane})", fontsize=9)
    return ax


def friction_rose(result, increment: int = -1, ax=None, plane: str = "xz", bins: int = 36):
    """Rose of mobilized friction ``|T|/N``, averaged over the closed contacts whose normal
    falls in each direction of ``plane``."""
    ax = _axes(ax, polar=True)
    snap = result.contacts[increment]
    closed = snap.force[:, 2] > 0
    mob = snap.mobilized_friction[closed]
    n = snap.frame[closed, 2, :]
    a, b = _PLANES[plane]
    ang = np.arctan2(n[:, b], n[:, a])
    ang = np.mod(np.concatenate((ang, ang + np.pi)), 2 * np.pi)
    mob = np.concatenate((mob, mob))
    sums, edges = np.histogram(ang, bins=bins, range=(0, 2 * np.pi), weights=mob)
    counts, _ = np.histogram(ang, bins=bins, range=(0, 2 * np.pi))
    mean = np.divide(sums, counts, out=np.zeros_like(sums), where=counts > 0)
    ax.bar(edges[:-1], mean, width=edges[1] - edges[0], align="edge", color="C3", alpha=0.7)
    top = float(mean.max()) if mean.max() > 0 else 1.0
    ax.set_rticks([0.5 * top, top])  # two labelled rings: more crowd the centre
    ax.set_rlabel_position(22.5)
    ax.tick_params(axis="y", labelsize=7)
    ax.set_title(f"mobilized friction |T|/N ({plane})", fontsize=9)
    return ax


def plot_dem_run(result, increment: int = -1, plane: str = "xz"):
    """A dynamic run on one figure: σ1/σ3 and volumetric strain (:func:`plot_response`), the
    coordination and sliding fraction (:func:`plot_coordination`) against axial strain, and
    the force network at a record (:func:`force_network`). Returns the (2, 2) array of Axes
    (the right axis of the coordination panel is ``plot_coordination``'s)."""
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 2, figsize=(9.5, 7.5))
    plot_response(result, axes=axes[0])
    plot_coordination(result, ax=axes[1, 0])
    x, h = _geometry(result, increment)
    thickness = _slab_of(x, h, None)  # the default slab, drawn and named in the title
    force_network(result, increment, ax=axes[1, 1], plane=plane, slab=thickness)
    k = increment % len(result.contacts)
    where = "" if thickness is None else f", a slab {thickness:.3g} thick"
    axes[1, 1].set_title(rf"normal forces at $\varepsilon_a$ = {result.axial_strain[k]:.3g} "
                         f"(width ∝ N{where})", fontsize=9)
    fig.tight_layout()
    return axes


_CURVE_LABELS = {"stress_ratio": r"stress ratio $\sigma_1/\sigma_3$",
                 "friction_angle": r"mobilized friction angle $\varphi$ (deg)",
                 "volumetric_strain": r"volumetric strain $\varepsilon_v$ (compression > 0)",
                 "coordination": r"coordination $Z$"}


def plot_ensemble(result, quantity: str = "stress_ratio", ax=None, condition=None):
    r"""The mean curve of ``quantity`` against the axial strain over the completed runs of an
    :class:`~frictionrules.EnsembleResult`, with its 95 % band (the Student-t confidence
    interval of the mean at each strain, :meth:`~frictionrules.EnsembleResult.curve`); one
    curve per condition (or only ``condition``). Where a condition has one run, its curve is
    drawn without a band and the legend says ``n = 1``. Returns the Axes.

    ``quantity``: "stress_ratio" (σ1/σ3), "friction_angle" (:math:`\sin\varphi = (R-1)/(R+1)`,
    degrees), "volumetric_strain" (compression positive) or "coordination".
    """
    ax = _axes(ax)
    conditions = range(len(result.summary)) if condition is None else [condition]
    for c in conditions:
        curve = result.curve(quantity, c)
        if curve.n == 0:
            continue
        s = result.summary[c]
        where = ", ".join(f"{k} = {v}" for k, v in s.options.items())
        label = f"{where + ', ' if where else ''}n = {curve.n}"
        if len(result.summary) > 1 and not where:
            label = f"condition {c}, {label}"
        (line,) = ax.plot(curve.axial_strain, curve.mean, label=label)
        if curve.n > 1:
            ax.fill_between(curve.axial_strain, curve.low, curve.high, color=line.get_color(),
                            alpha=0.25, lw=0)
    ax.set_ylabel(_CURVE_LABELS.get(quantity, quantity))
    _strain_axis(ax)
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3), useMathText=True)
    ax.set_title("mean of the runs, 95 % band", fontsize=9)
    if ax.lines:
        ax.legend(fontsize=7)
    return ax
