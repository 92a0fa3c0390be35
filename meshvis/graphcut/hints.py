"""User hints: points and boxes declared inside or outside (appendix H §3.2.1, Fig. 3).

Without guidance the INSIDE terminal has no geometric meaning; a user who knows that a
point (or an axis-aligned box) is inside or outside the model gives it one.  Rays are cast
from the hint in uniform directions; every node they reach gets an extra terminal link of
weight ``A · n_hj / n_h`` (the share of the hint's rays that land on node *j*, scaled by
the model's total area ``A``, as in the ray-measure reading of Eq. 6).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from meshvis import _validate
from meshvis.errors import ParameterError
from meshvis.graphcut.nodes import NodeSet
from meshvis.rays.caster import RayCaster
from meshvis.rays.samples import uniform_sphere


@dataclass
class Hints:
    """Points and boxes known to be inside or outside.

    Parameters
    ----------
    inside_points : (k, 3) float array
        Points known to be inside.
    outside_points : (k, 3) float array
        Points known to be outside.
    inside_boxes : (k, 2, 3) float array
        Boxes known to be inside, as (min corner, max corner).
    outside_boxes : (k, 2, 3) float array
        Boxes known to be outside.
    rays : int
        Rays cast per hint point (boxes: in total, from random points in the box).
    strength : float
        Multiplier of the hint links (default 10: a hint should win over the ray evidence
        of a side that escapes freely, whose outside link is at most its area).
    """

    inside_points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    outside_points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    inside_boxes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 3)))
    outside_boxes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 3)))
    rays: int = 4096
    strength: float = 10.0

    def __post_init__(self) -> None:
        for name in ("inside_points", "outside_points"):
            setattr(self, name, _validate.points(name, getattr(self, name), (3,)))
        for name in ("inside_boxes", "outside_boxes"):
            a = _validate.points(name, getattr(self, name), (2, 3))
            if np.any(a[:, 1] < a[:, 0]):
                raise ParameterError(f"{name.replace('_', ' ')} must be finite (min, max) corner pairs")
            setattr(self, name, a)
        self.rays = _validate.integer("hint rays", self.rays, 1, 1 << 20)
        self.strength = _validate.real("hint strength", self.strength, 0.0, open_lo=True)

    @classmethod
    def coerce(cls, hints) -> Hints | None:
        """Accept None, a Hints, or a dict with the same keys."""
        if hints is None or isinstance(hints, Hints):
            return hints
        if isinstance(hints, dict):
            _validate.keywords(hints, cls)
            return cls(**hints)
        raise ParameterError(f"hints must be a Hints or a dict, got {type(hints).__name__}")

    @property
    def empty(self) -> bool:
        """True when no point or box is given."""
        return not (
            len(self.inside_points)
            or len(self.outside_points)
            or len(self.inside_boxes)
            or len(self.outside_boxes)
        )


def _hint_origins(points: np.ndarray, boxes: np.ndarray, rays: int, rng: np.random.Generator) -> np.ndarray:
    parts = [np.repeat(points, rays, axis=0)]
    for lo, hi in boxes:
        parts.append(lo + rng.random((rays, 3)) * (hi - lo))
    return np.concatenate(parts) if parts else np.zeros((0, 3))


def hint_weights(
    caster: RayCaster, nodes: NodeSet, hints: Hints, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, int]:
    """Extra terminal weights (to OUTSIDE, to INSIDE) from the hints, and the rays cast."""
    from meshvis.graphcut.sampling import snap_to_points

    total_area = float(nodes.area.sum()) / 2  # each triangle has two sides
    out = []
    n_cast = 0
    for points, boxes in (
        (hints.outside_points, hints.outside_boxes),
        (hints.inside_points, hints.inside_boxes),
    ):
        origins = _hint_origins(points, boxes, hints.rays, rng)
        w: np.ndarray = np.zeros(nodes.n)
        if len(origins):
            dirs = uniform_sphere(len(origins), rng)
            h = caster.intersect(origins, dirs)
            n_cast += len(origins)
            hit = h.face >= 0
            hit[hit] = (nodes.side_node[h.face[hit], 0] >= 0) | (nodes.flagged_index[h.face[hit]] >= 0)
            f, s = h.face[hit], h.side[hit].astype(np.int64)  # faces with no node are passed over
            dst = nodes.side_node[f, s]
            flag = dst < 0
            if flag.any():
                assert h.bary is not None  # intersect always fills it
                dst[flag] = nodes.point_node(snap_to_points(nodes, f[flag], h.bary[hit][flag]), s[flag])
            w = np.bincount(dst, minlength=nodes.n) * (hints.strength * total_area / max(len(dst), 1))
        out.append(w)
    return out[0], out[1], n_cast
