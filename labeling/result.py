"""The result of laying out the labels of one frame."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshvis.rays.camera import Camera


@dataclass
class Label:
    """One placed label.  Coordinates are image pixels (x right, y down).

    Attributes
    ----------
    part : int
        Part id in the model
    name : str
        Part name
    text : str
        Label text
    anchor : (2,) float
        The anchor ``a`` (centre of a pixel of the part)
    anchor_3d : (3,) float
        The surface point seen at the anchor
    endpoint : (2,) float
        The candidate endpoint ``e`` on the boundary of ``A_I``
    leader : (k, 2) float
        The drawn leader, from the anchor to the box
    box : (4,) float
        ``(x0, y0, x1, y1)``.
    side : str
        "west", "east", "north", "south" or "radial"
    rank : int
        Greedy order (0 = placed first)
    feasibility : float
        ``F`` of the chosen candidate (Eq. 12).
    priority : float
        ``P_i`` of the area when chosen (Eq. 14).
    shift : float
        How far the box was shifted from the candidate endpoint (pixels)
    tier : int
        0 next to ``A_I``, higher = pushed further out.
    """

    part: int
    name: str
    text: str
    anchor: np.ndarray
    anchor_3d: np.ndarray
    endpoint: np.ndarray
    leader: np.ndarray
    box: np.ndarray
    side: str
    rank: int
    feasibility: float = float("nan")
    priority: float = float("nan")
    shift: float = 0.0
    tier: int = 0

    @property
    def port(self) -> np.ndarray:
        """Where the leader meets the box."""
        return self.leader[-1]

    def to_json(self) -> dict[str, Any]:
        """The label as a JSON-ready dict (points rounded to 3 decimals)."""

        def pt(v: np.ndarray) -> list[float]:
            return [round(float(x), 3) for x in np.ravel(v)]

        return {
            "part": int(self.part),
            "name": self.name,
            "text": self.text,
            "anchor": pt(self.anchor),
            "anchor_3d": [float(x) for x in self.anchor_3d],
            "endpoint": pt(self.endpoint),
            "leader": [pt(p) for p in self.leader],
            "box": pt(self.box),
            "side": self.side,
            "rank": int(self.rank),
            "feasibility": round(float(self.feasibility), 6),
            "priority": round(float(self.priority), 3),
            "shift": round(float(self.shift), 3),
            "tier": int(self.tier),
        }


@dataclass
class LayoutResult:
    """Labels of one frame plus everything needed to draw and judge them.

    Attributes
    ----------
    labels : list of Label
        In greedy order
    invisible : list of (int, str)
        ``(part id, name)`` of parts with no visible pixel.
    unplaced : list of (int, str)
        ``(part id, name)`` of visible parts that got no valid box.
    skipped : list of (int, str)
        ``(part id, name)`` of parts with an empty label text.
    image : (h, w, 3) uint8
        The shaded picture
    ids : (h, w) int64
        The object-ID buffer
    camera : Camera
        The view.
    layout : str
        Layout name
    method : str
        "fuzzy", "two-step" or "adjusttext"
    area_polygon : (k, 2) float
        Boundary of ``A_I``
    font_size : int
        Label font size in pixels.
    box_height : float
        Box height in pixels.
    sphere_diameter : float
        ``d_S`` in pixels.
    params : dict
        The parameters used (weights, d_a, d_e, ...)
    metrics : dict
        See :mod:`labeling.metrics`
    timings : dict
        Seconds per stage
    """

    labels: list[Label]
    invisible: list[tuple[int, str]]
    unplaced: list[tuple[int, str]]
    skipped: list[tuple[int, str]]
    image: np.ndarray
    ids: np.ndarray
    camera: Camera
    layout: str
    method: str
    area_polygon: np.ndarray
    font_size: int
    box_height: float
    sphere_diameter: float
    params: dict[str, Any] = field(default_factory=dict)
    metrics: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of the image."""
        return int(self.ids.shape[1]), int(self.ids.shape[0])

    @property
    def canvas(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1): the image grown to hold every box and leader, plus a 2 px rim."""
        w, h = self.size
        x0, y0, x1, y1 = 0.0, 0.0, float(w), float(h)
        for lab in self.labels:
            x0 = min(x0, lab.box[0] - 2, lab.leader[:, 0].min() - 2)
            y0 = min(y0, lab.box[1] - 2, lab.leader[:, 1].min() - 2)
            x1 = max(x1, lab.box[2] + 2, lab.leader[:, 0].max() + 2)
            y1 = max(y1, lab.box[3] + 2, lab.leader[:, 1].max() + 2)
        return float(np.floor(x0)), float(np.floor(y0)), float(np.ceil(x1)), float(np.ceil(y1))

    def by_part(self) -> dict[int, Label]:
        """The labels keyed by part id."""
        return {lab.part: lab for lab in self.labels}

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready summary of the frame (labels, parts left out, metrics, timings)."""
        return {
            "layout": self.layout,
            "method": self.method,
            "size": list(self.size),
            "canvas": list(self.canvas),
            "camera": self.camera.to_json(),
            "font_size": self.font_size,
            "box_height": round(self.box_height, 3),
            "sphere_diameter": round(self.sphere_diameter, 3),
            "params": self.params,
            "labels": [lab.to_json() for lab in self.labels],
            "invisible": [{"part": p, "name": n} for p, n in self.invisible],
            "unplaced": [{"part": p, "name": n} for p, n in self.unplaced],
            "skipped": [{"part": p, "name": n} for p, n in self.skipped],
            "metrics": self.metrics,
            "timings": {k: round(v, 6) for k, v in self.timings.items()},
        }
