"""The labeling pipeline of one frame (appendix I, §6.1), from model and camera to labels.

Stages and their timing keys:

``setup``       load / combine the model, build the ray caster (once per model)
``idbuffer``    primary rays -> object ids, visible areas (Step 1)
``area``        the internal area ``A_I``
``candidates``  leader candidate and ``f2`` of every pixel of ``A_I`` (Steps 2-3)
``salience``    distance to the own area's silhouette, ``f3`` (Step 4)
``memberships`` ``F`` of every candidate of a labelled area (Step 6)
``greedy``      the greedy loop (Step 7)
``boxes``       label boxes: stacking, shift, swap (Step 8)
``metrics``     quality measures (not part of the layout)

``layout_ms`` in the timings is everything after the ID buffer up to and including the
boxes: the number the paper reports per frame.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis.errors import ParameterError
from meshvis.rays.camera import Camera
from meshvis.rays.caster import RayCaster
from meshvis.soup import Soup

from .boxes import Spacing, place_boxes
from .candidates import LAYOUTS, SIDE_NAMES, check_layout, is_horizontal, leader_candidates
from .greedy import greedy_layout, stable_order
from .idbuffer import IdBuffer, id_buffer
from .inputs import label_texts, load_models
from .internal_area import internal_area
from .membership import Weights, f2_length, f3_salience, f_coherence, silhouette_distance, weighted
from .metrics import frame_metrics
from .result import Label, LayoutResult
from .text import TextStyle, default_font_size

METHODS = ("fuzzy", "two-step")

#: default of ``min_pixels``: a part seen by fewer pixels is not labelled.  An anchor needs
#: a few pixels around it to be told apart from its neighbours (and to stay on its part
#: from frame to frame); parts of a handful of pixels flicker in and out along a path
MIN_PIXELS = 10

#: stages that make up the per-frame layout time
LAYOUT_STAGES = ("area", "candidates", "salience", "memberships", "greedy", "boxes")


def fit_camera(
    soup: Soup,
    *,
    azimuth: float = 30.0,
    elevation: float = 20.0,
    distance: float | None = None,
    fov: float = 35.0,
    orthographic: bool = False,
    up: Sequence[float] | None = None,
    margin: float = 1.6,
    size: tuple[int, int] | None = None,
) -> Camera:
    """The default labeling camera: like :meth:`Camera.fit` but with room around the model.

    ``margin`` 1.6 leaves about a fifth of the image on each side for the labels.  ``fov``
    is the vertical field of view; with ``size`` = (width, height) of a portrait image the
    narrower horizontal field of view decides the distance, so that the model fits both.

    Examples
    --------
    >>> import trimesh
    >>> soup = Soup(trimesh.creation.box().vertices, trimesh.creation.box().faces)
    >>> wide, tall = fit_camera(soup, size=(400, 200)), fit_camera(soup, size=(200, 400))
    >>> bool(np.linalg.norm(tall.position - tall.target) > np.linalg.norm(wide.position - wide.target))
    True
    """
    aspect = 1.0 if size is None else float(size[0]) / float(size[1])
    if aspect < 1.0 and distance is None and not orthographic:
        # the bounding sphere (times margin) must fit the horizontal field of view too
        radius = 0.5 * soup.diagonal or 1.0
        half = np.arctan(np.tan(np.radians(fov) / 2) * aspect)
        distance = margin * radius / np.sin(half)
    cam = Camera.fit(
        soup,
        azimuth=azimuth,
        elevation=elevation,
        distance=distance,
        fov=fov,
        orthographic=orthographic,
        margin=margin,
        up=up,
    )
    if orthographic and aspect < 1.0 and cam.ortho_height is not None:
        cam = Camera(cam.position, cam.target, cam.up, cam.fov, True, cam.ortho_height / aspect)
    return cam


def _fit_font(
    n_labels: int, layout: str, height: int, font_size: int, min_size: int = 6, gap: float = 3.0
) -> TextStyle:
    """Shrink the font until the boxes of a west/east column fit the image height."""
    style = TextStyle(font_size)
    if not is_horizontal(layout) or n_labels == 0:
        return style
    per_side = int(np.ceil(n_labels / len(LAYOUTS[layout])))
    while style.font_size > min_size and per_side * (style.box_height + gap) > 0.92 * height:
        style = TextStyle(style.font_size - 1)
    return style


#: hysteresis along a camera path: a label keeps last frame's anchor (followed on the
#: surface) unless a candidate is more than ANCHOR_KEEP times as feasible, and keeps its
#: side unless the other side's leader is shorter by more than the factor SIDE_KEEP
ANCHOR_KEEP = 4.0
#: the same for the top and bottom rows, whose ports follow their anchors from frame to
#: frame: an anchor that jumps across its part drags its leader and box along
ANCHOR_KEEP_ROWS = 30.0
SIDE_KEEP = 20.0
#: side changes come together: in a frame where some label changes side, every label
#: whose other side is shorter by more than this factor changes too.  A viewer sees one
#: rearrangement instead of one label after another over the next frames
SIDE_BATCH = 1.5
#: how far an anchor may slide over its part from one frame to the next, as a fraction of
#: ``d_S`` (and at least ANCHOR_DRIFT_PX): it creeps towards better places instead of jumping
ANCHOR_DRIFT = 0.01
ANCHOR_DRIFT_PX = 2.0


@dataclass
class _Previous:
    """The previous frame's labels, moved with the model into this frame.

    Every array has a row per label of this frame (NaN / -1 where the label was absent).
    The anchor is the previous anchor's surface point seen by this frame's camera; the
    endpoint and box centres are moved by the same screen offset, so that a label that
    follows its anchor counts as not having moved.

    Attributes
    ----------
    anchor, endpoint : (n, 2) float
    box : (n, 4) float, the box centre along the west, east, north and south sides (y for
        west/east, x for north/south; NaN on the other sides)
    side : (n,) int, side code (-1: absent)
    centre : (n, 2) float, the box centre
    leader : n polylines (k, 2) (None: absent), the leader without its anchor point
    lines : (4,) float, the x of the west and east columns, the y of the north and south
        rows (NaN: no label there); not moved
    motion : (n,) float, how far the surface under the previous anchor moved on the screen
        (pixels; NaN: absent)
    left_out : (n,) bool, the label was left out for lack of room
    """

    anchor: np.ndarray
    endpoint: np.ndarray
    box: np.ndarray
    side: np.ndarray
    centre: np.ndarray
    lines: np.ndarray
    leader: list
    motion: np.ndarray
    left_out: np.ndarray


def _previous_frame(previous: LayoutResult, idbuf: IdBuffer, slot: np.ndarray, n: int) -> _Previous:
    """Where the previous frame's labels are now (see :class:`_Previous`)."""
    anchor, endpoint, box = np.full((n, 2), np.nan), np.full((n, 2), np.nan), np.full((n, 4), np.nan)
    side = np.full(n, -1, np.int64)
    centre = np.full((n, 2), np.nan)
    leader: list = [None] * n
    lines = np.full(4, np.nan)
    motion = np.full(n, np.nan)
    left_out = np.zeros(n, bool)
    for p, _ in previous.unplaced:
        if p < len(slot) and slot[p] >= 0:
            left_out[slot[p]] = True
    for lab in previous.labels:
        code = SIDE_NAMES.index(lab.side)
        if code < 4 and lab.tier == 0:
            # the column's x is the box edge facing the model, the row's y the leader port's
            lines[code] = {0: lab.box[2], 1: lab.box[0]}.get(
                code, lab.leader[-1][1] if lab.tier == 0 else np.nan
            )
    labs = [lab for lab in previous.labels if lab.part < len(slot) and slot[lab.part] >= 0]
    if not labs:
        return _Previous(anchor, endpoint, box, side, centre, lines, leader, motion, left_out)
    h, w = idbuf.shape
    moved, _ = idbuf.camera.project(np.array([lab.anchor_3d for lab in labs], np.float64), w, h)
    for lab, now in zip(labs, moved):
        s = slot[lab.part]
        delta = now - lab.anchor if np.all(np.isfinite(now)) else np.zeros(2)
        anchor[s], endpoint[s] = lab.anchor + delta, lab.endpoint + delta
        motion[s] = float(np.hypot(*delta))
        code = SIDE_NAMES.index(lab.side)
        side[s] = code
        centre[s] = 0.5 * (lab.box[:2] + lab.box[2:]) + delta
        leader[s] = lab.leader[1:] + delta
        if code < 4:
            axis = 1 if code < 2 else 0
            box[s, code] = 0.5 * (lab.box[axis] + lab.box[axis + 2]) + delta[axis]
    return _Previous(anchor, endpoint, box, side, centre, lines, leader, motion, left_out)


def _preferred_sides(idbuf: IdBuffer, labelled: np.ndarray, prev: _Previous | None) -> np.ndarray | None:
    """(h, w) side code of the previous frame's label of each pixel's part (-1: none)."""
    if prev is None:
        return None
    of_part = np.full(len(idbuf.part_names) + 1, -1, np.int8)
    known = prev.side >= 0
    of_part[labelled[known]] = prev.side[known]
    return of_part[idbuf.ids]  # background (-1) reads the last entry: -1


class _Stopwatch:
    """Seconds per stage, added up under the stage's timing key."""

    def __init__(self) -> None:
        self.timings: dict[str, float] = {}

    def tick(self, key: str, t0: float) -> float:
        """Add the time since ``t0`` to ``key``; return now (the next stage's start)."""
        t = time.perf_counter()
        self.timings[key] = self.timings.get(key, 0.0) + t - t0
        return t


@dataclass
class _Pixels:
    """The candidates of the labelled areas' pixels, grouped by area (row-major inside one).

    ``slot``: (parts,) the area index of each labelled part (-1: not labelled); the others
    are per pixel: its flat index, area, anchor ``(ax, ay)``, candidate endpoint
    ``(ex, ey)``, endpoint id, leader length, side code and salience.
    """

    slot: np.ndarray
    pix: np.ndarray
    area_of: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    ex: np.ndarray
    ey: np.ndarray
    eid: np.ndarray
    length: np.ndarray
    side: np.ndarray
    sal: np.ndarray


def _check_arguments(
    layout: str, method: str, d_a: float, d_e: float | None, n_texts: int, n_parts: int
) -> None:
    """Raise ParameterError on an argument of :func:`solve` out of its range."""
    check_layout(layout)
    if method not in METHODS:
        raise ParameterError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    if not (np.isfinite(d_a) and d_a >= 0):
        raise ParameterError(f"d_a must be >= 0, got {d_a}")
    if d_e is not None and not (np.isfinite(d_e) and d_e >= 0):
        raise ParameterError(f"d_e must be >= 0, got {d_e}")
    if n_texts != n_parts:
        raise ParameterError(f"{n_texts} label texts for {n_parts} parts")


def _sort_parts(idbuf: IdBuffer, texts: Sequence[str], min_pixels: int) -> tuple[list, list, np.ndarray]:
    """Sort the parts into those to skip and those to label.

    Returns (part id, name) of the invisible parts, (part id, name) of the visible ones
    without a text, and the ids of the parts to label.
    """
    names = idbuf.part_names
    visible = idbuf.visible(min_pixels)
    invisible = [(int(p), names[p]) for p in idbuf.invisible(min_pixels)]
    skipped = [(int(p), names[p]) for p in visible if not texts[p]]
    labelled = np.array([p for p in visible if texts[p]], np.int64)
    return invisible, skipped, labelled


def _params(
    layout: str,
    area: str,
    margin: float,
    method: str,
    weights: Weights,
    thresholds: dict,
    min_pixels: int,
    stats,
) -> dict[str, Any]:
    """``LayoutResult.params``: the parameters used and the counts of the box corrections."""
    return {
        "layout": layout,
        "area": area,
        "margin": margin,
        "method": method,
        "weights": weights.as_dict(),
        **thresholds,
        "min_pixels": int(min_pixels),
        "corrections": {"shifted": stats.shifted, "swaps": stats.swaps, "repaired": stats.repaired},
    }


def _thresholds(d_a: float, d_e: float | None, d_s: float, da_px: float, de_px: float, d_max: float) -> dict:
    """The distance thresholds used, as fractions of ``d_S`` and in pixels (``params``)."""
    return {
        "d_a": d_a,
        "d_e": (de_px / d_s) if d_e is None else d_e,
        "d_a_px": da_px,
        "d_e_px": de_px,
        "d_max_px": d_max,
    }


def _nothing_to_label(
    idbuf: IdBuffer,
    invisible: list,
    skipped: list,
    *,
    layout: str,
    method: str,
    area: str,
    margin: float | None,
    font_size: int | None,
    timings: dict[str, float],
) -> LayoutResult:
    """The result of a view without a labelled visible part (or without any model pixel)."""
    ia = internal_area(idbuf.model_mask, area, margin) if idbuf.model_mask.any() else None
    return LayoutResult(
        labels=[],
        invisible=invisible,
        unplaced=[],
        skipped=skipped,
        image=idbuf.image,
        ids=idbuf.ids,
        camera=idbuf.camera,
        layout=layout,
        method=method,
        area_polygon=ia.polygon if ia is not None else np.zeros((0, 2)),
        font_size=font_size or default_font_size(idbuf.shape[0]),
        box_height=0.0,
        sphere_diameter=idbuf.sphere_diameter,
        params={},
        metrics=frame_metrics_empty(),
        timings=timings,
    )


def _pixels(idbuf: IdBuffer, cand, dist_sil: np.ndarray, labelled: np.ndarray, n_parts: int) -> _Pixels:
    """Gather the candidates of every pixel of the labelled areas (stable: row-major inside an area)."""
    w = idbuf.shape[1]
    slot = np.full(n_parts, -1, np.int64)
    slot[labelled] = np.arange(len(labelled))
    ids_flat = idbuf.ids.ravel()
    pix = np.flatnonzero(ids_flat >= 0)
    pix = pix[slot[ids_flat[pix]] >= 0]
    area_of = slot[ids_flat[pix]]
    order = stable_order(area_of)
    pix, area_of = pix[order], area_of[order]
    row, col = np.divmod(pix, w)
    return _Pixels(
        slot=slot,
        pix=pix,
        area_of=area_of,
        ax=col + 0.5,
        ay=row + 0.5,
        ex=cand.ex.ravel()[pix],
        ey=cand.ey.ravel()[pix],
        eid=cand.eid.ravel()[pix],
        length=cand.length.ravel()[pix],
        side=cand.side.ravel()[pix],
        sal=dist_sil.ravel()[pix],
    )


def _fuzzy_picks(
    px: _Pixels,
    cand,
    weights: Weights,
    previous: _Previous | None,
    n: int,
    d_s: float,
    da_px: float,
    de_px: float,
    clock: _Stopwatch,
    t: float,
    keep: float = ANCHOR_KEEP,
) -> tuple[tuple[np.ndarray, ...], float]:
    """Compute the memberships and run the greedy loop.

    The memberships follow Eq. 11, with the coherence terms f6, f7 given ``previous``
    (measured from the previous anchors and endpoints moved with the model).
    Returns the area order, each area's pick, feasibility and priority, and the clock.
    """
    static = weighted(f2_length(px.length, cand.d_max), weights.w2) * weighted(
        f3_salience(px.sal, cand.d_max), weights.w3
    )
    follow = None
    if previous is not None:
        static = static * weighted(f_coherence(px.ax, px.ay, previous.anchor[px.area_of], d_s), weights.w6)
        static = static * weighted(f_coherence(px.ex, px.ey, previous.endpoint[px.area_of], d_s), weights.w7)
        follow = previous.anchor
    t = clock.tick("memberships", t)
    g = greedy_layout(
        px.area_of,
        px.ax,
        px.ay,
        px.eid,
        cand.endpoints,
        static,
        n,
        da_px,
        de_px,
        weights.w4,
        weights.w5,
        follow=follow,
        drift=max(ANCHOR_DRIFT * d_s, ANCHOR_DRIFT_PX),
        keep=keep,
    )
    t = clock.tick("greedy", t)
    return (g.area_order, g.pick, g.feasibility, g.priority), t


def _changes_side(px: _Pixels, order: tuple[np.ndarray, ...], prev: _Previous) -> bool:
    """True when a picked candidate leaves on another side than its label did last frame."""
    areas, picks = order[0], order[1]
    before = prev.side[areas]
    return bool(np.any((before >= 0) & (px.side[picks] != before)))


def _two_step_picks(px: _Pixels, n: int, clock: _Stopwatch, t: float) -> tuple[tuple[np.ndarray, ...], float]:
    """The classic baseline: pick the most salient pixel of each area.

    Ties go to the first pixel in row-major order; there is no feasibility or priority (NaN).
    """
    t = clock.tick("memberships", t)
    key = np.lexsort((px.pix, -px.sal, px.area_of))
    first = np.searchsorted(px.area_of[key], np.arange(n))
    picks = key[first]
    t = clock.tick("greedy", t)
    return (np.arange(n), picks, np.full(n, np.nan), np.full(n, np.nan)), t


def _endpoint_threshold(
    d_e: float | None, d_s: float, style: TextStyle, widths: np.ndarray, layout: str, spacing: Spacing
) -> float:
    """``d_e`` of Eq. 6 in pixels.

    By default it is the box height (west/east layouts) or the mean box width (others) plus
    the box gap, as the paper recommends (§7.2).
    """
    if d_e is None:
        return (style.box_height if is_horizontal(layout) else float(widths.mean())) + spacing.gap
    return d_e * d_s


def _place_labels(
    px: _Pixels,
    order: tuple[np.ndarray, ...],
    widths: np.ndarray,
    style: TextStyle,
    ia,
    image_size: tuple[int, int],
    spacing: Spacing,
    previous: _Previous | None,
    layout: str,
) -> tuple:
    """Place the boxes and leaders of the picked candidates (Step 8).

    Returns each area's rank in the greedy order, its anchor and endpoint, its placement
    (None when left out) and the correction counts.
    """
    areas_in_order, picks = order[0], order[1]
    n = len(widths)
    rank = np.empty(n, np.int64)
    rank[areas_in_order] = np.arange(len(areas_in_order))
    pick_of = np.empty(n, np.int64)
    pick_of[areas_in_order] = picks
    anchors = np.column_stack([px.ax[pick_of], px.ay[pick_of]])
    endpoints = np.column_stack([px.ex[pick_of], px.ey[pick_of]])
    sides = px.side[pick_of].astype(np.int64)
    prev_box = None if previous is None else previous.box
    placements, stats = place_boxes(
        anchors,
        endpoints,
        sides,
        widths,
        style.box_height,
        ia,
        image_size,
        rank,
        spacing,
        prev_box,
        LAYOUTS[layout],
        centres=None if previous is None else previous.centre,
        leaders=None if previous is None else previous.leader,
        lines=None if previous is None else previous.lines,
        motion=None if previous is None else previous.motion,
        left_out=None if previous is None else previous.left_out,
    )
    return rank, anchors, endpoints, placements, stats


#: the smallest font a label is shrunk to to keep the boxes inside the image (pixels)
MIN_FONT_SIZE = 6
#: a camera fitted by :func:`layout` moves back by this factor, at most this many times,
#: while labels do not fit the image
ZOOM_OUT = 1.3
ZOOM_OUT_STEPS = 3


def _off_image(placements: list, size: tuple[int, int]) -> list[int]:
    """Indices of the placed boxes that reach beyond the image."""
    w, h = size
    return [
        k
        for k, p in enumerate(placements)
        if p is not None and (p.box[0] < 0 or p.box[1] < 0 or p.box[2] > w or p.box[3] > h)
    ]


def _inside_image(place, style: TextStyle, size: tuple[int, int], start: int | None = None) -> tuple:
    """Place the boxes with the largest font (down to :data:`MIN_FONT_SIZE`) that keeps them in the image.

    ``place(style)`` returns what :func:`_place_labels` does.  The sizes are searched by
    bisection (a smaller font never needs more room), starting from ``start`` (the previous
    frame's size along a camera path, so that it stays while it fits).  The boxes still
    outside at the smallest size are left out (the labels become ``unplaced``;
    ``params["outside_image"]`` names them).  Returns the style used, the placement and
    the indices of the labels left out for this reason.
    """
    tried: dict[int, tuple] = {}

    def fits(font: int) -> bool:
        if font not in tried:
            tried[font] = place(TextStyle(font))
        return not _off_image(tried[font][3], size)

    hi = style.font_size
    lo = MIN_FONT_SIZE
    if start is not None and lo <= start < hi and fits(start):
        best = start
    elif hi <= lo or fits(hi):
        best = hi
    elif not fits(lo):
        best = lo
    else:  # lo fits, hi does not
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if fits(mid) else (lo, mid)
        best = lo
    fits(best)
    placed = tried[best]
    off = _off_image(placed[3], size)
    for k in off:
        placed[3][k] = None
    return TextStyle(best), placed, off


def _view_maps(
    idbuf: IdBuffer,
    mask: np.ndarray,
    area: str,
    margin: float | None,
    layout: str,
    prefer: np.ndarray | None,
    clock: _Stopwatch,
    t: float,
) -> tuple:
    """Compute the internal area, the leader candidates and the salience, timing each stage.

    ``mask`` is ``idbuf.model_mask``.  Returns the internal area ``A_I`` (stage ``area``), every pixel's leader candidate
    (``candidates``, Steps 2-3), the distance to its area's silhouette (``salience``,
    Step 4), and the clock.
    """
    ia = internal_area(mask, area, margin)
    t = clock.tick("area", t)
    cand = leader_candidates(ia, layout, prefer, SIDE_KEEP)
    t = clock.tick("candidates", t)
    dist_sil = silhouette_distance(idbuf.ids)
    t = clock.tick("salience", t)
    return ia, cand, dist_sil, t


def _layout_result(
    idbuf: IdBuffer,
    ia,
    style: TextStyle,
    *,
    labels: list[Label],
    invisible: list,
    unplaced: list,
    skipped: list,
    layout: str,
    method: str,
    params: dict,
    clock: _Stopwatch,
) -> LayoutResult:
    """The result of a laid-out view (metrics not measured yet)."""
    return LayoutResult(
        labels=labels,
        invisible=invisible,
        unplaced=unplaced,
        skipped=skipped,
        image=idbuf.image,
        ids=idbuf.ids,
        camera=idbuf.camera,
        layout=layout,
        method=method,
        area_polygon=ia.polygon,
        font_size=style.font_size,
        box_height=style.box_height,
        sphere_diameter=idbuf.sphere_diameter,
        params=params,
        metrics={},
        timings=clock.timings,
    )


def _measure(result: LayoutResult, dist_sil: np.ndarray, clock: _Stopwatch) -> None:
    """Fill ``result.metrics`` (stage ``metrics``, not part of the layout time)."""
    t = time.perf_counter()
    result.metrics = frame_metrics(result, dist_sil)
    clock.tick("metrics", t)


def _collect_labels(
    idbuf: IdBuffer,
    texts: Sequence[str],
    labelled: np.ndarray,
    order: tuple[np.ndarray, ...],
    rank: np.ndarray,
    anchors: np.ndarray,
    endpoints: np.ndarray,
    placements: list,
) -> tuple[list[Label], list[tuple[int, str]]]:
    """The placed labels in greedy order, and the visible parts left without a box."""
    names = idbuf.part_names
    areas_in_order, _, feas, prio = order
    feas_of = np.full(len(labelled), np.nan)
    feas_of[areas_in_order] = feas
    prio_of = np.full(len(labelled), np.nan)
    prio_of[areas_in_order] = prio
    anchors_3d = idbuf.surface_points(anchors)
    labels, unplaced = [], []
    for s in areas_in_order:
        p = int(labelled[s])
        pl = placements[s]
        if pl is None:
            unplaced.append((p, names[p]))
            continue
        labels.append(
            Label(
                part=p,
                name=names[p],
                text=texts[p],
                anchor=anchors[s],
                anchor_3d=anchors_3d[s],
                endpoint=endpoints[s],
                leader=pl.leader,
                box=pl.box,
                side=SIDE_NAMES[pl.side],
                rank=int(rank[s]),
                feasibility=float(feas_of[s]),
                priority=float(prio_of[s]),
                shift=pl.shift,
                tier=pl.tier,
            )
        )
    return labels, unplaced


def solve(
    idbuf: IdBuffer,
    texts: Sequence[str],
    *,
    layout: str = "left-right",
    area: str = "hull",
    margin: float | None = None,
    weights: Weights | None = None,
    d_a: float = 0.05,
    d_e: float | None = None,
    previous: LayoutResult | None = None,
    method: str = "fuzzy",
    font_size: int | None = None,
    min_pixels: int = MIN_PIXELS,
    spacing: Spacing | None = None,
    compute_metrics: bool = True,
    inside: bool = True,
) -> LayoutResult:
    """Lay out the labels of a view whose ID buffer is known.

    Parameters
    ----------
    idbuf : IdBuffer
        The view's ID buffer.
    texts : sequence of str
        One label text per part ("" = do not label).
    layout : str
        A key of :data:`labeling.candidates.LAYOUTS`.
    area : {"hull", "circle", "rectangle"}
        Shape of the internal area.
    margin : float, optional
        Growth of the internal area in pixels (default 2 % of the image's smaller side).
    weights : Weights, optional
        Weights of Eq. 11 (paper defaults).
    d_a : float
        Anchor distance threshold of Eq. 4, as a fraction of ``d_S``.
    d_e : float, optional
        Endpoint distance threshold of Eq. 6, as a fraction of ``d_S``; default: the box
        height (west/east layouts) or the mean box width (others) plus the box gap, as the
        paper recommends (§7.2)
    previous : LayoutResult, optional
        The previous frame's result, for the coherence terms f6 and f7 (Eq. 8-9).
    method : {"fuzzy", "two-step"}
        "fuzzy" (this paper) or "two-step" (classic baseline: the most salient point of
        each area, then its candidate leader, then the same box corrections)
    font_size : int, optional
        Label font size in pixels (default: :func:`labeling.text.default_font_size`;
        reduced for west/east layouts until the columns fit the image)
    min_pixels : int
        Parts with fewer visible pixels are treated as invisible (default
        :data:`MIN_PIXELS`).
    spacing : Spacing, optional
        Spacing of the boxes.
    compute_metrics : bool
        Measure the result (:func:`labeling.metrics.frame_metrics`).
    inside : bool
        Keep every box inside the image: shrink the font (down to
        :data:`MIN_FONT_SIZE`), then leave out the labels that still do not fit
        (``unplaced``, named in ``params["outside_image"]``); False lets boxes reach beyond
        the image (the pictures' canvas grows to hold them).

    Returns
    -------
    LayoutResult
    """
    names = idbuf.part_names
    _check_arguments(layout, method, d_a, d_e, len(texts), len(names))
    weights = weights or Weights()
    spacing = spacing or Spacing()
    clock = _Stopwatch()
    t = time.perf_counter()
    invisible, skipped, labelled = _sort_parts(idbuf, texts, min_pixels)
    mask = idbuf.model_mask
    if len(labelled) == 0 or not mask.any():
        empty = dict(layout=layout, method=method, area=area, margin=margin, font_size=font_size)
        return _nothing_to_label(idbuf, invisible, skipped, **empty, timings=clock.timings)
    slot = np.full(len(names), -1, np.int64)
    slot[labelled] = np.arange(len(labelled))
    prev = None if previous is None else _previous_frame(previous, idbuf, slot, len(labelled))
    prefer = _preferred_sides(idbuf, labelled, prev)
    ia, cand, dist_sil, t = _view_maps(idbuf, mask, area, margin, layout, prefer, clock, t)
    px = _pixels(idbuf, cand, dist_sil, labelled, len(names))
    (h, w), d_s = idbuf.shape, idbuf.sphere_diameter
    style = _fit_font(len(labelled), layout, h, int(font_size or default_font_size(h)))
    widths = style.box_widths([texts[p] for p in labelled])
    de_px = _endpoint_threshold(d_e, d_s, style, widths, layout, spacing)
    da_px = d_a * d_s
    if method == "fuzzy":
        keep = ANCHOR_KEEP if is_horizontal(layout) or layout == "silhouette" else ANCHOR_KEEP_ROWS
        order, t = _fuzzy_picks(px, cand, weights, prev, len(labelled), d_s, da_px, de_px, clock, t, keep)
        if prev is not None and len(LAYOUTS[layout]) > 1 and _changes_side(px, order, prev):
            # batch the side changes: the other labels that are nearer their other side go too
            cand = leader_candidates(ia, layout, prefer, SIDE_BATCH)
            t = clock.tick("candidates", t)
            px = _pixels(idbuf, cand, dist_sil, labelled, len(names))
            order, t = _fuzzy_picks(px, cand, weights, prev, len(labelled), d_s, da_px, de_px, clock, t, keep)
    else:
        order, t = _two_step_picks(px, len(labelled), clock, t)
    label_texts_ = [texts[p] for p in labelled]

    def place(st: TextStyle) -> tuple:
        return _place_labels(px, order, st.box_widths(label_texts_), st, ia, (w, h), spacing, prev, layout)

    if inside:
        start = None if previous is None else int(previous.font_size)
        style, placed, off_image = _inside_image(place, style, (w, h), start)
    else:
        placed, off_image = place(style), []
    rank, anchors, endpoints, placements, stats = placed
    t = clock.tick("boxes", t)
    labels, unplaced = _collect_labels(idbuf, texts, labelled, order, rank, anchors, endpoints, placements)
    clock.timings["layout_ms"] = 1000.0 * sum(clock.timings.get(k, 0.0) for k in LAYOUT_STAGES)
    thresholds = _thresholds(d_a, d_e, d_s, da_px, de_px, cand.d_max)
    params = _params(layout, area, ia.margin, method, weights, thresholds, min_pixels, stats)
    params["outside_image"] = [names[int(labelled[k])] for k in off_image]
    found = dict(labels=labels, invisible=invisible, unplaced=unplaced, skipped=skipped)
    result = _layout_result(
        idbuf, ia, style, **found, layout=layout, method=method, params=params, clock=clock
    )
    if compute_metrics:
        _measure(result, dist_sil, clock)
    return result


def warm_up() -> None:
    """Import the modules and load the font that the layout stages would use lazily.

    This takes about 0.2 s once per process; doing it here makes it count as set-up, not as
    the first frame's layout.
    """
    import scipy.spatial  # noqa: F401 - the convex hull of the internal area

    from .text import font

    font(default_font_size(512))


def frame_metrics_empty() -> dict[str, Any]:
    """Metrics of a frame with nothing to label."""
    return {
        "labels": 0,
        "labelling_rate": 1.0,
        "overlaps": 0,
        "overlap_area": 0.0,
        "crossings": 0,
        "leaders_through_labels": 0,
        "label_over_model": 0,
        "label_over_model_frac": 0.0,
        "leader_sum": 0.0,
        "leader_mean": 0.0,
        "leader_max": 0.0,
        "leader_sum_norm": 0.0,
        "leader_mean_norm": 0.0,
        "leader_max_norm": 0.0,
        "invalid_anchors": 0,
        "salience_mean": 0.0,
        "salience_min": 0.0,
        "shifted_labels": 0,
        "shift_mean": 0.0,
        "outside_image": 0,
    }


def layout(
    model: Any,
    camera: Camera | None = None,
    *,
    layout: str = "left-right",
    size: tuple[int, int] = (512, 512),
    texts: Mapping[Any, str] | Sequence[str] | None = None,
    caster: RayCaster | None = None,
    color_by: str | None = "part",
    azimuth: float = 30.0,
    elevation: float = 20.0,
    up: Sequence[float] | None = None,
    fit_margin: float = 1.6,
    **options: Any,
) -> LayoutResult:
    """Label the visible parts of a model seen by a camera.

    Parameters
    ----------
    model : Soup, path, trimesh object, or a list of them
        Combined when several (see :func:`labeling.inputs.load_models`).
    camera : Camera, optional
        Default: :func:`fit_camera` from ``azimuth``, ``elevation``, ``up``,
        ``fit_margin``.
    layout : {"left", "right", "left-right", "top", "bottom", "top-bottom", "silhouette"}
        Where the boxes go (default left-right).
    size : (2,) int
        ``(width, height)`` in pixels.
    texts : mapping or sequence of str, optional
        Label texts: a mapping ``{part name or index: text}`` or one text per part
    caster : RayCaster, optional
        A ray caster of the same model to reuse (frames, benchmarks).
    color_by : str or None
        Colouring of the shaded picture.
    **options
        Passed to :func:`solve` (area, margin, weights, d_a, d_e, previous, method,
        font_size, min_pixels, spacing, inside)

    Returns
    -------
    LayoutResult
        ``timings`` has ``setup`` and ``idbuffer`` besides the layout stages.  With the
        camera fitted here (``camera`` None), a view whose boxes do not fit the image is
        taken again from up to :data:`ZOOM_OUT_STEPS` times farther away (by
        :data:`ZOOM_OUT` each), until every label fits.

    Examples
    --------
    >>> import trimesh
    >>> from meshvis.soup import Soup
    >>> a, b = trimesh.creation.box(), trimesh.creation.icosphere()
    >>> b = b.apply_translation((1.5, 0, 0))
    >>> soup = Soup.concatenate([Soup(a.vertices, a.faces, part_names=["box"]),
    ...                          Soup(b.vertices, b.faces, part_names=["ball"])])
    >>> r = layout(soup, size=(128, 128))
    >>> sorted(lab.text for lab in r.labels), r.metrics["overlaps"]
    (['ball', 'box'], 0)
    """
    t0 = time.perf_counter()
    warm_up()
    soup = load_models(model)
    caster = caster or RayCaster(soup)
    fitted = camera is None
    if camera is None:
        camera = fit_camera(soup, azimuth=azimuth, elevation=elevation, up=up, margin=fit_margin, size=size)
    if texts is None or isinstance(texts, Mapping):
        text_list = label_texts(soup.part_names, texts)
    else:
        text_list = [str(t) for t in texts]
    t1 = time.perf_counter()
    idbuf = id_buffer(soup, camera, size, caster=caster, color_by=color_by)
    t2 = time.perf_counter()
    result = solve(idbuf, text_list, layout=layout, **options)
    for _ in range(ZOOM_OUT_STEPS if fitted else 0):
        if not result.params.get("outside_image"):
            break
        # a camera fitted here leaves more room around the model instead of dropping labels
        fit_margin *= ZOOM_OUT
        camera = fit_camera(soup, azimuth=azimuth, elevation=elevation, up=up, margin=fit_margin, size=size)
        idbuf = id_buffer(soup, camera, size, caster=caster, color_by=color_by)
        result = solve(idbuf, text_list, layout=layout, **options)
    result.timings = {"setup": t1 - t0, "idbuffer": t2 - t1, **result.timings}
    return result
