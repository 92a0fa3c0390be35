"""False pixels: how much of a deletion anyone sees (GVS §4.2-4.3; DESIGN.md §10).

The *original* model's face-ID buffer is rendered from :data:`VIEWS` viewpoints spread
evenly over the sphere (a Fibonacci sphere), orthographic, :data:`SIZE` x :data:`SIZE`
pixels, the bounding sphere filling the image.  A pixel is *false* when the face it shows
was deleted; the measure is false pixels per million model pixels (pixels that show any
face), as the mean over the views and for the worst view.  For scenes standing on the
ground the views from above the horizon (``dot(view, up) > 0``, half of them) are
reported too.

Only the pixel count of every face in every view is kept (a sparse table), and cached in an
``.npz`` keyed by the model's bytes: every method judged on one model reuses it.

>>> import trimesh, numpy as np
>>> views = face_pixels(trimesh.creation.box(), size=64)
>>> fp = false_pixels(views, np.zeros(12, bool))
>>> fp["mean"], fp["worst"]
(0.0, 0.0)
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass

import numpy as np

from meshvis.io import as_soup, atomic_write
from meshvis.rays.camera import Camera
from meshvis.rays.caster import RayCaster

#: viewpoints on the sphere (GVS renders many random views; DESIGN §10 fixes 128 even ones)
VIEWS = 128
#: image width and height in pixels
SIZE = 512
#: bump when the rendering changes, so that old caches are not reused
VERSION = 1


@dataclass(frozen=True)
class FacePixels:
    """Pixels of every face in every view of the original model.

    Attributes
    ----------
    view : (k,) int32
        Sparse table: view ``view[i]`` shows face ``face[i]`` on ``pixels[i]`` pixels.
    face : (k,) int64
        The face of each entry.
    pixels : (k,) int64
        The pixels of each entry.
    model_pixels : (VIEWS,) int64
        Pixels showing any face, per view.
    directions : (VIEWS, 3) float64
        Unit vectors from the model's centre towards each viewpoint.
    n_faces : int
    """

    view: np.ndarray
    face: np.ndarray
    pixels: np.ndarray
    model_pixels: np.ndarray
    directions: np.ndarray
    n_faces: int


def fibonacci_sphere(n: int) -> np.ndarray:
    """``n`` unit vectors spread evenly over the sphere (golden-angle spiral), deterministic."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (3 - np.sqrt(5)) * k
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def face_pixels(
    model, *, views: int = VIEWS, size: int = SIZE, cache: str | os.PathLike | None = None
) -> FacePixels:
    """Render the face-ID buffers of ``model`` and count pixels per face and view.

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
    views : int
        Viewpoints on the Fibonacci sphere.
    size : int
        Image width and height.
    cache : path, optional
        An ``.npz`` read when it holds this model's table, else written.

    Returns
    -------
    FacePixels
    """
    soup = as_soup(model)
    key = _key(soup, views, size)
    if cache is not None and os.path.isfile(cache):
        with np.load(cache) as data:
            if str(data["key"]) == key:
                return FacePixels(**{f: data[f] for f in _ARRAYS}, n_faces=soup.n_faces)
    caster = RayCaster(soup)
    lo, hi = soup.bounds
    center = 0.5 * (lo + hi)
    radius = max(0.5 * float(np.linalg.norm(hi - lo)), 1e-300)
    directions = fibonacci_sphere(views)
    rows = []
    model_pixels = np.zeros(views, np.int64)
    for v, d in enumerate(directions):
        up = (0.0, 0.0, 1.0) if abs(d[2]) < 0.9 else (0.0, 1.0, 0.0)
        cam = Camera(center + 3 * radius * d, center, up, orthographic=True, ortho_height=2 * radius)
        origins, rays = cam.rays(size, size)
        face = caster.intersect(origins, rays).face
        face = face[face >= 0]
        model_pixels[v] = len(face)
        ids, counts = np.unique(face, return_counts=True)
        rows.append((np.full(len(ids), v, np.int32), ids, counts))
    table = FacePixels(
        view=np.concatenate([r[0] for r in rows]),
        face=np.concatenate([r[1] for r in rows]).astype(np.int64),
        pixels=np.concatenate([r[2] for r in rows]).astype(np.int64),
        model_pixels=model_pixels,
        directions=directions,
        n_faces=soup.n_faces,
    )
    if cache is not None:
        with atomic_write(cache, "wb") as fh:
            np.savez_compressed(fh, key=np.array(key), **{f: getattr(table, f) for f in _ARRAYS})
    return table


_ARRAYS = ("view", "face", "pixels", "model_pixels", "directions")


def _key(soup, views: int, size: int) -> str:
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(soup.vertices, np.float64).tobytes())
    h.update(np.ascontiguousarray(soup.faces, np.int64).tobytes())
    h.update(repr((VERSION, views, size)).encode())
    return h.hexdigest()


def false_pixels(table: FacePixels, removed: np.ndarray, *, up=None) -> dict:
    """False pixels per million model pixels of a deletion.

    Parameters
    ----------
    table : FacePixels
        The original model's pixel table (:func:`face_pixels`).
    removed : (m,) bool
        Per input face: deleted.
    up : (3,) float, optional
        When given, only the views from above the horizon (``dot(direction, up) > 0``).

    Returns
    -------
    dict
        ``mean`` and ``worst`` (per million), ``worst_view`` (index), ``per_view`` (list),
        ``views`` (how many were used).
    """
    removed = np.asarray(removed, bool).reshape(-1)
    bad = np.bincount(
        table.view, weights=table.pixels * removed[table.face], minlength=len(table.model_pixels)
    )
    use = np.ones(len(table.model_pixels), bool)
    if up is not None:
        use = table.directions @ np.asarray(up, np.float64) > 0
    use &= table.model_pixels > 0
    per_view = np.where(use, bad / np.maximum(table.model_pixels, 1) * 1e6, 0.0)
    if not use.any():
        return {"mean": 0.0, "worst": 0.0, "worst_view": -1, "per_view": [], "views": 0}
    worst = int(np.argmax(np.where(use, per_view, -1)))
    return {
        "mean": float(per_view[use].mean()),
        "worst": float(per_view[worst]),
        "worst_view": worst,
        "per_view": per_view[use].tolist(),
        "views": int(use.sum()),
    }


def seen_faces(table: FacePixels) -> np.ndarray:
    """(m,) bool: faces that show on at least one pixel of some view."""
    out = np.zeros(table.n_faces, bool)
    out[table.face] = True
    return out
