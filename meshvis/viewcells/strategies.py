"""The ray distributions of global visibility sampling (AGVS §4.3-4.4), each vectorised over a batch.

A distribution draws *samples*: a point and a direction; the sampler casts a ray both ways
from the point and the free segment between the two hits carries what it sees to every
view cell it pierces (:mod:`.sampler`).

* **uniform** (view space-direction, §4.3): a uniform point of the view space, a uniform
  direction.  Its rays are also the random cameras of the pixel-error estimate (§4.5).
* **object** (object-direction, §4.3): a point on the surface, uniform by area, and a
  cosine-distributed direction on a random side of its face.
* **two-point** (§4.3): a uniform point of the view space aimed at a point on the surface
  (uniform by area): most rays go where the scene extends, roughly horizontal in a city.
* **mutation** (two-point mutation, §4.4): a segment that found something new, both ends
  moved by a Gaussian in the plane across it, the end on a face by the face's size, the
  other by the size of what it stopped on (a face, or the view cell where it left the view
  space); the new ray starts half way, away from the surfaces at the ends.
* **silhouette** (silhouette mutation, §4.4): from the far end of a successful segment,
  discovery rays towards points beside the face it hit, along a random direction across
  the segment, in two rounds of four (a quaternary search): the nearest one that misses
  the face passes its edge, and the new sample follows it past the edge.
* **border** (border mutation, after GVS's adaptive border sampling): from the point of the
  cell that saw a face new to it, a ray towards a neighbour of that face (sharing a
  vertex) the cell has not seen yet.
* **adjacent** (adjacent-cell mutation): a face new to a cell is aimed at from a cell next
  to it (sharing a piece of wall) that has not seen the face yet, from a random point of
  the wall they share (three samples in four) or of the whole cell.  The faces a cell misses
  are mostly small faces that its neighbours see: a viewer near the wall between two cells
  sees nearly what the other side sees, and a free segment through a point of the wall
  pierces both cells, so it adds the face to both.
* **wall** (two-point from the cells' walls): a uniform point on the walls of the view cells
  (the sides of their boxes, by area) aimed at a point on the surface.  The views a PVS
  gets most wrong stand near their cell's walls, where the cell's own samples are thinnest
  and the view reaches past what the rest of the cell sees; a segment through a point of a
  wall shared by two cells serves both, so neighbours agree along their common wall.

Mutation candidates are kept in :class:`MutationBuffer`, the least mutated first.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.rays.samples import tangent_frames, uniform_sphere

#: the distributions, in the order of the mixture
STRATEGIES = ("uniform", "object", "two-point", "mutation", "silhouette", "border", "adjacent", "wall")
#: discovery rays per round of the silhouette search, and rounds
SILHOUETTE_RAYS = 4
SILHOUETTE_ROUNDS = 2
#: rays per sample of each distribution (a sample is cast both ways)
RAYS_PER_SAMPLE = {
    "uniform": 2,
    "object": 2,
    "two-point": 2,
    "mutation": 2,
    "silhouette": 2 + SILHOUETTE_RAYS * SILHOUETTE_ROUNDS,
    "border": 2,
    "adjacent": 2,
    "wall": 2,
}
#: share of the adjacent-cell mutations that start on the wall the two cells share
ON_WALL = 0.75
#: points drawn on a cell's wall move off it, to a random side, by this many times the
#: caster's push off surfaces: a surface lying in the wall's plane (auto cells often split
#: along floors and walls) is then hit, not started on and passed through (Embree's ray
#: starts at t = 0, and an origin on a triangle misses it about half of the time)
WALL_PUSH = 10.0
#: candidates the mutation buffer holds (AGVS §7 uses 2 M)
BUFFER_SIZE = 1 << 20
#: a vertex shared by more faces than this (the hub of a fan) makes no neighbours for border mutations
FAN_CAP = 64


@dataclass
class Samples:
    """A batch of samples: points and unit directions; ``rays`` traced to make them (discovery rays)."""

    origin: np.ndarray
    direction: np.ndarray
    rays: int = 0


class SurfacePoints:
    """Area-uniform points on the model's faces (faces of zero area never drawn)."""

    def __init__(self, soup):
        self.triangles = soup.triangles
        self.normals = soup.normals
        area = np.where(np.isfinite(soup.areas), soup.areas, 0.0)
        total = float(area.sum())
        self.cdf = np.cumsum(area) / total if total > 0 else None

    def draw(self, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """``(faces, points)``: n faces by area and a uniform point on each."""
        if self.cdf is None:
            return np.zeros(0, np.int64), np.zeros((0, 3))
        face = np.minimum(np.searchsorted(self.cdf, rng.random(n), side="right"), len(self.cdf) - 1)
        r1, r2 = rng.random(n), rng.random(n)
        s = np.sqrt(r1)
        tri = self.triangles[face]
        w = np.stack([1 - s, s * (1 - r2), s * r2], axis=1)
        return face, np.einsum("ki,kij->kj", w, tri)


def uniform(view_space, n: int, rng: np.random.Generator) -> Samples:
    """View space-direction samples."""
    return Samples(view_space.sample(n, rng), uniform_sphere(n, rng))


def object_direction(surface: SurfacePoints, n: int, rng: np.random.Generator, push: float) -> Samples:
    """Object-direction samples: cosine-distributed about a random side of a random surface point.

    ``push`` moves the point off its face along the side's normal (the reverse ray then ends
    on the face itself).
    """
    face, point = surface.draw(n, rng)
    if len(face) == 0:
        return Samples(np.zeros((0, 3)), np.zeros((0, 3)))
    sign = np.where(rng.random(len(face)) < 0.5, 1.0, -1.0)[:, None]
    normal = surface.normals[face] * sign
    t1, t2 = tangent_frames(normal)
    r1, r2 = rng.random(len(face)), rng.random(len(face))
    sin_t, cos_t, phi = np.sqrt(r1), np.sqrt(1 - r1), 2 * np.pi * r2
    d = (sin_t * np.cos(phi))[:, None] * t1 + (sin_t * np.sin(phi))[:, None] * t2 + cos_t[:, None] * normal
    return Samples(point + push * normal, _unit(d))


def two_point(view_space, surface: SurfacePoints, n: int, rng: np.random.Generator) -> Samples:
    """Two-point samples: from a view space point towards a surface point."""
    v = view_space.sample(n, rng)
    _, o = surface.draw(n, rng)
    if len(o) == 0:
        return Samples(np.zeros((0, 3)), np.zeros((0, 3)))
    d = o - v
    ok = np.linalg.norm(d, axis=1) > 0
    return Samples(v[ok], _unit(d[ok]))


class CellWalls:
    """Area-uniform points on the walls of the view cells (the six sides of every cell's box).

    A wall two cells share is drawn from both sides (twice the weight of a wall of the
    view space's outside); points under the ground are dropped.  Each point moves off its
    wall by ``WALL_PUSH * push`` to a random side.

    Parameters
    ----------
    cells : ViewCells
        The view cells.
    push : float
        The caster's push off surfaces (its offset times its diagonal).
    """

    def __init__(self, cells, push: float):
        self.cells = cells
        self.push = WALL_PUSH * push
        ext = cells.cell_hi - cells.cell_lo
        # the area of side (cell, axis, low or high): the product of the two other extents
        area = np.stack([ext[:, 1] * ext[:, 2], ext[:, 0] * ext[:, 2], ext[:, 0] * ext[:, 1]], axis=1)
        area = np.repeat(area, 2, axis=1).ravel()
        total = float(area.sum())
        self.cdf = np.cumsum(area) / total if total > 0 else None

    def draw(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """(<= n, 3) points on the cells' walls, in the view space."""
        if self.cdf is None or n == 0:
            return np.zeros((0, 3))
        side = np.minimum(np.searchsorted(self.cdf, rng.random(n), side="right"), len(self.cdf) - 1)
        cell, axis, high = side // 6, (side // 2) % 3, side % 2
        lo, hi = self.cells.cell_lo[cell], self.cells.cell_hi[cell]
        x = lo + rng.random((n, 3)) * (hi - lo)
        rows = np.arange(n)
        x[rows, axis] = np.where(high == 1, hi[rows, axis], lo[rows, axis])
        x[rows, axis] += np.where(rng.random(n) < 0.5, self.push, -self.push)
        return x[self.cells.view_space.contains(x)]


def wall(walls: CellWalls, surface: SurfacePoints, n: int, rng: np.random.Generator) -> Samples:
    """Wall samples: from a point on a view cell's wall towards a surface point."""
    v = walls.draw(n, rng)
    _, o = surface.draw(len(v), rng)
    if len(o) == 0:
        return Samples(np.zeros((0, 3)), np.zeros((0, 3)))
    d = o - v
    ok = np.linalg.norm(d, axis=1) > 0
    return Samples(v[ok], _unit(d[ok]))


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


def _across(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors across each unit vector ``u`` (a frame of the plane perpendicular to it)."""
    return tangent_frames(u)


class MutationBuffer:
    """Mutation candidates (AGVS §4.4), least mutated first.

    A candidate is a record of arrays named by ``fields`` (for the two-point and silhouette
    mutations: a segment from ``s_o`` to ``s_t``, the face at ``s_t`` and the sizes ``r_o``,
    ``r_t`` of what its ends stopped on).  Candidates are kept in levels by how often they
    were mutated; :meth:`take` hands out the newest of the lowest level and moves them one
    level up, and beyond the capacity the oldest of the highest level are dropped.  Every
    operation touches only the candidates it moves (no sort of the whole buffer).

    Parameters
    ----------
    fields : tuple of str
        Names of the arrays each candidate carries.
    capacity : int
        Most candidates kept.
    """

    def __init__(self, fields=("s_o", "s_t", "face", "r_o", "r_t"), capacity: int = BUFFER_SIZE):
        self.fields = tuple(fields)
        self.capacity = int(capacity)
        #: level -> chunks (dicts of arrays), oldest first
        self.levels: dict[int, list[dict]] = {}
        self.size = 0

    def __len__(self) -> int:
        return self.size

    def add(self, **arrays) -> None:
        """Append candidates at level 0; drop the most mutated ones beyond the capacity."""
        n = len(arrays[self.fields[0]])
        if n == 0:
            return
        self._push(0, {f: arrays[f] for f in self.fields})
        while self.size > self.capacity:
            top = max(self.levels)
            chunk = self.levels[top][0]
            over = self.size - self.capacity
            n = len(chunk[self.fields[0]])
            if n <= over:
                self.levels[top].pop(0)
                self.size -= n
            else:
                self.levels[top][0] = {k: v[over:] for k, v in chunk.items()}
                self.size -= over
            if not self.levels[top]:
                del self.levels[top]

    def _push(self, level: int, chunk: dict) -> None:
        self.levels.setdefault(level, []).append(chunk)
        self.size += len(chunk[self.fields[0]])

    def take(self, k: int) -> dict | None:
        """``k`` candidates (arrays by field), the least mutated first, the newest among equals.

        When the buffer holds fewer than ``k``, candidates are handed out more than once;
        None when it is empty.
        """
        out: list[dict] = []
        while k > 0 and self.size > 0:
            level = min(self.levels)
            chunks = self.levels[level]
            chunk = chunks[-1]
            n = len(chunk[self.fields[0]])
            m = min(k, n)
            part = {f: v[n - m :] for f, v in chunk.items()}
            if m == n:
                chunks.pop()
                if not chunks:
                    del self.levels[level]
            else:
                chunks[-1] = {f: v[: n - m] for f, v in chunk.items()}
            self.size -= m
            self._push(level + 1, part)
            out.append(part)
            k -= m
        if not out:
            return None
        return {f: np.concatenate([p[f] for p in out]) for f in self.fields}


def two_point_mutation(buf: MutationBuffer, k: int, rng: np.random.Generator) -> Samples:
    """Two-point mutations of ``k`` candidates of the buffer."""
    c = buf.take(k)
    if c is None:
        return Samples(np.zeros((0, 3)), np.zeros((0, 3)))
    n = len(c["face"])
    s_o, s_t = c["s_o"], c["s_t"]
    u = _unit(s_t - s_o)
    e1, e2 = _across(u)
    g = rng.standard_normal((n, 4))
    r_o, r_t = c["r_o"][:, None], c["r_t"][:, None]
    a = s_o + r_o * (g[:, :1] * e1 + g[:, 1:2] * e2)
    b = s_t + r_t * (g[:, 2:3] * e1 + g[:, 3:4] * e2)
    d = b - a
    ok = np.linalg.norm(d, axis=1) > 0
    return Samples(0.5 * (a + b)[ok], _unit(d[ok]))


def silhouette_mutation(
    buf: MutationBuffer, k: int, rng: np.random.Generator, caster, push: float
) -> Samples:
    """Silhouette mutations of ``k`` candidates: samples that pass just beside the edge of their face.

    From ``s_o`` (moved ``push`` towards ``s_t``), discovery rays aim at points
    ``s_t + lam * 2 r_t * w`` for a random direction ``w`` across the segment; the smallest
    ``lam`` whose ray does not end on the candidate's face marks the edge, found in
    :data:`SILHOUETTE_ROUNDS` rounds of :data:`SILHOUETTE_RAYS` rays.
    """
    c = buf.take(k)
    if c is None:
        return Samples(np.zeros((0, 3)), np.zeros((0, 3)))
    n = len(c["face"])
    s_o, s_t, face = c["s_o"], c["s_t"], c["face"]
    u = _unit(s_t - s_o)
    e1, e2 = _across(u)
    phi = 2 * np.pi * rng.random(n)
    w = np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2
    reach = 2 * c["r_t"]
    start = s_o + push * u
    lam_lo, lam_hi = np.zeros(n), np.ones(n)
    rays = 0
    j = np.arange(1, SILHOUETTE_RAYS + 1) / SILHOUETTE_RAYS
    for _ in range(SILHOUETTE_ROUNDS):
        lam = lam_lo[:, None] + (lam_hi - lam_lo)[:, None] * j  # (n, J)
        target = s_t[:, None, :] + (lam * reach[:, None])[:, :, None] * w[:, None, :]
        o = np.repeat(start, SILHOUETTE_RAYS, axis=0)
        d = target.reshape(-1, 3) - o
        ok = np.linalg.norm(d, axis=1) > 0
        hit_face = np.full(len(d), -2, np.int64)
        if ok.any():
            hit_face[ok] = caster.intersect(o[ok], d[ok]).face
        rays += len(d)
        misses = (hit_face.reshape(n, SILHOUETTE_RAYS) != face[:, None]).astype(np.int8)
        # the first ray that does not end on the face; none: the outermost
        first = np.where(misses.any(axis=1), np.argmax(misses, axis=1), SILHOUETTE_RAYS - 1)
        new_hi = np.take_along_axis(lam, first[:, None], axis=1)[:, 0]
        new_lo = np.where(
            first > 0, np.take_along_axis(lam, np.maximum(first - 1, 0)[:, None], axis=1)[:, 0], lam_lo
        )
        lam_lo, lam_hi = new_lo, new_hi
    edge = s_t + (lam_hi * reach)[:, None] * w
    d = edge - s_o
    ok = np.linalg.norm(d, axis=1) > 0
    return Samples(0.5 * (s_o + edge)[ok], _unit(d[ok]), rays)


def face_neighbours(soup, fan_cap: int = FAN_CAP) -> tuple[np.ndarray, np.ndarray]:
    """CSR ``(ptr, nbr)`` of the faces that share a vertex with each face (after welding)."""
    from meshvis.geometry.adjacency import weld
    from meshvis.viewcells import _kernels

    _, welded = weld(soup.vertices, soup.faces)
    n_vertices = int(welded.max()) + 1 if welded.size else 0
    return _kernels.vertex_neighbours(np.ascontiguousarray(welded, np.int64), n_vertices, fan_cap)


def border_mutation(
    buf: MutationBuffer, k: int, rng: np.random.Generator, bits, neighbours, surface
) -> Samples:
    """Border mutations of ``k`` new PVS entries (least mutated first).

    From the point of the cell that saw a face, a ray towards a random point on a
    neighbour of that face (sharing a vertex) that the cell has not seen yet.
    """
    from meshvis.viewcells import _kernels

    c = buf.take(k)
    if c is None:
        return Samples(np.zeros((0, 3)), np.zeros((0, 3)))
    ptr, nbr = neighbours
    g = _kernels.pick_neighbours(c["face"], c["cell"], ptr, nbr, bits, rng.random(len(c["face"])))
    ok = g >= 0
    g, x = g[ok], c["x"][ok]
    r1, r2 = rng.random(len(g)), rng.random(len(g))
    s = np.sqrt(r1)
    w = np.stack([1 - s, s * (1 - r2), s * r2], axis=1)
    q = np.einsum("ki,kij->kj", w, surface.triangles[g])
    d = q - x
    ok = np.linalg.norm(d, axis=1) > 0
    return Samples(x[ok], _unit(d[ok]))


def adjacent_cell(
    buf: MutationBuffer,
    k: int,
    rng: np.random.Generator,
    bits,
    adjacent,
    cells,
    surface,
    push: float = 0.0,
) -> Samples:
    """Adjacent-cell mutations of ``k`` new PVS entries (least mutated first).

    For an entry (cell, face): a random cell sharing a wall with the cell, and when that
    cell has not seen the face, a ray towards a random point of the face from a random
    point (in the view space) of the wall the two cells share (a share :data:`ON_WALL` of
    the samples) or of the other cell.  A point on the wall moves off it by
    ``WALL_PUSH * push`` (the caster's push off surfaces) to a random side.
    """
    ptr, nbr = adjacent
    c = buf.take(k)
    if c is None or len(nbr) == 0:
        return Samples(np.zeros((0, 3)), np.zeros((0, 3)))
    count = ptr[c["cell"] + 1] - ptr[c["cell"]]
    has = count > 0
    cell, face, count = c["cell"][has], c["face"][has], count[has]
    other = nbr[ptr[cell] + np.minimum((rng.random(len(cell)) * count).astype(np.int64), count - 1)]
    word = bits[other, face >> 6]
    unseen = ((word >> (face & 63).astype(np.uint64)) & np.uint64(1)) == 0
    cell, other, face = cell[unseen], other[unseen], face[unseen]
    lo, hi = cells.cell_lo[other], cells.cell_hi[other]
    # the shared wall: the overlap of the two boxes, flat along the axis where they touch
    on_wall = (rng.random(len(other)) < ON_WALL)[:, None]
    lo = np.where(on_wall, np.maximum(lo, cells.cell_lo[cell]), lo)
    hi = np.where(on_wall, np.minimum(hi, cells.cell_hi[cell]), hi)
    x = lo + rng.random((len(other), 3)) * np.maximum(hi - lo, 0.0)
    flat = np.argmin(hi - lo, axis=1)
    rows = np.arange(len(other))
    x[rows, flat] += np.where(on_wall[:, 0], np.where(rng.random(len(other)) < 0.5, 1.0, -1.0), 0.0) * (
        WALL_PUSH * push
    )
    r1, r2 = rng.random(len(face)), rng.random(len(face))
    s = np.sqrt(r1)
    w = np.stack([1 - s, s * (1 - r2), s * r2], axis=1)
    q = np.einsum("ki,kij->kj", w, surface.triangles[face])
    ok = cells.view_space.contains(x) & (np.linalg.norm(q - x, axis=1) > 0)
    return Samples(x[ok], _unit((q - x)[ok]))
