"""The candidate search of a column or row label.

The search takes the cheapest valid place on the label's side, then on the layout's other
side; silhouette labels are handled by :mod:`.silhouette`.
"""

from __future__ import annotations

import numpy as np

from ..candidates import EAST, NORTH, RADIAL, SOUTH, WEST
from .collisions import _outside_image, _place, _valid
from .context import NEAR_REACH, Context
from .costs import OUTSIDE_IMAGE_COST, ROW_TIER_COST
from .silhouette import _search_radial

#: candidate ports per reach along a column (west/east) and a row (north/south), and the
#: least step between them (pixels): a row multiplies its ports by its tiers
COLUMN_STEPS = 96.0
ROW_STEPS = 48.0
MIN_STEP = 1.0
#: most tiers of a north/south candidate list
ROW_TIERS = 12
#: reaches (pixels) tried before the near and the far one: a label usually fits close to
#: its endpoint, and short candidate lists are cheap to test
SIDE_REACHES = (24.0, 96.0)


def _candidates(
    ctx: Context, k: int, reach: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Candidate (boxes, leaders, costs, tiers, shifts) of a column or row label within ``reach`` pixels."""
    side = int(ctx.sides[k])
    a = ctx.anchors[k]
    h = ctx.height
    if side in (WEST, EAST):
        step = max(MIN_STEP, reach / COLUMN_STEPS)
        ys = ctx.endpoints[k, 1] + np.arange(-reach, reach + 0.5 * step, step)
        boxes = ctx.column_box(k, side, ys)
        ports = np.column_stack([np.full(len(ys), ctx.col_x[side]), ys])
        leaders = np.stack([np.broadcast_to(a, ports.shape), ports, ports], axis=1)
        shifts = np.abs(ys - ctx.endpoints[k, 1])
        tiers = np.zeros(len(ys), np.int64)
        cost = shifts
    elif side in (NORTH, SOUTH):
        step = max(MIN_STEP, reach / ROW_STEPS)
        xs = ctx.endpoints[k, 0] + np.arange(-reach, reach + 0.5 * step, step)
        n_t = int(min(ROW_TIERS, max(1, reach // (h + ctx.sp.gap)) + 1))
        X, T = np.meshgrid(xs, np.arange(n_t))
        X, T = X.ravel(), T.ravel()
        boxes = ctx.row_box(k, side, X, T)
        y = ctx.row_y[side]
        tip = boxes[:, 3] if side == NORTH else boxes[:, 1]
        leaders = np.stack(
            [
                np.broadcast_to(a, (len(X), 2)),
                np.column_stack([X, np.full(len(X), y)]),
                np.column_stack([X, np.where(T > 0, tip, y)]),
            ],
            axis=1,
        )
        shifts = np.abs(X - ctx.endpoints[k, 0])
        tiers = T
        cost = shifts + T * (h + ctx.sp.gap) * ROW_TIER_COST
    else:
        raise ValueError("radial labels use _radial_candidates")
    cost = cost + OUTSIDE_IMAGE_COST * _outside_image(ctx, boxes)
    return boxes, leaders, cost, tiers, shifts


def _search(ctx: Context, k: int) -> bool:
    """Place label k at its cheapest valid candidate; widen the search until one is found.

    A column or row label with no valid place on its side tries the layout's other
    side (left-right, top-bottom), leaving from its anchor straight to that side.
    """
    if ctx.sides[k] == RADIAL:
        return _search_radial(ctx, k)
    side, endpoint = int(ctx.sides[k]), ctx.endpoints[k].copy()
    for alt in [side] + [d for d in ctx.directions if d != side]:
        if alt != side:
            ctx.sides[k], ctx.endpoints[k] = alt, _endpoint_towards(ctx, k, alt)
        if _search_side(ctx, k):
            return True
    ctx.sides[k], ctx.endpoints[k] = side, endpoint
    return False


def _endpoint_towards(ctx: Context, k: int, side: int) -> np.ndarray:
    """Where label k's leader meets the boundary of ``A_I`` leaving straight towards ``side``."""
    ax, ay = ctx.anchors[k]
    area, p = ctx.area, ctx.area.pad
    row, col = int(np.floor(ay)) + p, int(np.floor(ax)) + p
    if side == WEST:
        return np.array([area.left[row], ay])
    if side == EAST:
        return np.array([area.right[row], ay])
    if side == NORTH:
        return np.array([ax, area.top[col]])
    return np.array([ax, area.bottom[col]])


def _search_side(ctx: Context, k: int) -> bool:
    """Place column/row label k on its current side, at the cheapest valid candidate."""
    size = max(ctx.W, ctx.H)
    for reach in (*SIDE_REACHES, NEAR_REACH * size, ctx.reach):
        boxes, leaders, cost, tiers, shifts = _candidates(ctx, k, reach)
        ok = _valid(ctx, k, boxes, np.stack([leaders[:, :-1], leaders[:, 1:]], axis=2))
        if ok.any():
            cand = np.flatnonzero(ok)
            best = cand[np.argmin(cost[cand])]  # argmin: first of equal costs
            _place(ctx, k, leaders[best], boxes[best], tiers[best], shifts[best])
            return True
    return False
