"""The ray-visibility backend: the only module that talks to Embree (through ``embreex``).

Embree works in float32.  To keep float32 round-off independent of where the model sits
and how big it is, the scene is built on a *normalised* copy of the model: centred on its
bounding-box centre and scaled to unit bounding-box diagonal.  Callers pass and receive
input coordinates (float64); the mapping happens here.

Origins that lie on a surface must be pushed off it (Embree's ray always starts at t = 0,
so an origin exactly on its own triangle hits it about half of the time).  The push is
``offset`` (default 1e-5) times the diagonal, i.e. far above float32 resolution of the
normalised copy (about 6e-8) and far below any feature users care about.

The scene's vertex buffer holds one vertex per group of bit-identical input vertices
(:func:`meshvis.geometry.adjacency.group_vertices`): a soup whose faces each have their own
corners builds its scene about twice as fast on its distinct vertices, and every triangle
keeps the float32 corners it would have on the full buffer, so the hits are the same.

Threads or processes?  ``embreex`` releases the GIL while it traces, so two threads
trace a large batch faster than one on a machine with a free core; processes would have
to rebuild the scene and copy the rays and results, and measure slower.  ``meshvis bench
rays`` measures all three side by side (docs/benchmarks.md, "Ray backend").
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis import _validate
from meshvis._threads import default_threads, in_threads
from meshvis.errors import ModelError
from meshvis.geometry.adjacency import VertexGroups, group_vertices
from meshvis.io import as_soup
from meshvis.rays import _kernels

#: default push of an origin off its surface, as a fraction of the bounding-box diagonal
DEFAULT_OFFSET = 1e-5
#: push for rays that decide which side of a face is seen (the reference of DESIGN.md §10,
#: from-region visibility, the per-face evidence of ``orient``), a tenth of the default: a
#: surface nearer to a face than the push is jumped over, and real scenes have surfaces
#: within 1e-5 diagonals of each other
VISIBILITY_OFFSET = 1e-6
#: rays per chunk handed to one thread of the kept pool (:func:`meshvis._threads.pool`):
#: handing over a chunk costs tens of microseconds, Embree traces 2 k rays in about a
#: millisecond, so from two chunks on threads pay (``meshvis bench rays``)
CHUNK = 1 << 11
#: rays traced by every caster of this process and the seconds Embree took (read by the
#: benchmarks: ``meshvis bench scale --real`` reports them per command)
RAYS = {"rays": 0, "seconds": 0.0}


def _used_bounds(soup, firsts: np.ndarray) -> np.ndarray:
    """(2, 3) :attr:`Soup.bounds <meshvis.soup.Soup.bounds>`, from one vertex of each group.

    A soup's groups are several times fewer than its corners.  The minimum and maximum are
    the same numbers whatever the rows, except a zero extreme, whose sign bit depends on
    the order of the reduction: then the soup's own bounds are used, so that the scene's
    centre has exactly the bits it always had.
    """
    lo, hi = firsts.min(axis=0), firsts.max(axis=0)
    if (lo == 0).any() or (hi == 0).any():
        return soup.bounds
    return np.stack([lo, hi])


def _check_copies(corners: np.ndarray, n_groups: int, path: str | None) -> None:
    """Refuse more than :data:`meshvis.limits.MAX_FACE_COPIES` copies of one triangle.

    ``corners`` (m, 3) are the faces' vertex groups (bit-identical corners); a ray through a
    stack of copies tests every one of them, so the work of every ray grows with the stack.
    """
    from meshvis import limits

    if len(corners) <= limits.MAX_FACE_COPIES:
        return
    c = np.sort(corners.astype(np.int64), axis=1)
    if n_groups < 2**21:  # one int64 key per sorted corner triple
        key = (c[:, 0] * n_groups + c[:, 1]) * n_groups + c[:, 2]
        key.sort()
        starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1], True])
        most = int(np.diff(starts).max())
    else:
        most = int(np.unique(c, axis=0, return_counts=True)[1].max())
    if most > limits.MAX_FACE_COPIES:
        raise ModelError(
            f"{most} faces lie exactly on top of each other: a ray through them tests every one; "
            f"more than the cap MAX_FACE_COPIES of meshvis.limits ({limits.MAX_FACE_COPIES})",
            path,
        )


@dataclass
class Hits:
    """First hits of a batch of rays, in input coordinates.

    Attributes
    ----------
    face : (n,) int64 array
        Index of the face hit, -1 for a miss.
    distance : (n,) float64 array
        Distance along the (unit) direction, ``inf`` for a miss.
    side : (n,) int8 array
        0 when the ray hit the front (counter-clockwise) side, 1 the back, -1 miss.
    bary : (n, 2) float32 array
        Barycentric coordinates (u, v) of the hit on its face: the point is ``(1-u-v) a + u b + v
        c`` for the face's corners (a, b, c).
    """

    face: np.ndarray
    distance: np.ndarray
    side: np.ndarray
    bary: np.ndarray | None = None

    @property
    def hit(self) -> np.ndarray:
        """(n,) bool: the ray hit a face."""
        return self.face >= 0

    def points(self, origins: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """Hit points (NaN rows for misses)."""
        d = directions / np.linalg.norm(directions, axis=1, keepdims=True)
        return origins + d * self.distance[:, None]


class RayCaster:
    """Batched ray queries against one model, built once and reused by every stage.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh or tuple of (vertices, faces)
        The geometry.  Degenerate faces are kept (Embree skips them).
    offset : float
        Push of surface origins off their surface, relative to the bounding-box diagonal.
    threads : int, optional
        Threads for large batches (default: :func:`default_threads`).
    vertex_groups : VertexGroups, optional
        :func:`~meshvis.geometry.adjacency.group_vertices` of the model, when the caller has
        them (the classification shares them with its weld); computed here otherwise.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> rc = RayCaster(trimesh.creation.box())
    >>> h = rc.intersect(np.array([[0., 0, 5]]), np.array([[0., 0, -1]]), exact_distance=True)
    >>> int(h.side[0]), float(h.distance[0])
    (0, 4.5)
    """

    def __init__(
        self,
        model: Any,
        *,
        offset: float = DEFAULT_OFFSET,
        threads: int | None = None,
        vertex_groups: VertexGroups | None = None,
    ):
        import embreex.mesh_construction as mc
        import embreex.rtcore_scene as rs

        soup = as_soup(model)
        _validate.instance("vertex_groups", vertex_groups, VertexGroups, optional=True)
        self.soup = soup
        self.offset = _validate.real("offset", offset, 0.0, 0.1)
        self.threads = default_threads() if threads is None else _validate.integer("threads", threads, 1)
        groups = vertex_groups if vertex_groups is not None else group_vertices(soup.vertices, soup.faces)
        #: the bit-identical vertex groups of the model (the scene's vertex buffer)
        self.vertex_groups = groups
        firsts = soup.vertices[groups.first]
        lo, hi = _used_bounds(soup, firsts)
        self.center = 0.5 * (lo + hi)
        diag = float(np.linalg.norm(hi - lo))  # the arithmetic of Soup.diagonal
        # a model that is a single point (all faces degenerate) still gets a usable scale
        self.scale = 1.0 / diag if diag > 0 else 1.0
        self.diagonal = diag if diag > 0 else 1.0
        self.part_id = soup.part_id
        # one vertex per group; a group's vertices have the same bits, so the same float32
        v32 = ((firsts - self.center) * self.scale).astype(np.float32)
        # an extent beyond the float64 range (infinite diagonal) gives NaN: clamp it harmlessly
        v32[~np.isfinite(v32).all(axis=1)] = 0
        corners = groups.corner_groups(soup.faces, soup.n_vertices).astype(np.int32, copy=False)
        _check_copies(corners, len(groups.first), soup.path)
        self._scene = rs.EmbreeScene()
        self._mesh = mc.TriangleMesh(self._scene, v32, corners)

    @property
    def normals(self) -> np.ndarray:
        """(m, 3) unit face normals of the model (computed on first use, not with the scene)."""
        return self.soup.normals

    def with_offset(self, offset: float) -> RayCaster:
        """A caster of the same scene whose surface origins are pushed off by ``offset``.

        The Embree scene, the model and the threads are shared (nothing is built again);
        only the push of :meth:`push_off` and the compiled ray generators changes.

        Examples
        --------
        >>> import trimesh
        >>> rc = RayCaster(trimesh.creation.box())
        >>> fine = rc.with_offset(1e-6)
        >>> fine.offset, rc.offset, fine._scene is rc._scene
        (1e-06, 1e-05, True)
        """
        other = copy.copy(self)
        other.offset = _validate.real("offset", offset, 0.0, 0.1)
        return other

    # ------------------------------------------------------------------ coordinates
    def to_unit(self, points: np.ndarray) -> np.ndarray:
        """Input coordinates -> normalised float32 coordinates of the Embree scene."""
        return ((np.asarray(points, np.float64) - self.center) * self.scale).astype(np.float32)

    # ------------------------------------------------------------------ raw calls
    def _run(self, o32: np.ndarray, d32: np.ndarray, query: str, dists: np.ndarray | None = None) -> Any:
        """One Embree query over a batch, split over threads when it is large."""
        n = len(o32)
        if n == 0:
            if query == "INTERSECT":
                return {
                    "primID": np.zeros(0, np.int32),
                    "tfar": np.zeros(0, np.float32),
                    "Ng": np.zeros((0, 3), np.float32),
                    "u": np.zeros(0, np.float32),
                    "v": np.zeros(0, np.float32),
                }
            return np.zeros(0, np.int32)

        def call(a: int, b: int) -> Any:
            kw = {} if dists is None else {"dists": np.ascontiguousarray(dists[a:b])}
            if query == "INTERSECT":
                return self._scene.run(
                    np.ascontiguousarray(o32[a:b]), np.ascontiguousarray(d32[a:b]), output=1, **kw
                )
            return self._scene.run(
                np.ascontiguousarray(o32[a:b]), np.ascontiguousarray(d32[a:b]), query=query, **kw
            )

        t = time.perf_counter()
        parts = in_threads(call, n, threads=self.threads, rows=CHUNK)
        RAYS["rays"] += n
        RAYS["seconds"] += time.perf_counter() - t
        if len(parts) == 1:
            return parts[0]
        if query == "INTERSECT":
            return {
                "primID": np.concatenate([p["primID"] for p in parts]),
                "tfar": np.concatenate([p["tfar"] for p in parts]),
                "Ng": np.concatenate([p["Ng"] for p in parts]),
                "u": np.concatenate([p["u"] for p in parts]),
                "v": np.concatenate([p["v"] for p in parts]),
            }
        return np.concatenate(parts)

    # ------------------------------------------------------------------ public queries
    def intersect(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        max_distance: np.ndarray | float | None = None,
        *,
        exact_distance: bool = False,
    ) -> Hits:
        """First hit of every ray ``origins + t * directions``, ``0 <= t <= max_distance``.

        Parameters
        ----------
        origins : (n, 3) float array
            Ray origins in input coordinates.
        directions : (n, 3) float array
            Ray directions (need not be unit).
        max_distance : float or (n,) float array, optional
            Longest hit distance, in input units.
        exact_distance : bool
            Recompute each distance in float64 on the hit triangle's plane (otherwise it
            carries float32 round-off, about 1e-7 of the diagonal).

        Returns
        -------
        Hits
            ``side`` is 0 where ``dot(direction, normal) < 0`` (the ray met the front).
        """
        origins, directions = _validate.ray_arrays(origins, directions)
        d, o32, d32 = _kernels.ray_queries(
            np.ascontiguousarray(origins, np.float64),
            np.ascontiguousarray(directions, np.float64),
            np.asarray(self.center, np.float64),
            float(self.scale),
        )
        d = _validate.unit_directions(d)
        dists = None
        if max_distance is not None:
            max_distance = _validate.max_distance(max_distance, len(origins))
            dists = np.broadcast_to(
                np.asarray(max_distance, np.float64) * self.scale, (len(origins),)
            ).astype(np.float32)
        r = self._run(o32, d32, "INTERSECT", dists)
        # side from Embree's geometric normal, which points like ours (counter-clockwise)
        face, distance, side = _kernels.hit_results(
            np.ascontiguousarray(r["primID"]),
            np.ascontiguousarray(r["tfar"]),
            np.ascontiguousarray(r["Ng"]),
            d,
            float(self.scale),
        )
        hit = face >= 0
        if exact_distance and hit.any():
            # Refine in float64 on the hit triangle's plane (not for grazing hits).
            idx = np.flatnonzero(hit)
            n_hit = self.normals[face[idx]]
            cosine = np.einsum("ij,ij->i", d[idx], n_hit)
            v0 = self.soup.vertices[self.soup.faces[face[idx], 0]]
            steep = np.abs(cosine) > 1e-3
            t_plane = np.einsum("ij,ij->i", n_hit[steep], v0[steep] - origins[idx[steep]]) / cosine[steep]
            distance[idx[steep]] = np.maximum(t_plane, 0.0)
        return Hits(face, distance, side, np.stack([r["u"], r["v"]], axis=1))

    def occluded(self, origins: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """True where the open segment ``origins -> targets`` meets geometry.

        Both ends are excluded by ``offset`` × diagonal, so a target lying on a surface does
        not occlude itself; push origins off their own surface first (:meth:`push_off`).
        """
        origins, targets = _validate.ray_arrays(origins, targets, "targets")
        o32, d32, dist, ok = _kernels.segment_queries(
            np.ascontiguousarray(origins, np.float64),
            np.ascontiguousarray(targets, np.float64),
            np.asarray(self.center, np.float64),
            float(self.scale),
            float(self.offset),
        )
        return self.occluded_queries(o32, d32, dist) & ok

    def occluded_queries(self, o32: np.ndarray, d32: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """True where a ray already in scene coordinates meets geometry within ``dist``.

        For compiled ray generators that write Embree's inputs directly: float32 origins
        in the normalised coordinates of :meth:`to_unit`, float32 unit directions and
        float32 lengths in those units (:func:`meshvis.rays._kernels.segment_queries`).
        """
        return self._run(o32, d32, "OCCLUDED", dist) != -1

    def push_off(self, points: np.ndarray, face: np.ndarray, side: np.ndarray) -> np.ndarray:
        """Move points lying on ``face`` off its surface, towards ``side`` (0 front, 1 back)."""
        face = _validate.face_indices("face", face, self.soup.n_faces)
        sign = np.where(np.asarray(side) == 0, 1.0, -1.0)
        return points + self.normals[face] * (sign * self.offset * self.diagonal)[:, None]

    def intersect_from_surface(
        self, points: np.ndarray, face: np.ndarray, side: np.ndarray, directions: np.ndarray
    ) -> Hits:
        """Like :meth:`intersect` for rays that start on ``face`` and leave it on ``side``."""
        return self.intersect(self.push_off(points, face, side), directions)

    def part_of(self, face: np.ndarray) -> np.ndarray:
        """Part id of each face index (-1 for misses)."""
        face = _validate.face_indices("face", face, self.soup.n_faces, allow_miss=True)
        out = np.full(face.shape, -1, np.int64)
        hit = face >= 0
        out[hit] = self.part_id[face[hit]]
        return out

    def __repr__(self) -> str:
        return f"<RayCaster {self.soup.n_faces} faces, {self.threads} threads>"
