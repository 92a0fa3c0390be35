"""Where a viewer can stand: the view space of the PVS (DESIGN.md §11).

The view space is an axis-aligned box, cut from below by the *ground* for scenes that stand
on one.  The ground is a height field over the horizontal plane: in each column of a grid
over the footprint, rays cast upwards from below the model meet the lowest surface; when
that surface faces up (a floor, a terrain, a platform, seen from below through its back),
the space under it is outside the view space.  A column whose lowest surface faces down (the
bottom of a closed solid) or that meets nothing keeps the whole height of the box.  A scene
*stands on a ground* when most columns that meet something meet an upward-facing surface
first (:data:`GROUND_SHARE`): the monastery's platform and the floors of an indoor level do,
a level carved into a closed box does not.

>>> import trimesh
>>> vs = default_view_space(trimesh.creation.box(), "box")
>>> vs.lo.tolist(), vs.ground is None
([-0.5, -0.5, -0.5], True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.errors import ParameterError
from meshvis.io import as_soup
from meshvis.io.up_axis import up_vector

#: columns of the ground grid along the longer horizontal side of the box
GROUND_COLUMNS = 128
#: rays per column, on a square pattern inside it; the column's ground is their lowest, so a
#: hole under one of them (a stairwell, a gap between floor tiles) does not lift it
GROUND_RAYS_SIDE = 3
#: the scene stands on a ground when at least this share of the upward rays that meet anything
#: meet an upward-facing surface first
GROUND_SHARE = 0.5
#: view spaces of the text forms of :func:`default_view_space`
VIEW_SPACE_KINDS = ("auto", "box", "box:x0,y0,z0,x1,y1,z1")


@dataclass
class ViewSpace:
    """An axis-aligned box of viewer positions, optionally above a ground height field.

    Parameters
    ----------
    lo, hi : (3,) float64
        The box's corners.
    up_axis : int
        The coordinate axis that points up (0, 1 or 2).
    up_sign : float
        +1 when up is that axis' positive direction, -1 otherwise.
    ground : (gu, gv) float64 or None
        Ground height per column (a coordinate along ``up_axis``); None: no ground.  Column
        ``(i, j)`` covers ``[g_lo + (i, j) * g_step, g_lo + (i + 1, j + 1) * g_step)`` on the
        two horizontal axes (in increasing order of axis number).
    g_lo, g_step : (2,) float64
        Origin and size of the ground columns.
    kind : str
        How it was made: ``"auto"`` (the box above the ground), ``"box"`` or ``"region"``.

    Examples
    --------
    >>> vs = ViewSpace(np.zeros(3), np.ones(3))
    >>> vs.contains(np.array([[0.5, 0.5, 0.5], [2.0, 0.5, 0.5]])).tolist()
    [True, False]
    """

    lo: np.ndarray
    hi: np.ndarray
    up_axis: int = 2
    up_sign: float = 1.0
    ground: np.ndarray | None = None
    g_lo: np.ndarray | None = None
    g_step: np.ndarray | None = None
    kind: str = "box"

    def __post_init__(self) -> None:
        self.lo = np.asarray(self.lo, np.float64).reshape(3)
        self.hi = np.asarray(self.hi, np.float64).reshape(3)
        if not (np.isfinite(self.lo).all() and np.isfinite(self.hi).all()) or (self.hi <= self.lo).any():
            raise ParameterError(
                f"the view space needs a box of positive size, got {self.lo.tolist()} .. {self.hi.tolist()}"
            )

    @property
    def horizontal(self) -> tuple[int, int]:
        """The two horizontal axes, in increasing order."""
        h = [a for a in range(3) if a != self.up_axis]
        return h[0], h[1]

    @property
    def diagonal(self) -> float:
        """Length of the box's diagonal."""
        return float(np.linalg.norm(self.hi - self.lo))

    def ground_at(self, points: np.ndarray) -> np.ndarray:
        """(n,) ground height under each point (``-inf`` or ``+inf`` where there is none)."""
        floor = -np.inf * self.up_sign
        if self.ground is None:
            return np.full(len(points), floor)
        assert self.g_lo is not None and self.g_step is not None
        u, v = self.horizontal
        i = np.floor((points[:, u] - self.g_lo[0]) / self.g_step[0]).astype(np.int64)
        j = np.floor((points[:, v] - self.g_lo[1]) / self.g_step[1]).astype(np.int64)
        inside = (i >= 0) & (i < self.ground.shape[0]) & (j >= 0) & (j < self.ground.shape[1])
        out = np.full(len(points), floor)
        out[inside] = self.ground[i[inside], j[inside]]
        return out

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(n,) bool: the points lie in the box and above the ground."""
        points = np.asarray(points, np.float64).reshape(-1, 3)
        ok = np.asarray(((points >= self.lo) & (points <= self.hi)).all(axis=1))
        if self.ground is not None:
            height = points[:, self.up_axis] * self.up_sign
            ok &= height >= self.ground_at(points) * self.up_sign
        return ok

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """(n, 3) uniform random points of the view space (the box, rejecting points under the ground)."""
        out = np.empty((0, 3))
        share = max(self.volume_share(self.lo[None], self.hi[None])[0], 1e-6)
        while len(out) < n:
            want = int((n - len(out)) / share * 1.1) + 16
            p = self.lo + rng.random((want, 3)) * (self.hi - self.lo)
            out = np.concatenate([out, p[self.contains(p)]])
        return out[:n]

    def volume_share(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """(k,) the share of each box ``[lo, hi]`` (inside the view space's box) that lies above the ground.

        Exact for the ground's height field: each column's overlap with the box counts with
        the box's height above that column's ground.
        """
        lo, hi = np.atleast_2d(lo), np.atleast_2d(hi)
        size = np.maximum(hi - lo, 0.0)
        whole = size.prod(axis=1)
        if self.ground is None:
            return np.where(whole > 0, 1.0, 0.0)
        assert self.g_lo is not None and self.g_step is not None
        u, v = self.horizontal
        a = self.up_axis
        out = np.zeros(len(lo))
        gu, gv = self.ground.shape
        # column edges along u and v
        eu = self.g_lo[0] + self.g_step[0] * np.arange(gu + 1)
        ev = self.g_lo[1] + self.g_step[1] * np.arange(gv + 1)
        for k in range(len(lo)):
            if whole[k] <= 0:
                continue
            wu = np.clip(np.minimum(eu[1:], hi[k, u]) - np.maximum(eu[:-1], lo[k, u]), 0, None)
            wv = np.clip(np.minimum(ev[1:], hi[k, v]) - np.maximum(ev[:-1], lo[k, v]), 0, None)
            iu, iv = np.flatnonzero(wu), np.flatnonzero(wv)
            area = np.outer(wu[iu], wv[iv])
            g = self.ground[np.ix_(iu, iv)]
            if self.up_sign > 0:
                tall = np.clip(hi[k, a] - np.maximum(g, lo[k, a]), 0, None)
            else:
                tall = np.clip(np.minimum(g, hi[k, a]) - lo[k, a], 0, None)
            covered = area.sum()
            # the part of the box outside the ground grid has no ground
            outside = size[k, u] * size[k, v] - covered
            out[k] = ((area * tall).sum() + max(outside, 0.0) * size[k, a]) / whole[k]
        return out

    def describe(self) -> dict:
        """The view space as a JSON-ready dict."""
        d: dict = {"kind": self.kind, "lo": self.lo.tolist(), "hi": self.hi.tolist()}
        if self.ground is not None:
            d["ground"] = {
                "up_axis": "xyz"[self.up_axis],
                "up_sign": self.up_sign,
                "columns": list(self.ground.shape),
                "share_of_box": float(self.volume_share(self.lo[None], self.hi[None])[0]),
            }
        return d

    def arrays(self) -> dict[str, np.ndarray]:
        """The view space as named arrays (for the PVS file)."""
        out = {
            "vs_lo": self.lo,
            "vs_hi": self.hi,
            "vs_up": np.array([self.up_axis, self.up_sign]),
            "vs_kind": np.array(self.kind),
        }
        if self.ground is not None:
            assert self.g_lo is not None and self.g_step is not None
            out.update(vs_ground=self.ground, vs_g_lo=self.g_lo, vs_g_step=self.g_step)
        return out

    @classmethod
    def from_arrays(cls, data) -> ViewSpace:
        """The view space that :meth:`arrays` wrote."""
        up = np.asarray(data["vs_up"], np.float64)
        has = "vs_ground" in data
        return cls(
            lo=data["vs_lo"],
            hi=data["vs_hi"],
            up_axis=int(up[0]),
            up_sign=float(up[1]),
            ground=np.asarray(data["vs_ground"], np.float64) if has else None,
            g_lo=np.asarray(data["vs_g_lo"], np.float64) if has else None,
            g_step=np.asarray(data["vs_g_step"], np.float64) if has else None,
            kind=str(data["vs_kind"]),
        )


def default_view_space(
    model, view_space: str | ViewSpace | None = "auto", *, up=None, caster=None
) -> ViewSpace:
    """The view space of a model: the bounding box above its ground, the box, or a given box.

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model.
    view_space : str, ViewSpace or None
        ``"auto"`` (or None): the bounding box, above the ground when the scene stands on
        one; ``"box"``: the bounding box; ``"box:x0,y0,z0,x1,y1,z1"``: that box.  A
        ViewSpace is returned as it is.
    up : None, "x", "y", "z" or (3,) float
        The up direction (None: the model's own, ``Soup.up``); the ground's columns stand
        on the coordinate axis nearest to it.
    caster : RayCaster, optional
        A caster of the model to reuse for the ground rays.

    Returns
    -------
    ViewSpace

    Raises
    ------
    ParameterError
        Another text, a box of zero size, or a model with a flat bounding box (no volume to stand in).
    """
    if isinstance(view_space, ViewSpace):
        return view_space
    given = check_view_space(view_space)
    soup = as_soup(model)
    u = up_vector(up, soup)
    axis = int(np.argmax(np.abs(u)))
    sign = 1.0 if u[axis] > 0 else -1.0
    if isinstance(given, ViewSpace):
        return ViewSpace(given.lo, given.hi, axis, sign, kind="region")
    text = given
    lo, hi = soup.bounds
    if soup.n_faces == 0 or not (hi > lo).all():
        raise ParameterError(
            "the model's bounding box has no volume to stand in; give the view space as box:x0,y0,z0,x1,y1,z1"
        )
    if text == "box":
        return ViewSpace(lo, hi, axis, sign, kind="box")
    ground, g_lo, g_step = _ground(soup, lo, hi, axis, sign, caster)
    if ground is None:
        return ViewSpace(lo, hi, axis, sign, kind="auto")
    return ViewSpace(lo, hi, axis, sign, ground, g_lo, g_step, kind="auto")


def check_view_space(view_space: str | None) -> str | ViewSpace:
    """``"auto"`` or ``"box"`` (lower case), or the box a ``box:x0,y0,z0,x1,y1,z1`` text gives.

    Raises
    ------
    ParameterError
        Any other text, or a box of zero size.
    """
    text = "auto" if view_space is None else str(view_space).strip()
    if text.lower().startswith("box:"):
        from meshvis.visibility.regions import Box, parse_region

        region = parse_region(text)
        assert isinstance(region, Box)
        return ViewSpace(region.lo, region.hi, kind="region")
    if text.lower() not in ("auto", "box"):
        raise ParameterError(
            f"unknown view space {view_space!r}; use auto (the bounding box above the ground), "
            "box (the bounding box) or box:x0,y0,z0,x1,y1,z1"
        )
    return text.lower()


def _ground(soup, lo, hi, axis: int, sign: float, caster):
    """The ground height field of a scene standing on one, else ``(None, None, None)``."""
    from meshvis.rays.caster import RayCaster

    caster = caster or RayCaster(soup)
    u, v = [a for a in range(3) if a != axis]
    size = hi - lo
    n_u = max(1, int(round(GROUND_COLUMNS * size[u] / max(size[u], size[v]))))
    n_v = max(1, int(round(GROUND_COLUMNS * size[v] / max(size[u], size[v]))))
    step = np.array([size[u] / n_u, size[v] / n_v])
    k = GROUND_RAYS_SIDE
    # k x k rays per column on a square pattern, from below the box straight up
    sub = (np.arange(k) + 0.5) / k
    cu, cv = np.meshgrid(np.arange(n_u), np.arange(n_v), indexing="ij")
    su, sv = np.meshgrid(sub, sub, indexing="ij")
    pu = lo[u] + (cu[:, :, None, None] + su) * step[0]
    pv = lo[v] + (cv[:, :, None, None] + sv) * step[1]
    n = pu.size
    origins = np.empty((n, 3))
    origins[:, u] = pu.ravel()
    origins[:, v] = pv.ravel()
    below = lo[axis] - 0.01 * size[axis] if sign > 0 else hi[axis] + 0.01 * size[axis]
    origins[:, axis] = below
    direction = np.zeros((n, 3))
    direction[:, axis] = sign
    hits = caster.intersect(origins, direction)
    # the ray travels up; it meets an upward-facing surface's back (side 1)
    floor_hit = hits.side == 1
    met = hits.hit.reshape(n_u, n_v, k * k)
    floor = floor_hit.reshape(n_u, n_v, k * k)
    height = (below + sign * hits.distance).reshape(n_u, n_v, k * k)
    if not met.any() or floor[met].mean() < GROUND_SHARE:
        return None, None, None
    bottom = lo[axis] if sign > 0 else hi[axis]
    # a column is as low as its lowest ray; a ray that meets nothing or a downward face does not lift it
    per_ray = np.where(floor, height, bottom)
    ground = per_ray.min(axis=2) if sign > 0 else per_ray.max(axis=2)
    ground = np.clip(ground, lo[axis], hi[axis])
    return ground, np.array([lo[u], lo[v]]), step
