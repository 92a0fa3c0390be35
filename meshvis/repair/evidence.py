"""Per-face visibility evidence: which side of a face a viewer far away sees.

The graph cut labels half-space *nodes*, and a node is a whole cluster of faces: its
label weighs the cluster's escaping rays together, so one face of a large sheet whose
back is seen through a window, or a flagged face whose few escaping rays lose against
its neighbours' inside edges, can end up facing away from the only viewers who see it.
This module asks every face on its own: rays leave area-uniform points of the face in
uniformly random directions (about half through each side, as a viewer at a random place
far away would see it), and the escaping ones are counted per side.

Rays are cast in rounds, each for the faces the rounds before leave open:

1. :data:`FIRST_RAYS` through each side of every face (uniformly on its hemisphere), and
   as many again where none of them escaped (a side whose rays escape 3 % of the time
   escapes none of 32 in a third of the cases);
2. :data:`MORE_RAYS` more, uniformly on the sphere, where the side the face would not show
   escaped at least as often as the side it would show (elsewhere the first round already
   speaks against turning the face: a side escaping 4x as often rarely escapes less in 32
   rays), so that the decision rests on 512 rays, as in the reference of DESIGN.md §10;
3. :data:`LAST_RAYS` more where the side not shown escaped and the evidence is not yet
   decisive either way (a face seen rarely, or from both sides about equally: 512 rays
   leave it to chance whether it reaches :data:`MIN_ESCAPES`, or which side wins); at
   most :data:`LAST_SHARE` times the rays of the first round (or :data:`RARE_MIN_BUDGET`),
   largest faces first.

A face that shows neither side yet (it keeps the input's winding unless its rays decide
it, ``shown`` -1) gets rounds 2 and 3 where its counts leave open on which side of the
:data:`DOMINANCE` line it is (:func:`near_the_line`): which rays a face gets then does
not depend on how it came in wound.  Each face's rays come from a stream of its own
(:class:`RayStream`).

:func:`more_rays` casts further rounds for faces a caller picks: :func:`meshvis.repair.orient`
gives flagged faces whose rays barely escaped, and those whose sign test leans to the side
they do not show without passing, more rays before it decides.  :func:`until_decisive`
casts doubling rounds until a face's few escapes grow to a decision (orient's lone faces,
whose patch cannot speak for them), and :func:`until_settled` until the counts of a face
that leans to the side it does not show tell on which side of the :data:`DOMINANCE` line
it is (:func:`near_the_line`).

Most faces cost 64 rays.  A face's evidence is *decisive* when at least
:data:`MIN_ESCAPES` rays escape and one side escapes at least ``dominance`` (default
:data:`DOMINANCE`) times as often as the other: a face seen only through a thin gap
escapes a few rays of hundreds, and a face seen equally from both sides is no evidence
for either.
"""

from __future__ import annotations

import numpy as np

from meshvis.rays.caster import RayCaster
from meshvis.repair import _kernels
from meshvis.soup import Soup

#: rays per face and side in the first round
FIRST_RAYS = 32
#: more rays per face in the second round (both sides), for the faces whose side not shown
#: escaped in the first round at least as often as the side shown
MORE_RAYS = 448
#: more rays per face in the third round, for the faces whose evidence is not decisive
#: after the second though their side not shown escaped
LAST_RAYS = 2048
#: the third round casts at most this many times the rays of the first round, on the
#: largest of its faces first: an open sheet seen from both sides (a scan) leaves most of
#: its faces undecided, and 2048 rays for each would cost 30x the rest of ``orient``; on a
#: city of real models the round asks for 1.6 times the first round's rays, on the smallest
#: of its faces the most
LAST_SHARE = 0.5
#: :func:`until_decisive` gives its faces this many more rays in its first round, twice
#: as many in each round after it, up to this many: a side seen through a few percent of
#: its directions escapes none of 64 rays in one case of twenty (0.954^64 at 4.6 %)
RARE_FIRST_RAYS = 192
RARE_MOST_RAYS = 4096
#: ... and casts at most this many times the rays of the first round, largest faces first,
#: or at least :data:`RARE_MIN_BUDGET` rays: a model with a few faces tested would
#: otherwise give a lone face no round at all
RARE_SHARE = 2.0
RARE_MIN_BUDGET = 1 << 16
#: :func:`until_settled` starts with this many more rays per face
SETTLE_FIRST_RAYS = 1024
#: ... and casts at most this many times the rays of the first round (or
#: :data:`RARE_MIN_BUDGET`), largest faces first: the faces near the line are seen from both
#: sides about equally, and on a city of real models they ask for 1.1 times the first
#: round's rays, most of them on small faces
SETTLE_SHARE = 0.25
#: ... and goes on while a true ratio of :data:`DOMINANCE` has at least this chance
SETTLE_LEVEL = 0.05
#: ... or this chance, for a face whose counts already pass the line (about to leave the
#: side it shows): leaving needs stronger evidence than staying, and the stricter level for
#: every face near the line would spend the budget on faces below it
LEAVING_LEVEL = 0.01
#: evidence is decisive from this many escaping rays ...
MIN_ESCAPES = 8
#: ... when one side escapes at least this many times as often as the other
DOMINANCE = 4.0
#: a ray that meets nothing within this many bounding-box diagonals of its origin (on
#: the model) has left the model
ESCAPE_REACH = 2.0
#: rays traced per batch (bounded memory)
BATCH_RAYS = 1 << 20
#: :func:`stands_on_ground` looks at the model from straight below through a grid of this
#: many rays per side ...
GROUND_GRID = 64
#: ... and calls a surface a floor where it lies within this share of the model's height
#: above its lowest point ...
GROUND_BAND = 0.1
#: ... and within this many degrees of horizontal ...
GROUND_TILT = 10.0
#: ... and the model a scene standing on a ground where floors are at least this share of
#: what it shows below.  On the shared models: the monastery 0.78, the zdm2 level 1.0, the
#: van Gogh room 0.78; the teapot 0.37, the bunny 0.33, the pandora level 0.40, a car
#: or a plant less than 0.02
GROUND_SHARE = 0.5


class RayStream:
    """The random rays of a model's faces, one stream per face.

    The k-th ray cast from face f depends on the seed, f and k only
    (:func:`meshvis.repair._kernels.ray_uniform`): which faces the rounds below give more
    rays, and in which order, never changes another face's rays.  The rounds choose their
    faces by the side each face shows, which can depend on how the input is wound; with
    one stream for all faces, a face turned over anywhere would shift the rays of every
    face after it.

    The stream also says who sees the model: viewers far away in every direction, or,
    for a scene standing on the ground (``ground``, its up direction), only those above
    the horizon.  Then a ray that leaves the model downward does not escape: the ground
    under the scene stops it, as the ``upper-hemisphere`` region of
    :mod:`meshvis.visibility.regions` has no viewer below the horizon.  The rays drawn are
    the same either way.

    Parameters
    ----------
    seed : int
        Seed of the streams.
    n_faces : int
        Faces of the model.
    ground : (3,) float, optional
        The up direction of the ground the scene stands on; None: no ground.

    Examples
    --------
    >>> s = RayStream(0, 4)
    >>> s.take(np.array([1, 3]), 32).tolist(), s.take(np.array([3]), 64).tolist()
    ([0, 0], [32])
    """

    def __init__(self, seed: int, n_faces: int, ground: np.ndarray | None = None) -> None:
        self.key = _kernels.seed_key(seed)
        self.drawn = np.zeros(n_faces, np.int64)
        self.ground = None if ground is None else np.asarray(ground, np.float64).reshape(3)

    def take(self, faces: np.ndarray, rays: int) -> np.ndarray:
        """The index of the first of ``rays`` rays of each face, and count them as drawn.

        Parameters
        ----------
        faces : (k,) int
            Faces, each at most once.
        rays : int
            Rays per face.

        Returns
        -------
        (k,) int64
            Rays drawn from each face before these.
        """
        faces = np.asarray(faces, np.int64)
        start = self.drawn[faces]
        self.drawn[faces] += rays
        return start


def escapes(
    soup: Soup,
    caster: RayCaster,
    faces: np.ndarray,
    rays: int,
    stream: RayStream,
    through: np.ndarray | None = None,
) -> np.ndarray:
    """Escaping rays per side from ``rays`` uniformly random rays per face.

    Parameters
    ----------
    soup : Soup
        The model ``caster`` was built on
    caster : RayCaster of ``soup``
    faces : (k,) int64
        Faces to cast from, each at most once
    rays : int
        Rays per face
    stream : RayStream
        The rays' random numbers (a stream of ``soup``), and the ground that stops rays
        leaving downward, if any
    through : (k,) int, optional: cast through this side of each face only (0 front,
        1 back), uniformly on its hemisphere; default both, uniformly on the sphere

    Returns
    -------
    (k, 2) int64
        Escaping rays that left through the front (column 0) and the back
    """
    faces = np.asarray(faces, np.int64)
    out = np.zeros((len(faces), 2), np.int64)
    start = stream.take(faces, rays)
    per_batch = max(1, BATCH_RAYS // max(rays, 1))
    reach = ESCAPE_REACH * caster.diagonal
    through_all = np.full(len(faces), -1, np.int64) if through is None else np.asarray(through, np.int64)
    push = caster.offset * caster.diagonal  # origins off the surface
    center = np.asarray(caster.center, np.float64)
    for lo in range(0, len(faces), per_batch):
        local = np.arange(lo, min(len(faces), lo + per_batch))
        k = len(local)
        o32, d32, dist, ok, back = _kernels.escape_queries(
            soup.triangles[faces[local]],
            np.ascontiguousarray(caster.normals[faces[local]]),
            faces[local],
            start[local],
            rays,
            stream.key,
            through_all[local],
            push,
            reach,
            center,
            float(caster.scale),
            float(caster.offset),
        )
        # a ray escapes when nothing lies on it within the model's reach: an any-hit
        # query, cheaper than finding the first hit
        free = ~(caster.occluded_queries(o32, d32, dist) & ok)
        if stream.ground is not None:  # the ground stops every ray that leaves downward
            free &= d32 @ stream.ground.astype(np.float32) >= 0
        free = free.reshape(k, rays)
        back = back.reshape(k, rays)
        out[local, 0] = (free & ~back).sum(axis=1)
        out[local, 1] = (free & back).sum(axis=1)
    return out


def decisive(escaped: np.ndarray, dominance: float | np.ndarray = DOMINANCE) -> np.ndarray:
    """Whether per-side escape counts decide a face's side.

    Parameters
    ----------
    escaped : (k, 2) int
        Escaping rays per face and side.
    dominance : float or (k,) float
        How many times as often the winning side must escape.

    Returns
    -------
    (k,) bool
        At least :data:`MIN_ESCAPES` escapes, and one side ``dominance`` times the other.
    """
    lo, hi = np.sort(escaped, axis=1).T
    return (escaped.sum(axis=1) >= MIN_ESCAPES) & (hi >= np.asarray(dominance) * lo)


def significant(escaped: np.ndarray, level: float) -> np.ndarray:
    """Whether one side escapes more often than chance allows, per face (a sign test).

    Under "both sides escape equally often" the escapes of the side seen more follow a
    binomial law with half probability; the evidence is significant where at least
    :data:`MIN_ESCAPES` rays escape and the chance of so many or more is below ``level``.
    Unlike a fixed dominance, the ratio it asks for falls as the rays grow: 66 : 34 of 100
    escapes passes at ``level=1e-3``, 7 : 1 of 8 does not.

    Parameters
    ----------
    escaped : (k, 2) int
        Escaping rays per face and side.
    level : float
        Significance level of the one-sided test.

    Returns
    -------
    (k,) bool
        The side that escapes more often does so significantly.

    Examples
    --------
    >>> significant(np.array([[66, 34], [7, 1], [50, 50]]), 1e-3).tolist()
    [True, False, False]
    """
    from scipy.special import bdtrc  # P(X > k) of the binomial law; scipy.stats costs 0.7 s to import

    lo, hi = np.sort(np.asarray(escaped, np.int64), axis=1).T
    n = lo + hi
    return (n >= MIN_ESCAPES) & (hi > lo) & (bdtrc(hi - 1, n, 0.5) < level)


def seen_counts(
    soup: Soup,
    caster: RayCaster,
    faces: np.ndarray,
    shown: np.ndarray,
    stream: RayStream,
) -> tuple[np.ndarray, np.ndarray]:
    """Escaping rays per side of each face, over the rounds of the module docstring.

    Parameters
    ----------
    soup : Soup
        The model ``caster`` was built on.
    caster : RayCaster
        The ray caster of ``soup``.
    faces : (k,) int64
        Faces to test.
    shown : (k,) int
        The side (0 front, 1 back) each face would show without this test, or -1 for a
        face that shows neither (it keeps the input's winding unless the test decides it).
    stream : RayStream
        The random numbers of the rays (of ``soup``'s faces).

    Returns
    -------
    escaped : (k, 2) int64
        Escaping rays per face through its front (column 0) and its back.
    cast : (k,) int64
        Rays cast per face (about half of them through each side).
    """
    faces = np.asarray(faces, np.int64)
    shown = np.asarray(shown, np.int64)
    k = np.arange(len(faces))
    escaped = np.zeros((len(faces), 2), np.int64)
    for through in (0, 1):
        escaped += escapes(soup, caster, faces, FIRST_RAYS, stream, through=np.full(len(faces), through))
    cast = np.full(len(faces), 2 * FIRST_RAYS, np.int64)
    # faces from which nothing escaped get a second look through each side: one seen in
    # 3 % of its directions escapes none of 32 in a third of the cases (0.97^32)
    none = np.flatnonzero(escaped.sum(axis=1) == 0)
    for through in (0, 1):
        escaped[none] += escapes(
            soup, caster, faces[none], FIRST_RAYS, stream, through=np.full(len(none), through)
        )
    cast[none] += 2 * FIRST_RAYS
    # a face that shows neither side (``shown`` -1) gets more rays where its counts leave
    # open on which side of the 4x line it is: only there can they decide it
    neither = shown < 0
    other, own = _other_own(escaped, shown, k)
    again = np.flatnonzero(np.where(neither, near_the_line(escaped), (other > 0) & (other >= own)))
    if len(again):
        escaped[again] += escapes(soup, caster, faces[again], MORE_RAYS, stream)
        cast[again] += MORE_RAYS
    other, own = _other_own(escaped, shown, k)
    leaning = np.where(neither, near_the_line(escaped), (other > 0) & (DOMINANCE * other > own))
    last = np.flatnonzero(leaning & ~decisive(escaped))
    more_rays(soup, caster, faces, escaped, cast, last, LAST_RAYS, LAST_SHARE, stream, RARE_MIN_BUDGET)
    return escaped, cast


def more_rays(
    soup: Soup,
    caster: RayCaster,
    faces: np.ndarray,
    escaped: np.ndarray,
    cast: np.ndarray,
    which: np.ndarray,
    rays: int,
    share: float,
    stream: RayStream,
    floor: int = 0,
) -> np.ndarray:
    """Cast ``rays`` more rays from each face ``faces[which]``, adding to ``escaped`` and ``cast`` in place.

    At most ``share`` times the rays of the first round (``2 * FIRST_RAYS`` per face of
    ``faces``), or ``floor`` rays when that is more, are cast, on the largest of the faces
    first: the error is measured in area.

    Parameters
    ----------
    soup, caster : the model and its RayCaster
    faces : (k,) int64
        The faces tested
    escaped : (k, 2) int64
        Escaping rays per face and side so far (updated)
    cast : (k,) int64
        Rays cast per face so far (updated)
    which : (j,) int
        Positions in ``faces`` that get more rays
    rays : int
        Rays per face.
    share : float
        The cap.
    stream : RayStream
        The rays' random numbers (a stream of ``soup``).
    floor : int
        Rays the cap allows at least (a model with few faces tested).

    Returns
    -------
    (i,) int64
        The positions of ``which`` that were cast from (all, or the largest under
    the cap), sorted
    """
    cap = max(int(share * 2 * FIRST_RAYS * len(faces)), floor) // rays
    return _cast_largest(soup, caster, faces, escaped, cast, np.asarray(which, np.int64), rays, cap, stream)


def until_decisive(
    soup: Soup,
    caster: RayCaster,
    faces: np.ndarray,
    escaped: np.ndarray,
    cast: np.ndarray,
    which: np.ndarray,
    shown: np.ndarray,
    stream: RayStream,
    share: float = RARE_SHARE,
) -> None:
    """Rounds of more rays for faces whose few escapes leave their side open (in place).

    Every face of ``faces[which]`` gets :data:`RARE_FIRST_RAYS` more rays, and then each
    round twice as many as the one before (up to :data:`RARE_MOST_RAYS`) while some of its
    rays escaped, the side it does not show escaped at least as often as the side it shows
    (where the shown side leads, more rays would mostly confirm it; where none escaped
    after a round, the face is all but unseen), and either its escapes stay below
    :data:`MIN_ESCAPES` or a sign test at :data:`SETTLE_LEVEL` (:func:`significant`) does
    not yet tell which side is seen more (a face that only its own rays decide takes the
    side seen more often, and a tie keeps the side it shows: on the pandora level a lone
    face seen 4.7x as often through its back stopped at 10 : 10).  The rounds cast at most
    :data:`RARE_SHARE` times the rays of the first round (``2 * FIRST_RAYS`` per face of
    ``faces``) or :data:`RARE_MIN_BUDGET` rays, whichever is more, on the largest faces
    first.

    Parameters
    ----------
    soup, caster, faces, escaped, cast, which, stream : as :func:`more_rays` (``which``: the
        positions in ``faces`` that get the rounds)
    shown : (k,) int
        The side (0 front, 1 back) each face shows
    share : float
        The cap in place of :data:`RARE_SHARE` (the floor stays)

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box()
    >>> soup = Soup(np.asarray(box.vertices), np.asarray(box.faces))
    >>> caster = RayCaster(soup)
    >>> faces = np.arange(soup.n_faces)
    >>> escaped, cast = np.zeros((12, 2), np.int64), np.zeros(12, np.int64)
    >>> shown = np.ones(12, np.int64)  # every face shows its back, the side inside the box
    >>> until_decisive(soup, caster, faces, escaped, cast, [0, 1, 2], shown, RayStream(0, 12))
    >>> cast[:4].tolist(), bool((escaped[:3, 0] >= MIN_ESCAPES).all()), int(escaped[:, 1].sum())
    ([192, 192, 192, 0], True, 0)
    """
    shown = np.asarray(shown, np.int64)

    def keep(rows: np.ndarray) -> np.ndarray:
        total = escaped[rows].sum(axis=1)
        other, own = _other_own(escaped, shown, rows)
        untold = (total < MIN_ESCAPES) | ~significant(escaped[rows], SETTLE_LEVEL)
        return (total > 0) & untold & (other >= own)

    _rounds(soup, caster, faces, escaped, cast, which, keep, RARE_FIRST_RAYS, stream, share)


def until_settled(
    soup: Soup,
    caster: RayCaster,
    faces: np.ndarray,
    escaped: np.ndarray,
    cast: np.ndarray,
    which: np.ndarray,
    shown: np.ndarray,
    stream: RayStream,
) -> int:
    """Rounds of more rays for faces that lean to their other side near the :data:`DOMINANCE` line (in place).

    A face seen 7x as often through the side it does not show can escape 41 : 11 in 2,560
    rays (3.7x) and keep its side, and one seen 3x as often can pass 4x.  Every face of
    ``faces[which]`` whose side not shown escaped more often, and whose counts do not yet
    tell on which side of the line it is (:func:`near_the_line` at :data:`SETTLE_LEVEL`,
    or at :data:`LEAVING_LEVEL` where they pass it), gets :data:`SETTLE_FIRST_RAYS` more
    rays, then twice as many per round (up to :data:`RARE_MOST_RAYS`) while that still
    holds, within :data:`SETTLE_SHARE` times the rays of the first round (``2 * FIRST_RAYS``
    per face of ``faces``) or :data:`RARE_MIN_BUDGET` rays, largest faces first.

    Parameters
    ----------
    soup, caster, faces, escaped, cast, which, shown, stream : as :func:`until_decisive`

    Returns
    -------
    int
        Faces left out: a round was due to them, but the budget was spent on larger faces.
    """
    shown = np.asarray(shown, np.int64)

    def keep(rows: np.ndarray) -> np.ndarray:
        other, own = _other_own(escaped, shown, rows)
        level = np.where(other >= DOMINANCE * own, LEAVING_LEVEL, SETTLE_LEVEL)
        return (other > own) & near_the_line(escaped[rows], level=level)

    which = np.asarray(which, np.int64)
    return _rounds(
        soup, caster, faces, escaped, cast, which[keep(which)], keep, SETTLE_FIRST_RAYS, stream, SETTLE_SHARE
    )


def near_the_line(
    escaped: np.ndarray, cast: np.ndarray | None = None, level: float | np.ndarray = SETTLE_LEVEL
) -> np.ndarray:
    """Whether a face's counts leave open on which side of the :data:`DOMINANCE` line it is.

    Of ``n`` escapes the side with the larger escape share took ``x``; at a true share
    ratio of exactly ``D = DOMINANCE`` it would take each escape with chance
    ``D c1 / (D c1 + c0)`` (``c1`` its rays, ``c0`` the other side's; ``D / (D + 1)`` for
    equal rays), a binomial law.  The counts tell the side of the line where a count as
    far from that law's mean as ``x``, or farther, has a chance below ``level``.

    Parameters
    ----------
    escaped : (k, 2) int
        Escaping rays per face and side.
    cast : (k, 2) int, optional
        Rays per face and side (default: equal).
    level : float or (k,) float
        Chance below which the counts tell.

    Returns
    -------
    (k,) bool
        Some ray escaped, and the counts leave the side of the line open.

    Examples
    --------
    >>> near_the_line(np.array([[41, 11], [87, 36], [3, 60], [0, 0]])).tolist()
    [True, False, False, False]
    """
    from scipy.special import bdtr, bdtrc  # P(X <= k) and P(X > k) of the binomial law

    escaped = np.asarray(escaped, np.int64)
    cast = np.ones_like(escaped) if cast is None else np.asarray(cast, np.int64)
    rows = np.arange(len(escaped))
    more = (escaped[:, 1] * cast[:, 0] > escaped[:, 0] * cast[:, 1]).astype(np.int64)
    hi, lo = escaped[rows, more], escaped[rows, 1 - more]
    c_hi, c_lo = cast[rows, more], cast[rows, 1 - more]
    n = lo + hi
    line = DOMINANCE * c_hi / np.maximum(DOMINANCE * c_hi + c_lo, 1)
    above = hi * c_lo >= DOMINANCE * lo * c_hi
    chance = np.where(above, bdtrc(hi - 1, n, line), bdtr(hi, n, line))
    return (n > 0) & (chance >= level)


def _other_own(escaped: np.ndarray, shown: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Escapes of ``rows`` through the side each does not show, and through the side it shows.

    A face that shows neither side yet (``shown`` -1) counts its side seen more often as
    the side it does not show: every round open to a face leaning away from its side is
    open to it.
    """
    e = escaped[rows]
    s = shown[rows]
    side = np.where(s >= 0, s, (e[:, 1] >= e[:, 0]).astype(np.int64) ^ 1)
    k = np.arange(len(rows))
    return e[k, 1 - side], e[k, side]


def _rounds(
    soup, caster, faces, escaped, cast, which, keep, first: int, stream, share: float = RARE_SHARE
) -> int:
    """Doubling rounds of rays from ``faces[which]`` while ``keep(rows)`` holds (the budget of :func:`until_decisive`).

    Returns the faces left out: due a round, but beyond the budget.
    """
    which = np.asarray(which, np.int64)
    budget = max(int(share * 2 * FIRST_RAYS * len(faces)), RARE_MIN_BUDGET)
    rays, left_out = first, 0
    while len(which) and rays <= min(RARE_MOST_RAYS, budget):
        asked = len(which)
        which = _cast_largest(soup, caster, faces, escaped, cast, which, rays, budget // rays, stream)
        left_out += asked - len(which)
        budget -= rays * len(which)
        which = which[keep(which)]
        rays *= 2
    if rays <= RARE_MOST_RAYS:  # the budget ended the rounds of the faces still kept
        left_out += len(which)
    return left_out


def _cast_largest(soup, caster, faces, escaped, cast, which, rays: int, cap: int, stream) -> np.ndarray:
    """``rays`` more rays from the ``cap`` largest faces of ``faces[which]`` (all when fewer).

    Adds to ``escaped`` and ``cast`` in place; returns the positions cast from, sorted.
    """
    if len(which) > cap:
        by_area = np.argsort(-soup.areas[faces[which]], kind="stable")
        which = np.sort(which[by_area[:cap]])
    if len(which):
        escaped[which] += escapes(soup, caster, faces[which], rays, stream)
        cast[which] += rays
    return which


def seen_side(
    soup: Soup,
    caster: RayCaster,
    faces: np.ndarray,
    shown: np.ndarray,
    stream: RayStream,
    dominance: float | np.ndarray = DOMINANCE,
) -> tuple[np.ndarray, np.ndarray, int]:
    """The side a viewer sees of each face, where the evidence is decisive.

    Parameters
    ----------
    soup, caster : the model and its RayCaster
    faces : (k,) int64
        Faces to test
    shown : (k,) int
        The side (0 front, 1 back) each face would show without this test
    stream : RayStream
        The rays' random numbers (a stream of ``soup``)
    dominance : float or (k,) float, the dominance that makes a face's evidence decisive
        (:func:`decisive`)

    Returns
    -------
    side : (k,) int8
        The side that escapes more often (``shown`` on a tie)
    sure : (k,) bool
        The evidence is decisive (:func:`decisive`)
    rays : int
        Rays cast
    """
    shown = np.asarray(shown, np.int64)
    escaped, cast = seen_counts(soup, caster, faces, shown, stream)
    return more_seen(escaped, shown), decisive(escaped, dominance), int(cast.sum())


def more_seen(escaped: np.ndarray, shown: np.ndarray) -> np.ndarray:
    """The side whose rays escape more often; a tie keeps the side shown.

    Parameters
    ----------
    escaped : (k, 2) int
        Escapes per face from its front and its back
    shown : (k,) int
        The side (0 front, 1 back) each face shows without the evidence, or -1 for a face
        that shows neither yet (a tie gives it -1)

    Returns
    -------
    (k,) int8
        The side seen more often

    Examples
    --------
    >>> more_seen(np.array([[3, 9], [5, 5], [7, 1], [4, 4]]), np.array([0, 1, 1, -1])).tolist()
    [1, 1, 0, -1]
    """
    tie = escaped[:, 1] == escaped[:, 0]
    return np.where(tie, shown, escaped[:, 1] > escaped[:, 0]).astype(np.int8)


def stands_on_ground(soup: Soup, caster: RayCaster, up: np.ndarray) -> bool:
    """Whether the model is a scene standing on a ground: seen from below, mostly a floor.

    Rays go straight up from a :data:`GROUND_GRID` x :data:`GROUND_GRID` grid under the
    model's footprint.  Of those that meet the model, the share whose first surface is a
    floor (within :data:`GROUND_TILT` degrees of horizontal, within :data:`GROUND_BAND` of
    the height above the lowest point) must reach :data:`GROUND_SHARE`.  Such a scene is
    seen from above its ground only (:class:`RayStream`'s ``ground``); an object that
    rests on a few points (a car on its wheels, a plant in its pot) is not one.  The
    answer depends on the geometry and ``up`` only, not on how the faces are wound.

    Parameters
    ----------
    soup : Soup
        The model ``caster`` was built on.
    caster : RayCaster
        Its ray caster.
    up : (3,) float
        The up direction.

    Returns
    -------
    bool
        The model stands on a ground.

    Examples
    --------
    >>> import trimesh
    >>> slab = trimesh.creation.box(extents=(10, 10, 1))
    >>> soup = Soup(np.asarray(slab.vertices), np.asarray(slab.faces))
    >>> up = np.array([0.0, 0.0, 1.0])
    >>> stands_on_ground(soup, RayCaster(soup), up), stands_on_ground(soup, RayCaster(soup), -up)
    (True, True)
    >>> ball = trimesh.creation.icosphere(3)
    >>> soup = Soup(np.asarray(ball.vertices), np.asarray(ball.faces))
    >>> stands_on_ground(soup, RayCaster(soup), up)
    False
    """
    up = np.asarray(up, np.float64)
    up = up / np.linalg.norm(up)
    if soup.n_faces == 0:
        return False
    # two horizontal axes, and the grid of the footprint in them
    across = np.eye(3)[np.argmin(np.abs(up))]
    e1 = np.cross(up, across)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(up, e1)
    v = soup.vertices
    height = v @ up
    low, tall = height.min(), np.ptp(height)
    cells = (np.arange(GROUND_GRID) + 0.5) / GROUND_GRID
    a = (v @ e1).min() + cells * np.ptp(v @ e1)
    b = (v @ e2).min() + cells * np.ptp(v @ e2)
    a, b = (x.ravel() for x in np.meshgrid(a, b))
    below = low - caster.diagonal * 0.01  # under the lowest point
    origins = a[:, None] * e1 + b[:, None] * e2 + below * up
    hits = caster.intersect(origins, np.broadcast_to(up, origins.shape))
    if not hits.hit.any():
        return False
    face = hits.face[hits.hit]
    flat = np.abs(soup.normals[face] @ up) >= np.cos(np.radians(GROUND_TILT))
    near = soup.triangles[face].max(axis=1) @ up <= low + GROUND_BAND * tall
    return bool((flat & near).mean() >= GROUND_SHARE)
