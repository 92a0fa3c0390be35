"""Stacking of boxes along a side.

Boxes are shifted apart (pool-adjacent-violators), crossing leaders are swapped
(appendix I, §5.5) and the order of neighbours is kept between frames; this covers the
west/east columns and the north/south rows of flag boxes.
"""

from __future__ import annotations

import numpy as np

from ._kernels import uncross_ports
from .context import Context
from .costs import SHIFTED
from .spacing import Placement


def pack_1d(desired: np.ndarray, sizes: np.ndarray, gap: float, lo: float, hi: float) -> np.ndarray:
    """Centres of boxes in a row: least squared shift from ``desired``, order kept, no overlap.

    Minimises ``sum (p_i - desired_i)^2`` subject to ``p_{i+1} - p_i >= (s_i + s_{i+1})/2
    + gap`` and ``lo <= p_0 - s_0/2``, ``p_{n-1} + s_{n-1}/2 <= hi``.  The boxes keep the
    order they are given in (usually ``desired`` sorted).  Substituting ``z_i = p_i - o_i``
    (``o`` = cumulative spacing) turns it into isotonic regression of ``desired - o``,
    solved exactly by pool-adjacent-violators and then clipped to the bounds.  When the row does not fit, it is centred between them.
    """
    desired = np.asarray(desired, np.float64)
    sizes = np.asarray(sizes, np.float64)
    n = len(desired)
    if n == 0:
        return desired.copy()
    off = np.concatenate([[0.0], np.cumsum((sizes[:-1] + sizes[1:]) / 2 + gap)])
    z = desired - off
    sums: list[float] = []
    counts: list[int] = []
    for v in z:  # pool adjacent violators: one pass over the (few) labels of a side
        sums.append(float(v))
        counts.append(1)
        while len(sums) > 1 and sums[-2] / counts[-2] > sums[-1] / counts[-1]:
            s, c = sums.pop(), counts.pop()
            sums[-1] += s
            counts[-1] += c
    fit = np.repeat([s / c for s, c in zip(sums, counts)], counts)
    zlo = lo + sizes[0] / 2
    zhi = hi - sizes[-1] / 2 - off[-1]
    fit = np.clip(fit, zlo, zhi) if zlo <= zhi else np.full(n, 0.5 * (zlo + zhi))
    return fit + off


def uncross(anchors: np.ndarray, ports: np.ndarray, max_swaps: int | None = None) -> tuple[np.ndarray, int]:
    """Swap ports of crossing straight leaders ``anchor -> port`` until none cross.

    Each swap of two crossing segments' ends shortens the total length (triangle
    inequality), so the loop ends; the first crossing pair in index order is swapped.

    Returns
    -------
    assignment : (n,) int
        Port index of each anchor
    swaps : int
    """
    anchors = np.ascontiguousarray(anchors, np.float64).reshape(-1, 2)
    ports = np.ascontiguousarray(ports, np.float64).reshape(-1, 2)
    n = len(anchors)
    limit = n * n + 1 if max_swaps is None else max_swaps
    assign, swaps = uncross_ports(anchors, ports, limit)
    return assign, int(swaps)


def coherent_order(desired: np.ndarray, previous: np.ndarray, pitch: float) -> np.ndarray:
    """Order of the boxes of one side, by ``desired`` but coherent with the previous frame.

    Neighbours closer than ``pitch`` keep the order they had in the previous frame: boxes
    whose desired places are less than one box pitch apart are stacked next to each other
    whatever their order, so their order is free to follow the previous frame
    (``previous``: their coordinate along the same side then, NaN when a label was not on
    this side).  Adjacent such pairs are swapped back until none is left (bubble passes
    over the few labels of a side); crossings this creates are undone by :func:`uncross`.
    An addition to appendix I, whose coherence terms f6, f7 act on anchors and endpoints
    only.

    Returns
    -------
    (n,) int
        A permutation of ``range(n)``
    """
    desired = np.asarray(desired, np.float64)
    previous = np.asarray(previous, np.float64)
    order = list(np.lexsort((np.arange(len(desired)), desired)))
    changed = True
    while changed:
        changed = False
        for i in range(len(order) - 1):
            a, b = order[i], order[i + 1]
            if abs(desired[b] - desired[a]) < pitch and previous[a] > previous[b]:  # NaN compares False
                order[i], order[i + 1] = b, a
                changed = True
    return np.asarray(order, np.int64)


def _place_column(ctx: Context, idx: np.ndarray, side: int) -> None:
    """Stack the boxes of one west/east side in a column: shift, then swap."""
    if len(idx) == 0:
        return
    desired = ctx.endpoints[idx, 1]
    h = ctx.height
    order = coherent_order(desired, ctx.previous[idx, side], h + ctx.sp.gap)
    idx, desired = idx[order], desired[order]
    slots = pack_1d(desired, np.full(len(idx), h), ctx.sp.gap, 0.0, ctx.H)
    x = ctx.col_x[side]
    ports = np.column_stack([np.full(len(idx), x), slots])
    assign, swaps = uncross(ctx.anchors[idx], ports)
    ctx.stats.swaps += swaps
    for k, slot in zip(idx, assign):
        y = slots[slot]
        shift = abs(y - ctx.endpoints[k, 1])
        ctx.stats.shifted += int(shift > SHIFTED)
        ctx.placed[k] = Placement(
            leader=np.array([ctx.anchors[k], [x, y]]),
            box=ctx.column_box(k, side, np.array(y)),
            side=side,
            tier=0,
            shift=float(shift),
        )


def _flag_split(ctx: Context, idx: np.ndarray, port_x: np.ndarray) -> np.ndarray:
    """Which flag boxes of a row point left (True) or right of their ports.

    The ports left of some split point get left flags, the others right ones, so the two
    groups stack apart.  Without a previous frame the split is the centre of ``A_I``;
    along a camera path it is the split that turns the fewest flags against last frame's
    (ties: the fewest against the centre rule), so a box does not swing across its
    leader each time its port crosses the centre.
    """
    natural = port_x < ctx.center[0]
    before = np.zeros(len(idx), np.int64)  # 1: left last frame, -1: right, 0: unknown
    for j, k in enumerate(idx):
        lead = ctx.leaders[k]
        if lead is not None and len(lead) and np.all(np.isfinite(ctx.centres[k])):
            before[j] = 1 if ctx.centres[k][0] < lead[0][0] else -1
    if not before.any():
        return natural
    order = np.argsort(port_x, kind="stable")
    b, nat = before[order], natural[order]
    # split s: the first s ports (left to right) point left; count the flags each s turns
    left_cost = np.concatenate([[0], np.cumsum(b == -1)])  # right before, left now
    right_cost = np.concatenate([np.cumsum((b == 1)[::-1])[::-1], [0]])  # left before, right now
    nat_cost = np.concatenate([[0], np.cumsum(~nat)]) + np.concatenate([np.cumsum(nat[::-1])[::-1], [0]])
    s = int(np.lexsort((nat_cost, left_cost + right_cost))[0])
    left = np.zeros(len(idx), bool)
    left[order[:s]] = True
    return left


#: along a camera path a row's port follows its anchor from last frame's place and creeps
#: towards its candidate endpoint by at most this many pixels a frame (and no farther than
#: the surface under its anchor moved: on a still camera nothing moves)
PORT_CREEP = 2.0


#: surface motion (pixels) below which a label counts as not having moved
STILL_PX = 0.5


def _glided_ports(ctx: Context, idx: np.ndarray, side: int, desired: np.ndarray) -> tuple[np.ndarray, bool]:
    """Where the ports of a row would like to be along a camera path.

    A label that was on this side last frame starts from its port moved with its anchor
    (the row glides with the surface) and creeps towards its candidate endpoint by at most
    :data:`PORT_CREEP` pixels and the surface motion; the others start from their endpoints.
    """
    out = np.array(desired, np.float64)
    glided = False
    for j, k in enumerate(idx):
        lead = ctx.leaders[k]
        if np.isfinite(ctx.previous[k, side]) and lead is not None and len(lead):
            port = float(lead[0][0])
            creep = min(PORT_CREEP, float(ctx.motion[k]))
            out[j] = port + float(np.clip(out[j] - port, -creep, creep))
            glided = True
    return out, glided


def _place_row(ctx: Context, idx: np.ndarray, side: int) -> None:
    """Spread the ports of one north/south side (shift, swap), then stack flag boxes in tiers."""
    if len(idx) == 0:
        return
    desired = ctx.endpoints[idx, 0]
    # spread the ports as far as the image allows, up to one box width apart: wider
    # spacing means fewer tiers, at the price of more slanted leaders
    fair = (ctx.W - 2 * ctx.sp.clearance) / len(idx)
    gap = float(np.clip(fair, ctx.sp.port_gap, ctx.widths[idx].mean() + ctx.sp.gap))
    glided, any_glided = _glided_ports(ctx, idx, side, desired)
    still = bool((ctx.motion[idx] < STILL_PX).all())
    if any_glided and not (still and ctx.left_out[idx].any()):
        # along a camera path the ports follow their anchors and stay near them (the least
        # port gap), so that two anchors passing each other swap ports a few pixels apart
        # instead of a box width.  If the tiers this needs leave the image, the row is
        # spread as in a single frame; so is a row that did not move holding a label left
        # out last frame for lack of room (a still camera keeps its layout)
        stats, flags = (ctx.stats.shifted, ctx.stats.swaps), ctx.flags.copy()
        _stack_row(ctx, idx, side, glided, ctx.sp.port_gap)
        if not _off_image(ctx, idx):
            return
        ctx.stats.shifted, ctx.stats.swaps = stats
        ctx.flags[:] = flags
    _stack_row(ctx, idx, side, desired, gap)


def _off_image(ctx: Context, idx: np.ndarray) -> bool:
    """True when a box of the labels ``idx`` reaches beyond the image."""
    boxes = np.array([ctx.placed[k].box for k in idx if ctx.placed[k] is not None]).reshape(-1, 4)
    return bool((boxes[:, :2] < 0).any() or (boxes[:, 2] > ctx.W).any() or (boxes[:, 3] > ctx.H).any())


def _stack_row(ctx: Context, idx: np.ndarray, side: int, desired: np.ndarray, gap: float) -> None:
    """Place the ports of one row at least ``gap`` apart near ``desired``, then the flag boxes in tiers."""
    order = coherent_order(desired, ctx.previous[idx, side], gap)
    idx, desired = idx[order], desired[order]
    xs = pack_1d(desired, np.zeros(len(idx)), gap, 0.0, ctx.W)
    y = ctx.row_y[side]
    ports = np.column_stack([xs, np.full(len(idx), y)])
    assign, swaps = uncross(ctx.anchors[idx], ports)
    ctx.stats.swaps += swaps
    port_x = xs[assign]
    left = _flag_split(ctx, idx, port_x)
    ctx.flags[idx] = np.where(left, 1, -1)
    g = ctx.sp.gap
    # left group: outermost (leftmost) first; a box may sit in tier r only if it starts
    # right of every box already in tier r or above (those leaders pass through tier r)
    for group, sign in ((np.flatnonzero(left), 1.0), (np.flatnonzero(~left), -1.0)):
        seq = group[np.lexsort((idx[group], sign * port_x[group]))]
        tiers: list[int] = []
        edges: list[float] = []  # far edge of each placed box toward the centre
        for j in seq:
            k = idx[j]
            box0 = ctx.row_box(k, side, np.array(port_x[j]), np.array(0))
            near = box0[0] if sign > 0 else box0[2]  # edge facing the labels placed before
            r = 0
            t = np.array(tiers)
            e = np.array(edges)
            while True:
                above = t >= r
                if not above.any():
                    break
                if sign > 0 and near - g >= e[above].max():
                    break
                if sign < 0 and near + g <= e[above].min():
                    break
                r += 1
            box = ctx.row_box(k, side, np.array(port_x[j]), np.array(r))
            tiers.append(r)
            edges.append(box[2] if sign > 0 else box[0])
            shift = abs(port_x[j] - ctx.endpoints[k, 0])
            ctx.stats.shifted += int(shift > SHIFTED)
            ctx.placed[k] = Placement(
                leader=ctx.row_leader(k, side, float(port_x[j]), r),
                box=box,
                side=side,
                tier=r,
                shift=float(shift),
            )
