"""Where viewers may stand: the regions of from-region visibility (DESIGN.md §9).

A region answers three questions for the samplers of :mod:`meshvis.visibility.sampling`:

* ``seed_viewers(points, rng)`` -- for random points on faces, one random viewer each: a
  viewer is a ray ``(origin, direction)`` that starts in the region and points at the
  point on the face;
* ``border_origins(origin, direction, targets)`` -- the rays from the *same* viewer towards
  other target points (adaptive border sampling keeps the viewer fixed, GVS §3.2);
* ``origin_on_line(through, direction)`` -- a viewer in the region on the line that passes
  ``through`` a point along ``direction`` (reverse sampling moves the viewer, GVS §3.3),
  or ``ok = False`` where the line misses the region.
* ``view_lines(n, rng)`` -- random lines of sight from the region (GVS §3.1): a random
  viewer and a random direction, like a random pixel of a random view.

Two kinds of region: viewers at infinity (``outside``, ``upper-hemisphere``; the ray starts
beyond the bounding sphere, so its first hit is what a viewer far away along the line sees)
and viewers at finite points (a box, points, a camera path).  Every ray traced from a viewer
certifies its first hit as visible from the region.

>>> region = parse_region("box:0,0,0,1,1,1")
>>> region.kind, region.at_infinity
('box', False)
>>> parse_region("upper-hemisphere", up=(0, 0, 1)).up.tolist()
[0.0, 0.0, 1.0]
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from meshvis.errors import ParameterError
from meshvis.io import one_line
from meshvis.io.jsonfile import read_json
from meshvis.io.up_axis import up_vector
from meshvis.rays.samples import uniform_sphere
from meshvis.visibility import _kernels

#: viewers at infinity start this many bounding-sphere radii beyond the sphere (any positive
#: margin works; a small one keeps float32 round-off of the Embree scene small)
FAR_MARGIN = 0.05


@dataclass
class Region:
    """Base class: a set of viewer positions.

    Attributes
    ----------
    kind : str
        The region's name as :func:`parse_region` spells it.
    at_infinity : bool
        Viewers far away (rays with a fixed direction) or at finite points.
    """

    kind: str = "outside"
    at_infinity: bool = True

    # the bounding sphere of the model, set by :meth:`bind` before sampling
    center: np.ndarray = field(default_factory=lambda: np.zeros(3), repr=False)
    radius: float = field(default=1.0, repr=False)
    half: np.ndarray = field(default_factory=lambda: np.ones(3), repr=False)  # half the box's sides

    def bind(self, soup) -> Region:
        """Fix the model's bounding box and sphere (viewers at infinity start beyond the sphere)."""
        lo, hi = soup.bounds
        self.center = 0.5 * (lo + hi)
        self.radius = max(0.5 * float(np.linalg.norm(hi - lo)), 1e-300)
        self.half = 0.5 * (hi - lo)
        return self

    def far_origins(self, targets: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """Origins beyond the bounding sphere on the lines ``targets - s * directions``, s > 0."""
        return _kernels.far_origins(
            np.ascontiguousarray(targets, np.float64),
            np.ascontiguousarray(directions, np.float64),
            np.asarray(self.center, np.float64),
            (1 + FAR_MARGIN) * self.radius,
        )

    # --------------------------------------------------------------- interface
    def seed_viewers(
        self, points: np.ndarray, rng: np.random.Generator, plane_share: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """One random viewer per point: ``(origins, unit directions)`` of rays aimed at the points.

        ``plane_share`` of the viewers at infinity look along a coordinate plane
        (:func:`view_directions`); finite viewers are where the region puts them.
        """
        directions = -self._view_directions(len(points), rng, plane_share)
        return self.far_origins(points, directions), directions

    def _view_directions(self, n: int, rng: np.random.Generator, plane_share: float = 0.0) -> np.ndarray:
        """Unit directions from the model towards viewers at infinity."""
        return view_directions(n, rng, plane_share)

    def border_origins(self, origin: np.ndarray, direction: np.ndarray, targets: np.ndarray):
        """Rays from the viewers of ``(origin, direction)`` towards ``targets``."""
        if self.at_infinity:
            return self.far_origins(targets, direction), direction
        return origin, _kernels.aimed_from(
            np.ascontiguousarray(origin, np.float64), np.ascontiguousarray(targets, np.float64)
        )

    def origin_on_line(self, through: np.ndarray, direction: np.ndarray):
        """A viewer on each line ``through - s * direction`` (s > 0); ``(origins, ok)``."""
        ok = self._allows(direction)
        return self.far_origins(through, direction), ok

    def _allows(self, direction: np.ndarray) -> np.ndarray:
        return np.ones(len(direction), bool)

    def view_lines(
        self, n: int, rng: np.random.Generator, plane_share: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """``n`` random lines of sight ``(origins, unit directions)`` from the region (GVS §3.1).

        Viewers at infinity: a random viewing direction, and a point uniform on the
        rectangle that the bounding box projects to across it, as a random pixel of an
        orthographic view framed on the box (a flat scene seen edge-on fills a sliver of
        its bounding sphere's disk).  Finite viewers: a random viewer
        (:meth:`random_viewers`) looking in a uniformly random direction.
        """
        if not self.at_infinity:
            return self.random_viewers(n, rng), view_directions(n, rng, plane_share)
        directions = -self._view_directions(n, rng, plane_share)
        u, v = rng.random(n), rng.random(n)
        targets = _kernels.framed_targets(
            directions, u, v, np.asarray(self.center, np.float64), np.asarray(self.half, np.float64)
        )
        return self.far_origins(targets, directions), directions

    def random_viewers(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """(n, 3) random viewer positions (regions of finite viewers)."""
        raise NotImplementedError

    def contains_faces(self, triangles: np.ndarray) -> np.ndarray:
        """(m,) bool: faces inside the region, visible without rays (none for most regions)."""
        return np.zeros(len(triangles), bool)

    def describe(self) -> dict:
        """The region as a JSON-ready dict."""
        return {"kind": self.kind}


@dataclass
class Outside(Region):
    """Anywhere outside the model: a side is seen when a line from it escapes."""


@dataclass
class UpperHemisphere(Region):
    """Viewers far away above the horizon: lines leaving the model upwards (``dot(d, up) >= 0``).

    Parameters
    ----------
    up : None, "x", "y", "z" or (3,) float
        The up direction (normalised here); None: the model's own (``Soup.up``, the
        convention of its file format), taken when the region is bound to the model.
    """

    kind: str = "upper-hemisphere"
    up: np.ndarray | None = None

    def __post_init__(self) -> None:
        self._asked = None if self.up is None else up_vector(self.up)
        self.up = self._asked

    def bind(self, soup) -> Region:
        """Fix the model's bounding sphere, and its up axis when none was given."""
        super().bind(soup)
        self.up = up_vector(None, soup) if self._asked is None else self._asked
        return self

    def _view_directions(self, n, rng, plane_share=0.0):
        d = view_directions(n, rng, plane_share)
        flip = d @ self.up < 0
        d[flip] -= 2 * np.outer(d[flip] @ self.up, self.up)
        return d

    def _allows(self, direction):
        # the ray travels along ``direction`` from a viewer at -direction * infinity
        return direction @ self.up <= 0

    def describe(self):
        """The region as a JSON-ready dict."""
        return {"kind": self.kind, "up": None if self.up is None else self.up.tolist()}


@dataclass
class Box(Region):
    """Viewers anywhere in an axis-aligned box.

    Parameters
    ----------
    lo, hi : (3,) float
        The minimum and maximum corners.
    """

    kind: str = "box"
    at_infinity: bool = False
    lo: np.ndarray = field(default_factory=lambda: np.zeros(3))
    hi: np.ndarray = field(default_factory=lambda: np.ones(3))

    def __post_init__(self) -> None:
        self.lo = np.asarray(self.lo, np.float64).reshape(3)
        self.hi = np.asarray(self.hi, np.float64).reshape(3)
        if not (np.isfinite(self.lo).all() and np.isfinite(self.hi).all()) or (self.lo > self.hi).any():
            raise ParameterError(f"box region needs finite corners with min <= max, got {self.lo}, {self.hi}")

    def seed_viewers(self, points, rng, plane_share=0.0):
        """One viewer per point at a uniform random place in the box, aimed at the point."""
        return _aimed(self.random_viewers(len(points), rng), points)

    def random_viewers(self, n, rng):
        """(n, 3) uniform random places in the box."""
        return self.lo + rng.random((n, 3)) * (self.hi - self.lo)

    def origin_on_line(self, through, direction):
        """The middle of the half line's stretch inside the box; ``(origins, ok)``, ok False if it misses."""
        # slab test on the half line through - s * direction, s > 0; the viewer sits in the middle
        with np.errstate(divide="ignore", invalid="ignore"):
            a = (through - self.lo) / direction
            b = (through - self.hi) / direction
        near = np.nanmax(np.where(np.isnan(a), -np.inf, np.minimum(a, b)), axis=1)
        far = np.nanmin(np.where(np.isnan(a), np.inf, np.maximum(a, b)), axis=1)
        inside_slabs = (direction != 0) | ((through >= self.lo) & (through <= self.hi))
        near, far = np.maximum(near, 0.0), far
        ok = inside_slabs.all(axis=1) & (far >= near) & np.isfinite(far)
        s = np.where(ok, 0.5 * (near + far), 0.0)
        return through - direction * s[:, None], ok

    def contains_faces(self, triangles):
        """(m,) bool: faces with a corner, the centroid or an edge midpoint inside the box."""
        # a corner, the centroid or an edge midpoint inside the box
        probes = np.concatenate(
            [
                triangles,
                triangles.mean(axis=1, keepdims=True),
                0.5 * (triangles + np.roll(triangles, 1, axis=1)),
            ],
            axis=1,
        )
        inside = ((probes >= self.lo) & (probes <= self.hi)).all(axis=2)
        return inside.any(axis=1)

    def describe(self):
        """The region as a JSON-ready dict."""
        return {"kind": self.kind, "lo": self.lo.tolist(), "hi": self.hi.tolist()}


@dataclass
class Points(Region):
    """Viewers at a finite set of points (no reverse sampling: a point cannot move).

    Parameters
    ----------
    points : (k, 3) float
        The viewers.
    """

    kind: str = "points"
    at_infinity: bool = False
    points: np.ndarray = field(default_factory=lambda: np.zeros((1, 3)))

    def __post_init__(self) -> None:
        self.points = np.asarray(self.points, np.float64).reshape(-1, 3)
        if len(self.points) == 0 or not np.isfinite(self.points).all():
            raise ParameterError("a points region needs at least one finite point")

    def seed_viewers(self, points, rng, plane_share=0.0):
        """One viewer per point, picked at random among the region's points, aimed at the point."""
        return _aimed(self._pick(len(points), rng), points)

    def random_viewers(self, n, rng):
        """(n, 3) random points of the region (:meth:`_pick`)."""
        return self._pick(n, rng)

    def _pick(self, n, rng):
        return self.points[rng.integers(0, len(self.points), n)]

    def origin_on_line(self, through, direction):
        """The lines' own ``through`` points; ``(origins, ok)`` with ok all False."""
        return through.copy(), np.zeros(len(through), bool)

    def describe(self):
        """The region as a JSON-ready dict."""
        return {"kind": self.kind, "points": self.points.tolist()}


@dataclass
class CameraPath(Points):
    """Viewers anywhere on the polyline through camera positions (a walk-through).

    Parameters
    ----------
    points : (k, 3) float
        The positions in order; one position is a single viewpoint.
    """

    kind: str = "path"

    def _pick(self, n, rng):
        if len(self.points) == 1:
            return np.repeat(self.points, n, axis=0)
        seg = np.diff(self.points, axis=0)
        length = np.linalg.norm(seg, axis=1)
        if length.sum() == 0:
            return np.repeat(self.points[:1], n, axis=0)
        which = rng.choice(len(seg), size=n, p=length / length.sum())
        return self.points[which] + rng.random(n)[:, None] * seg[which]


def view_directions(n: int, rng: np.random.Generator, plane_share: float = 0.0) -> np.ndarray:
    """``n`` random unit directions: uniform, but ``plane_share`` of them close to a coordinate plane.

    Man-made models are built along their axes: a thin gap between parallel parts lies
    along a coordinate plane, and what is behind it shows only along directions within a
    fraction of a degree of that plane, which uniform directions almost never take (0.9 %
    of them lie within half a degree of a given plane).  A direction of the plane share
    lies in one of the three coordinate planes (chosen at random), tilted out of it by a
    normal angle of :data:`PLANE_TILT` degrees.

    Examples
    --------
    >>> d = view_directions(1000, np.random.default_rng(0), plane_share=1.0)
    >>> bool((np.abs(d).min(axis=1) < np.sin(np.radians(5 * PLANE_TILT))).all())
    True
    """
    d = uniform_sphere(n, rng)
    k = int(round(plane_share * n))
    if k == 0:
        return d
    axis = rng.integers(0, 3, k)
    tilt = np.radians(PLANE_TILT) * rng.standard_normal(k)
    _kernels.tilt_into_planes(d, axis, tilt)
    return d


#: the tilt of plane directions out of their coordinate plane: normal, this many degrees
#: (the gaps that uniform directions miss are seen within about a degree of their plane)
PLANE_TILT = 0.5


def _aimed(origins: np.ndarray, targets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = targets - origins
    norm = np.linalg.norm(d, axis=1, keepdims=True)
    return origins, d / np.where(norm > 0, norm, 1.0)


#: region names accepted by :func:`parse_region`
REGION_KINDS = ("outside", "upper-hemisphere", "box", "points", "path")


def parse_region(text: str | Region, *, up=None) -> Region:
    """A region from its text form (the ``--from`` option of the command line).

    Parameters
    ----------
    text : str or Region
        ``outside``; ``upper-hemisphere`` (uses ``up``) or ``upper-hemisphere:ux,uy,uz``;
        ``box:x0,y0,z0,x1,y1,z1``; ``points:x,y,z;x,y,z;...``; ``path:FILE.json`` (a JSON
        list of ``[x, y, z]`` positions, or ``{"positions": [...]}``, or a list of camera
        objects with a ``position`` key).  A Region is returned as it is.
    up : None, "x", "y", "z" or (3,) float
        Up direction of ``upper-hemisphere`` when the text gives none; None: the model's
        own (``Soup.up``), fixed when the region is bound to the model.

    Returns
    -------
    Region

    Raises
    ------
    ParameterError
        Unknown kind, wrong number of coordinates, a bad ``up``, an unreadable path file.

    Examples
    --------
    >>> parse_region("points:0,0,5;1,2,3").points.shape
    (2, 3)
    """
    if isinstance(text, Region):
        return text
    kind, _, rest = str(text).strip().partition(":")
    kind = kind.lower()
    if kind == "outside" and not rest:
        return Outside()
    if kind == "upper-hemisphere":
        return UpperHemisphere(up=_numbers(rest, 3, text) if rest else up)
    if kind == "box":
        v = _numbers(rest, 6, text)
        return Box(lo=v[:3], hi=v[3:])
    if kind == "points":
        pts = [_numbers(p, 3, text) for p in rest.split(";") if p.strip()]
        return Points(points=np.array(pts).reshape(-1, 3))
    if kind == "path":
        return CameraPath(points=_path_positions(rest))
    raise ParameterError(
        f"unknown region {text!r}; use outside, upper-hemisphere[:ux,uy,uz], box:x0,y0,z0,x1,y1,z1, "
        "points:x,y,z;..., path:FILE.json"
    )


def _numbers(text: str, n: int, whole) -> np.ndarray:
    try:
        v = np.array([float(t) for t in text.split(",")], np.float64)
    except ValueError:
        v = np.zeros(0)
    if len(v) != n:
        raise ParameterError(f"region {whole!r}: expected {n} comma-separated numbers, got {text!r}")
    return v


def _path_positions(path: str) -> np.ndarray:
    if not path or not os.path.isfile(path):
        raise ParameterError(f"{path or '(no file)'}: camera path file not found")
    try:
        data = read_json(path)
    except (OSError, ValueError) as exc:
        raise ParameterError(f"{path}: not a JSON camera path ({one_line(exc)})") from None
    if isinstance(data, dict):
        data = data.get("positions", data.get("cameras", []))
    try:
        pos = [d["position"] if isinstance(d, dict) else d for d in data]
        arr = np.array(pos, np.float64).reshape(-1, 3)
    except (KeyError, TypeError, ValueError):
        raise ParameterError(f"{path}: expected a list of [x, y, z] positions") from None
    if len(arr) == 0:
        raise ParameterError(f"{path}: the camera path has no positions")
    if not np.isfinite(arr).all():
        raise ParameterError(f"{path}: a camera position is not finite")
    return arr
