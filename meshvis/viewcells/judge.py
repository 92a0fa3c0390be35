"""Judging a PVS the AGVS way: wrong pixels of the full scene seen from inside the cells (AGVS §7).

From random viewpoints of the view space (six 90° views each, the faces of a cube map) and
from the points of a walkthrough (one view each, looking along the path), the face-ID
buffer of the *whole* model is rendered.  A pixel is wrong when its face is not in the PVS
of the cell the viewpoint stands in; the error of a view is its wrong pixels per million
pixels of the image (a pixel that shows nothing cannot be wrong), reported as the mean over
the views and for the worst view.  Only the pixel count of every face in every view is kept
(a sparse table), so one rendering judges any number of PVS of the same model and view
space.

>>> import trimesh
>>> from meshvis.viewcells.viewspace import ViewSpace
>>> inside = ViewSpace(np.full(3, -0.4), np.full(3, 0.4))  # in a closed box every pixel shows a face
>>> table = render_views(trimesh.creation.box(), inside, points=4, path=0, size=16, seed=0)
>>> table.n_views, int(table.pixels.sum()) == 4 * 6 * 16 * 16
(24, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.io import as_soup
from meshvis.rays.caster import RayCaster

#: random viewpoints (six views each) and walkthrough points (one view each)
VIEWPOINTS = 1024
PATH_POINTS = 256
#: pixels along each side of a view
SIZE = 128
#: waypoints of the walkthrough (a closed path through random points of the view space)
WAYPOINTS = 12
#: views per call of the ray caster
VIEWS_PER_CALL = 64


@dataclass
class ViewTable:
    """Pixels of every face in every view.

    Attributes
    ----------
    view, face, pixels : (k,) int arrays
        View ``view[i]`` shows face ``face[i]`` on ``pixels[i]`` pixels.
    position : (v, 3) float64
        Where each view is taken from.
    walkthrough : (v,) bool
        The view belongs to the walkthrough (else to a random viewpoint).
    size : int
        Pixels along each side of a view.
    """

    view: np.ndarray
    face: np.ndarray
    pixels: np.ndarray
    position: np.ndarray
    walkthrough: np.ndarray
    size: int

    @property
    def n_views(self) -> int:
        """Views in the table."""
        return len(self.position)


def cube_directions(size: int) -> np.ndarray:
    """(6 * size * size, 3) unit directions through the pixel centres of the six faces of a cube map."""
    c = (np.arange(size) + 0.5) / size * 2 - 1
    grid_u, grid_v = np.meshgrid(c, -c)
    u, v = grid_u.ravel(), grid_v.ravel()
    one = np.ones_like(u)
    faces = [
        np.stack([one, v, -u], 1),
        np.stack([-one, v, u], 1),
        np.stack([u, one, -v], 1),
        np.stack([u, -one, v], 1),
        np.stack([u, v, one], 1),
        np.stack([-u, v, -one], 1),
    ]
    d = np.concatenate(faces)
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def walkthrough(view_space, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A walkthrough: ``n`` points and the unit directions along the path there.

    The path is closed, through :data:`WAYPOINTS` random points of the view space; the
    points are evenly spaced by length.
    """
    if n <= 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    way = view_space.sample(WAYPOINTS, rng)
    loop = np.concatenate([way, way[:1]])
    seg = np.diff(loop, axis=0)
    length = np.linalg.norm(seg, axis=1)
    at = (np.arange(n) + 0.5) / n * length.sum()
    ends = np.cumsum(length)
    k = np.minimum(np.searchsorted(ends, at), len(seg) - 1)
    frac = (at - (ends[k] - length[k])) / np.maximum(length[k], 1e-300)
    points = loop[k] + frac[:, None] * seg[k]
    return points, seg[k] / np.maximum(length[k], 1e-300)[:, None]


def _forward_views(directions: np.ndarray, size: int) -> np.ndarray:
    """(n, size*size, 3) unit rays of 90° views looking along each direction."""
    c = (np.arange(size) + 0.5) / size * 2 - 1
    u, v = np.meshgrid(c, -c)
    f = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    helper = np.where(np.abs(f[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[0.0, 1.0, 0.0]])
    right = np.cross(f, helper)
    right /= np.linalg.norm(right, axis=1, keepdims=True)
    up = np.cross(right, f)
    d = (
        f[:, None, :]
        + u.ravel()[None, :, None] * right[:, None, :]
        + v.ravel()[None, :, None] * up[:, None, :]
    )
    return d / np.linalg.norm(d, axis=2, keepdims=True)


def render_views(
    model,
    view_space,
    *,
    points: int = VIEWPOINTS,
    path: int = PATH_POINTS,
    size: int = SIZE,
    seed: int = 0,
    caster: RayCaster | None = None,
) -> ViewTable:
    """The pixel table of ``points`` random viewpoints (six views each) and a ``path``-point walkthrough.

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model the PVS was made for.
    view_space : ViewSpace
        Where the viewpoints are drawn (uniformly) and the walkthrough goes.
    points, path : int
        Random viewpoints and walkthrough points.
    size : int
        Pixels along each side of a view.
    seed : int
        Seed of the viewpoints and the path.
    caster : RayCaster, optional
        A caster of the model to reuse.

    Returns
    -------
    ViewTable
    """
    soup = as_soup(model)
    caster = caster or RayCaster(soup)
    rng = np.random.default_rng(seed)
    spots = view_space.sample(points, rng)
    walk, along = walkthrough(view_space, path, rng)
    cube = cube_directions(size)
    per = size * size
    n_views = 6 * len(spots) + len(walk)
    position = np.concatenate([np.repeat(spots, 6, axis=0), walk])
    rows = []
    for first in range(0, n_views, VIEWS_PER_CALL):
        views = np.arange(first, min(first + VIEWS_PER_CALL, n_views))
        cube_views = views[views < 6 * len(spots)]
        path_views = views[views >= 6 * len(spots)] - 6 * len(spots)
        dirs = []
        if len(cube_views):
            dirs.append(cube.reshape(6, per, 3)[cube_views % 6].reshape(-1, 3))
        if len(path_views):
            dirs.append(_forward_views(along[path_views], size).reshape(-1, 3))
        d = np.concatenate(dirs)
        o = np.repeat(position[views], per, axis=0)
        face = caster.intersect(o, d).face
        which = np.repeat(views, per)
        hit = face >= 0
        key = which[hit].astype(np.int64) * soup.n_faces + face[hit]
        u, counts = np.unique(key, return_counts=True)
        rows.append((u // soup.n_faces, u % soup.n_faces, counts))
    return ViewTable(
        view=np.concatenate([r[0] for r in rows]).astype(np.int32),
        face=np.concatenate([r[1] for r in rows]),
        pixels=np.concatenate([r[2] for r in rows]).astype(np.int64),
        position=position,
        walkthrough=np.arange(n_views) >= 6 * len(spots),
        size=size,
    )


def pixel_errors(table: ViewTable, cells, bits: np.ndarray) -> np.ndarray:
    """(v,) wrong pixels per million of each view, for the PVS bit set ``bits`` of ``cells``.

    A view whose viewpoint lies in no cell counts every pixel that shows a face as wrong.
    """
    cell = cells.locate(table.position)
    c = cell[table.view]
    f = table.face
    ok = c >= 0
    known = np.zeros(len(f), bool)
    word = bits[np.maximum(c, 0), f >> 6]
    known[ok] = ((word[ok] >> (f[ok] & 63).astype(np.uint64)) & np.uint64(1)) != 0
    wrong = np.bincount(table.view, weights=table.pixels * ~known, minlength=table.n_views)
    return wrong / (table.size * table.size) * 1e6


def summary(errors: np.ndarray, table: ViewTable) -> dict:
    """Mean and worst error over all views, and over the walkthrough's alone."""
    walk = table.walkthrough
    out = {"views": int(len(errors)), "mean": float(errors.mean()), "worst": float(errors.max())}
    if walk.any():
        out["walkthrough_mean"] = float(errors[walk].mean())
        out["walkthrough_worst"] = float(errors[walk].max())
    return out
