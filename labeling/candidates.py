"""Leader-line candidates: one per pixel of the internal area (appendix I, §5.2, §5.6, Table 1).

For an anchor pixel ``a`` the candidate leader ``l = (a, e)`` is the shortest segment from
``a`` to the boundary of ``A_I`` along one of the layout's principal directions:

============  =====================  ==========================================
layout        principal directions   endpoint ``e``
============  =====================  ==========================================
left          west                   the boundary point of ``a``'s row, to the left
right         east                   ... to the right
left-right    west, east             the nearer of the two (ties: west)
top           north                  the boundary point of ``a``'s column, above
bottom        south                  ... below
top-bottom    north, south           the nearer of the two (ties: north)
silhouette    every direction        the nearest boundary point
============  =====================  ==========================================

Because ``A_I`` is convex, a row (column) crosses it in one interval, so the west/east
(north/south) distances are exact differences to the interval ends.  The silhouette
layout uses the exact Euclidean distance transform of ``A_I``
(``scipy.ndimage.distance_transform_edt`` with feature indices): the nearest pixel outside
``A_I`` gives the direction, and the endpoint is put on the boundary half a pixel before it.
This replaces the GPU jump flooding of the paper (§6.2) by exact CPU transforms.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from meshvis.errors import ParameterError

from ._kernels import radial_image
from .internal_area import InternalArea

#: side codes of a leader: the direction it leaves the model in
WEST, EAST, NORTH, SOUTH, RADIAL = 0, 1, 2, 3, 4
SIDE_NAMES = ("west", "east", "north", "south", "radial")

#: layout name -> principal directions (side codes)
LAYOUTS: dict[str, tuple[int, ...]] = {
    "left": (WEST,),
    "right": (EAST,),
    "left-right": (WEST, EAST),
    "top": (NORTH,),
    "bottom": (SOUTH,),
    "top-bottom": (NORTH, SOUTH),
    "silhouette": (RADIAL,),
}


def check_layout(layout: str) -> tuple[int, ...]:
    """The side codes of ``layout``; :class:`ParameterError` for an unknown name."""
    try:
        return LAYOUTS[layout]
    except KeyError:
        raise ParameterError(f"unknown layout {layout!r}; choose one of {', '.join(LAYOUTS)}") from None


def is_horizontal(layout: str) -> bool:
    """True for the layouts whose leaders run left/right (labels stacked in columns)."""
    return set(check_layout(layout)) <= {WEST, EAST}


@dataclass
class Candidates:
    """The leader candidate of every pixel of the image.

    Candidates that share an endpoint share its id: the west/east endpoint depends only on
    the row, the north/south one only on the column, the silhouette one only on the
    nearest outside pixel.  The greedy loop evaluates ``f5`` once per endpoint.

    Attributes
    ----------
    ex, ey : (h, w) float64
        Endpoint on the boundary of ``A_I`` (NaN outside ``A_I``)
    length : (h, w) float64, ``|a e|`` from the pixel centre (NaN outside ``A_I``)
    side : (h, w) int8
        Side code (:data:`WEST` ... :data:`RADIAL`), -1 outside ``A_I``
    eid : (h, w) int64
        Endpoint id (index into ``endpoints``), -1 outside ``A_I``
    endpoints : (n_e, 2) float64
        The distinct endpoints
    d_max : float
        The longest candidate over all of ``A_I`` (appendix I, §6.1 step 3)
    """

    ex: np.ndarray
    ey: np.ndarray
    length: np.ndarray
    side: np.ndarray
    eid: np.ndarray
    endpoints: np.ndarray
    d_max: float


def _radial(area: InternalArea, window: tuple[int, int, int, int]) -> Candidates:
    """The silhouette layout's candidates: every pixel's leader to the nearest boundary point.

    The EDT gives every inside pixel its nearest outside pixel ``q``; the endpoint of all
    pixels that share ``q`` is ``q`` moved half a pixel back along their mean direction,
    i.e. onto the boundary of ``A_I`` (:func:`._kernels.radial_image`, straight into the
    image's arrays).
    """
    r0, r1, c0, c1 = window
    p = area.pad
    hp, wp = area.mask.shape
    # the window is the bounding box of A_I plus a pixel: every inside pixel's nearest
    # outside pixel lies in it
    mask = area.mask[r0:r1, c0:c1]
    ri, ci = ndimage.distance_transform_edt(mask, return_distances=False, return_indices=True)
    ex, ey, length, eid, endpoints, d_max = radial_image(mask, ri, ci, r0 - p, c0 - p, hp - 2 * p, wp - 2 * p)
    side = np.where(eid >= 0, np.int8(RADIAL), np.int8(-1))
    d_max = float(d_max) if np.isfinite(d_max) else 1.0
    return Candidates(ex, ey, length, side, eid, endpoints, max(d_max, _MIN_D_MAX))


#: floor of ``d_max`` (pixels), which divides the leader lengths in ``f2``
_MIN_D_MAX = 1e-9


def _window(full: np.ndarray) -> tuple[int, int, int, int]:
    """Rows ``r0:r1`` and columns ``c0:c1`` of the bounding box of ``A_I`` plus a pixel.

    When ``A_I`` is empty the window is the whole grid.
    """
    hp, wp = full.shape
    rows, cols = np.flatnonzero(full.any(axis=1)), np.flatnonzero(full.any(axis=0))
    if len(rows):
        return max(rows[0] - 1, 0), min(rows[-1] + 2, hp), max(cols[0] - 1, 0), min(cols[-1] + 2, wp)
    return 0, hp, 0, wp


def _shortest(
    area: InternalArea,
    sides: tuple[int, ...],
    window: tuple[int, int, int, int],
    prefer: np.ndarray | None = None,
    keep: float = 1.0,
) -> tuple:
    """Find the shortest leader over ``sides`` (west, east, north, south) for each pixel of the window.

    Returns its length, endpoint, endpoint key on the padded grid and side code; the first
    side listed wins ties.  A pixel whose ``prefer`` (window-sized side codes, -1: none)
    names one of ``sides`` keeps that side while its leader is at most ``keep`` times the
    shortest.
    """
    full = area.mask
    hp, wp = full.shape
    p = area.pad
    r0, r1, c0, c1 = window
    mask = full[r0:r1, c0:c1]
    hb, wb = mask.shape
    xc = np.arange(c0, c1, dtype=np.float64) + 0.5 - p
    yc = np.arange(r0, r1, dtype=np.float64) + 0.5 - p
    X = np.broadcast_to(xc[None, :], (hb, wb))
    Y = np.broadcast_to(yc[:, None], (hb, wb))
    R = np.broadcast_to(np.arange(r0, r1)[:, None], (hb, wb))
    C = np.broadcast_to(np.arange(c0, c1)[None, :], (hb, wb))
    left, right = area.left[r0:r1, None], area.right[r0:r1, None]
    top, bottom = area.top[None, c0:c1], area.bottom[None, c0:c1]
    best = np.full((hb, wb), np.inf)
    ex = np.full((hb, wb), np.nan)
    ey = np.full((hb, wb), np.nan)
    side = np.full((hb, wb), -1, np.int8)
    key = np.full((hb, wb), -1, np.int64)

    offers = []

    def offer(code: int, length: np.ndarray, bx: np.ndarray, by: np.ndarray, k: np.ndarray) -> None:
        offers.append((code, length, bx, by, k))
        if len(sides) == 1:  # one direction: its candidate is every inside pixel's (NaN / -1 outside)
            best[...] = np.where(mask, length, np.inf)
            ex[...] = np.where(mask, bx, np.nan)
            ey[...] = np.where(mask, by, np.nan)
            key[...] = np.where(mask, k, -1)
            side[...] = np.where(mask, code, -1)
            return
        # strictly shorter wins, so the first direction listed wins ties
        better = mask & (length < best)
        best[better] = length[better]
        ex[better] = np.broadcast_to(bx, (hb, wb))[better]
        ey[better] = np.broadcast_to(by, (hb, wb))[better]
        key[better] = np.broadcast_to(k, (hb, wb))[better]
        side[better] = code

    with np.errstate(invalid="ignore"):
        for code in sides:
            if code == WEST:
                offer(code, X - left, left, Y, R)
            elif code == EAST:
                offer(code, right - X, right, Y, hp + R)
            elif code == NORTH:
                offer(code, Y - top, X, top, 2 * hp + C)
            else:
                offer(code, bottom - Y, X, bottom, 2 * hp + wp + C)
    if prefer is not None and len(sides) > 1:
        shortest = best.copy()
        for code, length, bx, by, k in offers:
            # hysteresis: a pixel of a label that left on this side last frame stays on it
            # unless another side is clearly shorter
            stay = mask & (prefer == code) & (side != code) & (length <= keep * shortest)
            best[stay] = length[stay]
            ex[stay] = np.broadcast_to(bx, (hb, wb))[stay]
            ey[stay] = np.broadcast_to(by, (hb, wb))[stay]
            key[stay] = np.broadcast_to(k, (hb, wb))[stay]
            side[stay] = code
    best[~mask] = np.nan
    return mask, best, ex, ey, side, key


def _dense_ids(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(keys, return_index=True, return_inverse=True)[1:]`` for small non-negative keys.

    The keys are pixel indices of a grid, so a lookup table replaces the sort.
    """
    if len(keys) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    present = np.zeros(int(keys.max()) + 1, bool)
    present[keys] = True
    dense = np.cumsum(present) - 1
    inv = dense[keys]
    first = np.full(int(dense[-1]) + 1, len(keys), np.int64)
    np.minimum.at(first, inv, np.arange(len(keys)))
    return first, inv


def leader_candidates(
    area: InternalArea, layout: str, prefer: np.ndarray | None = None, keep: float = 1.0
) -> Candidates:
    """Compute the candidate endpoint, length and side of every pixel of ``A_I``.

    Parameters
    ----------
    area : InternalArea
    layout : a key of :data:`LAYOUTS`
    prefer : (h, w) int, optional: a side code per image pixel (-1: none) that the pixel
        keeps while its leader on that side is at most ``keep`` times its shortest one
        (frame-to-frame hysteresis of the sides)
    keep : float, the length ratio of ``prefer``

    Returns
    -------
    Candidates
        Arrays cover the image (the padding of ``area`` is cut off); ``d_max`` is taken
        over the whole of ``A_I``, padding included.
    """
    sides = check_layout(layout)
    hp, wp = area.mask.shape
    p = area.pad
    # work on the bounding box of A_I only (plus a pixel); keys keep the padded grid's indices
    r0, r1, c0, c1 = window = _window(area.mask)
    if sides == (RADIAL,):
        return _radial(area, window)
    pref = None
    if prefer is not None:
        padded = np.full((hp, wp), -1, np.int8)
        padded[p : hp - p, p : wp - p] = prefer
        pref = padded[r0:r1, c0:c1]
    mask, best, ex, ey, side, key = _shortest(area, sides, window, pref, keep)
    d_max = float(np.nanmax(best)) if mask.any() else 1.0
    # out to the image: the part of the box inside it (the padding is cut off)
    H, W = hp - 2 * p, wp - 2 * p
    i0, i1, j0, j1 = max(r0, p), min(r1, hp - p), max(c0, p), min(c1, wp - p)
    src = (slice(i0 - r0, i1 - r0), slice(j0 - c0, j1 - c0))
    dst = (slice(i0 - p, i1 - p), slice(j0 - p, j1 - p))

    def image(a: np.ndarray, fill) -> np.ndarray:
        out = np.full((H, W), fill, a.dtype)
        out[dst] = a[src]
        return out

    exi, eyi, length = image(ex, np.nan), image(ey, np.nan), image(best, np.nan)
    side_img, key_img = image(side, -1), image(key, -1)
    inside = key_img >= 0
    first, inv = _dense_ids(key_img[inside])
    eid = np.full(key_img.shape, -1, np.int64)
    eid[inside] = inv
    endpoints = np.column_stack([exi[inside][first], eyi[inside][first]])
    return Candidates(
        ex=exi,
        ey=eyi,
        length=length,
        side=side_img,
        eid=eid,
        endpoints=endpoints,
        d_max=max(d_max, _MIN_D_MAX),
    )
