"""The ray strategies of from-region visibility, each one vectorised over a batch.

* **random seeds** (GVS §3.1): from area-uniform points on faces to random viewers of the
  region; a free segment certifies the side of the face that looks at the viewer;
* **adaptive border sampling** (GVS §3.2): a face just proven visible from a viewer is
  enlarged by a thin band in the plane across the viewing ray (9 points, 3 per corner:
  across each adjacent edge and along the bisector, GVS Eq. 1 in spirit); the viewer casts
  rays to those points, and every band edge whose two ends hit different faces is halved
  until its ends agree or it gets shorter than :data:`MIN_SEGMENT`;
* **reverse sampling** (GVS §3.3): a band ray stopped much closer than the plane of its
  face predicts met an occluder; the plane through the viewer, the stopping point and the
  face's certificate cuts the occluder along a segment; just beyond each end of it the
  line towards the predicted point passes beside the occluder, and a viewer of the region
  on that line gets a ray.

Every traced ray's first hit is visible from where it started, so every ray of the last two
strategies certifies its first hit (the records are :class:`Sightings`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.rays import _kernels as ray_kernels
from meshvis.rays.caster import Hits, RayCaster
from meshvis.visibility import _kernels
from meshvis.visibility.regions import Region

#: half-width of the band around a face, as a fraction of the diagonal (viewers at
#: infinity) or of the viewing distance (finite viewers): far above float32 round-off of the
#: unit-size Embree scene (~1e-7), far below any gap users care about
ENLARGE = 2e-5
#: band edges are not halved below this length (fraction of the diagonal) ...
MIN_SEGMENT = 1e-4
#: ... nor more often than this
MAX_DEPTH = 8
#: a band ray that stops this much (fraction of the diagonal) before its face's plane met an occluder
DISCONTINUITY = 1e-3
#: reverse-sampling points sit this far (fraction of the diagonal) beyond the occluder's edge
PASS_BY = 2e-5


@dataclass
class Sightings:
    """Rays that certify their first hit: face, side, and the viewer ray that saw it.

    Attributes
    ----------
    face : (n,) int64
        The face seen.
    side : (n,) int8
        The side seen (0 front, 1 back).
    origin, direction : (n, 3) float64
        The ray from the viewer
    point : (n, 3) float64
        Where the ray hit
    """

    face: np.ndarray
    side: np.ndarray
    origin: np.ndarray
    direction: np.ndarray
    point: np.ndarray

    @classmethod
    def empty(cls) -> Sightings:
        """No sightings."""
        z = np.zeros((0, 3))
        return cls(np.zeros(0, np.int64), np.zeros(0, np.int8), z, z, z)

    @classmethod
    def concat(cls, parts: list[Sightings]) -> Sightings:
        """The sightings of ``parts`` one after another."""
        parts = [p for p in parts if len(p.face)] or [cls.empty()]
        return cls(*(np.concatenate([getattr(p, k) for p in parts]) for k in cls.__dataclass_fields__))

    def subset(self, index: np.ndarray | slice) -> Sightings:
        """The sightings at ``index`` (an index array or mask copies; a slice gives views)."""
        return Sightings(*(getattr(self, k)[index] for k in self.__dataclass_fields__))


def trace(caster: RayCaster, origin: np.ndarray, direction: np.ndarray) -> tuple[Sightings, Hits]:
    """Trace viewer rays; the sightings of the rays that hit, and all the hits."""
    hits = caster.intersect(origin, direction)
    # the hit rows and points ``origin + direction * distance`` in one pass
    face, side, o, d, point = _kernels.hit_rows(
        np.ascontiguousarray(origin, np.float64),
        np.ascontiguousarray(direction, np.float64),
        hits.face,
        hits.side,
        hits.distance,
    )
    return Sightings(face, side, o, d, point), hits


def random_seeds(
    caster: RayCaster,
    region: Region,
    faces: np.ndarray,
    rng: np.random.Generator,
    want: np.ndarray | None = None,
) -> tuple[Sightings, int]:
    """One random seed ray per entry of ``faces`` (repeat a face for more rays).

    Parameters
    ----------
    want : (n,) int8, optional
        The side each seed should look at (-1: either); seeds whose random viewer is on the
        other side are dropped before tracing.

    Returns
    -------
    Sightings
        The seeds whose segment from the face to the viewer is free.
    rays : int
        Seeds traced.
    """
    # the two draws of uniform_in_triangles(caster.soup.triangles[faces], rng), without the gather
    ru, rv = rng.random(len(faces)), rng.random(len(faces))
    faces = np.asarray(faces, np.int64)
    points = ray_kernels.points_in_faces(caster.soup.triangles, faces, ru, rv)
    origin, direction = region.seed_viewers(points, rng)
    origin = np.ascontiguousarray(np.broadcast_to(origin, points.shape), np.float64)
    direction = np.ascontiguousarray(direction, np.float64)
    side = _kernels.facing_sides(direction, caster.normals, faces)
    if want is not None:
        keep = (want < 0) | (want == side)
        faces, side, points, origin, direction = (x[keep] for x in (faces, side, points, origin, direction))
    # caster.occluded(caster.push_off(points, faces, side), origin), prepared in one pass
    o32, d32, dist, ok = _kernels.seed_segments(
        points,
        caster.normals,
        faces,
        side,
        origin,
        np.asarray(caster.center, np.float64),
        float(caster.scale),
        float(caster.offset),
        float(caster.diagonal),
    )
    free = ~(caster.occluded_queries(o32, d32, dist) & ok)
    return Sightings(faces[free], side[free], origin[free], direction[free], points[free]), len(faces)


def _int64(*arrays: np.ndarray) -> list[np.ndarray]:
    return [np.ascontiguousarray(a, np.int64) for a in arrays]


def _float64(*arrays: np.ndarray) -> list[np.ndarray]:
    return [np.ascontiguousarray(a, np.float64) for a in arrays]


def border_band(caster: RayCaster, region: Region, seen: Sightings) -> np.ndarray:
    """(k, 9, 3) points of the band around each seen face, in order around it.

    For corner i the three points lie across edge (i-1, i), on the bisector, and across
    edge (i, i+1), each pushed out in the plane perpendicular to the viewing ray.
    """
    tri = caster.soup.triangles[seen.face]  # (k, 3, 3)
    if region.at_infinity:
        view = np.broadcast_to(seen.direction[:, None, :], tri.shape)
        width = np.full((len(tri), 3), ENLARGE * caster.diagonal)
    else:
        view = tri - seen.origin[:, None, :]
        dist = np.linalg.norm(view, axis=2)
        view = view / np.maximum(dist, 1e-300)[:, :, None]
        width = np.maximum(ENLARGE * dist, 0.05 * ENLARGE * caster.diagonal)
    nxt, prv, opp = np.roll(tri, -1, axis=1), np.roll(tri, 1, axis=1), np.roll(tri, -2, axis=1)
    across_next = _outward(np.cross(view, nxt - tri), opp - tri)
    across_prev = _outward(np.cross(view, tri - prv), nxt - tri)
    bisector = across_prev + across_next
    radial = tri - tri.mean(axis=1, keepdims=True)
    radial -= view * np.einsum("kij,kij->ki", radial, view)[:, :, None]
    weak = np.linalg.norm(bisector, axis=2) < 0.5  # sliver corner: the two normals nearly cancel
    bisector[weak] = radial[weak]
    bisector = _unit(bisector)
    band = np.stack([across_prev, bisector, across_next], axis=2) * width[:, :, None, None]
    return (tri[:, :, None, :] + band).reshape(len(tri), 9, 3)


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


def _outward(normal: np.ndarray, towards_inside: np.ndarray) -> np.ndarray:
    n = _unit(normal)
    flip = np.einsum("kij,kij->ki", n, towards_inside) > 0
    return np.where(flip[:, :, None], -n, n)


def border_sampling(caster: RayCaster, region: Region, seen: Sightings) -> tuple[Sightings, Sightings, int]:
    """Adaptive border sampling around every face of ``seen`` from its own viewer.

    Returns
    -------
    band : Sightings
        First hits of every band ray.
    parent : Sightings
        For each entry of ``band``, the sighting it was grown from.
    rays : int
        Rays traced.
    """
    k = len(seen.face)
    targets = border_band(caster, region, seen)  # (k, 9, 3)
    owner = np.repeat(np.arange(k), 9)
    flat = targets.reshape(-1, 3)
    face, found, rays = _cast_targets(caster, region, seen, owner, flat)
    collected = [found]
    # band edges (point j -> point j+1, closed), halved while their ends see different faces
    ends = face.reshape(k, 9)
    a_pt, b_pt = targets, np.roll(targets, -1, axis=1)
    a_f, b_f = ends, np.roll(ends, -1, axis=1)
    seg_owner = np.repeat(np.arange(k), 9)
    a_pt, b_pt, a_f, b_f = (x.reshape(len(seg_owner), *x.shape[2:]) for x in (a_pt, b_pt, a_f, b_f))
    a_pt, b_pt = _float64(a_pt, b_pt)
    a_f, b_f = _int64(a_f, b_f)
    min_len = MIN_SEGMENT * caster.diagonal
    for _ in range(MAX_DEPTH):
        seg_owner, a_pt, b_pt, a_f, b_f, mid = _kernels.split_segments(
            seg_owner, a_pt, b_pt, a_f, b_f, min_len
        )
        if len(seg_owner) == 0:
            break
        m_f, found, n = _cast_targets(caster, region, seen, seg_owner, mid)
        collected.append(found)
        rays += n
        seg_owner = np.concatenate([seg_owner, seg_owner])
        a_pt, b_pt = np.concatenate([a_pt, mid]), np.concatenate([mid, b_pt])
        a_f, b_f = np.concatenate([a_f, m_f]), np.concatenate([m_f, b_f])
    band = Sightings.concat([c[0] for c in collected])
    parent = seen.subset(np.concatenate([c[1] for c in collected]))
    return band, parent, rays


def _cast_targets(caster, region, seen: Sightings, owner: np.ndarray, targets: np.ndarray):
    """Cast rays from the viewers of ``seen[owner]`` to ``targets``.

    Returns the hit face per ray (-1 for a miss), the sightings with their owners, and the
    ray count.
    """
    origin, direction = region.border_origins(seen.origin[owner], seen.direction[owner], targets)
    if origin.shape != targets.shape:
        origin = np.broadcast_to(origin, targets.shape).copy()
    aimed = np.isfinite(direction).all(axis=1)  # a viewer standing on its target aims nowhere
    if aimed.all():
        found, hits = trace(caster, origin, direction)
        return hits.face, (found, owner[hits.hit]), len(targets)
    found, hits = trace(caster, origin[aimed], direction[aimed])
    face = np.full(len(targets), -1, hits.face.dtype)
    face[aimed] = hits.face
    return face, (found, owner[aimed][hits.hit]), len(targets)


def reverse_sampling(
    caster: RayCaster, region: Region, band: Sightings, parent: Sightings
) -> tuple[Sightings, int, int]:
    """Reverse-sampling rays for the band rays stopped well before their face's plane.

    Returns
    -------
    Sightings
        First hits of the mutated rays.
    rays : int
        Rays traced.
    refused : int
        Mutated rays dropped because no viewer of the region lies on their line.
    """
    # only rays that ended on another face can have met an occluder; of those, the ones
    # stopped well before their parent face's plane (one compiled pass, numpy's arithmetic)
    triangles = caster.soup.triangles
    band_face, parent_face = _int64(band.face, parent.face)
    b_origin, b_direction, b_point, p_point = _float64(band.origin, band.direction, band.point, parent.point)
    idx, t_pred = _kernels.reverse_jumps(
        band_face,
        parent_face,
        caster.normals,
        triangles,
        b_origin,
        b_direction,
        b_point,
        DISCONTINUITY * caster.diagonal,
    )
    if len(idx) == 0:
        return Sightings.empty(), 0, 0
    # just beyond each end of the occluder's cut by the plane of viewer ray and certificate
    beside, direction, ok_dir = _kernels.reverse_rays(
        idx,
        t_pred,
        band_face,
        triangles,
        b_origin,
        b_direction,
        b_point,
        p_point,
        bool(region.at_infinity),
        PASS_BY * caster.diagonal,
    )
    origin, ok = region.origin_on_line(beside, direction)
    ok &= ok_dir
    if not ok.any():
        return Sightings.empty(), 0, int((~ok).sum())
    found, _ = trace(caster, origin[ok], direction[ok])
    return found, int(ok.sum()), int((~ok).sum())
