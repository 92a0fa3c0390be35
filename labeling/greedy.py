"""Greedy placement of leader lines (appendix I, §5.4 and §6.1 step 7).

Every candidate ``l`` of every labelled area carries its feasibility ``F(l)`` (Eq. 12).
The loop

1. computes the priority of every unlabelled area: how few feasible candidates it has,
   ``P_i = -sum_{l in A_i} F(l)`` (see below),
2. takes the area with the highest priority,
3. takes its most feasible candidate as the leader (or, along a camera path, the candidate
   at last frame's anchor while nothing is clearly better: hysteresis),
4. updates the anchor- and endpoint-distance memberships ``f4``, ``f5`` (Eq. 4–7) of the
   candidates of the remaining areas, and the priorities with them,

until every area has its leader.  No backtracking, no wall-clock rule.

Priority.  §5.4 of appendix I wants "the areas with a low number of feasible leader line
candidates" first, so that parts hard to label are placed before others take their room.
Eq. 14 written out, ``sum (1 - F) = n_i - sum F``, grows with the pixel count ``n_i`` and
so ranks the largest areas first, the opposite.  The fuzzy count of feasible candidates
``sum F`` is what the text describes; the area with the least of it goes first.

Speed.  ``F(l) = s(l) f4(l)^w4 f5(e(l))^w5`` where ``s`` collects the memberships that do
not change (f2, f3, f6, f7) and ``f5`` depends on the endpoint only, which many candidates
share (a row, a column, a boundary pixel).  So with
``S[i, e] = sum of s f4^w4 over the candidates of area i with endpoint e``, and
``sum F = S @ f5^w5``: a small dense
matrix (areas x distinct endpoints).  ``f5`` is updated per endpoint; ``f4`` changes only for
candidates within ``d_a`` of the new anchor (found through a grid of buckets), and ``S``
takes the change of those few.  One step costs O(areas x endpoints + touched candidates).

Ties: areas of equal priority go by area index; candidates of equal feasibility go by
pixel order (row-major).  When every candidate of the chosen area has ``F = 0`` (all its
endpoints coincide with placed ones), the candidate with the best remaining criteria
(``F`` with ``f5`` floored at 1e-6) is taken.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._kernels import lower_f4_near
from .membership import dist_threshold


def stable_order(keys: np.ndarray) -> np.ndarray:
    """``np.argsort(keys, kind="stable")`` of small non-negative integers, faster.

    Keys below 2**15 are sorted as int16, for which numpy's stable sort is a radix sort
    (about 4x faster on the pixels of a frame than the merge sort of int64 keys); the
    order is the same.
    """
    keys = np.asarray(keys)
    if len(keys) and keys.min() >= 0 and keys.max() < np.iinfo(np.int16).max:
        keys = keys.astype(np.int16)
    return np.argsort(keys, kind="stable")


class _Buckets:
    """Indices of points grouped by grid cell, for "points within d of p" queries.

    The points of cell (i, j) are ``order[start[j * nx + i] : start[j * nx + i + 1]]``;
    :func:`._kernels.lower_f4_near` walks the cells around a new anchor.
    """

    def __init__(self, x: np.ndarray, y: np.ndarray, cell: float):
        self.cell = float(max(cell, 4.0))
        self.cx = np.floor(x / self.cell).astype(np.int64)
        self.cy = np.floor(y / self.cell).astype(np.int64)
        self.x0, self.y0 = int(self.cx.min()), int(self.cy.min())
        self.nx = int(self.cx.max()) - self.x0 + 1
        self.ny = int(self.cy.max()) - self.y0 + 1
        key = (self.cy - self.y0) * self.nx + (self.cx - self.x0)
        self.order = stable_order(key)
        self.start = np.searchsorted(key[self.order], np.arange(self.nx * self.ny + 1))
        self.grid = np.array([self.cell, self.x0, self.y0, self.nx, self.ny], np.float64)


@dataclass
class GreedyResult:
    """Outcome of the greedy loop.

    Attributes
    ----------
    area_order : (k,) int
        Areas in the order they were labelled
    pick : (k,) int
        Chosen candidate (index into the candidate arrays) of each of them
    feasibility : (k,) float, ``F`` of the chosen candidate when it was chosen
    priority : (k,) float, ``P_i = -sum F`` of the area when it was chosen
    """

    area_order: np.ndarray
    pick: np.ndarray
    feasibility: np.ndarray
    priority: np.ndarray


#: f5 of a used endpoint in the ranking of an area whose candidates are all infeasible: above
#: zero, so the other terms still order them
_F5_FLOOR = 1e-6


def _infeasible_pick(rest: np.ndarray, f5a: np.ndarray, w5: float, d_e: float) -> int:
    """Pick the candidate of an area whose candidates are all infeasible.

    Endpoints nobody uses come first, then the rest; ``rest`` holds the candidates'
    memberships other than f5 and ``f5a`` their f5.
    """
    tie = rest * np.maximum(f5a, _F5_FLOOR) ** w5
    tie = np.where(f5a > 0, tie + 1.0, tie) if d_e > 0 else tie
    return int(np.argmax(tie))


def _priority(S: np.ndarray, f5w: np.ndarray, count: np.ndarray) -> np.ndarray:
    """``P_i = -sum F`` of every area: the fuzzy count of its feasible candidates, negated."""
    return -(S @ f5w)


def _near_pick(F: np.ndarray, dx: np.ndarray, dy: np.ndarray, drift: float, keep: float, best: int) -> int:
    """Hysteresis: the best candidate within ``drift`` of the followed anchor (offsets ``dx``, ``dy``).

    It wins unless the overall best ``F[best]`` is more than ``keep`` times its ``F``; with
    no feasible candidate that near, ``best`` does.
    """
    near = np.flatnonzero(dx * dx + dy * dy <= drift * drift)
    if len(near) == 0:
        return best
    j = int(near[np.argmax(F[near])])
    return j if F[j] > 0 and F[best] <= keep * F[j] else best


def greedy_layout(
    area: np.ndarray,
    ax: np.ndarray,
    ay: np.ndarray,
    eid: np.ndarray,
    endpoints: np.ndarray,
    static: np.ndarray,
    n_areas: int,
    d_a: float,
    d_e: float,
    w4: float = 1.0,
    w5: float = 1.0,
    follow: np.ndarray | None = None,
    drift: float = 0.0,
    keep: float = 1.0,
) -> GreedyResult:
    """Run the greedy loop over candidates grouped by area.

    Parameters
    ----------
    area : (N,) int
        Area index (0 .. n_areas-1) of each candidate, **sorted ascending**
    ax, ay : (N,) float
        Anchor (pixel centre) of each candidate
    eid : (N,) int
        Endpoint id of each candidate (row of ``endpoints``)
    endpoints : (n_e, 2) float
        The distinct endpoints
    static : (N,) float
        Product of the weighted memberships that do not depend on the
        placed leaders: ``f2^w2 f3^w3 f6^w6 f7^w7``
    n_areas : int
        Number of areas
    d_a, d_e : float
        Distance thresholds of Eq. 4 and Eq. 6, pixels (0 disables)
    w4, w5 : weights of f4 and f5
    follow : (n_areas, 2) float, optional: per area the previous frame's anchor moved with
        the model (NaN: none).  The area takes its best candidate within ``drift`` pixels
        of it unless the best candidate overall has more than ``keep`` times its ``F``
    drift : float, pixels, how far an anchor may slide from ``follow`` in one frame
    keep : float, the hysteresis ratio of ``follow``

    Returns
    -------
    GreedyResult
    """
    area = np.asarray(area, np.int64)
    eid = np.asarray(eid, np.int64)
    static = np.asarray(static, np.float64)
    endpoints = np.asarray(endpoints, np.float64).reshape(-1, 2)
    n_e = len(endpoints)
    start = np.searchsorted(area, np.arange(n_areas + 1))
    count = np.diff(start).astype(np.float64)
    cell = area * n_e + eid
    f4w = np.ones(len(area))  # f4 ** w4 per candidate
    f4 = np.ones(len(area))
    f5 = np.ones(n_e)
    S = np.bincount(cell, weights=static, minlength=n_areas * n_e).reshape(n_areas, n_e)
    alive = count > 0
    done = np.zeros(len(area), bool)
    abk = _Buckets(ax, ay, d_a) if d_a > 0 and len(area) else None
    ax, ay = np.ascontiguousarray(ax, np.float64), np.ascontiguousarray(ay, np.float64)
    S_flat = S.reshape(-1)  # a view: the compiled f4 update writes through it
    acc = np.zeros(S.size)
    order, picks, feas, prio = [], [], [], []
    while alive.any():
        f5w = f5**w5 if w5 != 1 else f5
        P = _priority(S, f5w, count)
        i = int(np.argmax(np.where(alive, P, -np.inf)))
        lo, hi = start[i], start[i + 1]
        F = static[lo:hi] * f4w[lo:hi] * f5w[eid[lo:hi]]
        j = int(np.argmax(F))
        if follow is not None and np.isfinite(follow[i, 0]):
            j = _near_pick(F, ax[lo:hi] - follow[i, 0], ay[lo:hi] - follow[i, 1], drift, keep, j)
        if F[j] <= 0.0:
            j = _infeasible_pick(static[lo:hi] * f4w[lo:hi], f5[eid[lo:hi]], w5, d_e)
        pick = lo + j
        order.append(i)
        picks.append(pick)
        feas.append(float(F[j]))
        prio.append(float(P[i]))
        alive[i] = False
        done[lo:hi] = True
        if abk is not None:
            lower_f4_near(
                float(ax[pick]), float(ay[pick]), float(d_a), float(w4), ax, ay, done, static, cell,
                f4, f4w, S_flat, acc, abk.grid, abk.order, abk.start,
            )  # fmt: skip
        if d_e > 0:
            e = endpoints[eid[pick]]
            np.minimum(f5, dist_threshold(endpoints[:, 0] - e[0], endpoints[:, 1] - e[1], d_e), out=f5)
    return GreedyResult(
        area_order=np.array(order, np.int64),
        pick=np.array(picks, np.int64),
        feasibility=np.array(feas),
        priority=np.array(prio),
    )
