"""Baselines the fuzzy-greedy layout is compared with, run on the same ID buffer.

* **two-step** (:func:`two_step`): the classic pipeline of interactive labeling (Ali et al.,
  as described in appendix I §5): (1) the anchor of each area is its most salient point
  (the pixel farthest from the area's silhouette), (2) its leader goes to the nearest
  boundary point of ``A_I`` along the layout's directions, (3) the same box stacking and
  corrections as the fuzzy method.  Only the anchor choice differs, so the comparison
  isolates what the joint optimisation buys.
* **adjustText** (:func:`adjust_text`): a general 2D label-repel library (adjustText 1.x),
  fed the same salient anchors, the model's pixels as obstacles, with a fixed iteration
  count (no time limit, so the result is reproducible).  Leaders are straight segments
  from the anchor to the nearest point of the text box.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from .idbuffer import IdBuffer
from .metrics import frame_metrics
from .pipeline import solve
from .result import Label, LayoutResult
from .text import TextStyle, font_file


def two_step(idbuf: IdBuffer, texts: Sequence[str], **options: Any) -> LayoutResult:
    """The classic two-step layout (most salient anchor, then its leader, then box fixing)."""
    return solve(idbuf, texts, method="two-step", **options)


def _model_obstacles(ids: np.ndarray, cell: int) -> np.ndarray:
    """Boxes (x0, y0, x1, y1), one per ``cell`` x ``cell`` block holding model pixels."""
    h, w = ids.shape
    hb, wb = -(-h // cell), -(-w // cell)
    pad = np.zeros((hb * cell, wb * cell), bool)
    pad[:h, :w] = ids >= 0
    occ = pad.reshape(hb, cell, wb, cell).any(axis=(1, 3))
    r, c = np.nonzero(occ)
    return np.column_stack(
        [c * cell, r * cell, np.minimum((c + 1) * cell, w), np.minimum((r + 1) * cell, h)]
    ).astype(float)


def _nearest_on_box(p: np.ndarray, box: np.ndarray) -> np.ndarray:
    return np.array([np.clip(p[0], box[0], box[2]), np.clip(p[1], box[1], box[3])])


#: figure resolution of the adjustText canvas: at 72 dots per inch a point is one pixel
_DPI = 72.0


def _text_axes(w: int, h: int):
    """A matplotlib figure and axes of ``w`` x ``h`` pixels, y down like the image."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w / _DPI, h / _DPI), dpi=_DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_xlim(0, w)
    ax.set_ylim(h, 0)
    ax.axis("off")
    return fig, ax


def _text_artists(ax, reference: LayoutResult) -> list:
    """One boxed text per label of ``reference``, centred on its anchor, in its font."""
    from matplotlib.font_manager import FontProperties

    style = TextStyle(reference.font_size)
    prop = FontProperties(fname=font_file(), size=reference.font_size * 72.0 / _DPI)
    return [
        ax.text(
            lab.anchor[0],
            lab.anchor[1],
            lab.text,
            fontproperties=prop,
            ha="center",
            va="center",
            bbox=dict(
                boxstyle=f"square,pad={style.pad_y / reference.font_size:.3f}", fc="white", ec="0.4", lw=0.6
            ),
        )
        for lab in reference.labels
    ]


def _adjusted_labels(labs: Sequence[Label], texts: list, renderer, h: int) -> list[Label]:
    """Return the labels at the places where adjustText left their texts.

    Each label gets a straight leader from its anchor to the nearest point of its box.
    """
    out = []
    for lab, txt in zip(labs, texts):
        bb = txt.get_bbox_patch().get_window_extent(renderer)
        box = np.array([bb.x0, h - bb.y1, bb.x1, h - bb.y0])
        end = _nearest_on_box(lab.anchor, box)
        out.append(
            Label(
                part=lab.part,
                name=lab.name,
                text=lab.text,
                anchor=lab.anchor.copy(),
                anchor_3d=lab.anchor_3d.copy(),
                endpoint=end,
                leader=np.array([lab.anchor, end]),
                box=box,
                side="free",
                rank=lab.rank,
            )
        )
    return out


def adjust_text(reference: LayoutResult, *, iterations: int = 300, obstacle_cell: int = 16) -> LayoutResult:
    """Re-lay the labels of ``reference`` with adjustText, keeping its anchors.

    Parameters
    ----------
    reference : LayoutResult
        A LayoutResult (usually :func:`two_step`'s) whose anchors, texts and font
        are reused
    iterations : int
        AdjustText iterations (``iter_lim``); no time limit is used.
    obstacle_cell : int
        Size in pixels of the blocks the model's pixels are given to
        adjustText as obstacles

    Returns
    -------
    LayoutResult
        With ``method="adjusttext"``; ``timings["boxes"]`` is adjustText's time.
    """
    from meshvis._extras import import_extra

    adjustText = import_extra("adjustText", "the adjustText labeling baseline")
    from matplotlib.transforms import Bbox

    t0 = time.perf_counter()
    w, h = reference.size
    fig, ax = _text_axes(w, h)
    labs = reference.labels
    texts = _text_artists(ax, reference)
    obstacles = _model_obstacles(reference.ids, obstacle_cell)
    # display coordinates: pixels with y up
    objects = [Bbox([[b[0], h - b[3]], [b[2], h - b[1]]]) for b in obstacles]
    anchors = np.array([lab.anchor for lab in labs]).reshape(-1, 2)
    if labs:
        adjustText.adjust_text(
            texts,
            x=anchors[:, 0],
            y=anchors[:, 1],
            objects=objects,
            ax=ax,
            iter_lim=int(iterations),
            time_lim=None,
            ensure_inside_axes=True,
            expand_axes=False,
            prevent_crossings=True,
        )
    fig.canvas.draw()  # places the text boxes at the adjusted positions
    out = _adjusted_labels(labs, texts, fig.canvas.get_renderer(), h)
    elapsed = time.perf_counter() - t0
    res = LayoutResult(
        labels=out,
        invisible=reference.invisible,
        unplaced=reference.unplaced,
        skipped=reference.skipped,
        image=reference.image,
        ids=reference.ids,
        camera=reference.camera,
        layout=reference.layout,
        method="adjusttext",
        area_polygon=reference.area_polygon,
        font_size=reference.font_size,
        box_height=reference.box_height,
        sphere_diameter=reference.sphere_diameter,
        params={"iterations": int(iterations), "obstacle_cell": int(obstacle_cell)},
        metrics={},
        timings={"boxes": elapsed},
    )
    res.metrics = frame_metrics(res)
    return res
