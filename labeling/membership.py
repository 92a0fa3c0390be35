"""Fuzzy membership functions, their weighted aggregation and the area priority.

Appendix I, §5.3–5.4.  For a leader candidate ``l = (a, e)`` of area ``A_i``:

* Eq. 2, leader length:   ``f2 = 1 - |a e| / d_max``
* Eq. 3, anchor salience: ``f3 = dist_sil(a) / d_max``, ``dist_sil`` = distance of ``a`` to
  the silhouette of ``A_i``
* Eq. 4–5, anchor distance: ``f4 = AND_p min(|a a_p| / d_a, 1)`` over the placed leaders
* Eq. 6–7, endpoint distance: ``f5 = AND_p min(|e e_p| / d_e, 1)``
* Eq. 8, anchor coherence:   ``f6 = 1 - |a_t a_{t-1}| / d_S``
* Eq. 9, endpoint coherence: ``f7 = 1 - |e_t e_{t-1}| / d_S``
* Eq. 11, weighting (Yager): ``F_i = f_i ** w_i``
* Eq. 12, aggregation with the natural fuzzy conjunction (product): ``F = prod_i F_i``
* Eq. 14, priority of an area: ``P_i = sum_{l in A_i} (1 - F(l))``

The conjunction over placed leaders in Eq. 5 and 7 is taken as the minimum (the nearest
placed anchor or endpoint decides), which is how the thresholds ``d_a`` and ``d_e`` read as
"desired minimal distances"; the aggregation of Eq. 12 is the product, as the paper states.
Memberships are clipped to [0, 1] (f6, f7 would turn negative for moves beyond ``d_S``).
Weights default to the paper's values (§7.3): ``w2 = 0.2, w3 = 1, w4 = w5 = 1,
w6 = w7 = 0.7``.  ``d_a``, ``d_e`` and ``d_S`` are in pixels here; the public API takes
``d_a`` and ``d_e`` as fractions of ``d_S`` like the paper (§7.2).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from meshvis.errors import ParameterError

from ._kernels import own_silhouette_distance


@dataclass(frozen=True)
class Weights:
    """Weights ``w2 ... w7`` of Eq. 11 (paper defaults, appendix I §7.3)."""

    w2: float = 0.2
    w3: float = 1.0
    w4: float = 1.0
    w5: float = 1.0
    w6: float = 0.7
    w7: float = 0.7

    def __post_init__(self) -> None:
        for k, v in asdict(self).items():
            if not (np.isfinite(v) and 0.0 <= v <= 1.0):
                raise ParameterError(f"weight {k} must be in [0, 1], got {v}")

    def as_dict(self) -> dict[str, float]:
        """The weights as a dict keyed by field name."""
        return asdict(self)


def f2_length(length: np.ndarray, d_max: float) -> np.ndarray:
    """Eq. 2: ``1 - |a e| / d_max`` (short leaders are better)."""
    return np.clip(1.0 - np.asarray(length, np.float64) / d_max, 0.0, 1.0)


def f3_salience(dist_sil: np.ndarray, d_max: float) -> np.ndarray:
    """Eq. 3: ``dist_sil(a) / d_max`` (anchors deep inside their area are better)."""
    return np.clip(np.asarray(dist_sil, np.float64) / d_max, 0.0, 1.0)


def dist_threshold(dx: np.ndarray, dy: np.ndarray, d: float) -> np.ndarray:
    """Eq. 4 / Eq. 6: ``min(|v| / d, 1)`` for offsets ``(dx, dy)``; 1 everywhere when ``d <= 0``."""
    if d <= 0:
        return np.ones(np.broadcast(dx, dy).shape)
    return np.minimum(np.hypot(dx, dy) / d, 1.0)


def f4_anchor_distance(ax: np.ndarray, ay: np.ndarray, placed: np.ndarray, d_a: float) -> np.ndarray:
    """Eq. 5: conjunction (minimum) of Eq. 4 over the placed anchors ``placed`` (k, 2)."""
    out = np.ones(np.shape(ax))
    for px, py in np.asarray(placed, np.float64).reshape(-1, 2):
        np.minimum(out, dist_threshold(ax - px, ay - py, d_a), out=out)
    return out


def f_coherence(x: np.ndarray, y: np.ndarray, prev: np.ndarray, d_s: float) -> np.ndarray:
    """Eq. 8 / Eq. 9: ``1 - |p_t - p_{t-1}| / d_S``, clipped to [0, 1]; 1 where ``prev`` is NaN.

    ``prev`` broadcasts against ``x`` with a trailing axis of 2 (previous position per element).
    """
    prev = np.asarray(prev, np.float64)
    d = np.hypot(x - prev[..., 0], y - prev[..., 1])
    out = np.clip(1.0 - d / d_s, 0.0, 1.0)
    return np.where(np.isnan(d), 1.0, out)


def weighted(f: np.ndarray, w: float) -> np.ndarray:
    """Eq. 11: Yager's weighting ``f ** w`` (``0 ** 0 = 1``: a zero weight ignores the criterion)."""
    if w == 0:
        return np.ones(np.shape(f))
    if w == 1:
        return np.asarray(f, np.float64)
    return np.power(f, w)


def aggregate(memberships: dict[str, np.ndarray], weights: Weights) -> np.ndarray:
    """Eq. 12: product of the weighted memberships ``{"f2": ..., ..., "f7": ...}``."""
    w = weights.as_dict()
    out = None
    for name, f in memberships.items():
        term = weighted(f, w["w" + name[1:]])
        out = term.copy() if out is None else out * term
    return out


def priority(feasibility: np.ndarray, area: np.ndarray, n_areas: int) -> np.ndarray:
    """Eq. 14: ``P_i = sum over the candidates l of area i of (1 - F(l))``."""
    return np.bincount(area, weights=1.0 - feasibility, minlength=n_areas)


def silhouette_distance(ids: np.ndarray) -> np.ndarray:
    """Distance of every pixel to the silhouette of its own area (for Eq. 3), in pixels.

    The silhouette pixels of all areas are found at once (a pixel whose 4-neighbour has
    another id, or lies outside the image); areas do not overlap, so one exact Euclidean
    distance transform serves every area (appendix I, §6.2).  A silhouette pixel gets 1,
    its inner neighbours 2, and so on; background pixels get 0.
    """
    ids = np.asarray(ids)
    dist = np.zeros(ids.shape)
    rows = np.flatnonzero((ids >= 0).any(axis=1))
    cols = np.flatnonzero((ids >= 0).any(axis=0))
    if len(rows) == 0:
        return dist
    # work on the model's bounding box only: background pixels are silhouette anyway
    r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    dist[r0:r1, c0:c1] = own_silhouette_distance(np.ascontiguousarray(ids[r0:r1, c0:c1], np.int64))
    return dist
