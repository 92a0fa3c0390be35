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
from typing import Any

import numpy as np

from meshvis.errors import ParameterError
from meshvis.rays.camera import Camera
from meshvis.rays.caster import RayCaster
from meshvis.soup import Soup

from .boxes import Spacing, place_boxes
from .candidates import LAYOUTS, SIDE_NAMES, check_layout, is_horizontal, leader_candidates
from .greedy import greedy_layout
from .idbuffer import IdBuffer, id_buffer
from .inputs import label_texts, load_models
from .internal_area import internal_area
from .membership import Weights, f2_length, f3_salience, f_coherence, silhouette_distance, weighted
from .metrics import frame_metrics
from .result import Label, LayoutResult
from .text import TextStyle, default_font_size

METHODS = ("fuzzy", "two-step")

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
    up: Sequence[float] = (0.0, 0.0, 1.0),
    margin: float = 1.6,
) -> Camera:
    """The default labeling camera: like :meth:`Camera.fit` but with room around the model.

    ``margin`` 1.6 leaves about a fifth of the image on each side for the labels.
    """
    return Camera.fit(
        soup,
        azimuth=azimuth,
        elevation=elevation,
        distance=distance,
        fov=fov,
        orthographic=orthographic,
        margin=margin,
        up=up,
    )


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


def _previous_frame(
    previous: LayoutResult, slot: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The previous frame's anchor (n, 2), endpoint (n, 2) and box centre along each of the
    west, east, north and south sides (n, 4; y for west/east, x for north/south) of every
    label of this frame; NaN where the label was absent or on another side."""
    anchor, endpoint, box = np.full((n, 2), np.nan), np.full((n, 2), np.nan), np.full((n, 4), np.nan)
    for lab in previous.labels:
        s = slot[lab.part] if lab.part < len(slot) else -1
        if s < 0:
            continue
        anchor[s], endpoint[s] = lab.anchor, lab.endpoint
        code = SIDE_NAMES.index(lab.side)
        if code < 4:
            axis = 1 if code < 2 else 0
            box[s, code] = 0.5 * (lab.box[axis] + lab.box[axis + 2])
    return anchor, endpoint, box


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
    min_pixels: int = 1,
    spacing: Spacing | None = None,
    compute_metrics: bool = True,
) -> LayoutResult:
    """Lay out the labels of a view whose ID buffer is known.

    Parameters
    ----------
    idbuf : IdBuffer
    texts : one label text per part ("" = do not label)
    layout : a key of :data:`labeling.candidates.LAYOUTS`
    area : internal area shape, "hull", "circle" or "rectangle"
    margin : growth of the internal area in pixels (default 2 % of the image's smaller side)
    weights : Weights of Eq. 11 (paper defaults)
    d_a : anchor distance threshold of Eq. 4, as a fraction of ``d_S``
    d_e : endpoint distance threshold of Eq. 6, as a fraction of ``d_S``; default: the box
        height (west/east layouts) or the mean box width (others) plus the box gap, as the
        paper recommends (§7.2)
    previous : the previous frame's result, for the coherence terms f6 and f7 (Eq. 8-9)
    method : "fuzzy" (this paper) or "two-step" (classic baseline: the most salient point of
        each area, then its candidate leader, then the same box corrections)
    font_size : label font size in pixels (default: :func:`labeling.text.default_font_size`;
        reduced for west/east layouts until the columns fit the image)
    min_pixels : parts with fewer visible pixels are treated as invisible
    spacing : Spacing of the boxes
    compute_metrics : measure the result (:func:`labeling.metrics.frame_metrics`)

    Returns
    -------
    LayoutResult
    """
    check_layout(layout)
    if method not in METHODS:
        raise ParameterError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    if not (np.isfinite(d_a) and d_a >= 0):
        raise ParameterError(f"d_a must be >= 0, got {d_a}")
    if d_e is not None and not (np.isfinite(d_e) and d_e >= 0):
        raise ParameterError(f"d_e must be >= 0, got {d_e}")
    weights = weights or Weights()
    spacing = spacing or Spacing()
    names = idbuf.part_names
    if len(texts) != len(names):
        raise ParameterError(f"{len(texts)} label texts for {len(names)} parts")
    timings: dict[str, float] = {}
    h, w = idbuf.shape
    d_s = idbuf.sphere_diameter

    def tick(key: str, t0: float) -> float:
        t = time.perf_counter()
        timings[key] = timings.get(key, 0.0) + t - t0
        return t

    t = time.perf_counter()
    visible = idbuf.visible(min_pixels)
    invisible = [(int(p), names[p]) for p in idbuf.invisible(min_pixels)]
    skipped = [(int(p), names[p]) for p in visible if not texts[p]]
    labelled = np.array([p for p in visible if texts[p]], np.int64)
    if len(labelled) == 0 or not idbuf.model_mask.any():
        ia = internal_area(idbuf.model_mask, area, margin) if idbuf.model_mask.any() else None
        return LayoutResult(
            [],
            invisible,
            [],
            skipped,
            idbuf.image,
            idbuf.ids,
            idbuf.camera,
            layout,
            method,
            ia.polygon if ia is not None else np.zeros((0, 2)),
            font_size or default_font_size(h),
            0.0,
            d_s,
            {},
            frame_metrics_empty(),
            timings,
        )
    ia = internal_area(idbuf.model_mask, area, margin)
    t = tick("area", t)
    cand = leader_candidates(ia, layout)
    t = tick("candidates", t)
    dist_sil = silhouette_distance(idbuf.ids)
    t = tick("salience", t)

    # candidates of the labelled areas, grouped by area (stable: row-major inside an area)
    slot = np.full(len(names), -1, np.int64)
    slot[labelled] = np.arange(len(labelled))
    ids_flat = idbuf.ids.ravel()
    pix = np.flatnonzero(ids_flat >= 0)
    pix = pix[slot[ids_flat[pix]] >= 0]
    area_of = slot[ids_flat[pix]]
    order = np.argsort(area_of, kind="stable")
    pix, area_of = pix[order], area_of[order]
    row, col = np.divmod(pix, w)
    ax, ay = col + 0.5, row + 0.5
    ex, ey = cand.ex.ravel()[pix], cand.ey.ravel()[pix]
    eid = cand.eid.ravel()[pix]
    length = cand.length.ravel()[pix]
    side = cand.side.ravel()[pix]
    sal = dist_sil.ravel()[pix]

    style = _fit_font(len(labelled), layout, h, int(font_size or default_font_size(h)))
    label_texts_ = [texts[p] for p in labelled]
    widths = style.box_widths(label_texts_)
    if d_e is None:
        de_px = (style.box_height if is_horizontal(layout) else float(widths.mean())) + spacing.gap
    else:
        de_px = d_e * d_s
    da_px = d_a * d_s

    if method == "fuzzy":
        static = weighted(f2_length(length, cand.d_max), weights.w2) * weighted(
            f3_salience(sal, cand.d_max), weights.w3
        )
        if previous is not None:
            prev_a, prev_e, _ = _previous_frame(previous, slot, len(labelled))
            static = static * weighted(f_coherence(ax, ay, prev_a[area_of], d_s), weights.w6)
            static = static * weighted(f_coherence(ex, ey, prev_e[area_of], d_s), weights.w7)
        t = tick("memberships", t)
        g = greedy_layout(
            area_of, ax, ay, eid, cand.endpoints, static, len(labelled), da_px, de_px, weights.w4, weights.w5
        )
        areas_in_order, picks, feas, prio = g.area_order, g.pick, g.feasibility, g.priority
        t = tick("greedy", t)
    else:
        t = tick("memberships", t)
        # the most salient pixel of each area (first in row-major order on ties)
        key = np.lexsort((pix, -sal, area_of))
        first = np.searchsorted(area_of[key], np.arange(len(labelled)))
        picks_by_area = key[first]
        areas_in_order = np.arange(len(labelled))
        picks = picks_by_area
        feas = np.full(len(labelled), np.nan)
        prio = np.full(len(labelled), np.nan)
        t = tick("greedy", t)

    rank = np.empty(len(labelled), np.int64)
    rank[areas_in_order] = np.arange(len(areas_in_order))
    pick_of = np.empty(len(labelled), np.int64)
    pick_of[areas_in_order] = picks
    anchors = np.column_stack([ax[pick_of], ay[pick_of]])
    endpoints = np.column_stack([ex[pick_of], ey[pick_of]])
    sides = side[pick_of].astype(np.int64)
    prev_box = None if previous is None else _previous_frame(previous, slot, len(labelled))[2]
    placements, stats = place_boxes(
        anchors,
        endpoints,
        sides,
        widths,
        style.box_height,
        ia,
        (w, h),
        rank,
        spacing,
        prev_box,
        LAYOUTS[layout],
    )
    t = tick("boxes", t)

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
    timings["layout_ms"] = 1000.0 * sum(timings.get(k, 0.0) for k in LAYOUT_STAGES)
    params = {
        "layout": layout,
        "area": area,
        "margin": ia.margin,
        "method": method,
        "weights": weights.as_dict(),
        "d_a": d_a,
        "d_e": (de_px / d_s) if d_e is None else d_e,
        "d_a_px": da_px,
        "d_e_px": de_px,
        "d_max_px": cand.d_max,
        "min_pixels": int(min_pixels),
        "corrections": {"shifted": stats.shifted, "swaps": stats.swaps, "repaired": stats.repaired},
    }
    result = LayoutResult(
        labels,
        invisible,
        unplaced,
        skipped,
        idbuf.image,
        idbuf.ids,
        idbuf.camera,
        layout,
        method,
        ia.polygon,
        style.font_size,
        style.box_height,
        d_s,
        params,
        {},
        timings,
    )
    if compute_metrics:
        t = time.perf_counter()
        result.metrics = frame_metrics(result, dist_sil)
        tick("metrics", t)
    return result


def warm_up() -> None:
    """Import the modules and load the font the layout stages use lazily (about 0.2 s
    once per process), so that they count as set-up, not as the first frame's layout."""
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
    up: Sequence[float] = (0.0, 0.0, 1.0),
    fit_margin: float = 1.6,
    **options: Any,
) -> LayoutResult:
    """Label the visible parts of a model seen by a camera.

    Parameters
    ----------
    model : Soup, path, trimesh object, or a list of them (combined; see
        :func:`labeling.inputs.load_models`)
    camera : Camera; default :func:`fit_camera` from ``azimuth``, ``elevation``, ``up``,
        ``fit_margin``
    layout : "left", "right", "left-right" (default), "top", "bottom", "top-bottom", "silhouette"
    size : (width, height) in pixels
    texts : label texts: a mapping {part name or index: text} or one text per part
    caster : a RayCaster of the same model to reuse (frames, benchmarks)
    color_by : colouring of the shaded picture
    **options : passed to :func:`solve` (area, margin, weights, d_a, d_e, previous, method,
        font_size, min_pixels, spacing)

    Returns
    -------
    LayoutResult
        ``timings`` has ``setup`` and ``idbuffer`` besides the layout stages.

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
    if camera is None:
        camera = fit_camera(soup, azimuth=azimuth, elevation=elevation, up=up, margin=fit_margin)
    if texts is None or isinstance(texts, Mapping):
        text_list = label_texts(soup.part_names, texts)
    else:
        text_list = [str(t) for t in texts]
    t1 = time.perf_counter()
    idbuf = id_buffer(soup, camera, size, caster=caster, color_by=color_by)
    t2 = time.perf_counter()
    result = solve(idbuf, text_list, layout=layout, **options)
    result.timings = {"setup": t1 - t0, "idbuffer": t2 - t1, **result.timings}
    return result
