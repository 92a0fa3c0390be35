"""External labeling of 3D models: fuzzy-greedy layout on meshvis' ray backend.

Implements thesis appendix I ("Layout-aware optimization for interactive labeling of 3D
models"): an object-ID buffer from primary rays, leader candidates for every pixel of a
convex internal area, fuzzy membership functions aggregated per candidate, a greedy
placement order, label-box stacking with shift-and-swap corrections, frame-to-frame
coherence, and the measures and baselines to judge the result.

>>> import meshvis, meshvis.labeling, trimesh
>>> box, ball = trimesh.creation.box(), trimesh.creation.icosphere()
>>> ball = ball.apply_translation((1.5, 0, 0))
>>> parts = meshvis.Soup.concatenate([meshvis.Soup(box.vertices, box.faces, part_names=["box"]),
...                                   meshvis.Soup(ball.vertices, ball.faces, part_names=["ball"])])
>>> meshvis.save(parts, "parts.obj")
>>> result = meshvis.labeling.layout("parts.obj", layout="left-right")
>>> sorted(label.text for label in result.labels)
['ball', 'box']
>>> meshvis.labeling.write(result, "labels.svg")
['labels.svg']
"""

from __future__ import annotations

from .baselines import adjust_text, two_step
from .candidates import LAYOUTS
from .frames import layout_frames, orbit, read_camera_path
from .idbuffer import IdBuffer, id_buffer
from .internal_area import SHAPES
from .membership import Weights
from .metrics import frame_metrics, is_clean, motion_metrics, sequence_metrics
from .output import to_svg, write, write_gif, write_json, write_png, write_svg
from .pipeline import METHODS, fit_camera, layout, solve
from .result import Label, LayoutResult

__all__ = [
    "LAYOUTS",
    "SHAPES",
    "METHODS",
    "Weights",
    "Label",
    "LayoutResult",
    "IdBuffer",
    "layout",
    "solve",
    "fit_camera",
    "id_buffer",
    "layout_frames",
    "orbit",
    "read_camera_path",
    "two_step",
    "adjust_text",
    "frame_metrics",
    "motion_metrics",
    "sequence_metrics",
    "is_clean",
    "write",
    "write_svg",
    "write_png",
    "write_gif",
    "write_json",
    "to_svg",
]
