"""The box layout of one frame: columns, rows and the ring, then the repair of conflicting pairs."""

from __future__ import annotations

import numpy as np

from ..candidates import EAST, NORTH, RADIAL, SOUTH, WEST
from ..geometry2d import boxes_overlap, segment_hits_box, segments_intersect
from ..internal_area import InternalArea
from .context import Context
from .search import _search
from .silhouette import _keep_previous, _place_ring
from .spacing import BoxStats, Placement, Spacing
from .stacking import _place_column, _place_row

#: rounds of the last pass (re-place the later label of every conflicting pair); what still
#: conflicts after them is left out and reported
REPAIR_ROUNDS = 4


def _conflicting(ctx: Context) -> list[int]:
    """Labels to re-place: the later-ranked member of every conflicting pair."""
    ids = [i for i, p in enumerate(ctx.placed) if p is not None]
    if len(ids) < 2:
        return []
    boxes = np.array([ctx.placed[i].box for i in ids])
    segs, owner = [], []
    for n, i in enumerate(ids):
        pts = ctx.placed[i].leader
        s = np.stack([pts[:-1], pts[1:]], axis=1)
        segs.extend(s)
        owner.extend([n] * len(s))
    segs = np.array(segs)
    owner = np.array(owner)
    m = len(ids)
    one_hot = np.zeros((len(segs), m), np.int64)
    one_hot[np.arange(len(segs)), owner] = 1
    bad = boxes_overlap(boxes, boxes, 0.0)
    bad |= (one_hot.T @ segments_intersect(segs, segs).astype(np.int64) @ one_hot) > 0
    through = (one_hot.T @ segment_hits_box(segs, boxes).astype(np.int64)) > 0
    bad |= through | through.T
    np.fill_diagonal(bad, False)
    over = ctx.area.boxes_hit(boxes) > 0
    redo = set(np.array(ids)[over].tolist())
    ii, jj = np.nonzero(np.triu(bad, 1))
    for a, b in zip(ii, jj):
        i, j = ids[a], ids[b]
        redo.add(i if ctx.rank[i] > ctx.rank[j] else j)
    return sorted(redo, key=lambda i: (ctx.rank[i], i))


def _place_radial(ctx: Context, ring: np.ndarray, endpoints_in: np.ndarray, leaders: list | None) -> None:
    """Silhouette boxes: keep last frame's valid boxes (hysteresis), search places for the others.

    When that leaves a label without room, every box of the ring is searched for afresh
    from this frame's own endpoints (the search still prefers the places the boxes had,
    :data:`~.costs.COHERENCE_COST`).
    """
    state = (ctx.stats.shifted, ctx.stats.swaps, len(ctx.stats.unplaced))
    kept = _keep_previous(ctx, ring, leaders)
    _place_ring(ctx, ring[~np.isin(ring, kept)])
    if kept and len(ctx.stats.unplaced) > state[2]:
        ctx.stats.shifted, ctx.stats.swaps = state[:2]
        del ctx.stats.unplaced[state[2] :]
        for k in ring:
            ctx.placed[k] = None
        ctx.endpoints[ring] = endpoints_in[ring]
        ctx._rays = None
        _place_ring(ctx, ring)


#: a silhouette label keeps last frame's endpoint (moved with its anchor, onto the boundary
#: of ``A_I``) while that leader is at most this many times as long as the nearest one
RADIAL_KEEP = 3.0


def _keep_radial_endpoints(ctx: Context, ring: np.ndarray, leaders: list | None) -> None:
    """Hysteresis of the silhouette endpoints: a leader leaves where it left last frame.

    The nearest boundary point of an anchor near the middle of a long part can jump to the
    far side of ``A_I`` between two frames, and the box with it; the point of the boundary
    nearest to last frame's endpoint (moved with the anchor) is kept instead while its
    leader is at most :data:`RADIAL_KEEP` times as long.
    """
    known = [k for k in ring if leaders is not None and leaders[k] is not None and len(leaders[k])]
    if not known:
        return
    pts, _ = ctx.boundary
    for k in known:
        before = np.asarray(leaders[k][0], np.float64)
        if not np.all(np.isfinite(before)):
            continue
        q = pts[int(np.argmin(((pts - before) ** 2).sum(axis=1)))]
        nearest = np.hypot(*(ctx.endpoints[k] - ctx.anchors[k]))
        if np.hypot(*(q - ctx.anchors[k])) <= RADIAL_KEEP * nearest:
            ctx.endpoints[k] = q
    ctx._rays = None


def place_boxes(
    anchors: np.ndarray,
    endpoints: np.ndarray,
    sides: np.ndarray,
    widths: np.ndarray,
    height: float,
    area: InternalArea,
    image_size: tuple[int, int],
    rank: np.ndarray | None = None,
    spacing: Spacing | None = None,
    previous: np.ndarray | None = None,
    directions: tuple[int, ...] | None = None,
    *,
    centres: np.ndarray | None = None,
    leaders: list | None = None,
    lines: np.ndarray | None = None,
    motion: np.ndarray | None = None,
    left_out: np.ndarray | None = None,
) -> tuple[list[Placement | None], BoxStats]:
    """Lay out the boxes and leaders of all labels of one frame.

    Parameters
    ----------
    anchors, endpoints : (n, 2) float
        The anchors and candidate endpoints (pixels)
    sides : (n,) int
        Side code of each label
    widths : (n,) float
        Box widths.
    height : float
        Box height.
    area : InternalArea
    image_size : (width, height)
    rank : (n,) int
        Greedy placement order (lower = placed first); default 0..n-1
    spacing : Spacing
    previous : (n, 4) float, optional: each label's box centre along the west, east,
        north and south side in the previous frame (y for west/east, x for north/south;
        NaN where it was not on that side), for :func:`coherent_order`
    directions : side codes of the layout (default: those in ``sides``); a label with no
        room on its side may move to another one of them
    centres : (n, 2) float, optional: each label's box centre in the previous frame moved
        with its anchor (NaN: none); silhouette boxes prefer places near it
    leaders : n polylines or None, optional: each label's leader in the previous frame
        moved with its anchor, without the anchor point; a silhouette box is kept with it
    lines : (4,) float, optional: the x of the west and east columns and the y of the north
        and south rows in the previous frame (NaN: none); a column or row stays there while
        that is still valid and not much farther out than needed
    motion : (n,) float, optional: how far the surface under each anchor moved on the
        screen since the previous frame (pixels; NaN or 0: unknown); a row's port creeps
        towards its endpoint no faster
    left_out : (n,) bool, optional: the labels left out for lack of room in the previous
        frame; a row holding one is spread as in a single frame

    Returns
    -------
    placements : list of Placement or None (no valid place found)
    stats : BoxStats
    """
    n = len(anchors)
    rank = np.arange(n) if rank is None else np.asarray(rank)
    ctx = Context(
        anchors,
        endpoints,
        sides,
        widths,
        height,
        area,
        image_size,
        spacing or Spacing(),
        rank,
        previous,
        directions,
        centres,
        lines,
        leaders,
        motion,
        left_out,
    )
    endpoints_in = ctx.endpoints.copy()  # a ring placed afresh starts from these
    _keep_radial_endpoints(ctx, np.flatnonzero(ctx.sides == RADIAL), leaders)
    for side in (WEST, EAST):
        _place_column(ctx, np.flatnonzero(ctx.sides == side), side)
    for side in (NORTH, SOUTH):
        _place_row(ctx, np.flatnonzero(ctx.sides == side), side)
    _place_radial(ctx, np.flatnonzero(ctx.sides == RADIAL), endpoints_in, leaders)
    for _ in range(REPAIR_ROUNDS):
        redo = _conflicting(ctx)
        if not redo:
            break
        for k in redo:
            ctx.placed[k] = None
        for k in redo:
            ctx.stats.repaired += 1
            if not _search(ctx, k) and k not in ctx.stats.unplaced:
                ctx.stats.unplaced.append(int(k))
    else:
        for k in _conflicting(ctx):
            ctx.placed[k] = None
            if k not in ctx.stats.unplaced:
                ctx.stats.unplaced.append(int(k))
    return ctx.placed, ctx.stats
