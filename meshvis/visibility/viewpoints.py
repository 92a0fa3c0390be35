"""Viewpoints with their fields of view: what conservative from-point visibility looks from.

A viewpoint is a position and the directions it looks in, given as *roots*: pyramids with
their apex at the position whose rays are ``axis + u * right + w * up`` for ``u, w`` in
``[-1, 1]``.  A viewer that looks everywhere has the six roots of a cube map (together
they cover every direction); a camera has one, its view.

``points:x,y,z;...`` gives viewpoints that look everywhere.  ``path:CAMERAS.json`` gives one
viewpoint per camera: a JSON list of ``[x, y, z]`` positions (they look everywhere) or of
camera objects (``position``; with a ``target``, the camera looks only into its view:
vertical field of view ``fov`` in degrees, default :data:`DEFAULT_FOV`, width over
height ``aspect``, default 1, ``up`` default +y), or ``{"cameras": [...]}`` /
``{"positions": [...]}``.

>>> views = parse_viewpoints("points:0,0,0;1,2,3")
>>> len(views), views[0].roots.shape
(2, (6, 3, 3))
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass

import numpy as np

from meshvis.errors import ParameterError
from meshvis.visibility.regions import Points, Region

#: vertical field of view of a camera object without ``fov``, in degrees (as
#: :class:`meshvis.rays.camera.Camera`)
DEFAULT_FOV = 35.0
#: a camera's field of view must stay below this many degrees in either direction (a wider
#: pyramid is not convex; give no target to look everywhere)
MAX_FOV = 170.0


@dataclass(frozen=True)
class Viewpoint:
    """A position and the pyramids of directions it looks in.

    Attributes
    ----------
    position : (3,) float64
        Where the viewer stands.
    roots : (r, 3, 3) float64
        ``axis``, ``right``, ``up`` of each root (see the module notes); ``axis`` is a unit
        vector orthogonal to ``right`` and ``up``.
    """

    position: np.ndarray
    roots: np.ndarray

    @property
    def everywhere(self) -> bool:
        """The viewpoint looks in every direction (the six cube-map roots)."""
        return len(self.roots) == 6


def cube_roots() -> np.ndarray:
    """(6, 3, 3): the roots of a cube map, one per face (``+x, -x, +y, -y, +z, -z``).

    Examples
    --------
    >>> r = cube_roots()
    >>> (r[:, 0] + 0.0).tolist()[:2], float(np.abs(np.einsum("ij,ij->i", r[:, 0], r[:, 1])).max())
    ([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]], 0.0)
    """
    e = np.eye(3)
    roots = []
    for i in range(3):
        for sign in (1.0, -1.0):
            roots.append([sign * e[i], e[(i + 1) % 3], e[(i + 2) % 3]])
    return np.array(roots, np.float64)


def camera_root(
    position, target, up=(0.0, 1.0, 0.0), fov: float = DEFAULT_FOV, aspect: float = 1.0
) -> np.ndarray:
    """(1, 3, 3): the root of a pinhole camera's view.

    Parameters
    ----------
    position, target : (3,) float
        Where the camera is and the point it looks at.
    up : (3,) float
        Approximate up direction.
    fov : float
        Vertical field of view in degrees.
    aspect : float
        Width over height of the view.

    Raises
    ------
    ParameterError
        The target is the position, the view is wider than :data:`MAX_FOV`, or a value is
        not finite.

    Examples
    --------
    >>> (camera_root((0, 0, 0), (0, 0, -1), fov=90)[0].round(6) + 0.0).tolist()
    [[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    """
    p, t, u = (np.asarray(x, np.float64).reshape(3) for x in (position, target, up))
    fov, aspect = float(fov), float(aspect)
    if not (np.isfinite(p).all() and np.isfinite(t).all() and np.isfinite(u).all()):
        raise ParameterError("camera position, target and up must be finite")
    if not (np.isfinite(aspect) and aspect > 0):
        raise ParameterError(f"camera aspect must be a positive number, got {aspect}")
    half_h = np.tan(np.radians(fov) / 2) if 0 < fov < 180 else np.inf
    half_w = half_h * aspect
    widest = 2 * np.degrees(np.arctan(max(half_h, half_w)))
    if not widest < MAX_FOV:
        raise ParameterError(
            f"camera view of {widest:.1f} degrees is too wide (at most {MAX_FOV:g}; leave out the target to look everywhere)"
        )
    forward = t - p
    if not np.linalg.norm(forward) > 0:
        raise ParameterError("camera target must differ from its position")
    forward /= np.linalg.norm(forward)
    if abs(np.dot(forward, u)) > 0.999 * np.linalg.norm(u) or not np.linalg.norm(u) > 0:
        u = np.array([0.0, 1.0, 0.0]) if abs(forward[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    right = np.cross(forward, u)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    return np.array([[forward, right * half_w, true_up * half_h]], np.float64)


def parse_viewpoints(region: str | Region) -> list[Viewpoint]:
    """The viewpoints of a region text (``points:...`` or ``path:CAMERAS.json``) or of a Points region.

    Parameters
    ----------
    region : str or Region
        ``points:x,y,z;...`` or ``path:FILE.json`` (see the module notes), or a
        :class:`~meshvis.visibility.regions.Points` region (its positions look everywhere).

    Returns
    -------
    list of Viewpoint

    Raises
    ------
    ParameterError
        Any other region (viewers in a box or outside are not points), a bad file or camera.

    Examples
    --------
    >>> parse_viewpoints("points:1,2,3")[0].position.tolist()
    [1.0, 2.0, 3.0]
    """
    if isinstance(region, Points):
        return [Viewpoint(p.copy(), cube_roots()) for p in region.points]
    if isinstance(region, str):
        kind, _, rest = region.strip().partition(":")
        if kind.lower() == "path":
            return _cameras(rest)
        if kind.lower() == "points":
            from meshvis.visibility.regions import parse_region

            parsed = parse_region(region)
            assert isinstance(parsed, Points)
            return parse_viewpoints(parsed)
    what = region.kind if isinstance(region, Region) else repr(region)
    raise ParameterError(
        f"conservative visibility looks from points: use points:x,y,z;... or path:CAMERAS.json, not {what}"
    )


def _cameras(path: str) -> list[Viewpoint]:
    if not path or not os.path.isfile(path):
        raise ParameterError(f"{path or '(no file)'}: camera path file not found")
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError) as exc:
        raise ParameterError(f"{path}: not a JSON camera path ({exc})") from None
    if isinstance(data, dict):
        data = data.get("cameras", data.get("positions", []))
    if not isinstance(data, list) or not data:
        raise ParameterError(f"{path}: expected a list of positions or cameras")
    out = []
    for i, item in enumerate(data):
        try:
            out.append(_camera(item))
        except (KeyError, TypeError, ValueError) as exc:
            raise ParameterError(f"{path}: camera {i}: {exc}") from None
    return out


def _camera(item) -> Viewpoint:
    if not isinstance(item, dict):
        position = np.asarray(item, np.float64).reshape(3)
        item = {}
    else:
        position = np.asarray(item["position"], np.float64).reshape(3)
    if not np.isfinite(position).all():
        raise ValueError("the position must be finite")
    if item.get("orthographic"):
        raise ValueError("an orthographic camera has no viewpoint")
    if item.get("target") is None:
        return Viewpoint(position, cube_roots())
    root = camera_root(
        position,
        item["target"],
        item.get("up", (0.0, 1.0, 0.0)),
        float(item.get("fov", DEFAULT_FOV)),
        float(item.get("aspect", 1.0)),
    )
    return Viewpoint(position, root)
