"""Label boxes: stacking along the internal area and the corrections of appendix I §5.5.

The greedy step gives every label an anchor ``a`` and a candidate endpoint ``e`` on the
boundary of ``A_I``.  This module turns them into drawn leaders and boxes with no box
overlaps, no leader crossings and no box over the model:

* **west / east** (left, right, left-right layouts): the boxes of a side are stacked in one
  column just outside ``A_I`` (as in appendix I, Fig. 2a-b).  A box wants to sit at its
  endpoint's height; where boxes would overlap they are **shifted** apart along the
  column by the least total squared displacement that keeps their order (pool-adjacent-
  violators on the stacked positions).  Shifting rotates leaders ("relieving criterion 1"),
  which may make two of them cross; crossing pairs then **swap** their slots, which
  strictly shortens the sum of leader lengths, so the swapping ends (§5.5).
* **north / south** (top, bottom, top-bottom): leader ports are spread along a line just
  above (below) ``A_I`` with the same shift-then-swap step; the boxes hang like flags off
  the leaders and are stacked in tiers away from the model where they do not fit side by
  side; labels left of the centre extend left and fill tiers outside-in, those right of it
  extend right, which keeps every extended leader clear of the other boxes.
* **radial** (silhouette layout): labels are taken in order along the boundary of
  ``A_I``, their endpoints first moved apart to at least ``Spacing.endpoint_gap`` (labels
  of small neighbouring parts often share one); each box goes on the ray of the
  boundary's outward normal at its endpoint, just outside ``A_I``, and is pushed further
  out in tiers where it collides (the "extruded" leaders of Fig. 4b).  A box may hang
  off its port at any corner or edge middle; the cheapest valid place that blocks no
  later label's ray wins.  Normals of a convex boundary diverge, so the rays never meet.  A box that would be pushed out is
  instead hung, when that makes a shorter leader, off a *rotated* leader: endpoint moved
  up to ``Spacing.rotate`` pixels along the boundary to a stretch with room within two
  tiers.  A label whose own leader is blocked (e.g. it shares its endpoint with a placed
  one) gets its endpoint moved a few pixels along the boundary.

A last pass checks every pair of labels and re-places a label of any conflicting pair
(the one placed later by the greedy order) by the same candidate search; a label with no
valid place is left out and reported.  Everything is deterministic: sorts are stable
with the label index as the last key, and candidate ties go to the lowest index.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .candidates import EAST, NORTH, RADIAL, SOUTH, WEST
from .geometry2d import boxes_overlap, polyline_length, segment_hits_box, segments_intersect
from .internal_area import InternalArea, resample_boundary


@dataclass(frozen=True)
class Spacing:
    """Distances of the box layout, in pixels.

    Attributes
    ----------
    gap : free space between two boxes
    clearance : free space between ``A_I`` and the boxes (column / row / ray start)
    port_gap : least distance between two leader ports of the north/south layouts
    inset : distance of a flag leader from the near end of its box (north/south)
    rotate : largest move of an endpoint along the boundary of ``A_I`` that turns a
        leader towards free space, instead of pushing its box out (silhouette layout;
        0 = never)
    endpoint_gap : least distance along the boundary of ``A_I`` between the endpoints of
        the silhouette layout (closer ones are moved apart; 0 = never)
    """

    gap: float = 3.0
    clearance: float = 4.0
    port_gap: float = 5.0
    inset: float = 2.0
    rotate: float = 64.0
    endpoint_gap: float = 3.0


@dataclass
class Placement:
    """Where one label ended up.

    Attributes
    ----------
    leader : (k, 2) float, polyline from the anchor to the box
    box : (4,) float, (x0, y0, x1, y1)
    side : int, side code
    tier : int, 0 next to ``A_I``, higher = pushed further out
    shift : float, distance of the box's port from the candidate endpoint along the side
    """

    leader: np.ndarray
    box: np.ndarray
    side: int
    tier: int = 0
    shift: float = 0.0

    @cached_property
    def segments(self) -> np.ndarray:
        """(k - 1, 2, 2) segments of the leader."""
        return np.stack([self.leader[:-1], self.leader[1:]], axis=1)


@dataclass
class BoxStats:
    """Counts of the corrections applied."""

    shifted: int = 0
    swaps: int = 0
    repaired: int = 0
    unplaced: list = field(default_factory=list)


# ---------------------------------------------------------------------------- shift (1D)
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
    assignment : (n,) int, port index of each anchor
    swaps : int
    """
    n = len(anchors)
    assign = np.arange(n)
    limit = n * n + 1 if max_swaps is None else max_swaps
    swaps = 0
    segs = np.stack([anchors, ports[assign]], axis=1)
    x = segments_intersect(segs, segs)
    np.fill_diagonal(x, False)
    while swaps < limit and x.any():
        i, j = np.unravel_index(np.argmax(np.triu(x, 1)), x.shape)
        assign[[i, j]] = assign[[j, i]]
        swaps += 1
        segs[[i, j], 1] = ports[assign[[i, j]]]
        rows = segments_intersect(segs[[i, j]], segs)  # only the two moved leaders changed
        x[[i, j], :] = rows
        x[:, [i, j]] = rows.T
        np.fill_diagonal(x, False)
    return assign, swaps


def coherent_order(desired: np.ndarray, previous: np.ndarray, pitch: float) -> np.ndarray:
    """Order of the boxes of one side: by ``desired``, but neighbours closer than ``pitch``
    keep the order they had in the previous frame.

    Boxes whose desired places are less than one box pitch apart are stacked next to each
    other whatever their order, so their order is free to follow the previous frame
    (``previous``: their coordinate along the same side then, NaN when a label was not on
    this side).  Adjacent such pairs are swapped back until none is left (bubble passes
    over the few labels of a side); crossings this creates are undone by :func:`uncross`.
    An addition to appendix I, whose coherence terms f6, f7 act on anchors and endpoints
    only.

    Returns
    -------
    (n,) int, a permutation of ``range(n)``
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


# ---------------------------------------------------------------------------- layout context
class _Context:
    """Everything the placement of one frame shares."""

    def __init__(
        self,
        anchors,
        endpoints,
        sides,
        widths,
        height,
        area,
        image_size,
        spacing,
        rank,
        previous=None,
        directions=None,
    ):
        self.anchors = np.asarray(anchors, np.float64).reshape(-1, 2)
        # per label: its box centre along each side in the previous frame (NaN: elsewhere)
        self.previous = (
            np.full((len(self.anchors), 4), np.nan) if previous is None else np.asarray(previous, np.float64)
        )
        self.endpoints = np.array(endpoints, np.float64).reshape(-1, 2)  # a copy: parting moves them
        self.sides = np.array(sides, np.int64)  # a copy: a label may change side
        # the layout's principal directions (a label may move to another one of them)
        self.directions = tuple(sorted(set(self.sides.tolist()))) if directions is None else tuple(directions)
        self.widths = np.asarray(widths, np.float64)
        self.height = float(height)
        self.area = area
        self.W, self.H = (float(s) for s in image_size)
        self.sp = spacing
        self.rank = np.asarray(rank, np.int64)
        self.placed: list[Placement | None] = [None] * len(self.anchors)
        x0, y0, x1, y1 = area.bbox
        self.col_x = {
            WEST: float(np.nanmin(area.left)) - spacing.clearance,
            EAST: float(np.nanmax(area.right)) + spacing.clearance,
        }
        self.row_y = {
            NORTH: float(np.nanmin(area.top)) - spacing.clearance,
            SOUTH: float(np.nanmax(area.bottom)) + spacing.clearance,
        }
        self.center = area.centroid
        self.stats = BoxStats()
        self._boundary = None
        self._rays = None
        self._cache = None

    # geometry of one label in a column / row
    def column_box(self, k: int, side: int, y: np.ndarray) -> np.ndarray:
        x = self.col_x[side]
        w, h = self.widths[k], self.height
        y = np.asarray(y, np.float64)
        x0 = np.full_like(y, x - w if side == WEST else x)
        return np.stack([x0, y - h / 2, x0 + w, y + h / 2], axis=-1)

    def row_box(self, k: int, side: int, x: np.ndarray, tier: np.ndarray) -> np.ndarray:
        """Flag box of label k whose leader port is at ``x``, in ``tier``."""
        w, h, sp = self.widths[k], self.height, self.sp
        x = np.asarray(x, np.float64)
        tier = np.asarray(tier, np.float64)
        left_flag = x < self.center[0]
        x0 = np.where(left_flag, x + sp.inset - w, x - sp.inset)
        step = h + sp.gap
        if side == NORTH:
            y1 = self.row_y[NORTH] - tier * step
            y0 = y1 - h
        else:
            y0 = self.row_y[SOUTH] + tier * step
            y1 = y0 + h
        x0, y0, y1 = np.broadcast_arrays(x0, y0, y1)
        return np.stack([x0, y0, x0 + w, y1], axis=-1)

    def row_leader(self, k: int, side: int, x: float, tier: int) -> np.ndarray:
        box = self.row_box(k, side, np.array(x), np.array(tier))
        port = (x, self.row_y[side])
        pts = [self.anchors[k], port]
        if tier > 0:
            pts.append((x, box[3] if side == NORTH else box[1]))
        return np.array(pts, np.float64)

    boundary_step = 2.0
    future: tuple = ()

    def ray_direction(self, k: int) -> np.ndarray:
        """Outward unit normal of ``A_I`` at label k's endpoint: the direction of its push-out.

        Normals of a convex boundary turn monotonically, so these rays never meet.
        """
        if self._rays is None:
            pts, normals = self.boundary
            d2 = ((self.endpoints[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2)
            self._nearest = np.argmin(d2, axis=1)
            self._rays = normals[self._nearest]
        return self._rays[k]

    def boundary_index(self, k: int) -> int:
        """Index of the boundary point (:attr:`boundary`) nearest to label k's endpoint."""
        self.ray_direction(k)
        return int(self._nearest[k])

    def future_rays(self, k: int) -> np.ndarray:
        """Rays (m, 2, 2) of the radial labels not placed yet (other than k)."""
        js = np.array([j for j in self.future if j != k], np.int64)
        if len(js) == 0:
            return np.zeros((0, 2, 2))
        self.ray_direction(0)
        e = self.endpoints[js]
        return np.stack([e, e + self.ray_length * self._rays[js]], axis=1)

    @property
    def reach(self) -> float:
        """Farthest push-out of a box (pixels) the candidate searches consider."""
        size = max(self.W, self.H)
        return max(1.2 * size, 3.0 * len(self.anchors) * (self.height + self.sp.gap))

    @property
    def ray_length(self) -> float:
        """Length of a label's push-out ray in the tests against boxes: longer than any
        push-out the search may choose plus the widest box (a box beyond a ray's end
        would count as leaving it free)."""
        return 2.0 * self.reach + float(self.widths.max()) + self.height

    def future_insides(self, k: int) -> np.ndarray:
        """Inside parts (m, 2, 2), anchor to endpoint, of the radial labels not placed yet (other than k)."""
        js = np.array([j for j in self.future if j != k], np.int64)
        return np.stack([self.anchors[js], self.endpoints[js]], axis=1).reshape(-1, 2, 2)

    @property
    def boundary(self) -> tuple[np.ndarray, np.ndarray]:
        """Points every 2 px along the boundary of ``A_I`` and their outward unit normals."""
        if self._boundary is None:
            pts, arc = resample_boundary(self.area.polygon, 2.0)
            self.boundary_step = float(arc[1] - arc[0])
            tangent = np.roll(pts, -1, axis=0) - np.roll(pts, 1, axis=0)
            normal = np.column_stack([tangent[:, 1], -tangent[:, 0]])
            normal /= np.maximum(np.hypot(normal[:, 0], normal[:, 1]), 1e-12)[:, None]
            outward = np.einsum("ij,ij->i", normal, pts - self.center) >= 0
            normal[~outward] *= -1  # convex area: outward = away from the centre
            self._boundary = (pts, normal)
        return self._boundary


# ---------------------------------------------------------------------------- sides
def _place_column(ctx: _Context, idx: np.ndarray, side: int) -> None:
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
        ctx.stats.shifted += int(shift > 0.5)
        ctx.placed[k] = Placement(
            leader=np.array([ctx.anchors[k], [x, y]]),
            box=ctx.column_box(k, side, np.array(y)),
            side=side,
            tier=0,
            shift=float(shift),
        )


def _place_row(ctx: _Context, idx: np.ndarray, side: int) -> None:
    """Spread the ports of one north/south side (shift, swap), then stack flag boxes in tiers."""
    if len(idx) == 0:
        return
    desired = ctx.endpoints[idx, 0]
    # spread the ports as far as the image allows, up to one box width apart: wider
    # spacing means fewer tiers, at the price of more slanted leaders
    fair = (ctx.W - 2 * ctx.sp.clearance) / len(idx)
    gap = float(np.clip(fair, ctx.sp.port_gap, ctx.widths[idx].mean() + ctx.sp.gap))
    order = coherent_order(desired, ctx.previous[idx, side], gap)
    idx, desired = idx[order], desired[order]
    xs = pack_1d(desired, np.zeros(len(idx)), gap, 0.0, ctx.W)
    y = ctx.row_y[side]
    ports = np.column_stack([xs, np.full(len(idx), y)])
    assign, swaps = uncross(ctx.anchors[idx], ports)
    ctx.stats.swaps += swaps
    port_x = xs[assign]
    left = port_x < ctx.center[0]
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
            ctx.stats.shifted += int(shift > 0.5)
            ctx.placed[k] = Placement(
                ctx.row_leader(k, side, float(port_x[j]), r), box, side, r, float(shift)
            )


def _ring_order(ctx: _Context, idx: np.ndarray) -> np.ndarray:
    """Labels ordered along the boundary of ``A_I``, starting after the widest gap."""
    pts, _ = ctx.boundary
    e = ctx.endpoints[idx]
    q = np.argmin(((e[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2), axis=1)
    order = np.lexsort((idx, q))
    idx, q = idx[order], q[order]
    gaps = np.diff(np.append(q, q[0] + len(pts)))
    return np.roll(idx, -((int(np.argmax(gaps)) + 1) % len(idx)))


def _part_endpoints(ctx: _Context, order: np.ndarray) -> None:
    """Move the silhouette layout's endpoints apart along the boundary of ``A_I``.

    Labels of small neighbouring parts often get the same or nearly the same endpoint
    (their candidates all end on one short stretch of the boundary).  Boxes on rays that
    coincide cannot be stacked: every place of one blocks the other.  So endpoints
    closer than ``Spacing.endpoint_gap`` along the boundary are spread apart, in ring
    order ``order``, by the least squared moves (:func:`pack_1d` on the arc length).
    """
    if len(order) < 2 or ctx.sp.endpoint_gap <= 0:
        return
    pts, normals = ctx.boundary
    m = len(pts)
    ctx.ray_direction(0)  # fills ctx._nearest: each endpoint's boundary point
    q = ctx._nearest[order]
    arc = ((q - q[0]) % m) * ctx.boundary_step  # ring order: increasing from the first
    room = m * ctx.boundary_step
    packed = pack_1d(arc, np.zeros(len(arc)), ctx.sp.endpoint_gap, arc[0] - room, arc[-1] + room)
    if np.allclose(packed, arc):
        return
    new_q = (q[0] + np.round(packed / ctx.boundary_step).astype(np.int64)) % m
    moved = new_q != q
    ctx.endpoints[order[moved]] = pts[new_q[moved]]
    ctx._nearest[order] = new_q
    ctx._rays[order] = normals[new_q]


def _uncross_endpoints(ctx: _Context, idx: np.ndarray) -> int:
    """Swap the endpoints of silhouette labels whose inside parts (anchor -> endpoint) cross.

    Segments to the nearest boundary points of a convex area never cross, but parted
    endpoints and the boundary's 2 px sampling can make two long, nearly parallel ones
    do, and then no push-out can place the later label.  The swap of §5.5 of appendix I
    (:func:`uncross`) fixes it: it keeps the set of endpoints, so their spacing, and
    shortens the leaders.  Returns the number of swaps.
    """
    if len(idx) < 2:
        return 0
    ctx.ray_direction(0)  # fills ctx._nearest and ctx._rays
    assign, swaps = uncross(ctx.anchors[idx], ctx.endpoints[idx])
    if swaps:
        src = idx[assign]
        ctx.endpoints[idx] = ctx.endpoints[src]
        ctx._nearest[idx] = ctx._nearest[src]
        ctx._rays[idx] = ctx._rays[src]
        ctx.stats.swaps += swaps
    return swaps


def _run_order(ctx: _Context, ring: np.ndarray) -> list[int]:
    """Placement order of the silhouette labels: crowded runs from both ends inwards.

    A run is a stretch of labels, consecutive along the boundary, whose boxes next to
    ``A_I`` would collide with the next one's (box on box, or box on the next ray).  In a
    run the boxes become a staircase; placed from one end only, every box has to clear
    all the earlier ones and the stairs grow with the run's length.  Taken alternately
    from both ends, each box hangs towards the end it comes from and the stairs meet in
    the middle at half the height (the same idea as the flags of the top/bottom rows).
    """
    n = len(ring)
    if n < 3:
        return [int(k) for k in ring]
    e, nrm = ctx.endpoints[ring], ctx._rays[ring]
    half = np.column_stack([ctx.widths[ring] / 2, np.full(n, ctx.height / 2)])
    # each box next to A_I, at the attach point that faces its ray most (as the search prefers)
    off = _ATTACH[None, :, :] * half[:, None, :]  # (n, A, 2)
    along = _facing(nrm[:, None, :], off)  # (n, A)
    c = e + ctx.sp.clearance * nrm + off[np.arange(n), np.argmax(along, axis=1)]
    bx = np.concatenate([c - half, c + half], axis=1)
    rays = np.stack([e, e + ctx.ray_length * nrm], axis=1)
    a, b = np.arange(n - 1), np.arange(1, n)
    clash = (
        boxes_overlap(bx[a], bx[b], ctx.sp.gap).diagonal()
        | segment_hits_box(rays[b], bx[a]).diagonal()
        | segment_hits_box(rays[a], bx[b]).diagonal()
    )
    order: list[int] = []
    for run in np.split(np.asarray(ring), np.flatnonzero(~clash) + 1):
        lo, hi = 0, len(run) - 1
        while lo <= hi:  # first, last, second, second to last, ...
            order.extend(int(k) for k in dict.fromkeys((run[lo], run[hi])))
            lo, hi = lo + 1, hi - 1
    return order


def _place_in_order(ctx: _Context, order: list[int]) -> list[int]:
    """Search a place for each silhouette label in ``order``; the labels left out."""
    unplaced = []
    for n, k in enumerate(order):
        ctx.future = tuple(order[n + 1 :])
        if not _search(ctx, k):
            unplaced.append(k)
    ctx.future = ()
    return unplaced


def _place_ring(ctx: _Context, idx: np.ndarray) -> None:
    """Place the boxes of the silhouette layout around ``A_I`` (Fig. 4b of appendix I).

    Labels are taken in their order along the boundary of ``A_I``, starting after the
    widest gap between endpoints, crowded runs from both ends (:func:`_run_order`), and
    each gets its cheapest valid candidate (:func:`_search`): the box just outside
    ``A_I`` on its endpoint's normal ray, else pushed out in tiers, preferring places that
    leave the rays of the labels still to come free.  A box may hang off its port at any
    corner or edge middle, so that a crowded stretch of the boundary becomes a staircase
    of boxes instead of a pile.  If that order leaves a label out, the plain order along
    the boundary is tried too, and the layout that places more labels (then the one with
    shorter leaders) is kept.
    """
    if len(idx) == 0:
        return
    ring = _ring_order(ctx, idx)
    _part_endpoints(ctx, ring)
    if _uncross_endpoints(ctx, idx):
        ring = _ring_order(ctx, idx)
    plain = [int(k) for k in ring]
    orders = [_run_order(ctx, ring), plain]
    shifted = ctx.stats.shifted
    best = None
    for order in orders[:1] if orders[0] == plain else orders:
        if best is not None:  # start the second order from the same state as the first
            ctx.stats.shifted = shifted
            for k in plain:
                ctx.placed[k] = None
        unplaced = _place_in_order(ctx, order)
        score = (len(unplaced), sum(polyline_length(ctx.placed[k].leader) for k in plain if ctx.placed[k]))
        if best is None or score < best[0]:  # ties keep the first order
            best = (score, [ctx.placed[k] for k in plain], ctx.stats.shifted, unplaced)
        if not unplaced:
            break
    _, placements, ctx.stats.shifted, unplaced = best
    for k, p in zip(plain, placements):
        ctx.placed[k] = p
    ctx.stats.unplaced.extend(unplaced)


#: endpoint moves along the boundary (step, largest; pixels) that part leaders sharing an endpoint
_PARTING = (3.0, 24.0)
#: step of the endpoint moves of rotated leaders (pixels), and the tiers their boxes may use
_ROTATE_STEP = 4.0
_ROTATE_TIERS = 3

#: attach points of a box: offsets of the box centre from the port, in half widths/heights
_ATTACH = np.array([[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [1, -1], [-1, 1], [-1, -1]], np.float64)


def _facing(normals: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Cosine between a ray ``normals[..., :]`` and the direction of each box-centre offset
    ``offsets[..., :]`` from the port (broadcast): 1 = the box sits straight on the ray."""
    return np.einsum("...j,...j->...", normals, offsets) / np.hypot(offsets[..., 0], offsets[..., 1])


# ---------------------------------------------------------------------------- candidate search
def _placed_arrays(ctx: _Context, exclude: int) -> tuple[np.ndarray, np.ndarray]:
    """Boxes (P, 4) and leader segments (Q, 2, 2) of every placed label except ``exclude``."""
    key = (exclude, tuple(id(p) for p in ctx.placed))
    if ctx._cache is not None and ctx._cache[0] == key:
        return ctx._cache[1]
    boxes, segs = [], []
    for i, p in enumerate(ctx.placed):
        if p is None or i == exclude:
            continue
        boxes.append(p.box)
        segs.append(p.segments)
    out = (
        np.array(boxes, np.float64).reshape(-1, 4),
        np.concatenate(segs).reshape(-1, 2, 2) if segs else np.zeros((0, 2, 2)),
    )
    ctx._cache = (key, out)
    return out


def _valid(ctx: _Context, k: int, boxes: np.ndarray, leaders: np.ndarray) -> np.ndarray:
    """Which candidates (boxes (K, 4), leaders (K, S, 2, 2)) collide with nothing placed."""
    pboxes, psegs = _placed_arrays(ctx, k)
    ok = _boxes_free(ctx, boxes, pboxes, psegs)
    live = np.flatnonzero(ok)
    if len(live):
        # leaders as polylines; the column/row layouts have few distinct ones per label
        poly = np.concatenate([leaders[live, :, 0], leaders[live, -1:, 1]], axis=1)
        ok[live] = _leaders_free(poly, pboxes, psegs, None)
    return ok


def _outside_image(ctx: _Context, boxes: np.ndarray) -> np.ndarray:
    return (boxes[:, 0] < 0) | (boxes[:, 1] < 0) | (boxes[:, 2] > ctx.W) | (boxes[:, 3] > ctx.H)


def _radial_tiers(ctx: _Context, reach: float) -> int:
    """Push-out tiers of the silhouette layout's candidates within ``reach`` pixels."""
    return int(min(96, max(2, reach // (0.5 * ctx.height + ctx.sp.gap) + 1)))


def _candidates(
    ctx: _Context, k: int, reach: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Candidate (boxes, leaders, costs, tiers, shifts) of a column or row label within ``reach`` pixels."""
    side = int(ctx.sides[k])
    a = ctx.anchors[k]
    h = ctx.height
    if side in (WEST, EAST):
        step = max(1.0, reach / 96.0)
        ys = ctx.endpoints[k, 1] + np.arange(-reach, reach + 0.5 * step, step)
        boxes = ctx.column_box(k, side, ys)
        ports = np.column_stack([np.full(len(ys), ctx.col_x[side]), ys])
        leaders = np.stack([np.broadcast_to(a, ports.shape), ports, ports], axis=1)
        shifts = np.abs(ys - ctx.endpoints[k, 1])
        tiers = np.zeros(len(ys), np.int64)
        cost = shifts
    elif side in (NORTH, SOUTH):
        step = max(1.0, reach / 48.0)
        xs = ctx.endpoints[k, 0] + np.arange(-reach, reach + 0.5 * step, step)
        n_t = int(min(12, max(1, reach // (h + ctx.sp.gap)) + 1))
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
        cost = shifts + T * (h + ctx.sp.gap) * 2.0
    else:
        raise ValueError("radial labels use _radial_candidates")
    cost = cost + 1e4 * _outside_image(ctx, boxes)
    return boxes, leaders, cost, tiers, shifts


def _radial_candidates(
    ctx: _Context, k: int, reach: float, moves: tuple[float, float] | None = None, below: float = np.inf
) -> tuple[np.ndarray, ...]:
    """Candidates of a silhouette-layout label: boxes pushed out along the ray of an endpoint.

    Every endpoint E (the label's own; with ``moves`` = (step, most) also points every
    ``step`` up to ``most`` pixels either way along the boundary of ``A_I``), every tier t
    within ``reach`` (port at ``E + (clearance + t * step) n(E)``, the extruded leaders of
    appendix I Fig. 4b) and every attach point of :data:`_ATTACH`; only those that cost
    less than ``below``.

    Returns
    -------
    boxes : (K, 4)
    leaders : (L, 3, 2), anchor -> E -> port, one per (endpoint, tier)
    lid : (K,) int, the leader of each box
    cost : (K,) pixels of leader: the push-out ``t * step``, plus for a moved endpoint
        the longer inside part and one box height for the bend; then ``(1 - along) h``
        (boxes centred on the ray before corner flags), 1e6 for boxes behind the port,
        1e4 for boxes outside the image
    tiers, shifts : (K,) tier and endpoint move (pixels)
    """
    pts, normals = ctx.boundary
    h, w, a = ctx.height, ctx.widths[k], ctx.anchors[k]
    E, N = ctx.endpoints[k][None], ctx.ray_direction(k)[None]
    if moves:
        step, most = moves
        m = len(pts)
        js = np.unique(np.round(np.arange(step, most + 0.5, step) / ctx.boundary_step).astype(np.int64))
        js = np.concatenate([-js, js])
        q = (ctx.boundary_index(k) + js[(js != 0) & (np.abs(js) <= m // 2)]) % m
        E, N = np.concatenate([E, pts[q]]), np.concatenate([N, normals[q]])
    tier_step = 0.5 * h + ctx.sp.gap
    n_t = _radial_tiers(ctx, reach)
    t = np.arange(n_t)
    off = _ATTACH * np.array([w / 2, h / 2])  # (A, 2)
    along = _facing(N[:, None, :], off[None])  # (E, A)
    moved = np.hypot(*(E - ctx.endpoints[k]).T)
    longer = np.hypot(*(E - a).T) - np.hypot(*(ctx.endpoints[k] - a))
    cost = (
        (t * tier_step)[None, :, None]
        + ((moved > 0) * (h + longer))[:, None, None]
        + ((1.0 - along) * h + 1e6 * (along <= 0.05))[:, None, :]
    )
    ie, it, ia = np.nonzero(cost < below)
    port = E + (ctx.sp.clearance + t[:, None, None] * tier_step) * N  # (T, E, 2)
    c = port[it, ie] + off[ia]
    half = np.array([w / 2, h / 2])
    boxes = np.concatenate([c - half, c + half], axis=1)
    cost = cost[ie, it, ia] + 1e4 * _outside_image(ctx, boxes)
    keep = cost < below
    lid = (ie * n_t + it)[keep]
    used, lid = np.unique(lid, return_inverse=True)
    ue, ut = np.divmod(used, n_t)
    leaders = np.stack([np.broadcast_to(a, (len(used), 2)), E[ue], port[ut, ue]], axis=1)
    return boxes[keep], leaders, lid.ravel(), cost[keep], it[keep], moved[ie[keep]]


def _simplify(pts: np.ndarray) -> np.ndarray:
    """Drop repeated points and middle points that lie on the straight line of their neighbours."""
    keep = [pts[0]]
    for i in range(1, len(pts)):
        if np.hypot(*(pts[i] - keep[-1])) < 1e-9:
            continue
        if len(keep) >= 2:
            a, b = keep[-2], keep[-1]
            u, v = b - a, pts[i] - b
            if abs(u[0] * v[1] - u[1] * v[0]) <= 1e-9 * (np.hypot(*u) * np.hypot(*v)) and u @ v > 0:
                keep[-1] = pts[i]
                continue
        keep.append(pts[i])
    return np.array(keep, np.float64)


def _place(ctx: _Context, k: int, leader: np.ndarray, box: np.ndarray, tier: int, shift: float) -> None:
    ctx.placed[k] = Placement(_simplify(leader), box.copy(), int(ctx.sides[k]), int(tier), float(shift))
    ctx.stats.shifted += int(shift > 0.5)


def _search(ctx: _Context, k: int) -> bool:
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


def _endpoint_towards(ctx: _Context, k: int, side: int) -> np.ndarray:
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


def _search_side(ctx: _Context, k: int) -> bool:
    """Place column/row label k on its current side, at the cheapest valid candidate."""
    size = max(ctx.W, ctx.H)
    for reach in (24.0, 96.0, 0.4 * size, ctx.reach):
        boxes, leaders, cost, tiers, shifts = _candidates(ctx, k, reach)
        ok = _valid(ctx, k, boxes, np.stack([leaders[:, :-1], leaders[:, 1:]], axis=2))
        if ok.any():
            cand = np.flatnonzero(ok)
            best = cand[np.argmin(cost[cand])]  # argmin: first of equal costs
            _place(ctx, k, leaders[best], boxes[best], tiers[best], shifts[best])
            return True
    return False


def _boxes_free(ctx: _Context, boxes: np.ndarray, pboxes: np.ndarray, psegs: np.ndarray) -> np.ndarray:
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


def _cheapest(
    ctx: _Context, k: int, cands: tuple, rays: np.ndarray, paths: np.ndarray | None
) -> tuple[int | None, int | None]:
    """Cheapest valid radial candidate that blocks no future ray, and the cheapest valid one.

    ``cands`` = (boxes, leaders, lid, cost, ...) of :func:`_radial_candidates`, where the
    boxes of one leader share it, so each leader is tested once for all its boxes (the
    box tests run first and drop most candidates).  ``rays``: rays of the labels still
    to come; ``paths``: their leader paths, which the leaders must not cut (for moved
    endpoints).  Returns indices into ``cands`` (None: no such candidate): the first
    free one in order of cost (stable: the lower index on ties), else None and the
    valid one of least cost + 1e5 x rays blocked.
    """
    boxes, leaders, leader_of, cost = cands[:4]
    pboxes, psegs = _placed_arrays(ctx, k)
    idx = np.argsort(cost, kind="stable")
    idx = idx[_boxes_free(ctx, boxes[idx], pboxes, psegs)]
    used, inverse = np.unique(leader_of[idx], return_inverse=True)
    idx = idx[_leaders_free(leaders[used], pboxes, psegs, paths)[inverse.ravel()]]
    if len(idx) == 0:
        return None, None
    blocks = segment_hits_box(rays, boxes[idx]).sum(axis=0) if len(rays) else np.zeros(len(idx))
    if (blocks == 0).any():
        return int(idx[np.argmax(blocks == 0)]), None
    return None, int(idx[np.argmin(cost[idx] + 1e5 * blocks)])


def _search_radial(ctx: _Context, k: int) -> bool:
    """Place label k of the silhouette layout.

    Candidates (:func:`_radial_candidates`), cheapest valid first: on the label's own
    ray; then, if that box is pushed out, a *rotated* leader (endpoint moved up to
    ``Spacing.rotate`` pixels along the boundary, box within ``_ROTATE_TIERS`` tiers)
    when it costs less leader; if the own ray has no valid place at all, endpoints moved
    a few pixels (:data:`_PARTING`: a leader blocked at its start, e.g. by one sharing
    its endpoint).  A moved endpoint's leader must not cut the path of a label still to
    come; a box that would block the ray of one is taken only when no candidate avoids it.
    """
    size = max(ctx.W, ctx.H)
    far = ctx.reach
    rays = ctx.future_rays(k)
    paths = np.concatenate([ctx.future_insides(k), rays]) if len(rays) else rays
    tier_step = 0.5 * ctx.height + ctx.sp.gap
    best = fallback = None
    for reach in (0.4 * size, far):  # the far list extends the near one
        own = _radial_candidates(ctx, k, reach)
        best, fallback = _cheapest(ctx, k, own, rays, None)
        if best is not None:
            break
    if best is not None:
        choice = own
        # a rotated leader costs at least one box height more than its tier's push-out,
        # so only a box pushed out further than that can lose to one
        room = min(own[3][best] - ctx.height, (min(own[4][best], _ROTATE_TIERS) - 1) * tier_step)
        if room >= 0 and ctx.sp.rotate > 0:
            rot = _radial_candidates(ctx, k, room, (_ROTATE_STEP, ctx.sp.rotate), below=own[3][best])
            r, _ = _cheapest(ctx, k, rot, rays, paths)
            if r is not None:
                choice, best = rot, r
    else:
        for reach in (0.4 * size, far):
            moved = _radial_candidates(ctx, k, reach, _PARTING)
            best, fallback2 = _cheapest(ctx, k, moved, rays, paths)
            if best is not None:
                break
        choice = moved
        if best is None:
            if fallback is not None:
                choice, best = own, fallback
            elif fallback2 is not None:
                best = fallback2
            else:
                return False
    boxes, leaders, leader_of, cost, tiers, shifts = choice
    _place(ctx, k, leaders[leader_of[best]], boxes[best], tiers[best], shifts[best])
    return True


def _conflicting(ctx: _Context) -> list[int]:
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
) -> tuple[list[Placement | None], BoxStats]:
    """Lay out the boxes and leaders of all labels of one frame.

    Parameters
    ----------
    anchors, endpoints : (n, 2) float, the anchors and candidate endpoints (pixels)
    sides : (n,) int, side code of each label
    widths : (n,) float, box widths; ``height`` : box height
    area : InternalArea
    image_size : (width, height)
    rank : (n,) int, greedy placement order (lower = placed first); default 0..n-1
    spacing : Spacing
    previous : (n, 4) float, optional: each label's box centre along the west, east,
        north and south side in the previous frame (y for west/east, x for north/south;
        NaN where it was not on that side), for :func:`coherent_order`
    directions : side codes of the layout (default: those in ``sides``); a label with no
        room on its side may move to another one of them

    Returns
    -------
    placements : list of Placement or None (no valid place found)
    stats : BoxStats
    """
    n = len(anchors)
    rank = np.arange(n) if rank is None else np.asarray(rank)
    ctx = _Context(
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
    )
    for side in (WEST, EAST):
        _place_column(ctx, np.flatnonzero(ctx.sides == side), side)
    for side in (NORTH, SOUTH):
        _place_row(ctx, np.flatnonzero(ctx.sides == side), side)
    _place_ring(ctx, np.flatnonzero(ctx.sides == RADIAL))
    for _ in range(4):
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
