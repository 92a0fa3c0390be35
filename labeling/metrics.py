"""Quality measures of a label layout (one frame) and of a sequence of frames.

All lengths are in pixels and, where named ``*_norm``, divided by ``d_S`` (the projected
diameter of the bounding sphere) so that different image sizes compare.

Per frame (:func:`frame_metrics`):

* ``overlaps`` — pairs of label boxes that share area; ``overlap_area`` their total area
* ``crossings`` — pairs of labels whose leaders meet
* ``leaders_through_labels`` — (leader, other label's box) pairs where the leader passes
  through the box's interior
* ``label_over_model`` — model pixels covered by label boxes; ``label_over_model_frac`` the
  same divided by the total box area
* ``leader_sum``, ``leader_mean``, ``leader_max`` (+ ``_norm``) — leader lengths
* ``invalid_anchors`` — labels whose anchor pixel does not show the label's own part
* ``salience_mean``, ``salience_min`` — anchor salience: the anchor's distance to the
  silhouette of its own area divided by the largest such distance in that area (1 = the
  most salient point of the area)
* ``labelling_rate`` — labelled parts / visible labellable parts
* ``shifted_labels``, ``shift_mean`` — labels whose box had to move off its candidate
  endpoint (rotated or bent leader) and the mean move, pixels
* ``outside_image`` — boxes not entirely inside the image

Between frames (:func:`motion_metrics`): ``anchor_motion_mean``/``_max``,
``label_motion_mean``/``_max`` (box centres), their ``_norm`` versions, ``side_flips``
and ``order_swaps`` (pairs of labels on the same side whose order along it reversed).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy import ndimage

from .geometry2d import overlap_area, polyline_length, segment_hits_box, segments_intersect
from .membership import silhouette_distance
from .result import LayoutResult


def _segments(result: LayoutResult) -> tuple[np.ndarray, np.ndarray]:
    segs, owner = [], []
    for n, lab in enumerate(result.labels):
        pts = lab.leader
        s = np.stack([pts[:-1], pts[1:]], axis=1)
        segs.append(s)
        owner.extend([n] * len(s))
    if not segs:
        return np.zeros((0, 2, 2)), np.zeros(0, np.int64)
    return np.concatenate(segs), np.array(owner, np.int64)


def _pair_matrix(hits: np.ndarray, owner_a: np.ndarray, owner_b: np.ndarray, n: int) -> np.ndarray:
    a = np.zeros((len(owner_a), n), np.int64)
    a[np.arange(len(owner_a)), owner_a] = 1
    b = np.zeros((len(owner_b), n), np.int64)
    b[np.arange(len(owner_b)), owner_b] = 1
    return (a.T @ hits.astype(np.int64) @ b) > 0


def area_salience(ids: np.ndarray, dist_sil: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Silhouette distance per pixel and its maximum per part id."""
    if dist_sil is None:
        dist_sil = silhouette_distance(ids)
    n = int(ids.max()) + 1 if ids.max() >= 0 else 0
    best = np.zeros(n)
    if n:
        m = ids >= 0
        best = ndimage.maximum(dist_sil[m], ids[m], index=np.arange(n))
        best = np.nan_to_num(np.asarray(best, np.float64))
    return dist_sil, best


def frame_metrics(result: LayoutResult, dist_sil: np.ndarray | None = None) -> dict[str, Any]:
    """Measure one frame; see the module docstring for the keys."""
    labs = result.labels
    n = len(labs)
    d_s = result.sphere_diameter
    h, w = result.ids.shape
    out: dict[str, Any] = {"labels": n}
    n_vis = n + len(result.unplaced)
    out["labelling_rate"] = float(n / n_vis) if n_vis else 1.0
    boxes = np.array([lab.box for lab in labs], np.float64).reshape(-1, 4)
    ov = overlap_area(boxes, boxes)
    np.fill_diagonal(ov, 0.0)
    out["overlaps"] = int(np.triu(ov > 0, 1).sum())
    out["overlap_area"] = float(np.triu(ov, 1).sum())
    segs, owner = _segments(result)
    if n:
        cross = _pair_matrix(segments_intersect(segs, segs), owner, owner, n)
        np.fill_diagonal(cross, False)
        out["crossings"] = int(np.triu(cross, 1).sum())
        through = _pair_matrix(segment_hits_box(segs, boxes), owner, np.arange(n), n)
        np.fill_diagonal(through, False)
        out["leaders_through_labels"] = int(through.sum())
    else:
        out["crossings"] = 0
        out["leaders_through_labels"] = 0
    covered = np.zeros((h, w), bool)
    for b in boxes:  # one slice per label, not per pixel
        c0, c1 = int(np.clip(np.ceil(b[0] - 0.5), 0, w)), int(np.clip(np.floor(b[2] - 0.5) + 1, 0, w))
        r0, r1 = int(np.clip(np.ceil(b[1] - 0.5), 0, h)), int(np.clip(np.floor(b[3] - 0.5) + 1, 0, h))
        covered[r0:r1, c0:c1] = True
    over = int((covered & (result.ids >= 0)).sum())
    box_area = float(((boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])).sum())
    out["label_over_model"] = over
    out["label_over_model_frac"] = over / box_area if box_area > 0 else 0.0
    lengths = np.array([polyline_length(lab.leader) for lab in labs])
    out["leader_sum"] = float(lengths.sum())
    out["leader_mean"] = float(lengths.mean()) if n else 0.0
    out["leader_max"] = float(lengths.max()) if n else 0.0
    for k in ("leader_sum", "leader_mean", "leader_max"):
        out[k + "_norm"] = out[k] / d_s
    ax = np.array([lab.anchor for lab in labs]).reshape(-1, 2)
    col = np.clip(np.floor(ax[:, 0]).astype(np.int64), 0, w - 1)
    row = np.clip(np.floor(ax[:, 1]).astype(np.int64), 0, h - 1)
    parts = np.array([lab.part for lab in labs], np.int64)
    inside = (ax[:, 0] >= 0) & (ax[:, 0] < w) & (ax[:, 1] >= 0) & (ax[:, 1] < h)
    valid = inside & (result.ids[row, col] == parts)
    out["invalid_anchors"] = int((~valid).sum())
    dist, best = area_salience(result.ids, dist_sil)
    if n:
        sal = np.where(valid, dist[row, col] / np.maximum(best[np.clip(parts, 0, len(best) - 1)], 1e-12), 0.0)
        out["salience_mean"] = float(sal.mean())
        out["salience_min"] = float(sal.min())
    else:
        out["salience_mean"] = out["salience_min"] = 0.0
    shifts = np.array([lab.shift for lab in labs])
    out["shifted_labels"] = int((shifts > 0.5).sum())
    out["shift_mean"] = float(shifts.mean()) if n else 0.0
    out["outside_image"] = int(
        ((boxes[:, 0] < 0) | (boxes[:, 1] < 0) | (boxes[:, 2] > w) | (boxes[:, 3] > h)).sum()
    )
    return out


def _side_coordinate(lab, center: np.ndarray) -> float:
    """Position of a label along its side: y for west/east, x for north/south, angle for radial."""
    c = 0.5 * (lab.box[:2] + lab.box[2:])
    if lab.side in ("west", "east"):
        return float(c[1])
    if lab.side in ("north", "south"):
        return float(c[0])
    return float(np.arctan2(c[1] - center[1], c[0] - center[0]))


def motion_metrics(prev: LayoutResult, cur: LayoutResult) -> dict[str, Any]:
    """Frame-to-frame motion of the labels the two frames share (see the module docstring)."""
    a, b = prev.by_part(), cur.by_part()
    common = sorted(set(a) & set(b))
    d_s = cur.sphere_diameter
    out: dict[str, Any] = {"common_labels": len(common)}
    if not common:
        for k in ("anchor_motion_mean", "anchor_motion_max", "label_motion_mean", "label_motion_max"):
            out[k] = out[k + "_norm"] = 0.0
        out["side_flips"] = out["order_swaps"] = 0
        return out
    am = np.array([np.linalg.norm(b[p].anchor - a[p].anchor) for p in common])
    lm = np.array(
        [
            np.linalg.norm((b[p].box[:2] + b[p].box[2:]) / 2 - (a[p].box[:2] + a[p].box[2:]) / 2)
            for p in common
        ]
    )
    out["anchor_motion_mean"], out["anchor_motion_max"] = float(am.mean()), float(am.max())
    out["label_motion_mean"], out["label_motion_max"] = float(lm.mean()), float(lm.max())
    for k in ("anchor_motion_mean", "anchor_motion_max", "label_motion_mean", "label_motion_max"):
        out[k + "_norm"] = out[k] / d_s
    out["side_flips"] = int(sum(a[p].side != b[p].side for p in common))
    ca = np.array(prev.size, np.float64) / 2
    cb = np.array(cur.size, np.float64) / 2
    swaps = 0
    same = [p for p in common if a[p].side == b[p].side]
    pa = np.array([_side_coordinate(a[p], ca) for p in same])
    pb = np.array([_side_coordinate(b[p], cb) for p in same])
    sides = np.array([a[p].side for p in same])
    for s in np.unique(sides):
        m = sides == s
        da = np.sign(pa[m][:, None] - pa[m][None, :])
        db = np.sign(pb[m][:, None] - pb[m][None, :])
        swaps += int(np.triu(da * db < 0, 1).sum())
    out["order_swaps"] = swaps
    return out


def sequence_metrics(results: Sequence[LayoutResult]) -> dict[str, Any]:
    """Motion summed (flips, swaps) or averaged (motions) over consecutive frames."""
    steps = [motion_metrics(p, c) for p, c in zip(results[:-1], results[1:])]
    if not steps:
        return {"frames": len(results)}
    out: dict[str, Any] = {"frames": len(results)}
    for k in ("anchor_motion_mean", "label_motion_mean", "anchor_motion_mean_norm", "label_motion_mean_norm"):
        out[k] = float(np.mean([s[k] for s in steps]))
    for k in ("anchor_motion_max", "label_motion_max"):
        out[k] = float(np.max([s[k] for s in steps]))
    out["side_flips"] = int(sum(s["side_flips"] for s in steps))
    out["order_swaps"] = int(sum(s["order_swaps"] for s in steps))
    return out


def is_clean(metrics: dict[str, Any]) -> bool:
    """True when a frame has no overlap, no crossing, no box over the model, no bad anchor."""
    return (
        metrics["overlaps"] == 0
        and metrics["crossings"] == 0
        and metrics["label_over_model"] == 0
        and metrics["invalid_anchors"] == 0
    )


#: a label whose box centre moves more than this between two frames (pixels) has jumped
JUMP_PX = 50.0


def _side_changed(a, b) -> bool:
    """The label left on another side; a radial one: its box turned > 90 degrees about its anchor."""
    if a.side != b.side:
        return True
    if a.side != "radial":
        return False
    da = (a.box[:2] + a.box[2:]) / 2 - a.anchor
    db = (b.box[:2] + b.box[2:]) / 2 - b.anchor
    return bool(np.dot(da, db) < 0)


def orbit_coherence(results: Sequence[LayoutResult], jump: float = JUMP_PX) -> dict[str, Any]:
    """How well the labels of a frame sequence follow the model.

    For every pair of consecutive frames and every label both frames have, the *surface
    motion* is how far the surface point under the earlier anchor moved on the screen
    (the point ``anchor_3d`` of the earlier frame projected with the later camera), and the
    *label motion* how far the box centre moved.  A transition is *jumpy* when one of its
    labels moves more than ``jump`` pixels or changes side (for the silhouette layout:
    its box turns by more than 90 degrees around its anchor).

    Parameters
    ----------
    results : sequence of LayoutResult
        The frames, in order.
    jump : float
        The label motion (pixels) that counts as a jump.

    Returns
    -------
    dict
        ``transitions``, ``jumpy_transitions``, ``jumpy_fraction``, ``jumps`` and
        ``side_changes`` (labels), ``label_motion_mean`` and ``surface_motion_mean``
        (pixels per label and transition) and ``motion_ratio`` (their quotient; 0 without a
        shared label).

    Examples
    --------
    >>> orbit_coherence([])["transitions"]
    0
    """
    label_motion, surface_motion = [], []
    jumpy = jumps = side_changes = 0
    for prev, cur in zip(results[:-1], results[1:]):
        a, b = prev.by_part(), cur.by_part()
        common = sorted(set(a) & set(b))
        if not common:
            continue
        w, h = cur.size
        p3 = np.array([a[p].anchor_3d for p in common], np.float64).reshape(-1, 3)
        moved, _ = cur.camera.project(p3, w, h)
        was = np.array([a[p].anchor for p in common])
        surface = np.hypot(*(moved - was).T)
        centre = np.array(
            [[(b[p].box[:2] + b[p].box[2:]) / 2, (a[p].box[:2] + a[p].box[2:]) / 2] for p in common]
        )
        label = np.hypot(*(centre[:, 0] - centre[:, 1]).T)
        flips = np.array([_side_changed(a[p], b[p]) for p in common])
        ok = np.isfinite(surface)
        label_motion.extend(label[ok])
        surface_motion.extend(surface[ok])
        jumps += int((label > jump).sum())
        side_changes += int(flips.sum())
        jumpy += int(bool((label > jump).any() or flips.any()))
    n = max(len(results) - 1, 0)
    lm = float(np.mean(label_motion)) if label_motion else 0.0
    sm = float(np.mean(surface_motion)) if surface_motion else 0.0
    return {
        "transitions": n,
        "jumpy_transitions": jumpy,
        "jumpy_fraction": jumpy / n if n else 0.0,
        "jumps": jumps,
        "side_changes": side_changes,
        "label_motion_mean": lm,
        "surface_motion_mean": sm,
        "motion_ratio": lm / sm if sm > 0 else 0.0,
    }
