"""The object-ID buffer: which part every pixel sees (appendix I, §6.1 step 1).

One primary ray per pixel is traced through the shared :class:`meshvis.rays.caster.RayCaster`
(via :func:`meshvis.rays.render.render`, which also gives the shaded picture the labels are drawn
on).  The part id of the first hit is the pixel's object id; the visible area ``A_i`` of
part *i* is its pixel count.  Parts with no pixel (or fewer than ``min_pixels``) are
invisible: they are reported and not labelled.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.errors import ParameterError
from meshvis.rays.camera import Camera
from meshvis.rays.caster import RayCaster
from meshvis.soup import Soup


@dataclass
class IdBuffer:
    """Per-pixel object ids of one view and what the layout needs to know about the view.

    Attributes
    ----------
    ids : (h, w) int64
        Part id seen by each pixel, -1 for background
    face : (h, w) int64
        Face index seen by each pixel, -1 for background
    depth : (h, w) float64
        Distance along the primary ray (inf for background)
    image : (h, w, 3) uint8
        The shaded picture
    camera : Camera
        The view.
    areas : (n_parts,) int64
        Visible pixel count ``A_i`` of each part
    part_names : list of str
        The name of every part.
    sphere_center : (2,) float
        The projected centre of the model's bounding sphere (pixels)
    sphere_diameter : float
        ``d_S``: the projected diameter of the bounding sphere (pixels).
    """

    ids: np.ndarray
    face: np.ndarray
    depth: np.ndarray
    image: np.ndarray
    camera: Camera
    areas: np.ndarray
    part_names: list[str]
    sphere_center: np.ndarray
    sphere_diameter: float

    @property
    def shape(self) -> tuple[int, int]:
        """(height, width) in pixels."""
        return self.ids.shape  # type: ignore[return-value]

    @property
    def model_mask(self) -> np.ndarray:
        """(h, w) bool, pixels that see the model."""
        return self.ids >= 0

    def visible(self, min_pixels: int = 1) -> np.ndarray:
        """Ids of the parts with at least ``min_pixels`` visible pixels, ascending."""
        return np.flatnonzero(self.areas >= max(1, int(min_pixels)))

    def invisible(self, min_pixels: int = 1) -> np.ndarray:
        """Ids of the parts with fewer than ``min_pixels`` visible pixels, ascending."""
        return np.flatnonzero(self.areas < max(1, int(min_pixels)))

    def surface_points(self, xy: np.ndarray) -> np.ndarray:
        """3D points seen at pixel positions ``xy`` (n, 2) (NaN where the pixel is background)."""
        xy = np.asarray(xy, np.float64).reshape(-1, 2)
        h, w = self.shape
        col = np.clip(np.floor(xy[:, 0]).astype(np.int64), 0, w - 1)
        row = np.clip(np.floor(xy[:, 1]).astype(np.int64), 0, h - 1)
        origins, dirs = pixel_rays(self.camera, col, row, w, h)
        depth = self.depth[row, col]
        out = origins + dirs * np.where(np.isfinite(depth), depth, np.nan)[:, None]
        return out


def pixel_rays(
    camera: Camera, col: np.ndarray, row: np.ndarray, width: int, height: int
) -> tuple[np.ndarray, np.ndarray]:
    """The primary rays of a few pixels (one per anchor): :meth:`Camera.pixel_rays`."""
    return camera.pixel_rays(col, row, width, height)


def projected_sphere(soup: Soup, camera: Camera, width: int, height: int) -> tuple[np.ndarray, float]:
    """Centre (pixels) and diameter ``d_S`` (pixels) of the projected bounding sphere.

    The sphere is the one around the bounding box (centre = box centre, radius = half the
    diagonal).  Its projected diameter is measured across the view, through the centre,
    which is exact for an orthographic camera and for a perspective camera looking at it.
    """
    lo, hi = soup.bounds
    center = 0.5 * (lo + hi)
    radius = 0.5 * soup.diagonal or 1.0
    right, _, _ = camera.basis()
    pts = np.stack([center, center - radius * right, center + radius * right])
    xy, depth = camera.project(pts, width, height)
    if not np.all(np.isfinite(xy)) or depth[0] <= 0:
        # the camera sits inside the sphere or behind it: fall back to the image size
        return np.array([width / 2.0, height / 2.0]), float(min(width, height))
    return xy[0], float(np.linalg.norm(xy[2] - xy[1]))


def id_buffer(
    soup: Soup,
    camera: Camera,
    size: tuple[int, int] = (512, 512),
    *,
    caster: RayCaster | None = None,
    color_by: str | None = "part",
) -> IdBuffer:
    """Trace one primary ray per pixel and return the object-ID buffer of the view.

    Parameters
    ----------
    soup : Soup
        The model; its ``part_id`` gives the object ids
    camera : Camera
        The view.
    size : (2,) int
        ``(width, height)`` in pixels.
    caster : RayCaster, optional
        A ray caster of the model, reused between frames.
    color_by : str or None
        Colouring of the shaded picture (see :func:`meshvis.rays.render.render`).

    Returns
    -------
    IdBuffer
    """
    from meshvis.rays.render import render

    width, height = (int(s) for s in size)
    if width < 8 or height < 8:
        raise ParameterError(f"image size must be at least 8 x 8 pixels, got {width} x {height}")
    rendering = render(soup, camera, size=(width, height), color_by=color_by, caster=caster)
    ids = rendering.part
    areas = np.bincount(ids[ids >= 0].ravel(), minlength=soup.n_parts).astype(np.int64)
    center, diameter = projected_sphere(soup, camera, width, height)
    return IdBuffer(
        ids=ids,
        face=rendering.face,
        depth=rendering.depth,
        image=rendering.image,
        camera=camera,
        areas=areas,
        part_names=list(soup.part_names),
        sphere_center=center,
        sphere_diameter=max(diameter, 1.0),
    )
