"""Shaded preview images made with primary rays through the shared ray backend.

No GPU and no display: one ray per pixel through :class:`~meshvis.rays.caster.RayCaster`,
Lambert shading with a head light.  Front sides and back sides get clearly different
colours (blue and orange), so a face that points the wrong way shows at a glance.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis import _validate
from meshvis.io import as_soup
from meshvis.rays.camera import Camera
from meshvis.rays.caster import RayCaster

FRONT = np.array([96, 140, 220], np.float64)
BACK = np.array([235, 120, 60], np.float64)
BACKGROUND = np.array([255, 255, 255], np.uint8)


def palette(n: int) -> np.ndarray:
    """``n`` distinct, deterministic RGB colours (float 0..255), golden-angle hues."""
    import colorsys

    hues = (np.arange(n) * 0.61803398875) % 1.0
    return np.array([colorsys.hsv_to_rgb(h, 0.55, 0.92) for h in hues]).reshape(-1, 3) * 255


@dataclass
class Rendering:
    """A rendered view: the image and the per-pixel buffers it came from.

    Attributes
    ----------
    image : (h, w, 3) uint8 array
        The picture.
    face : (h, w) int64 array
        Face index per pixel, -1 for background.
    part : (h, w) int64 array
        Part id per pixel, -1 for background.
    side : (h, w) int8 array
        Side seen (0 front, 1 back, -1 background).
    depth : (h, w) float64 array
        Distance along the ray, inf for background.
    camera : Camera
        The view the image was taken from.
    """

    image: np.ndarray
    face: np.ndarray
    part: np.ndarray
    side: np.ndarray
    depth: np.ndarray
    camera: Camera


def shade(normals: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Head-light Lambert factor in [0.3, 1] for unit normals seen along unit directions."""
    return 0.3 + 0.7 * np.abs(np.einsum("ij,ij->i", normals, directions))


def render(
    model: Any,
    camera: Camera | None = None,
    *,
    size: tuple[int, int] = (512, 512),
    color_by: str | None = "side",
    face_values: np.ndarray | None = None,
    caster: RayCaster | None = None,
    azimuth: float = 30.0,
    elevation: float = 20.0,
    up: Any = None,
) -> Rendering:
    """Render a model to an image with one primary ray per pixel.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (vertices, faces) or path
        The model.
    camera : Camera, optional
        The view; fitted to the model from ``azimuth`` and ``elevation`` when omitted.
    size : tuple of 2 int
        ``(width, height)`` in pixels.
    color_by : {"side", "part", "layer"} or None
        Front blue and back orange, a colour per part, a colour per ``face_values``, or grey.
    face_values : (m,) int array
        Per-face values coloured by ``color_by="layer"`` (e.g. layer index).
    caster : RayCaster, optional
        A prebuilt caster of the same model to reuse.
    azimuth : float
        Degrees around the up axis of the fitted camera.
    elevation : float
        Degrees above the horizon of the fitted camera.
    up : (3,) float, optional
        The model's up axis for the fitted camera (default: the rule of
        :func:`meshvis.rays.camera.model_up`, y for glTF and OBJ files, z otherwise).

    Returns
    -------
    Rendering
        The image and its per-pixel buffers.

    Examples
    --------
    >>> import trimesh
    >>> r = render(trimesh.creation.box(), size=(32, 24))
    >>> r.image.shape
    (24, 32, 3)
    """
    width, height = _validate.render_args(size, color_by, face_values, azimuth, elevation)
    _validate.instance("camera", camera, Camera, optional=True)
    _validate.instance("caster", caster, RayCaster, optional=True)
    soup = as_soup(model)
    caster = caster or RayCaster(soup)
    camera = camera or Camera.fit(soup, azimuth=azimuth, elevation=elevation, up=up)
    origins, directions = camera.rays(width, height)
    hits = caster.intersect(origins, directions)
    hit = hits.hit
    face = hits.face
    light = np.ones(len(face))
    light[hit] = shade(soup.normals[face[hit]], directions[hit])

    if color_by == "side":
        base = np.where((hits.side[hit] == 0)[:, None], FRONT, BACK)
    elif color_by == "part":
        base = palette(soup.n_parts)[soup.part_id[face[hit]]]
    elif color_by == "layer":
        if face_values is None:
            raise ValueError("color_by='layer' needs face_values")
        vals = _validate.per_face("face_values", face_values, soup.n_faces, "iu")[face[hit]]
        base = palette(int(vals.max()) + 2)[np.maximum(vals, 0)]
    elif color_by is None:
        base = np.full((int(hit.sum()), 3), 200.0)
    else:
        raise ValueError(f"unknown color_by {color_by!r}")

    image = np.empty((len(face), 3), np.uint8)
    image[:] = BACKGROUND
    image[hit] = np.clip(base * light[hit, None], 0, 255).astype(np.uint8)
    shape = (height, width)
    return Rendering(
        image=image.reshape(height, width, 3),
        face=face.reshape(shape),
        part=caster.part_of(face).reshape(shape),
        side=hits.side.reshape(shape),
        depth=hits.distance.reshape(shape),
        camera=camera,
    )


def save_png(image: np.ndarray, path: str) -> None:
    """Write an RGB(A) uint8 image as PNG, atomically."""
    from PIL import Image

    from meshvis.io import atomic_write

    with atomic_write(path, "wb") as fh:
        Image.fromarray(np.asarray(image, np.uint8)).save(fh, format="PNG")


#: picture file extension -> Pillow format name
IMAGE_FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG"}
#: quality of JPEG pictures (Pillow's scale, 1..95)
JPEG_QUALITY = 92


def check_image_format(path: str) -> str:
    """The Pillow format that ``path``'s extension names (:data:`IMAGE_FORMATS`).

    Raises
    ------
    OutputError
        Any other extension: the picture is refused before it is rendered.

    Examples
    --------
    >>> check_image_format("view.JPG")
    'JPEG'
    """
    import os

    from meshvis.errors import OutputError

    ext = os.path.splitext(str(path))[1].lower()
    if ext not in IMAGE_FORMATS:
        known = ", ".join(sorted(IMAGE_FORMATS))
        raise OutputError(f"cannot write '{ext or '(no extension)'}' pictures; known: {known}", str(path))
    return IMAGE_FORMATS[ext]


def save_image(image: np.ndarray, path: str) -> None:
    """Write an RGB(A) uint8 image in the format its extension names (PNG or JPEG), atomically.

    Raises
    ------
    OutputError
        An extension of no known picture format (:func:`check_image_format`).
    """
    from PIL import Image

    from meshvis.io import atomic_write

    fmt = check_image_format(path)
    picture = Image.fromarray(np.asarray(image, np.uint8))
    extra = {}
    if fmt == "JPEG":  # no alpha channel in JPEG
        picture, extra = picture.convert("RGB"), {"quality": JPEG_QUALITY}
    with atomic_write(path, "wb") as fh:
        picture.save(fh, format=fmt, **extra)


def render_layers(
    model: Any,
    layer: np.ndarray,
    camera: Camera | None = None,
    *,
    size: tuple[int, int] = (512, 512),
    caster: RayCaster | None = None,
    max_peel: int = 12,
    azimuth: float = 30.0,
    elevation: float = 20.0,
    up: Any = None,
) -> np.ndarray:
    """Layered transparency: outer layers translucent, the innermost layer opaque.

    Each pixel's ray is followed through up to ``max_peel`` surfaces (depth peeling by
    re-casting from just beyond each hit) and the colours are composited front to back.
    Layer ``k`` of ``K`` gets opacity ``0.15 + 0.85 (k-1)/(K-1)``: the outer shell is a
    faint veil, the deepest layer is solid.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, tuple of (vertices, faces) or path
        The model.
    layer : (m,) int array
        Layer of every face, 1 = outer (:attr:`meshvis.repair.layers.LayerResult.layer`).
    camera : Camera, optional
        The view; fitted to the model from ``azimuth`` and ``elevation`` when omitted.
    size : tuple of 2 int
        ``(width, height)`` in pixels.
    caster : RayCaster, optional
        A prebuilt caster of the same model to reuse.
    max_peel : int
        Most surfaces followed per pixel.
    azimuth : float
        Degrees around the up axis of the fitted camera.
    elevation : float
        Degrees above the horizon of the fitted camera.

    Returns
    -------
    (h, w, 3) uint8 array
        The picture.
    """
    soup = as_soup(model)
    layer = np.asarray(layer, np.int64)
    caster = caster or RayCaster(soup)
    camera = camera or Camera.fit(soup, azimuth=azimuth, elevation=elevation, up=up)
    width, height = int(size[0]), int(size[1])
    origins, directions = camera.rays(width, height)
    n_layers = max(int(layer.max()), 1)
    colours = palette(n_layers + 1)
    alpha_of = 0.15 + 0.85 * (np.arange(n_layers + 1) - 1) / max(n_layers - 1, 1)
    alpha_of[n_layers] = 1.0
    colour = np.zeros((len(origins), 3))
    transmit = np.ones(len(origins))
    live = np.arange(len(origins))
    o = origins.copy()
    step = caster.offset * caster.diagonal
    for _ in range(max_peel):
        if len(live) == 0:
            break
        h = caster.intersect(o[live], directions[live])
        hit = h.face >= 0
        live, f = live[hit], h.face[hit]
        if len(live) == 0:
            break
        lay = np.clip(layer[f], 1, n_layers)
        a = alpha_of[lay]
        lit = shade(soup.normals[f], directions[live])
        colour[live] += (transmit[live] * a)[:, None] * colours[lay] * lit[:, None]
        transmit[live] *= 1 - a
        o[live] = o[live] + directions[live] * (h.distance[hit] + 2 * step)[:, None]
        live = live[transmit[live] > 0.02]
    image = colour + transmit[:, None] * BACKGROUND.astype(np.float64)
    return np.clip(image, 0, 255).astype(np.uint8).reshape(height, width, 3)
