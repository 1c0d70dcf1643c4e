"""Layout helpers shared by the figures: legends beside the data, labels on free ground,
arrows as patches (so that legends and labels can avoid them).

Everything here works in display coordinates after the data limits are final: call
:func:`place_labels` last, once the curves are drawn and the limits set.
"""

from __future__ import annotations

import numpy as np

#: Offsets (points) tried around a label's anchor, with the alignment that keeps the text on
#: that side of the anchor: right, above, left, below, then the diagonals, then farther out.
_SIDES = ((1, 0, "left", "center"), (0, 1, "center", "bottom"), (-1, 0, "right", "center"),
          (0, -1, "center", "top"), (1, 1, "left", "bottom"), (-1, 1, "right", "bottom"),
          (-1, -1, "right", "top"), (1, -1, "left", "top"))


def legend_beside(ax, where: str = "right", **kw):
    """Legend outside the axes and their tick labels (``"right"`` or ``"below"``), so that it
    never covers data. Call it once the axis labels are set."""
    kw.setdefault("fontsize", 7)
    kw.setdefault("handler_map", arrow_handler_map())
    if ax.get_legend() is not None:
        ax.get_legend().remove()
    fig = ax.figure
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    if ax.name == "3d":     # its box has wide empty margins: go by the axis and tick labels
        from matplotlib.transforms import Bbox
        texts = [a.label for a in (ax.xaxis, ax.yaxis, ax.zaxis)]
        texts += [t for a in (ax.xaxis, ax.yaxis, ax.zaxis) for t in a.get_ticklabels()]
        box = Bbox.union([t.get_window_extent(renderer) for t in texts if t.get_text()])
    else:
        box = ax.get_tightbbox(renderer)
    x1, y0 = ax.transAxes.inverted().transform((box.x1, box.y0))
    if where == "right":
        return ax.legend(loc="upper left", bbox_to_anchor=(x1 + 0.02, 1.0), borderaxespad=0.0, **kw)
    return ax.legend(loc="upper center", bbox_to_anchor=(0.5, y0 - 0.02), borderaxespad=0.0, **kw)


def arrow(ax, start, end, color, lw: float = 1.2, **kw):
    """Arrow from ``start`` to ``end`` in data coordinates, kept inside the autoscaled view.

    A :class:`~matplotlib.patches.FancyArrowPatch` in ``ax.patches``: legends and label
    placement see it as data, and with ``label=...`` it appears in the legend as an arrow
    (:func:`legend_beside` passes :func:`arrow_handler_map`).
    """
    from matplotlib.patches import FancyArrowPatch
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    patch = FancyArrowPatch(tuple(start), tuple(end), arrowstyle="->", mutation_scale=10,
                            color=color, lw=lw, shrinkA=0, shrinkB=0, **kw)
    ax.add_patch(patch)
    ax.update_datalim(np.stack((start, end)))
    ax.autoscale_view()
    return patch


def data_points(ax, spacing: float = 1.0) -> np.ndarray:
    """Display coordinates ``(n, 2)`` of everything drawn as data on ``ax``: lines (densified
    to ``spacing`` pixels), markers, scatter points, collection paths and arrow patches, as far
    as they lie within the axes."""
    from matplotlib.collections import PathCollection
    from matplotlib.patches import FancyArrowPatch

    out = [np.zeros((0, 2))]
    for line in ax.lines:
        if line.get_visible() and len(line.get_xydata()):
            out.append(_dense(line.get_xydata(), line.get_transform(), spacing))
    for coll in ax.collections:
        if not coll.get_visible():
            continue
        if isinstance(coll, PathCollection) and len(coll.get_offsets()):
            out.append(coll.get_offset_transform().transform(np.asarray(coll.get_offsets())))
            continue
        for path in coll.get_paths():
            for poly in path.to_polygons(closed_only=False):
                out.append(_dense(poly, coll.get_transform(), spacing))
    for patch in ax.patches:
        if isinstance(patch, FancyArrowPatch) and patch.get_visible():
            for poly in patch.get_path().to_polygons(closed_only=False):
                out.append(_dense(poly, patch.get_transform(), spacing))
    pts = np.concatenate(out)
    box = ax.bbox                 # the artists are clipped to the axes
    keep = ((pts[:, 0] >= box.x0) & (pts[:, 0] <= box.x1) & (pts[:, 1] >= box.y0) & (pts[:, 1] <= box.y1))
    return pts[keep]


def _dense(xy, transform, spacing):
    """Points of the polyline ``xy`` (in the coordinates of ``transform``) in display
    coordinates, subdivided so that consecutive points are at most ``spacing`` pixels apart;
    a non-finite point is a gap in the line."""
    xy = np.asarray(xy, dtype=float)
    bad = ~np.all(np.isfinite(xy), axis=1)
    if bad.any():
        pieces = np.split(xy, np.flatnonzero(bad))
        return np.concatenate([np.zeros((0, 2))] + [_dense(p[np.all(np.isfinite(p), axis=1)],
                                                           transform, spacing) for p in pieces])
    if len(xy) < 2:
        return transform.transform(xy) if len(xy) else np.zeros((0, 2))
    disp = transform.transform(xy)
    seg = np.hypot(*np.diff(disp, axis=0).T)
    k = np.maximum(1, np.ceil(np.where(np.isfinite(seg), seg, 0.0) / spacing)).astype(int)
    idx = np.repeat(np.arange(len(k)), k)
    t = (np.arange(len(idx)) - np.repeat(np.cumsum(k) - k, k) + 1.0) / k[idx]
    dense = xy[idx] + t[:, None] * (xy[idx + 1] - xy[idx])
    return transform.transform(np.concatenate((xy[:1], dense)))


def hits(bbox, points, pad: float = 0.0) -> bool:
    """True if any of ``points`` (display coordinates) lies inside ``bbox`` grown by ``pad``."""
    x0, y0, x1, y1 = bbox.x0 - pad, bbox.y0 - pad, bbox.x1 + pad, bbox.y1 + pad
    p = points
    return bool(np.any((p[:, 0] > x0) & (p[:, 0] < x1) & (p[:, 1] > y0) & (p[:, 1] < y1)))


def place_labels(ax, labels, distances=(5.0, 10.0, 16.0, 24.0), pad: float = 1.5,
                 drop: bool = False):
    """Move each annotation of ``labels`` (``textcoords="offset points"``) to the first
    position around its anchor where its box touches no data, no other label and stays inside
    the axes; where there is none it stays where it was, or with ``drop`` it is removed (only
    readable labels remain). Returns the labels kept."""
    fig = ax.figure
    fig.draw_without_rendering()                       # final limits, aspect and layout
    renderer = fig.canvas.get_renderer()
    points = data_points(ax)
    inside = ax.get_window_extent(renderer)
    taken, kept = [], []
    for ann in labels:
        start = (tuple(ann.xyann), ann.get_ha(), ann.get_va())
        for r in distances:
            for sx, sy, ha, va in _SIDES:
                ann.xyann = (sx * r, sy * r)
                ann.set_ha(ha)
                ann.set_va(va)
                box = ann.get_window_extent(renderer)
                if (box.x0 >= inside.x0 and box.x1 <= inside.x1 and box.y0 >= inside.y0
                        and box.y1 <= inside.y1 and not hits(box, points, pad)
                        and not any(box.overlaps(t) for t in taken)):
                    break
            else:
                continue
            break
        else:
            if drop:
                ann.remove()
                continue
            ann.xyann, ha, va = start
            ann.set_ha(ha)
            ann.set_va(va)
        taken.append(ann.get_window_extent(renderer))
        kept.append(ann)
    return kept


def label(ax, text, xy, color="k", fontsize=8, **kw):
    """An annotation at ``xy`` (data) offset in points, ready for :func:`place_labels`."""
    return ax.annotate(text, xy, xytext=(5, 5), textcoords="offset points", color=color,
                       fontsize=fontsize, **kw)


def arrow_handler_map():
    """``handler_map`` that draws :class:`FancyArrowPatch` legend entries as arrows."""
    from matplotlib.legend_handler import HandlerPatch
    from matplotlib.patches import FancyArrowPatch

    class _Arrow(HandlerPatch):
        def create_artists(self, legend, orig, xdescent, ydescent, width, height, fontsize, trans):
            p = FancyArrowPatch((-xdescent, height / 2 - ydescent), (width - xdescent, height / 2 - ydescent),
                                arrowstyle="->", mutation_scale=10, color=orig.get_edgecolor(),
                                lw=orig.get_linewidth(), shrinkA=0, shrinkB=0)
            p.set_transform(trans)
            return [p]

    return {FancyArrowPatch: _Arrow()}


def polar_radius_labels(ax, angles=np.arange(0.0, 360.0, 7.5), pad: float = 1.5):
    """Put the radius tick labels of a polar ``ax`` along the first angle (degrees) where none
    of them touches a curve; where every angle has a clash, take the angle with the fewest and
    drop the ticks whose labels still touch a curve.

    Candidate angles are screened with each label's box moved to its place along the angle,
    and the chosen one is checked on a drawn figure."""
    fig = ax.figure
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    points = data_points(ax)
    rmax = ax.get_rmax()

    def labelled():
        locs = ax.yaxis.get_majorticklocs()
        return [(v, t) for v, t in zip(locs, ax.yaxis.get_ticklabels()) if t.get_text() and 0 < v <= rmax]

    def clashes(shift_to=None):
        out = []
        for v, t in labelled():
            box = t.get_window_extent(renderer)
            if shift_to is not None:     # the same box, moved with the tick to the new angle
                old = ax.transData.transform((np.deg2rad(ax.get_rlabel_position()), v))
                new = ax.transData.transform((np.deg2rad(shift_to), v))
                box = box.translated(*(new - old))
            if hits(box, points, pad):
                out.append(v)
        return out

    ranked = sorted(angles, key=lambda a: (len(clashes(a)), list(angles).index(a)))
    best = None
    for a in ranked[:8]:
        ax.set_rlabel_position(a)
        fig.draw_without_rendering()
        bad = clashes()
        if not bad:
            return ax
        if best is None or len(bad) < len(best[1]):
            best = (a, bad)
    ax.set_rlabel_position(best[0])
    ax.set_rticks([v for v in ax.yaxis.get_majorticklocs() if v not in best[1] and 0 < v <= rmax])
    ax.set_rmax(rmax)
    return ax
