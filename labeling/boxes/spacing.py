"""Distances of the box layout, and what it returns: one placement per label and counts."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np


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
    leader : (k, 2) float
        Polyline from the anchor to the box
    box : (4,) float, (x0, y0, x1, y1)
    side : int
        Side code
    tier : int, 0 next to ``A_I``, higher = pushed further out
    shift : float
        Distance of the box's port from the candidate endpoint along the side
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
