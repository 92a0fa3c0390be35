"""The pixel-error estimate of AGVS §4.5, computed while sampling.

A random camera in the view space casts rays of the view space-direction distribution: a
uniform point and a uniform direction.  A pixel is wrong when its ray's first hit is not
in the PVS of the cell the camera stands in, so the rate at which those rays still find
faces new to their own cell estimates the share of wrong pixels:
``e = N_c / N`` (per ray, reported per million).  The window of recent rays grows until it
holds the ``N`` that Eq. 5 asks for the estimate to be within ``k e`` of the truth with
probability ``P``: ``N >= (1 - e) / (k^2 e (1 - P))``.  The window looks back in time, when
the PVS was smaller, so the estimate errs high.

>>> est = ErrorEstimate()
>>> est.add(rays=5_000_000, contributing=50)
>>> round(est.per_million, 1), est.enough
(10.0, True)
"""

from __future__ import annotations

import math

#: Eq. 5's constants: the estimate is within K * e of the truth with probability P
P = 0.9
K = 0.5


def rays_needed(e: float) -> float:
    """Eq. 5: rays for an estimate of ``e`` (per ray) within ``K e`` with probability ``P``."""
    if e <= 0:
        return math.inf
    return (1 - e) / (K * K * e * (1 - P))


class ErrorEstimate:
    """Rays of the estimate's distribution and how many found something new, per batch."""

    def __init__(self) -> None:
        self.rays: list[int] = []
        self.contributing: list[int] = []
        self.per_million = math.inf
        self.window = 0
        self.enough = False

    def add(self, rays: int, contributing: int) -> None:
        """Fold in a batch and update :attr:`per_million`, :attr:`window` and :attr:`enough`."""
        if rays <= 0:
            return
        self.rays.append(int(rays))
        self.contributing.append(int(contributing))
        n = nc = 0
        for r, c in zip(reversed(self.rays), reversed(self.contributing)):
            n += r
            nc += c
            # with no contributing ray yet, one more would have been the estimate
            if n >= rays_needed(max(nc, 1) / n):
                break
        self.window = n
        self.per_million = 1e6 * nc / n
        self.enough = n >= rays_needed(max(nc, 1) / n)
