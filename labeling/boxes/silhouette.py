"""The silhouette layout.

Boxes are pushed out along the normals of ``A_I`` (appendix I, Fig. 4b), in ring order,
with parted, rotated and uncrossed endpoints.
"""

from __future__ import annotations

import numpy as np

from ..geometry2d import boxes_overlap, polyline_length, segment_hits_box
from ._kernels import first_free, radial_candidates
from .collisions import _boxes_free, _leaders_free, _outside_image, _place, _placed_arrays
from .context import NEAR_REACH, Context
from .costs import BEHIND_PORT_COS, BEHIND_PORT_COST, BLOCKED_RAY_COST, COHERENCE_COST, OUTSIDE_IMAGE_COST
from .stacking import pack_1d, uncross

#: push-out tiers of a silhouette box are half a box height (plus the gap) apart: boxes of
#: neighbouring rays interleave at that pitch
RADIAL_TIER = 0.5
#: fewest and most push-out tiers a silhouette candidate list holds
RADIAL_TIERS = (2, 96)
#: endpoint moves along the boundary (step, largest; pixels) that part leaders sharing an endpoint
_PARTING = (3.0, 24.0)


#: step of the endpoint moves of rotated leaders (pixels), and the tiers their boxes may use
_ROTATE_STEP = 4.0


_ROTATE_TIERS = 3


#: attach points of a box: offsets of the box centre from the port, in half widths/heights
_ATTACH = np.array([[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [1, -1], [-1, 1], [-1, -1]], np.float64)
#: the penalties of a candidate, as :func:`._kernels.radial_candidates` takes them
_COSTS = (float(BEHIND_PORT_COST), float(BEHIND_PORT_COS), float(OUTSIDE_IMAGE_COST), float(COHERENCE_COST))


def _facing(normals: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Cosine between a ray and the direction of each box-centre offset from the port.

    The ray is ``normals[..., :]`` and the offsets are ``offsets[..., :]`` (broadcast);
    1 means the box sits straight on the ray.
    """
    return np.einsum("...j,...j->...", normals, offsets) / np.hypot(offsets[..., 0], offsets[..., 1])


def _radial_tiers(ctx: Context, reach: float) -> int:
    """Push-out tiers of the silhouette layout's candidates within ``reach`` pixels."""
    return int(
        min(RADIAL_TIERS[1], max(RADIAL_TIERS[0], reach // (RADIAL_TIER * ctx.height + ctx.sp.gap) + 1))
    )


def _radial_candidates(
    ctx: Context, k: int, reach: float, moves: tuple[float, float] | None = None, below: float = np.inf
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
    leaders : (L, 3, 2)
        Anchor -> E -> port, one per (endpoint, tier)
    lid : (K,) int
        The leader of each box
    cost : (K,) pixels of leader: the push-out ``t * step``, plus for a moved endpoint
        the longer inside part and one box height for the bend; then ``(1 - along) h``
        (boxes centred on the ray before corner flags), :data:`~.costs.BEHIND_PORT_COST` for
        boxes behind the port, :data:`~.costs.OUTSIDE_IMAGE_COST` for boxes outside the image
    tiers, shifts : (K,) tier and endpoint move (pixels)

    The lists are built by the compiled :func:`._kernels.radial_candidates` (a label
    searches several times per frame, each list of a few hundred candidates).
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
    return radial_candidates(
        np.ascontiguousarray(E, np.float64),
        np.ascontiguousarray(N, np.float64),
        np.asarray(ctx.endpoints[k], np.float64),
        np.asarray(a, np.float64),
        float(w),
        float(h),
        float(RADIAL_TIER * h + ctx.sp.gap),
        float(ctx.sp.clearance),
        _radial_tiers(ctx, reach),
        float(below),
        np.array([ctx.W, ctx.H], np.float64),
        np.asarray(ctx.centres[k], np.float64),
        _ATTACH,
        _COSTS,
    )


def _cheapest(
    ctx: Context, k: int, cands: tuple, rays: np.ndarray, paths: np.ndarray | None
) -> tuple[int | None, int | None]:
    """Cheapest valid radial candidate that blocks no future ray, and the cheapest valid one.

    ``cands`` = (boxes, leaders, lid, cost, ...) of :func:`_radial_candidates`, where the
    boxes of one leader share it, so each leader is tested once for all its boxes (the
    box tests run first and drop most candidates).  ``rays``: rays of the labels still
    to come; ``paths``: their leader paths, which the leaders must not cut (for moved
    endpoints).  Returns indices into ``cands`` (None: no such candidate): the first
    free one in order of cost (stable: the lower index on ties), else None and the
    valid one of least cost + :data:`~.costs.BLOCKED_RAY_COST` x rays blocked.
    """
    boxes, leaders, leader_of, cost = cands[:4]
    pboxes, psegs = _placed_arrays(ctx, k)
    order = np.argsort(cost, kind="stable")
    free, fallback = first_free(
        order,
        np.ascontiguousarray(boxes, np.float64),
        np.ascontiguousarray(leader_of, np.int64),
        np.ascontiguousarray(leaders, np.float64),
        np.ascontiguousarray(cost, np.float64),
        ctx.area.integral,
        int(ctx.area.pad),
        np.ascontiguousarray(pboxes, np.float64),
        np.ascontiguousarray(psegs, np.float64).reshape(-1, 2, 2),
        np.zeros((0, 2, 2)) if paths is None else np.ascontiguousarray(paths, np.float64).reshape(-1, 2, 2),
        np.ascontiguousarray(rays, np.float64).reshape(-1, 2, 2),
        float(ctx.sp.gap),
        float(BLOCKED_RAY_COST),
    )
    return (int(free) if free >= 0 else None), (int(fallback) if fallback >= 0 else None)


def _search_radial(ctx: Context, k: int) -> bool:
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
    tier_step = RADIAL_TIER * ctx.height + ctx.sp.gap
    best = fallback = None
    for reach in (NEAR_REACH * size, far):  # the far list extends the near one
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
        for reach in (NEAR_REACH * size, far):
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


def _ring_order(ctx: Context, idx: np.ndarray) -> np.ndarray:
    """Labels ordered along the boundary of ``A_I``, starting after the widest gap."""
    pts, _ = ctx.boundary
    e = ctx.endpoints[idx]
    q = np.argmin(((e[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2), axis=1)
    order = np.lexsort((idx, q))
    idx, q = idx[order], q[order]
    gaps = np.diff(np.append(q, q[0] + len(pts)))
    return np.roll(idx, -((int(np.argmax(gaps)) + 1) % len(idx)))


def _part_endpoints(ctx: Context, order: np.ndarray) -> None:
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


def _uncross_endpoints(ctx: Context, idx: np.ndarray) -> int:
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


def _run_order(ctx: Context, ring: np.ndarray) -> list[int]:
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


#: a box kept from the previous frame must hang off its leader within this angle of the
#: boundary's outward normal at the leader's endpoint (cosine): not behind the leader
KEEP_COS = 0.5


#: a kept box that now covers the model or another label may move this far (pixels) to
#: the nearest free place around where it was, in steps of NUDGE_STEP: a small glide
#: instead of a search that may take it anywhere around the model
NUDGE_REACH = 24.0
NUDGE_STEP = 3.0
#: nudged places whose leaders are tried per label (nearest first)
NUDGE_TRIES = 20


def _nudges(ctx: Context, c: np.ndarray) -> np.ndarray:
    """Offsets (m, 2) of a kept box centre ``c``, nearest first: none, then outwards and along."""
    u = c - ctx.center
    u = u / max(float(np.hypot(*u)), 1e-9)
    v = np.array([-u[1], u[0]])
    t = np.arange(0.0, NUDGE_REACH + 1e-9, NUDGE_STEP)
    t = np.concatenate([-t[:0:-1], t])
    a, b = np.meshgrid(t, t, indexing="ij")
    off = a.reshape(-1, 1) * u + b.reshape(-1, 1) * v
    d = np.hypot(off[:, 0], off[:, 1])
    keep = d <= NUDGE_REACH + 1e-9
    order = np.lexsort((b.reshape(-1)[keep], a.reshape(-1)[keep], d[keep]))
    return off[keep][order]


def _kept_leaders(
    ctx: Context, k: int, c: np.ndarray, half: np.ndarray, before: np.ndarray | None, offset: np.ndarray
) -> list:
    """Leaders a kept box may hang off.

    Last frame's leader moved with the anchor (its port moved with the box by ``offset``),
    then one from this frame's endpoint.
    """
    out = []
    if before is not None:
        before = np.array(before, np.float64)
        before[-1] += offset
        out.append(np.vstack([ctx.anchors[k][None], before]))
    e, n = ctx.endpoints[k], ctx.ray_direction(k)
    ports = c - _ATTACH * half  # the attach points of the box
    d = ports - e
    length = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)
    facing = (d @ n) / length >= KEEP_COS
    if facing.any():
        out.append(np.array([ctx.anchors[k], e, ports[np.flatnonzero(facing)[np.argmin(length[facing])]]]))
    return out


def _expected_paths(ctx: Context, idx: np.ndarray, leaders: list | None) -> list[np.ndarray]:
    """Per ring label, the segments (m, 2, 2) its leader is expected to take this frame.

    Last frame's leader moved with its anchor where there is one (it is kept if it can
    be), else the inside part from its anchor to its endpoint.
    """
    out = []
    for k in idx:
        before = None if leaders is None else leaders[k]
        if before is not None and len(before):
            pts = np.vstack([ctx.anchors[k][None], np.asarray(before, np.float64)])
        else:
            pts = np.array([ctx.anchors[k], ctx.endpoints[k]])
        out.append(np.stack([pts[:-1], pts[1:]], axis=1))
    return out


def _keep_previous(ctx: Context, idx: np.ndarray, leaders: list | None = None) -> list[int]:
    """Hysteresis of the silhouette layout: keep last frame's boxes where they are still valid.

    Each label (in greedy order) whose box moved with its anchor (``ctx.centres``) still
    covers no model pixel, no placed box or leader, stays inside the image, and can be
    reached from this frame's endpoint through one of its attach points without crossing
    a placed leader or the path of another label, is placed there; where that box is not
    free, the nearest free place within :data:`NUDGE_REACH` is taken instead.  Returns the
    labels placed; the others go through the search.
    """
    known = [int(k) for k in idx if np.isfinite(ctx.centres[k, 0])]
    if not known:
        return []
    kept: list[int] = []
    paths = _expected_paths(ctx, idx, leaders)
    for k in sorted(known, key=lambda k: (ctx.rank[k], k)):
        others = [p for j, p in zip(idx, paths) if j != k and ctx.placed[j] is None]
        others = np.concatenate(others) if others else None
        before = None if leaders is None else leaders[k]
        # where it was first; the nudged places only when that fails (the usual case is cheap)
        if _keep_at(ctx, k, np.zeros((1, 2)), before, others) or _keep_at(
            ctx, k, _nudges(ctx, ctx.centres[k])[1:], before, others
        ):
            kept.append(k)
    return kept


def _keep_at(ctx: Context, k: int, offsets: np.ndarray, before: np.ndarray | None, others) -> bool:
    """Place label k at the first valid one of its moved box shifted by ``offsets`` (nearest first)."""
    half = np.array([ctx.widths[k] / 2, ctx.height / 2])
    centres = ctx.centres[k] + offsets
    boxes = np.concatenate([centres - half, centres + half], axis=1)
    pboxes, psegs = _placed_arrays(ctx, k)
    ok = ~_outside_image(ctx, boxes)
    live = np.flatnonzero(ok)
    ok[live] = _boxes_free(ctx, boxes[live], pboxes, psegs)
    for m in np.flatnonzero(ok)[:NUDGE_TRIES]:
        for leader in _kept_leaders(ctx, k, centres[m], half, before, offsets[m]):
            if _leaders_free(leader[None], pboxes, psegs, others)[0]:
                _place(ctx, k, leader, boxes[m], 0, float(np.hypot(*(leader[1] - ctx.endpoints[k]))))
                return True
    return False


def _place_in_order(ctx: Context, order: list[int]) -> list[int]:
    """Search a place for each silhouette label in ``order``; the labels left out."""
    unplaced = []
    for n, k in enumerate(order):
        ctx.future = tuple(order[n + 1 :])
        if not _search_radial(ctx, k):
            unplaced.append(k)
    ctx.future = ()
    return unplaced


def _place_ring(ctx: Context, idx: np.ndarray) -> None:
    """Place the boxes of the silhouette layout around ``A_I`` (Fig. 4b of appendix I).

    Labels are taken in their order along the boundary of ``A_I``, starting after the
    widest gap between endpoints, crowded runs from both ends (:func:`_run_order`), and
    each gets its cheapest valid candidate (:func:`_search_radial`): the box just outside
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

    def score(placements: list, unplaced: list) -> tuple[int, float]:
        return len(unplaced), sum(polyline_length(p.leader) for p in placements if p)

    best = None
    for order in orders[:1] if orders[0] == plain else orders:
        if best is not None:  # start the second order from the same state as the first
            ctx.stats.shifted = shifted
            for k in plain:
                ctx.placed[k] = None
        unplaced = _place_in_order(ctx, order)
        found = ([ctx.placed[k] for k in plain], ctx.stats.shifted, unplaced)
        # ties keep the first order (the scores are measured only when two orders compete)
        if best is None or score(found[0], found[2]) < score(best[0], best[2]):
            best = found
        if not unplaced:
            break
    placements, ctx.stats.shifted, unplaced = best
    for k, p in zip(plain, placements):
        ctx.placed[k] = p
    ctx.stats.unplaced.extend(unplaced)
