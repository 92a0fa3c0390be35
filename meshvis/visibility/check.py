"""The self-check of a removal: fresh random lines of sight from every removed face.

A search by sight certifies what it sees and only estimates what it does not; the cut
does not look at lines of sight at all.  So after every removal a fixed number of random
seed rays (:data:`CHECK_RAYS` per face) start at area-uniform points of every removed face
and run to random viewers of the region (for ``outside``: uniformly random directions
that escape), drawn from a random stream of their own (:data:`CHECK_STREAM`), so that
they repeat nothing the search did.  A face one of them reaches was seen: it should not
have been removed.  The check only reports; the removal stays what its method decided.
The constants are read by the command line, which does not load the ray tracer for them.

The same draw from another stream (:data:`RESCUE_STREAM`) is the removal's last pass by
sight, the *rescue* (:func:`rescue_pass`): a face that is about to be removed and that one
of its random rays reaches a viewer from is kept (:func:`meshvis.remove_interior`,
:func:`meshvis.layers`).  It spends its rays where a view is likely: every face gets
:data:`RESCUE_FIRST_RAYS`, and a face that shares a corner with a seen or rescued face gets
:data:`RESCUE_RAYS` in all (rounds, until no newly rescued face has such a neighbour left).
A face seen only through a gap whose neighbours the search saw through the same gap is
seen along nearly the same line as they are: after the first rays, every such face also
gets :data:`SIGHT_AIM_RAYS` rays along the search's sighting of each of its seen
neighbours (:attr:`meshvis.visibility.Visibility.sighting`), turned by a few degrees.
A face deep inside an enclosed region, all of whose neighbours are hidden too, gets the
first rays only: on a city of a million faces most unseen faces are of this kind.  The
check that is reported afterwards draws its own stream again, so it judges the removal
with rays that the removal did not see.

Of a removed face that a viewer sees with probability *p* per random ray, the check finds
it with probability ``1 - (1 - p) ** CHECK_RAYS``: it catches faces that are plainly
visible (a face left out by a budget or a bug), not those seen only through rare gaps.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from meshvis.visibility.regions import Region
    from meshvis.visibility.visible import Visibility

#: random rays from each removed face
CHECK_RAYS = 64
#: the check's random stream: ``numpy.random.default_rng([seed, CHECK_STREAM])``, apart from
#: the search's ``default_rng(seed)``
CHECK_STREAM = 0x5E1FC4EC
#: random rays from each face in the rescue pass: on a car of 3.9 k faces whose search left
#: a face seen in 752 pixels per million of one view, 64 rays kept 1 face and the view stayed
#: at 752, 256 kept 2 and brought it to 139, at 2-7 % of the removal's time
RESCUE_RAYS = 256
#: the rescue pass's rays next to seen faces stop at this share of the search's rays (the
#: count per face is lowered; the report says for how many faces)
RESCUE_SHARE = 0.2
#: random rays from each face in the rescue pass's first round, also from faces none of
#: whose neighbours was seen (the others get :data:`RESCUE_RAYS` in all)
RESCUE_FIRST_RAYS = 32
#: the rescue pass's random stream: ``numpy.random.default_rng([seed, RESCUE_STREAM])``
RESCUE_STREAM = 0x2E5C0E
#: rays traced per batch (bounded memory, about 200 bytes a ray)
CHECK_BATCH = 1 << 20
#: rays from each unseen neighbour of a rescued face along the rescued face's line of sight
AIM_RAYS = 64
#: how far those rays turn from it (radians, the standard deviation of a random turn)
AIM_SPREAD = 0.03
#: rays from each unseen face next to a face the search saw, along the search's sighting of
#: that neighbour (per shared corner, the neighbour the most of the search's rays saw: on
#: the van Gogh room the neighbour the fewest rays saw was often one seen through a crack
#: far narrower than a pixel, and the faces found through it took 16 % of the hidden area
#: at seed 0 with no change to any view)
SIGHT_AIM_RAYS = 8
#: how far those rays turn from the sighting (radians, the standard deviation of a random
#: turn: gaps seen within a few degrees of one direction)
SIGHT_AIM_SPREAD = 0.035
#: sightings whose border is sampled at once in the rescue pass (each costs tens of rays)
SPREAD_BATCH = 1 << 14


@dataclass
class SelfCheck:
    """Result of :func:`self_check`.

    Attributes
    ----------
    rays_per_face : int
        Random rays from each removed face.
    faces : int
        Removed faces checked (faces of zero area have nothing to see and are not).
    seen : (m,) bool
        Per input face: removed, and a check ray saw it.
    seen_area_fraction : float
        Area of the seen faces over the area removed (0 when nothing was removed).
    rays : int
        Rays traced.
    seconds : float
    seen_side : (m, 2) bool
        Per input face and side (0 front, 1 back): a ray from that side reached a viewer.
    full_faces : int or None
        The rescue pass (:func:`rescue_pass`): faces that got ``rays_per_face`` rays (the
        others got :data:`RESCUE_FIRST_RAYS`); None for the self-check, where every face did.
    short_faces : int or None
        The rescue pass: faces next to a seen one that got fewer than ``rays_per_face``
        rays because the pass reached its budget.
    """

    rays_per_face: int
    faces: int
    seen: np.ndarray
    seen_area_fraction: float
    rays: int
    seconds: float
    seen_side: np.ndarray
    full_faces: int | None = None
    short_faces: int | None = None

    def report(self) -> dict:
        """JSON-ready summary."""
        d: dict[str, int | float | None] = {
            "rays_per_face": self.rays_per_face,
            "faces_checked": self.faces,
            "faces_seen": int(self.seen.sum()),
            "seen_area_fraction": self.seen_area_fraction,
            "rays": self.rays,
            "seconds": self.seconds,
        }
        if self.full_faces is not None:
            d["faces_full_rays"] = self.full_faces
            d["faces_short_of_rays"] = self.short_faces
        return d

    def summary(self) -> str:
        """One line for the console."""
        return (
            f"self-check: {self.rays_per_face} fresh random rays from each of {self.faces} removed faces saw "
            f"{int(self.seen.sum())} of them ({100 * self.seen_area_fraction:.3g} % of the removed area)"
        )


def self_check(
    caster,
    region: Region,
    removed: np.ndarray,
    *,
    rays: int = CHECK_RAYS,
    seed: int = 0,
    stream: int = CHECK_STREAM,
) -> SelfCheck:
    """Cast ``rays`` fresh random rays from every removed face to viewers of ``region``.

    Parameters
    ----------
    caster : RayCaster
        The scene that sight is traced against (see-through faces left out or not, as
        in the removal).
    region : Region
        Where viewers are, bound to the model (:meth:`Region.bind`).
    removed : (m,) bool
        The removed faces.
    rays : int
        Rays per removed face (0: no check).
    seed : int
        The removal's seed; the check draws from its own stream of it.
    stream : int
        That stream: :data:`CHECK_STREAM` for the check, :data:`RESCUE_STREAM` for the
        rescue pass.

    Returns
    -------
    SelfCheck

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> from meshvis.rays.caster import RayCaster
    >>> from meshvis.visibility import parse_region
    >>> box = trimesh.creation.box()
    >>> removed = np.zeros(12, bool); removed[0] = True
    >>> check = self_check(RayCaster(box), parse_region("outside").bind(box), removed)
    >>> check.faces, int(check.seen.sum())
    (1, 1)
    """
    import numpy as np

    start = time.perf_counter()
    soup = caster.soup
    removed = np.asarray(removed, bool).reshape(soup.n_faces)
    faces = np.flatnonzero(removed & (soup.areas > 0))
    rng = np.random.default_rng([int(seed), int(stream)])
    seen_side = np.zeros((soup.n_faces, 2), bool)
    rays = max(int(rays), 0)
    cast = _cast(caster, region, faces, rays, rng, None, seen_side)
    return _result(soup, removed, faces, rays, cast, seen_side, start)


def rescue_pass(
    caster,
    region: Region,
    unseen: np.ndarray,
    seen: np.ndarray,
    *,
    rays: int = RESCUE_RAYS,
    first: int = RESCUE_FIRST_RAYS,
    seed: int = 0,
    search: Visibility | None = None,
    budget: int | None = None,
) -> SelfCheck:
    """The rescue: random rays from the faces about to be removed, most next to what was seen.

    Every face of ``unseen`` gets ``first`` random rays to viewers of ``region``; every one
    that shares a corner (vertices with identical coordinates) with a face of ``seen`` then
    gets :data:`SIGHT_AIM_RAYS` rays along the ``search``'s sighting of such a neighbour, per
    shared corner; then every one that shares a corner with a face of ``seen`` or with a
    rescued face gets ``rays - first`` random rays more, round after round while the rounds
    rescue faces with such neighbours left.  A face one of its rays reaches a viewer from is
    rescued.

    Parameters
    ----------
    caster : RayCaster
        The scene sight is traced against.
    region : Region
        Where viewers are, bound to the model.
    unseen : (m,) bool
        The faces about to be removed.
    seen : (m,) bool
        The faces seen already (their neighbours get every ray).
    rays : int
        Rays of a face next to a seen one (0: no rays at all).
    first : int
        Rays of every face (at most ``rays``).
    seed : int
        The removal's seed; the pass draws from :data:`RESCUE_STREAM` of it.
    search : Visibility, optional
        The search that saw ``seen``: its sightings aim rays, and its rays set the default
        ``budget`` (:data:`RESCUE_SHARE` of them).  Without it, no rays are aimed along
        sightings and there is no budget.
    budget : int, optional
        Once the pass has cast this many rays, the faces next to seen ones get fewer than
        ``rays`` (as many as fit; the first round and the aimed rays are always cast).

    Returns
    -------
    SelfCheck
        ``seen``: the rescued faces; ``full_faces``: the faces that got ``rays``;
        ``short_faces``: those next to a seen face that the budget left with fewer.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> from meshvis.rays.caster import RayCaster
    >>> from meshvis.visibility import parse_region
    >>> box = trimesh.creation.box()
    >>> unseen = np.zeros(12, bool); unseen[0] = True
    >>> r = rescue_pass(RayCaster(box), parse_region("outside").bind(box), unseen, ~unseen)
    >>> r.faces, r.full_faces, int(r.seen.sum())
    (1, 0, 1)
    """
    import numpy as np

    start = time.perf_counter()
    soup = caster.soup
    unseen = np.asarray(unseen, bool).reshape(soup.n_faces)
    seen = np.asarray(seen, bool).reshape(soup.n_faces)
    if budget is None and search is not None:
        budget = int(RESCUE_SHARE * search.rays["total"])
    todo = unseen & (soup.areas > 0)
    faces = np.flatnonzero(todo)
    rng = np.random.default_rng([int(seed), RESCUE_STREAM])
    seen_side = np.zeros((soup.n_faces, 2), bool)
    rays = max(int(rays), 0)
    first = min(max(int(first), 0), rays)
    sightings: list = []
    cast = _cast(caster, region, faces, first, rng, todo, seen_side, sightings)
    full = np.zeros(soup.n_faces, bool)
    tried = np.zeros(soup.n_faces, bool)  # had their second round, full or cut short
    short = 0
    if rays > first and len(faces):
        corners = caster.vertex_groups.corner_groups(soup.faces, len(soup.vertices))
        if search is not None and search.sighting is not None:
            cast += _aim_sightings(caster, region, corners, search, seen, todo, rng, seen_side, sightings)
        rescued = seen_side.any(axis=1)
        frontier = np.asarray(seen, bool) | rescued
        aimed = 0
        while True:
            cast += _aim(caster, region, corners, sightings[aimed:], todo, rng, seen_side, sightings)
            aimed = len(sightings)
            now = seen_side.any(axis=1)
            frontier |= now & ~rescued
            rescued = now
            touched = np.zeros(int(corners.max()) + 1, bool)
            touched[corners[frontier].ravel()] = True
            near = todo & ~tried & ~rescued & touched[corners].any(axis=1)
            if not near.any():
                break
            more = np.flatnonzero(near)
            per = rays - first if budget is None else min(rays - first, max(budget - cast, 0) // len(more))
            if per < rays - first:
                short += len(more)
                if per == 0:
                    break
            cast += _cast(caster, region, more, per, rng, todo, seen_side, sightings)
            tried |= near
            if per == rays - first:
                full |= near
            now = seen_side.any(axis=1)
            frontier = np.logical_and(now, ~rescued)
            rescued = now
    out = _result(soup, unseen, faces, rays, cast, seen_side, start)
    out.full_faces, out.short_faces = int(full.sum()), short
    return out


def _aim_sightings(
    caster,
    region: Region,
    corners,
    search: Visibility,
    seen,
    todo,
    rng,
    seen_side: np.ndarray,
    sightings: list,
) -> int:
    """Rays from each unseen face of ``todo`` along the search's sightings of its seen neighbours.

    Per corner group, the face of ``seen`` with a sighting that the most of the search's
    rays saw lends its sighting's direction; each unseen face of ``todo`` casts
    :data:`SIGHT_AIM_RAYS` rays along the direction of each different neighbour so found,
    turned by about :data:`SIGHT_AIM_SPREAD` radians.  Returns the rays traced.
    """
    import numpy as np

    from meshvis.visibility.sampling import Sightings

    sighting = np.asarray(search.sighting)
    lender = np.flatnonzero(seen & (np.abs(sighting).sum(axis=1) > 0))
    near = todo & ~seen_side.any(axis=1)
    if not len(lender) or not near.any():
        return 0
    group = corners[lender].ravel()
    face = np.repeat(lender, 3)
    seen_by = search.rays_seen[face].sum(axis=1)
    order = np.lexsort((face, -seen_by, group))
    groups, head = np.unique(group[order], return_index=True)
    owner = np.full(int(corners.max()) + 1, -1, np.int64)
    owner[groups] = face[order][head]
    faces = np.flatnonzero(near)
    by = np.sort(owner[corners[faces]], axis=1)  # (k, 3): each corner's lender, -1 for none
    keep = by >= 0
    keep[:, 1:] &= by[:, 1:] != by[:, :-1]  # a neighbour sharing two corners lends once
    row, col = np.nonzero(keep)
    if not len(row):
        return 0
    target = np.repeat(faces[row], SIGHT_AIM_RAYS)
    direction = np.repeat(sighting[by[row, col]], SIGHT_AIM_RAYS, axis=0)
    hits, n = _along(caster, region, target, direction, SIGHT_AIM_SPREAD, rng)
    return n + _spread(caster, region, Sightings.concat(hits), todo, seen_side, sightings)


def _along(caster, region: Region, face: np.ndarray, direction: np.ndarray, spread: float, rng):
    """Viewer rays to random points of ``face`` along ``direction`` turned by about ``spread``.

    Returns the sightings (a list of batches) and the rays traced.
    """
    import numpy as np

    from meshvis.visibility.sampling import trace

    rays, hits = 0, []
    for lo in range(0, len(face), CHECK_BATCH):
        f = face[lo : lo + CHECK_BATCH]
        d = direction[lo : lo + CHECK_BATCH] + spread * rng.normal(size=(len(f), 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        u, v = rng.random(len(f)), rng.random(len(f))
        flip = u + v > 1
        u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
        tri = caster.soup.triangles[f]
        point = tri[:, 0] + u[:, None] * (tri[:, 1] - tri[:, 0]) + v[:, None] * (tri[:, 2] - tri[:, 0])
        origin, ok = region.origin_on_line(point, d)
        hit, _ = trace(caster, origin[ok], d[ok])
        rays += int(ok.sum())
        hits.append(hit)
    return hits, rays


def _aim(
    caster, region: Region, corners, parts: list, todo, rng, seen_side: np.ndarray, sightings: list
) -> int:
    """Rays along the line of sight of each rescued face, to its unseen neighbours.

    A face seen only through a gap is seen along a narrow cone of directions, and so are its
    neighbours: each unseen face of ``todo`` that shares a corner with a face of the new
    sightings ``parts`` gets :data:`AIM_RAYS` rays from random points of it along that
    sighting's direction, turned by a random angle of about :data:`AIM_SPREAD` radians.
    """
    import numpy as np

    from meshvis.visibility.sampling import Sightings

    found = Sightings.concat(parts)
    if not len(found.face):
        return 0
    owner = np.full(int(corners.max()) + 1, -1, np.int64)
    owner[corners[found.face].ravel()] = np.repeat(np.arange(len(found.face)), 3)
    near = todo & ~seen_side.any(axis=1)
    near[near] = (owner[corners[near]] >= 0).any(axis=1)
    faces = np.flatnonzero(near)
    if not len(faces):
        return 0
    by = owner[corners[faces]]
    pick = by[np.arange(len(faces)), np.argmax(by >= 0, axis=1)]
    face = np.repeat(faces, AIM_RAYS)
    direction = found.direction[np.repeat(pick, AIM_RAYS)]
    hits, rays = _along(caster, region, face, direction, AIM_SPREAD, rng)
    return rays + _spread(caster, region, Sightings.concat(hits), todo, seen_side, sightings)


def _cast(
    caster, region: Region, faces: np.ndarray, rays: int, rng, todo, seen_side: np.ndarray, sightings=None
) -> int:
    """``rays`` random rays from each of ``faces``; then border sampling around what they saw.

    Marks the sides of the faces of ``todo`` that a ray saw (in place).  Every face of ``todo``
    seen for the first time has its sighting propagated (:func:`_spread`).  Returns the
    rays traced.
    """
    import numpy as np

    from meshvis.visibility.sampling import Sightings, random_seeds  # the ray tracer: not for the defaults

    per_batch = max(1, CHECK_BATCH // max(rays, 1))
    found = []
    for lo in range(0, len(faces) if rays else 0, per_batch):
        s, _ = random_seeds(caster, region, np.repeat(faces[lo : lo + per_batch], rays), rng)
        found.append(s)
    cast = len(faces) * rays
    if todo is None or not found:
        for s in found:
            seen_side[s.face, s.side] = True
        return cast
    return cast + _spread(caster, region, Sightings.concat(found), todo, seen_side, sightings)


def _fresh(s, todo: np.ndarray, seen_side: np.ndarray):
    """The first sighting of each face of ``todo`` that ``s`` sees for the first time; mark them all."""
    import numpy as np

    on = todo[s.face]
    s = s.subset(np.flatnonzero(on))
    new = ~seen_side[s.face].any(axis=1)
    _, first = np.unique(s.face[new], return_index=True)
    seen_side[s.face, s.side] = True
    return s.subset(np.flatnonzero(new)[first])


def _spread(caster, region: Region, found, todo: np.ndarray, seen_side: np.ndarray, sightings=None) -> int:
    """Border and reverse sampling from each new sighting, as the search does, until nothing new.

    A face that only a rare line of sight reaches (a gap, a crack) has neighbours that the
    same line of sight reaches: its viewer looks at them around the seen face's border.
    Only sightings of faces of ``todo`` seen for the first time are propagated, so each face
    is propagated from once.  Returns the rays traced.
    """
    from meshvis.visibility.sampling import Sightings, border_sampling, reverse_sampling

    rays = 0
    fresh = _fresh(found, todo, seen_side)
    while len(fresh.face):
        if sightings is not None:
            sightings.append(fresh)
        parts = []
        for lo in range(0, len(fresh.face), SPREAD_BATCH):
            band, parent, n_band = border_sampling(caster, region, fresh.subset(slice(lo, lo + SPREAD_BATCH)))
            mutated, n_rev, _ = reverse_sampling(caster, region, band, parent)
            rays += n_band + n_rev
            parts.append(Sightings.concat([band, mutated]))
        fresh = _fresh(Sightings.concat(parts), todo, seen_side)
    return rays


def _result(soup, asked, faces, rays: int, cast: int, seen_side, start: float) -> SelfCheck:
    """The :class:`SelfCheck` of a pass over ``faces`` (of the ``asked`` mask)."""
    seen = seen_side[:, 0] | seen_side[:, 1]
    gone = float(soup.areas[asked].sum())
    return SelfCheck(
        rays_per_face=rays,
        faces=len(faces),
        seen=seen,
        seen_area_fraction=float(soup.areas[seen].sum()) / gone if gone > 0 else 0.0,
        rays=cast,
        seconds=time.perf_counter() - start,
        seen_side=seen_side,
    )
