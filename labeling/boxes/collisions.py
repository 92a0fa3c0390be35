"""What a candidate may not touch: the model, the placed boxes and leaders; recording a placement."""

from __future__ import annotations

import numpy as np

from ..geometry2d import boxes_overlap, segment_hits_box, segments_intersect
from .context import Context
from .costs import SHIFTED
from .spacing import Placement

#: leader points closer than this (pixels), or turning by less than this relative cross
#: product, are one point / one straight line
COLLINEAR = 1e-9


def _placed_arrays(ctx: Context, exclude: int) -> tuple[np.ndarray, np.ndarray]:
    """Boxes (P, 4) and leader segments (Q, 2, 2) of every placed label except ``exclude``.

    The arrays of all placed labels are built once per change of the placements (the
    searches of one label ask several times, with the label itself left out).
    """
    key = tuple(map(id, ctx.placed))
    if ctx._cache is None or ctx._cache[0] != key:
        ids = [i for i, p in enumerate(ctx.placed) if p is not None]
        segs = [ctx.placed[i].segments for i in ids]
        ctx._cache = (
            key,
            np.array([ctx.placed[i].box for i in ids], np.float64).reshape(-1, 4),
            np.array(ids, np.int64),
            np.concatenate(segs).reshape(-1, 2, 2) if segs else np.zeros((0, 2, 2)),
            np.repeat(np.array(ids, np.int64), [len(s) for s in segs]),
        )
    _, boxes, box_of, segs, seg_of = ctx._cache
    if ctx.placed[exclude] is None:
        return boxes, segs
    return boxes[box_of != exclude], segs[seg_of != exclude]


def _valid(ctx: Context, k: int, boxes: np.ndarray, leaders: np.ndarray) -> np.ndarray:
    """Which candidates (boxes (K, 4), leaders (K, S, 2, 2)) collide with nothing placed."""
    pboxes, psegs = _placed_arrays(ctx, k)
    ok = _boxes_free(ctx, boxes, pboxes, psegs)
    live = np.flatnonzero(ok)
    if len(live):
        # leaders as polylines; the column/row layouts have few distinct ones per label
        poly = np.concatenate([leaders[live, :, 0], leaders[live, -1:, 1]], axis=1)
        ok[live] = _leaders_free(poly, pboxes, psegs, None)
    return ok


def _outside_image(ctx: Context, boxes: np.ndarray) -> np.ndarray:
    return (boxes[:, 0] < 0) | (boxes[:, 1] < 0) | (boxes[:, 2] > ctx.W) | (boxes[:, 3] > ctx.H)


def _boxes_free(ctx: Context, boxes: np.ndarray, pboxes: np.ndarray, psegs: np.ndarray) -> np.ndarray:
    """Which boxes (K, 4) cover no model pixel, no placed box and no placed leader."""
    ok = ctx.area.boxes_hit(boxes) == 0
    # each test runs only on the boxes that passed the ones before (cheapest first)
    if len(pboxes):
        live = np.flatnonzero(ok)
        ok[live[boxes_overlap(boxes[live], pboxes, ctx.sp.gap).any(axis=1)]] = False
    if len(psegs):
        live = np.flatnonzero(ok)
        ok[live[segment_hits_box(psegs, boxes[live]).any(axis=0)]] = False
    return ok


def _leaders_free(
    leaders: np.ndarray, pboxes: np.ndarray, psegs: np.ndarray, paths: np.ndarray | None
) -> np.ndarray:
    """Which polylines (L, P, 2) cross no placed box, no placed leader and none of ``paths``."""
    L, P = leaders.shape[:2]
    segs = np.stack([leaders[:, :-1], leaders[:, 1:]], axis=2).reshape(-1, 2, 2)
    bad = np.zeros(len(segs), bool)
    if len(pboxes):
        bad |= segment_hits_box(segs, pboxes).any(axis=1)
    for other in (psegs, paths):
        if other is not None and len(other):
            bad |= segments_intersect(segs, other).any(axis=1)
    return ~bad.reshape(L, P - 1).any(axis=1)


def _simplify(pts: np.ndarray) -> np.ndarray:
    """Drop repeated points and middle points that lie on the straight line of their neighbours."""
    keep = [pts[0]]
    for i in range(1, len(pts)):
        if np.hypot(*(pts[i] - keep[-1])) < COLLINEAR:
            continue
        if len(keep) >= 2:
            a, b = keep[-2], keep[-1]
            u, v = b - a, pts[i] - b
            if abs(u[0] * v[1] - u[1] * v[0]) <= COLLINEAR * (np.hypot(*u) * np.hypot(*v)) and u @ v > 0:
                keep[-1] = pts[i]
                continue
        keep.append(pts[i])
    return np.array(keep, np.float64)


def _place(ctx: Context, k: int, leader: np.ndarray, box: np.ndarray, tier: int, shift: float) -> None:
    ctx.placed[k] = Placement(
        leader=_simplify(leader), box=box.copy(), side=int(ctx.sides[k]), tier=int(tier), shift=float(shift)
    )
    ctx.stats.shifted += int(shift > SHIFTED)
