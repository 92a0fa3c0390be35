"""The internal area ``A_I``: a convex region around the model's pixels (appendix I, §2.1, §5.6).

Labels go outside ``A_I`` (the external area ``A_E``); leaders run from an anchor inside
a part to the boundary of ``A_I``.  Three shapes are offered (appendix I, Fig. 6):

* ``"hull"`` (default): the convex hull of the model's pixels grown by ``margin`` pixels
  (the Minkowski sum with a disc, approximated by a 64-gon per hull corner);
* ``"circle"``: a circle around the hull (centre of its bounding box, radius to the
  farthest hull corner) plus ``margin``;
* ``"rectangle"``: the bounding box of the model's pixels plus ``margin``.

All three are convex polygons, which is what makes the leader candidates crossing-free
(appendix I, §5.2).  The polygon is rasterised on a grid padded by ``pad`` pixels on every
side so that it is never clipped by the image border (the distance transforms then see the
true boundary).  Coordinates are pixel coordinates of the *image*: x right, y down, pixel
(r, c) covering ``[c, c+1) x [r, r+1)`` with its centre at ``(c + 0.5, r + 0.5)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.errors import ParameterError

from ._kernels import scanline_mask

SHAPES = ("hull", "circle", "rectangle")


@dataclass
class InternalArea:
    """A rasterised convex internal area.

    Attributes
    ----------
    kind : "hull", "circle" or "rectangle"
    margin : float
        Growth in pixels
    polygon : (k, 2) float
        The corners of the boundary in order, not closed
    pad : int
        Padding of the raster grid on every side
    mask : (h + 2 pad, w + 2 pad) bool
        Pixel centres inside the polygon (padded grid)
    left, right : (h + 2 pad,) float
        X of the boundary on each padded row (NaN: row empty)
    top, bottom : (w + 2 pad,) float
        Y of the boundary on each padded column (NaN: empty)
    integral : (h + 2 pad + 1, w + 2 pad + 1) int32
        Summed-area table of ``mask``
    """

    kind: str
    margin: float
    polygon: np.ndarray
    pad: int
    mask: np.ndarray
    left: np.ndarray
    right: np.ndarray
    top: np.ndarray
    bottom: np.ndarray
    integral: np.ndarray

    @property
    def image_mask(self) -> np.ndarray:
        """(h, w) bool, the part of the mask inside the image."""
        p = self.pad
        return self.mask[p:-p, p:-p]

    @property
    def bbox(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1) of the polygon, image coordinates."""
        lo, hi = self.polygon.min(axis=0), self.polygon.max(axis=0)
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])

    @property
    def centroid(self) -> np.ndarray:
        """Centre of the pixels of the area, image coordinates."""
        rows, cols = self.mask.sum(axis=1), self.mask.sum(axis=0)
        n = max(int(rows.sum()), 1)
        r = float(rows @ np.arange(len(rows))) / n
        c = float(cols @ np.arange(len(cols))) / n
        return np.array([c + 0.5 - self.pad, r + 0.5 - self.pad])

    def boxes_hit(self, boxes: np.ndarray) -> np.ndarray:
        """Number of area pixels (centres) inside each box ``(n, 4)`` = (x0, y0, x1, y1).

        Uses the summed-area table: O(1) per box.
        """
        boxes = np.asarray(boxes, np.float64).reshape(-1, 4)
        hp, wp = self.mask.shape
        p = self.pad
        # pixel columns whose centre lies in [x0, x1]: c + 0.5 >= x0  <=>  c >= ceil(x0 - 0.5)
        c0 = np.clip(np.ceil(boxes[:, 0] - 0.5 + p), 0, wp).astype(np.int64)
        c1 = np.clip(np.floor(boxes[:, 2] - 0.5 + p) + 1, 0, wp).astype(np.int64)
        r0 = np.clip(np.ceil(boxes[:, 1] - 0.5 + p), 0, hp).astype(np.int64)
        r1 = np.clip(np.floor(boxes[:, 3] - 0.5 + p) + 1, 0, hp).astype(np.int64)
        c1 = np.maximum(c1, c0)
        r1 = np.maximum(r1, r0)
        s = self.integral
        return s[r1, c1] - s[r0, c1] - s[r1, c0] + s[r0, c0]


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull of 2D points, its corners in order (scipy's Qhull)."""
    from scipy.spatial import ConvexHull

    pts = np.asarray(points, np.float64).reshape(-1, 2)
    # drop repeated points (sorting complex numbers is much faster than np.unique(axis=0))
    z = np.unique(np.round(pts[:, 0], 9) + 1j * np.round(pts[:, 1], 9))
    pts = np.column_stack([z.real, z.imag])
    if len(pts) < 3:
        return pts
    try:
        return pts[ConvexHull(pts).vertices]
    except Exception:  # all points on a line: the hull is that segment
        return pts[[0, -1]]


def _row_extremes(mask: np.ndarray) -> np.ndarray:
    """Corners of the first and last pixel of every non-empty row of ``mask`` (image coords)."""
    rows = np.flatnonzero(mask.any(axis=1))
    first = np.argmax(mask[rows], axis=1)
    last = mask.shape[1] - 1 - np.argmax(mask[rows, ::-1], axis=1)
    r = rows.astype(np.float64)
    xs = np.concatenate([first, first, last + 1, last + 1]).astype(np.float64)
    ys = np.concatenate([r, r + 1, r, r + 1])
    return np.column_stack([xs, ys])


def _scan(polygon: np.ndarray, n: int, offset: float, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """Extent of a convex polygon along scan lines ``coord[axis] = k + 0.5 - offset``.

    Returns the min and max of the other coordinate on each of the ``n`` lines (NaN where
    the line misses the polygon).
    """
    a = polygon
    b = np.roll(polygon, -1, axis=0)
    other = 1 - axis
    lines = np.arange(n) + 0.5 - offset  # (n,)
    a_s, b_s = a[:, axis][:, None], b[:, axis][:, None]
    a_o, b_o = a[:, other][:, None], b[:, other][:, None]
    lo_s, hi_s = np.minimum(a_s, b_s), np.maximum(a_s, b_s)
    inside = (lines >= lo_s) & (lines <= hi_s) & (hi_s > lo_s)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (lines - a_s) / (b_s - a_s)
        x = a_o + t * (b_o - a_o)
    lo = np.where(inside, x, np.inf).min(axis=0)
    hi = np.where(inside, x, -np.inf).max(axis=0)
    bad = ~np.isfinite(lo)
    lo[bad] = np.nan
    hi[bad] = np.nan
    return lo, hi


def _disc(k: int = 16) -> np.ndarray:
    """Corners of a regular k-gon circumscribing the unit disc (so offsets contain the disc)."""
    ang = (np.arange(k) + 0.5) * 2 * np.pi / k
    return np.column_stack([np.cos(ang), np.sin(ang)]) / np.cos(np.pi / k)


def _grown_corners(hull: np.ndarray, margin: float, k: int) -> np.ndarray:
    """The points whose convex hull is ``hull`` grown by ``margin`` (corners plus a ``k``-gon).

    Only the offsets that can lie on the grown hull are kept: at each corner those whose
    direction is within one step of the ``k``-gon of the cone between the normals of the
    corner's two edges.  The hull of these is the hull of all ``len(hull) * k`` points.
    """
    disc = _disc(k)
    if len(hull) < 3:
        return (hull[:, None, :] + margin * disc[None]).reshape(-1, 2)
    e = np.roll(hull, -1, axis=0) - hull
    after = np.arctan2(-e[:, 0], e[:, 1])  # direction of each edge's right-hand normal
    before = np.roll(after, 1)
    nxt = np.roll(e, -1, axis=0)
    if (e[:, 0] * nxt[:, 1] - e[:, 1] * nxt[:, 0]).sum() < 0:
        # clockwise corners: outward are the left-hand normals, and they turn the other way
        after, before = before + np.pi, after + np.pi
    phi = np.arctan2(disc[:, 1], disc[:, 0])
    step = 2 * np.pi / k
    turn = np.mod(after - before, 2 * np.pi)
    rel = np.mod(phi[None, :] - before[:, None] + step, 2 * np.pi)
    near = rel <= turn[:, None] + 2 * step
    return (hull[:, None, :] + margin * disc[None])[near]


def internal_area(
    model_mask: np.ndarray,
    kind: str = "hull",
    margin: float | None = None,
) -> InternalArea:
    """Build the internal area around the model's pixels.

    Parameters
    ----------
    model_mask : (h, w) bool
        Pixels that see the model
    kind : "hull" (default), "circle" or "rectangle"
    margin : float
        Growth in pixels; default 2 % of the image's smaller side

    Returns
    -------
    InternalArea

    Raises
    ------
    ParameterError
        Unknown ``kind``, negative margin, or no model pixel.
    """
    if kind not in SHAPES:
        raise ParameterError(f"unknown internal area {kind!r}; choose one of {', '.join(SHAPES)}")
    model_mask = np.asarray(model_mask, bool)
    h, w = model_mask.shape
    if margin is None:
        margin = 0.02 * min(h, w)
    margin = float(margin)
    if not np.isfinite(margin) or margin < 0:
        raise ParameterError(f"internal area margin must be >= 0 pixels, got {margin}")
    if not model_mask.any():
        raise ParameterError("the model is not visible in the view: nothing to label")
    corners = _row_extremes(model_mask)
    hull = _hull(corners)
    if kind == "hull":
        polygon = _hull(_grown_corners(hull, margin, 64)) if margin > 0 else hull
    elif kind == "circle":
        lo, hi = hull.min(axis=0), hull.max(axis=0)
        center = 0.5 * (lo + hi)
        radius = float(np.linalg.norm(hull - center, axis=1).max()) + margin
        polygon = center + radius * _disc(96)
    else:
        lo, hi = hull.min(axis=0) - margin, hull.max(axis=0) + margin
        polygon = np.array([[lo[0], lo[1]], [lo[0], hi[1]], [hi[0], hi[1]], [hi[0], lo[1]]])
    if kind != "hull" or margin <= 0:
        polygon = _hull(polygon)
    # the padded grid holds the whole polygon
    lo, hi = polygon.min(axis=0), polygon.max(axis=0)
    pad = int(max(2, np.ceil(max(-lo.min(), hi[0] - w, hi[1] - h, 0.0)) + 2))
    hp, wp = h + 2 * pad, w + 2 * pad
    left, right = _scan(polygon, hp, pad, axis=1)
    top, bottom = _scan(polygon, wp, pad, axis=0)
    mask, integral = scanline_mask(left, right, np.arange(wp) + 0.5 - pad)
    return InternalArea(
        kind=kind,
        margin=margin,
        polygon=polygon,
        pad=pad,
        mask=mask,
        left=left,
        right=right,
        top=top,
        bottom=bottom,
        integral=integral,
    )


def resample_boundary(polygon: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``step`` pixels along the closed polygon and their arc length."""
    closed = np.vstack([polygon, polygon[:1]])
    seg = np.linalg.norm(np.diff(closed, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    total = cum[-1]
    n = max(8, int(np.ceil(total / max(step, 1e-6))))
    s = np.arange(n) * (total / n)
    x = np.interp(s, cum, closed[:, 0])
    y = np.interp(s, cum, closed[:, 1])
    return np.column_stack([x, y]), s
