"""The dense random visibility reference that judges results on real scenes (DESIGN.md §10).

No truth is constructed for a real scene, so a side's visibility is *certified* instead: a
ray that leaves a point of the face and escapes the model proves that the side it left
through can be seen from outside.  The reference casts

* 8 area-uniform points per face x 64 uniformly random directions (512 rays per face); a ray
  leaves through the side its direction points to, its origin pushed 1e-6 of the diagonal
  off the surface on that side;
* then, for the faces from which no ray has escaped yet, rounds of 64, 256, 1,024 and 4,096
  more random rays per face (new points, new directions).

``seen`` is therefore exact where it is True and an upper bound on "hidden" where it is
False (random sampling converges slowly: faces seen only through small gaps stay unseen).
The per-side counts of the first 512 rays decide orientation: a face is *decisive* when at
least 8 of its rays escape and one side escapes at least 4 times as often as the other.

It costs minutes on large scenes, so :func:`reference` caches its result in an ``.npz``
file keyed by the model's bytes, the seed and the parameters.

Eight points judge a face, so a large face that other geometry covers in part is judged
by where those eight happen to fall: on the monastery a ground face of 0.1 % of the
decisive area escapes 0 : 10 (front : back) in the reference and 248 : 308 in 8,192 rays
from as many points.  :func:`confirm` recounts the decisive faces that way
(:data:`CONFIRM_RAYS` rays, each from its own area-uniform point), and where those counts
leave open on which side of the 4x line a face is, it doubles the rays until they tell
(up to :data:`SETTLE_RAYS`).  The faces it also finds decisive, with the side it finds,
are a judge whose verdicts do not depend on where eight points fell, nor on the noise of
512 rays at the line (docs/benchmarks.md, "How much of the error is the reference's").

>>> from meshvis.eval import generators
>>> ref = reference(generators.nested_shells(subdivisions=1).soup, seed=0)
>>> bool(ref.seen[ref.escaped.sum(axis=1) > 0].all())
True
"""

from __future__ import annotations

import hashlib
import os
import time
from dataclasses import dataclass

import numpy as np

from meshvis.io import as_soup, atomic_write
from meshvis.rays.caster import VISIBILITY_OFFSET, RayCaster
from meshvis.rays.samples import uniform_in_triangles, uniform_sphere
from meshvis.repair.evidence import SETTLE_LEVEL, near_the_line
from meshvis.soup import Soup

#: area-uniform points per face in the first round
POINTS_PER_FACE = 8
#: uniformly random directions per point in the first round
DIRECTIONS_PER_POINT = 64
#: rays per still-unseen face in each refinement round
REFINE_ROUNDS = (64, 256, 1024, 4096)
#: a face decides orientation when at least this many of its first-round rays escape ...
MIN_ESCAPES = 8
#: ... and one side escapes at least this many times as often as the other
DOMINANCE = 4.0
#: rays traced per batch (bounded memory)
BATCH_RAYS = 1 << 21
#: bump when the sampling changes, so that old caches are not reused
VERSION = 1
#: rays per decisive face in :func:`confirm`, each from its own area-uniform point
CONFIRM_RAYS = 2048
#: ... and a face whose counts leave open on which side of the :data:`DOMINANCE` line it is
#: (:func:`meshvis.repair.evidence.near_the_line`) rounds of as many rays again, up to this
#: many in all: 2,048 rays can put a face near the line on the wrong side of it
SETTLE_RAYS = 32768


@dataclass(frozen=True)
class Reference:
    """Certified visibility of every face side of one model.

    Attributes
    ----------
    escaped : (m, 2) int64
        Escaping first-round rays per face and side (0 = front, 1 = back).
    cast : (m, 2) int64
        First-round rays per face and side (uniform directions: about half each).
    seen : (m,) bool
        Some ray from the face escaped, in any round: a certificate of visibility.
    seen_side : (m, 2) bool
        The same per side.
    rays : (m,) int64
        Rays cast from each face over all rounds.
    area : (m,) float64
        Face areas, in input units.
    seconds : float
        Time it took to compute (not to load from the cache).
    """

    escaped: np.ndarray
    cast: np.ndarray
    seen: np.ndarray
    seen_side: np.ndarray
    rays: np.ndarray
    area: np.ndarray
    seconds: float

    @property
    def decisive(self) -> np.ndarray:
        """(m,) bool: the faces whose first-round counts decide which side is outside."""
        return _dominant(self.escaped, 1)  # counts, as DESIGN.md §10 defines it

    @property
    def outside_side(self) -> np.ndarray:
        """(m,) int8: the side that escapes more often (0 front, 1 back; 0 on ties)."""
        return (self.escaped[:, 1] > self.escaped[:, 0]).astype(np.int8)

    @property
    def hidden_area(self) -> float:
        """Area of the faces from which no ray escaped (an upper bound on the hidden area)."""
        return float(self.area[~self.seen].sum())

    def orientation_error(self, front_side: np.ndarray) -> float:
        """Share of the decisive area whose front is not the side that escapes more.

        Parameters
        ----------
        front_side : (m,) int
            For every input face, which of its input sides is the front after a repair:
            0 where the face kept its winding, 1 where it was flipped.

        Returns
        -------
        float
            Misoriented decisive area over decisive area (0 when nothing is decisive).
        """
        front_side = np.asarray(front_side).reshape(-1)
        decisive = self.decisive
        total = self.area[decisive].sum()
        if total <= 0:
            return 0.0
        wrong = decisive & (front_side != self.outside_side)
        return float(self.area[wrong].sum() / total)


def reference(model, *, seed: int = 0, cache: str | os.PathLike | None = None, progress=None) -> Reference:
    """The dense random reference of ``model`` (see the module docstring).

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model.
    seed : int
        Seed of the one random generator; same model and seed give the same reference.
    cache : path, optional
        An ``.npz`` file: read when it holds the reference of this model, seed and
        parameters, else (re)written.
    progress : callable, optional
        Called as ``progress(done, total)`` with faces done in the current round.

    Returns
    -------
    Reference
    """
    soup = as_soup(model)
    key = _key(soup, seed)
    if cache is not None and os.path.isfile(cache):
        with np.load(cache) as data:
            if str(data["key"]) == key:
                return Reference(**{f: data[f] for f in _ARRAYS}, seconds=float(data["seconds"]))
    start = time.perf_counter()
    rng = np.random.default_rng(seed)
    caster = RayCaster(soup, offset=VISIBILITY_OFFSET)
    escaped, cast, seen_side, rays = _first_round(soup, caster, rng, progress)
    for per_face in REFINE_ROUNDS:
        todo = np.flatnonzero(~seen_side.any(axis=1) & (soup.areas > 0))
        if len(todo) == 0:
            break
        found, n_rays = _cast(soup, caster, todo, per_face, rng, progress)
        seen_side[todo] |= found
        rays[todo] += n_rays
    ref = Reference(
        escaped=escaped,
        cast=cast,
        seen=seen_side.any(axis=1),
        seen_side=seen_side,
        rays=rays,
        area=soup.areas.copy(),
        seconds=time.perf_counter() - start,
    )
    if cache is not None:
        with atomic_write(cache, "wb") as fh:
            np.savez_compressed(
                fh, key=np.array(key), seconds=ref.seconds, **{f: getattr(ref, f) for f in _ARRAYS}
            )
    return ref


_ARRAYS = ("escaped", "cast", "seen", "seen_side", "rays", "area")


def _dominant(escaped: np.ndarray, cast: np.ndarray | int) -> np.ndarray:
    """Enough escapes, and one side's escape share at least :data:`DOMINANCE` times the other's.

    With ``cast`` 1 the shares are the counts themselves (exactly: integers in float64).
    """
    share = escaped / np.maximum(cast, 1)
    lo, hi = np.sort(share, axis=1).T
    return (escaped.sum(axis=1) >= MIN_ESCAPES) & (hi >= DOMINANCE * lo)


@dataclass(frozen=True)
class Confirmation:
    """The reference's decisive faces, recounted with many points each (:func:`confirm`).

    Attributes
    ----------
    faces : (k,) int64
        The faces recounted: the reference's decisive faces.
    escaped : (k, 2) int64
        Escaping rays per face and side.
    cast : (k, 2) int64
        Rays per face and side.
    """

    faces: np.ndarray
    escaped: np.ndarray
    cast: np.ndarray

    def judged(self, m: int) -> tuple[np.ndarray, np.ndarray]:
        """The faces the recount also finds decisive, and the side it finds outside.

        Parameters
        ----------
        m : int
            Faces of the model.

        Returns
        -------
        decisive : (m,) bool
            Decisive in the reference and in the recount (escape shares at least
            :data:`DOMINANCE` times apart, at least :data:`MIN_ESCAPES` escapes, and
            counts that tell on which side of that line the face is:
            :func:`meshvis.repair.evidence.near_the_line`).
        outside_side : (m,) int8
            The side whose escape share is larger (0 front, 1 back); 0 off ``decisive``.
        """
        decisive = np.zeros(m, bool)
        # a face whose counts still leave the side of the line open is no verdict either way
        decisive[self.faces] = _dominant(self.escaped, self.cast) & ~near_the_line(self.escaped, self.cast)
        share = self.escaped / np.maximum(self.cast, 1)
        side = np.zeros(m, np.int8)
        side[self.faces] = share[:, 1] > share[:, 0]
        side[~decisive] = 0
        return decisive, side


def confirm(
    model,
    ref: Reference,
    *,
    rays: int = CONFIRM_RAYS,
    seed: int = 0,
    cache: str | os.PathLike | None = None,
    progress=None,
) -> Confirmation:
    """Recount the reference's decisive faces with ``rays`` rays each, every ray from its own point.

    A face whose counts leave open on which side of the :data:`DOMINANCE` line it is
    (:func:`meshvis.repair.evidence.near_the_line`) then gets rounds of as many rays again
    as it has, while that holds, up to :data:`SETTLE_RAYS` in all.

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model ``ref`` was computed on.
    ref : Reference
        Its reference.
    rays : int
        Rays per face (uniform directions: about half through each side).
    seed : int
        Seed of the random generator.
    cache : path, optional
        An ``.npz`` file, read when it holds this recount, else (re)written.
    progress : callable, optional
        Called as ``progress(done, total)`` with faces done.

    Returns
    -------
    Confirmation

    Examples
    --------
    >>> from meshvis.eval import generators
    >>> soup = generators.nested_shells(subdivisions=1).soup
    >>> ref = reference(soup, seed=0)
    >>> decisive, side = confirm(soup, ref, rays=256).judged(soup.n_faces)
    >>> bool((side[decisive] == ref.outside_side[decisive]).all())
    True
    """
    soup = as_soup(model)
    faces = np.flatnonzero(ref.decisive)
    key = f"{_key(soup, seed)}:confirm:{rays}:{SETTLE_LEVEL}:{SETTLE_RAYS}:shares:{hashlib.sha256(faces.tobytes()).hexdigest()}"
    if cache is not None and os.path.isfile(cache):
        with np.load(cache) as data:
            if str(data["key"]) == key:
                return Confirmation(faces, data["escaped"], data["cast"])
    rng = np.random.default_rng([seed, 0xC0F])
    caster = RayCaster(soup, offset=VISIBILITY_OFFSET)
    escaped, cast = _recount(soup, caster, faces, rays, rng, progress)
    # a face near the DOMINANCE line gets rounds of as many rays again until its counts tell
    todo = np.flatnonzero(near_the_line(escaped, cast))
    total = rays  # every face still in the rounds has had this many rays
    while len(todo) and 2 * total <= SETTLE_RAYS:
        more = _recount(soup, caster, faces[todo], total, rng, None)
        escaped[todo] += more[0]
        cast[todo] += more[1]
        total *= 2
        todo = todo[near_the_line(escaped[todo], cast[todo])]
    result = Confirmation(faces, escaped, cast)
    if cache is not None:
        with atomic_write(cache, "wb") as fh:
            np.savez_compressed(fh, key=np.array(key), escaped=escaped, cast=cast)
    return result


def _recount(soup: Soup, caster: RayCaster, faces: np.ndarray, rays: int, rng, progress):
    """(k, 2) escaping rays and rays per face and side, ``rays`` per face, each from its own point."""
    escaped = np.zeros((len(faces), 2), np.int64)
    cast = np.zeros((len(faces), 2), np.int64)
    per_batch = max(1, BATCH_RAYS // max(rays, 1))
    for lo in range(0, len(faces), per_batch):
        local = np.arange(lo, min(len(faces), lo + per_batch))
        face = np.repeat(faces[local], rays)
        side, out = _escape(caster, uniform_in_triangles(soup.triangles[face], rng), face, rng)
        escaped[local], cast[local] = _per_side(np.repeat(local - lo, rays), side, out, len(local))
        if progress is not None:
            progress(local[-1] + 1, len(faces))
    return escaped, cast


def _key(soup: Soup, seed: int) -> str:
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(soup.vertices, np.float64).tobytes())
    h.update(np.ascontiguousarray(soup.faces, np.int64).tobytes())
    params = (VERSION, seed, POINTS_PER_FACE, DIRECTIONS_PER_POINT, REFINE_ROUNDS, VISIBILITY_OFFSET)
    h.update(repr(params).encode())
    return h.hexdigest()


def _first_round(soup: Soup, caster: RayCaster, rng: np.random.Generator, progress):
    """8 points x 64 directions per face, counted per side."""
    m = soup.n_faces
    per_face = POINTS_PER_FACE * DIRECTIONS_PER_POINT
    escaped = np.zeros((m, 2), np.int64)
    cast = np.zeros((m, 2), np.int64)
    seen_side = np.zeros((m, 2), bool)
    faces_per_batch = max(1, BATCH_RAYS // per_face)
    for lo in range(0, m, faces_per_batch):
        idx = np.arange(lo, min(m, lo + faces_per_batch))
        points = uniform_in_triangles(np.repeat(soup.triangles[idx], POINTS_PER_FACE, axis=0), rng)
        points = np.repeat(points, DIRECTIONS_PER_POINT, axis=0)
        face = np.repeat(idx, per_face)
        side, out = _escape(caster, points, face, rng)
        escaped[idx], cast[idx] = _per_side(face - lo, side, out, len(idx))
        if progress is not None:
            progress(idx[-1] + 1, m)
    seen_side |= escaped > 0
    rays = np.full(m, per_face, np.int64)
    return escaped, cast, seen_side, rays


def _cast(soup: Soup, caster: RayCaster, todo: np.ndarray, per_face: int, rng, progress):
    """``per_face`` random rays from each face of ``todo``; which sides saw an escape."""
    found = np.zeros((len(todo), 2), bool)
    faces_per_batch = max(1, BATCH_RAYS // per_face)
    for lo in range(0, len(todo), faces_per_batch):
        local = np.arange(lo, min(len(todo), lo + faces_per_batch))
        face = np.repeat(todo[local], per_face)
        points = uniform_in_triangles(soup.triangles[face], rng)
        side, out = _escape(caster, points, face, rng)
        hit_slots = np.repeat(local, per_face)[out] * 2 + side[out]
        found.reshape(-1)[hit_slots] = True
        if progress is not None:
            progress(local[-1] + 1, len(todo))
    return found, np.full(len(todo), per_face, np.int64)


def _per_side(at: np.ndarray, side: np.ndarray, out: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """(k, 2) escaping rays and (k, 2) rays per face and side, from each ray's face position ``at``."""
    slot = at * 2 + side
    escaped = np.bincount(slot, weights=out, minlength=2 * k).reshape(-1, 2).astype(np.int64)
    return escaped, np.bincount(slot, minlength=2 * k).reshape(-1, 2)


def _escape(caster: RayCaster, points: np.ndarray, face: np.ndarray, rng) -> tuple[np.ndarray, np.ndarray]:
    """Uniform directions from points on faces: the side each ray leaves by, and whether it escaped."""
    directions = uniform_sphere(len(points), rng)
    side = (np.einsum("ij,ij->i", directions, caster.normals[face]) < 0).astype(np.int64)
    hits = caster.intersect_from_surface(points, face, side, directions)
    return side, hits.face < 0
