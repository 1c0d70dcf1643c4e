"""Layout checks for the figures, in display coordinates, written independently of the
plotting helpers: the data of an Axes (lines, collections, arrows) is turned into points at
most one pixel apart, and a legend, a label or a polar tick label must not contain any of them."""

import numpy as np


def _polyline(disp):
    """Points of a display-space polyline, at most 1 px apart; a non-finite point is a gap."""
    bad = ~np.all(np.isfinite(disp), axis=1)
    if bad.any():
        pieces = np.split(disp, np.flatnonzero(bad))
        return np.concatenate([_polyline(p[np.all(np.isfinite(p), axis=1)]) for p in pieces])
    if len(disp) < 2:
        return disp
    a, b = disp[:-1], disp[1:]
    k = np.maximum(1, np.ceil(np.hypot(*(b - a).T))).astype(int)
    seg = np.repeat(np.arange(len(k)), k)
    t = (np.arange(seg.size) - np.repeat(np.cumsum(k) - k, k) + 1) / k[seg]
    return np.concatenate((disp[:1], a[seg] + t[:, None] * (b - a)[seg]))


def data_points(ax):
    """Display points of everything drawn as data, within the axes (the artists are clipped)."""
    ax.figure.canvas.draw()
    pts = [np.zeros((0, 2))]
    for line in ax.lines:
        xy = np.asarray(line.get_xydata(), dtype=float)
        if line.get_visible() and len(xy):
            if ax.name == "polar":   # an arc between two samples: interpolate in (theta, r)
                t = np.linspace(0, 1, 8, endpoint=False)[None, :, None]
                xy = np.concatenate(((xy[:-1, None] + t * (xy[1:] - xy[:-1])[:, None]).reshape(-1, 2),
                                     xy[-1:]))
            pts.append(_polyline(line.get_transform().transform(xy)))
    for artist in list(ax.collections) + list(ax.patches):
        paths = artist.get_paths() if hasattr(artist, "get_paths") else [artist.get_path()]
        for path in paths:
            for poly in path.to_polygons(closed_only=False):
                pts.append(_polyline(artist.get_transform().transform(poly)))
    pts = np.concatenate(pts)
    box = ax.bbox
    return pts[(pts[:, 0] >= box.x0) & (pts[:, 0] <= box.x1) & (pts[:, 1] >= box.y0) & (pts[:, 1] <= box.y1)]


def inside(bbox, pts, margin=1.0):
    return np.flatnonzero((pts[:, 0] > bbox.x0 + margin) & (pts[:, 0] < bbox.x1 - margin)
                          & (pts[:, 1] > bbox.y0 + margin) & (pts[:, 1] < bbox.y1 - margin))


def assert_readable(ax):
    """No legend over data, no label (ax.texts) struck by a curve, no polar tick label on a curve."""
    renderer = ax.figure.canvas.get_renderer()
    pts = data_points(ax)
    legend = ax.get_legend()
    if legend is not None:
        hit = inside(legend.get_window_extent(renderer), pts)
        assert not len(hit), f"legend covers data at {pts[hit[0]]}"
    inline = {id(t) for c in ax.collections for t in getattr(c, "labelTexts", ())}
    for text in ax.texts:
        if id(text) in inline:      # contour labels sit in a gap cut into their own line
            continue
        hit = inside(text.get_window_extent(renderer), pts)
        assert not len(hit), f"label {text.get_text()!r} is crossed by data"
    if ax.name == "polar":
        lo, hi = ax.get_ylim()
        for r, text in zip(ax.yaxis.get_majorticklocs(), ax.yaxis.get_ticklabels()):
            if text.get_visible() and text.get_text() and lo < r <= hi:
                hit = inside(text.get_window_extent(renderer), pts)
                assert not len(hit), f"polar tick label {text.get_text()!r} sits on a curve"
