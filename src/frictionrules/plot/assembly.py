"""Figures of grain assemblies: the response of a test (stress ratio and volumetric strain
against axial strain), the contact-force network, and the roses of contact normals and of
mobilized friction. Each function takes ``ax=None`` (or ``axes``) and returns what it drew on.
"""

from __future__ import annotations

import numpy as np

__all__ = ["plot_response", "force_network", "normal_rose", "friction_rose"]


def _axes(ax, polar=False, size=(5.0, 4.0)):
    if ax is None:
        import matplotlib.pyplot as plt
        ax = plt.figure(figsize=size).add_subplot(111, projection="polar" if polar else None)
    return ax


def plot_response(result, axes=None, label=None, linestyle="-", title=None):
    r"""Stress ratio σ1/σ3 (left) and volumetric strain ε_v (right, compression positive)
    against the axial strain ε_a of a :class:`TriaxialResult`, both strains as fractions (as
    the result and the command line give them); the peak is marked with a circle, which the
    legend of the left Axes names. Returns the two Axes.

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
    if result.failed:
        k = int(np.argmax(np.where(ok, result.stress_ratio, -np.inf)))
        named = any(h.get_label() == _PEAK for h in a.lines)
        a.plot(result.axial_strain[k], result.stress_ratio[k], "o", color=line.get_color(), ms=4,
               label="_" if named else _PEAK)
    a.set_xlabel(r"axial strain $\varepsilon_a$ (compression > 0)")
    a.set_ylabel(r"stress ratio $\sigma_1/\sigma_3$")
    b.plot(x, result.volumetric_strain[ok], color=line.get_color(), label=label,
           linestyle=linestyle)
    b.set_xlabel(r"axial strain $\varepsilon_a$ (compression > 0)")
    b.set_ylabel(r"volumetric strain $\varepsilon_v$ (compression > 0)")
    for ax in axes:
        ax.locator_params(axis="x", nbins=5)
        ax.ticklabel_format(style="sci", scilimits=(-2, 3), useMathText=True)  # ×10⁻⁴ at the end
        ax.grid(alpha=0.3)
    if title is None:
        title = f"{result.kind.replace('_', ' ')} test"
        if label is None:
            title += (rf": peak $\sigma_1/\sigma_3$ = {result.peak_ratio:.4g}, friction angle "
                      f"{result.peak_friction_angle:.3g}°" if result.failed else ": no failure")
    a.set_title(title, fontsize=9)
    if any(not h.get_label().startswith("_") for h in a.lines):
        a.legend(fontsize=7)
    return axes


#: Legend entry of the peak marker.
_PEAK = r"peak $\sigma_1/\sigma_3$"


def _segments(snapshot, state, plane):
    """End points of the branch vectors of the contacts, projected on ``plane``."""
    x, h = state.positions, state.cell
    i, j, k = snapshot.grains[:, 0], snapshot.grains[:, 1], snapshot.shift
    start = x[i]
    end = x[j] + k @ h.T
    axes = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}[plane] if x.shape[1] == 3 else (0, 1)
    return start[:, axes], end[:, axes]


def force_network(result, increment: int = -1, ax=None, plane: str = "xz"):
    """The contact-force network at an increment: the branch vectors of the closed contacts
    drawn with widths proportional to the normal force (a projection on ``plane`` in 3-D)."""
    import matplotlib.collections as mc
    ax = _axes(ax)
    snap = result.contacts[increment]
    state = result.final if increment in (-1, len(result.contacts) - 1) else None
    if state is None:
        raise ValueError("force_network draws the last increment (the state it has positions for)")
    start, end = _segments(snap, state, plane)
    N = snap.force[:, 2]
    closed = N > 0
    width = 4 * N[closed] / N[closed].max() if closed.any() else []
    ax.add_collection(mc.LineCollection(np.stack((start[closed], end[closed]), axis=1),
                                        linewidths=width, colors="k"))
    ax.set_aspect("equal")
    ax.autoscale()
    names = plane if state.positions.shape[1] == 3 else "xy"
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1])
    return ax


def _angles(snapshot, plane):
    n = snapshot.frame[:, 2, :]
    a, b = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}[plane]
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
    a, b = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}[plane]
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
