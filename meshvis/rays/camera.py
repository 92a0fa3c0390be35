"""A pinhole (or orthographic) camera: primary rays and projection of points to pixels.

Pixel convention: x grows to the right, y grows downwards, pixel (0, 0) is the top-left
pixel and its centre is at (0.5, 0.5).  The vertical field of view ``fov`` is in degrees.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from meshvis import _validate
from meshvis.errors import ParameterError
from meshvis.io.up_axis import AXES, FALLBACK_UP, FORMAT_UP, format_up, up_vector  # noqa: F401


def up_axis(name: str, paths: list[str] | tuple[str, ...] = ()) -> tuple[float, float, float]:
    """The up vector for an axis name, or for ``"auto"`` the up axis of the files' format.

    ``"auto"`` looks the files' extensions up in :data:`~meshvis.io.up_axis.FORMAT_UP`;
    files of formats that disagree, or no file, give z.

    Examples
    --------
    >>> up_axis("auto", ["truck.glb"]), up_axis("auto", ["part.stl"]), up_axis("x")
    ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
    """
    if name != "auto":
        return tuple(up_vector(name).tolist())
    found = {format_up(p) for p in paths if p}
    return found.pop() if len(found) == 1 else AXES[FALLBACK_UP]


def model_up(model: Any) -> tuple[float, float, float]:
    """The up vector of a model: ``Soup.up``, or the format's of a file (z for anything else)."""
    if isinstance(model, (list, tuple)) and model and all(isinstance(m, (str, os.PathLike)) for m in model):
        return up_axis("auto", [os.fspath(m) for m in model])
    return tuple(up_vector(None, model).tolist())


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v)
    if n == 0:
        raise ParameterError("camera vectors must not be zero")
    return v / n


@dataclass
class Camera:
    """A camera looking from ``position`` at ``target``.

    Parameters
    ----------
    position : (3,) float array
        Where the camera is.
    target : (3,) float array
        The point it looks at.
    up : (3,) float array
        Approximate up direction (default +y, as in glTF and most OBJ files).
    fov : float
        Vertical field of view in degrees (perspective).
    orthographic : bool
        Parallel projection instead of perspective.
    ortho_height : float
        Height of the view in model units (orthographic).

    Examples
    --------
    >>> cam = Camera((0, -5, 0), (0, 0, 0))
    >>> o, d = cam.rays(4, 4)
    >>> o.shape, d.shape
    ((16, 3), (16, 3))
    """

    position: Any
    target: Any
    up: Any = field(default=(0.0, 1.0, 0.0))
    fov: float = 35.0
    orthographic: bool = False
    ortho_height: float | None = None

    def __post_init__(self) -> None:
        for name in ("position", "target", "up"):
            v = _validate.points(f"camera {name}", getattr(self, name))
            if len(v) != 1:
                raise ParameterError(f"camera {name} must be three numbers, got {len(v)} points")
            setattr(self, name, v[0])
        if not np.any(self.up):
            raise ParameterError("camera up must not be zero")
        self.fov = _field_of_view(self.fov)
        self.orthographic = _validate.flag("orthographic", self.orthographic)
        if self.ortho_height is not None:
            self.ortho_height = _validate.real("ortho_height", self.ortho_height, 0.0, open_lo=True)

    # ------------------------------------------------------------------ frame
    def basis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Unit vectors (right, true up, forward)."""
        forward = _unit(self.target - self.position)
        up = self.up
        if abs(np.dot(_unit(up), forward)) > 0.999:  # looking along up: pick another up
            up = np.array([0.0, 1.0, 0.0]) if abs(forward[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
        right = _unit(np.cross(forward, up))
        true_up = np.cross(right, forward)
        return right, true_up, forward

    def _half_height(self) -> float:
        if self.orthographic:
            h = self.ortho_height or np.linalg.norm(self.target - self.position)
            return 0.5 * float(h)
        return float(np.tan(np.radians(self.fov) / 2))

    # ------------------------------------------------------------------ rays and projection
    def rays(self, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """Primary rays through every pixel centre, row-major from the top-left pixel.

        Parameters
        ----------
        width : int
            Image width in pixels.
        height : int
            Image height in pixels.

        Returns
        -------
        origins : (height*width, 3) float64 array
            Ray origins.
        directions : (height*width, 3) float64 array
            Unit ray directions.
        """
        width, height = _validate.image_size((width, height))
        row, col = np.divmod(np.arange(width * height), width)
        return self.pixel_rays(col, row, width, height)

    def pixel_rays(
        self, col: np.ndarray, row: np.ndarray, width: int, height: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Primary rays through the centres of the given pixels of a ``width`` x ``height`` image.

        Parameters
        ----------
        col : (n,) int array
            Pixel columns.
        row : (n,) int array
            Pixel rows, 0 at the top.
        width : int
            Image width in pixels.
        height : int
            Image height in pixels.

        Returns
        -------
        origins : (n, 3) float64 array
            Ray origins.
        directions : (n, 3) float64 array
            Unit ray directions.
        """
        right, up, forward = self.basis()
        hh = self._half_height()
        hw = hh * width / height
        gx = ((np.asarray(col) + 0.5) / width * 2 - 1) * hw
        gy = (1 - (np.asarray(row) + 0.5) / height * 2) * hh
        if self.orthographic:
            origins = self.position + gx[:, None] * right + gy[:, None] * up
            directions = np.broadcast_to(forward, origins.shape).copy()
        else:
            directions = forward + gx[:, None] * right + gy[:, None] * up
            directions /= np.linalg.norm(directions, axis=1, keepdims=True)
            origins = np.broadcast_to(self.position, directions.shape).copy()
        return origins, directions

    def project(self, points: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates (x right, y down) and depth along the view axis of 3D points."""
        right, up, forward = self.basis()
        rel = np.asarray(points, np.float64).reshape(-1, 3) - self.position
        x, y, z = rel @ right, rel @ up, rel @ forward
        hh = self._half_height()
        hw = hh * width / height
        if self.orthographic:
            u, v = x / hw, y / hh
        else:
            with np.errstate(divide="ignore", invalid="ignore"):
                u, v = x / (z * hw), y / (z * hh)
        px = (u + 1) / 2 * width
        py = (1 - v) / 2 * height
        return np.stack([px, py], axis=1), z

    # ------------------------------------------------------------------ construction
    @classmethod
    def fit(
        cls,
        model: Any,
        azimuth: float = 30.0,
        elevation: float = 20.0,
        distance: float | None = None,
        fov: float = 35.0,
        orthographic: bool = False,
        margin: float = 1.0,
        up: Any = None,
    ) -> Camera:
        """A camera framing the model's bounding sphere.

        ``azimuth`` turns around the up axis, ``elevation`` lifts the camera above the
        horizon; both in degrees.  ``distance`` defaults to the distance
        at which the bounding sphere (times ``margin``) fills the view.  ``up`` (an axis name
        or a vector) defaults to the model's up axis (:func:`model_up`).
        """
        azimuth, elevation = _validate.real("azimuth", azimuth), _validate.real("elevation", elevation)
        if distance is not None:
            distance = _validate.real("distance", distance, 0.0, open_lo=True)
        margin = _validate.real("margin", margin, 0.0, open_lo=True)
        fov = _field_of_view(fov)
        bounds = _bounds_of(model)
        center = bounds.mean(axis=0)
        radius = 0.5 * float(np.linalg.norm(bounds[1] - bounds[0])) or 1.0
        up = np.asarray(model_up(model)) if up is None else up_vector(up)
        # a horizontal frame orthogonal to up; azimuth 0 views the model's "front": from +z
        # for y-up models (glTF, most OBJ), from -y for z-up models (CAD, STL)
        ref = np.array([0.0, 0.0, 1.0]) if abs(up[2]) < 0.9 else np.array([0.0, -1.0, 0.0])
        e1 = _unit(ref - np.dot(ref, up) * up)
        e2 = np.cross(up, e1)
        az, el = np.radians(azimuth), np.radians(elevation)
        view = np.cos(el) * (np.cos(az) * e1 + np.sin(az) * e2) + np.sin(el) * up  # from target to camera
        if distance is None:
            distance = margin * radius / np.sin(np.radians(fov) / 2)
        position = center + view * distance
        return cls(position, center, up, fov, orthographic, 2 * margin * radius if orthographic else None)

    @classmethod
    def orbit(
        cls, model: Any, n_frames: int, elevation: float = 20.0, start: float = 30.0, **kw: Any
    ) -> list[Camera]:
        """``n_frames`` cameras turning once around the model."""
        return [
            cls.fit(model, azimuth=start + 360.0 * k / n_frames, elevation=elevation, **kw)
            for k in range(n_frames)
        ]

    def to_json(self) -> dict:
        """The camera as a dict of plain floats and bools (inverse of :meth:`from_json`)."""
        d = asdict(self)
        for k in ("position", "target", "up"):
            d[k] = [float(x) for x in getattr(self, k)]
        return d

    @classmethod
    def from_json(cls, d: dict) -> Camera:
        """The camera written by :meth:`to_json`.

        Raises
        ------
        ParameterError
            ``d`` is not an object with ``position`` and ``target``, has a key that is not
            a camera field, or a value out of its range.
        """
        if not isinstance(d, Mapping):
            raise ParameterError(
                f"a camera must be an object with position and target, got {type(d).__name__}"
            )
        known = {"position", "target", "up", "fov", "orthographic", "ortho_height"}
        unknown = set(map(str, d)) - known
        if unknown:
            raise ParameterError(f"unknown camera keys: {', '.join(sorted(unknown))}")
        missing = {"position", "target"} - set(d)
        if missing:
            raise ParameterError(f"the camera has no {' and no '.join(sorted(missing))}")
        return cls(**d)


def _field_of_view(value: Any) -> float:
    """A vertical field of view: a number of degrees in (0, 180)."""
    fov = _validate.real("field of view", value)
    if not 0 < fov < 180:
        raise ParameterError(f"field of view must be in (0, 180) degrees, got {fov}")
    return fov


def _bounds_of(model: Any) -> np.ndarray:
    if hasattr(model, "bounds") and not callable(model.bounds):
        b = np.asarray(model.bounds, np.float64)
        if b.shape == (2, 3):
            return b
    from meshvis.io import as_soup

    return as_soup(model).bounds
