"""Normal orientation (appendix H §5, "Normal Orientation").

:func:`orient` decides, for every face, which side becomes its front, in named steps:

1. **own sides** — every face whose sides got exactly one outside label (or whose sample
   points are outside on one side only, or more on one side) faces the outside; faces
   seen from both sides are decided by the options below;
2. **hidden sides** — faces with no outside side are oriented by the layer they belong to
   (layer semantics, DESIGN.md §4: each shell faces outward with respect to its layer; with
   ``semantics="cavity"`` shells of even layers face inward), voted by area over their
   orientable patch; faces two-sided at their layer on a patch without a vote are decided
   by ray parity against their own body where that body is closed and parity tells the
   two sides apart, and keep their winding otherwise;
3. **whole patches** — an orientable patch (faces joined by manifold edges after welding,
   flagged faces and degenerate slivers included; a sliver, which has no side of its
   own, shows the side its patch shows)
   is turned as a whole or not at all: every face of a patch with
   a clear area vote takes the patch's side.  What is seen from outside votes (one-sided
   faces; flagged faces whose sample points disagree, weighted by the margin); faces that
   are one-sided only at a deeper layer vote only on patches no layer-1 face votes for,
   and the hidden faces whose side parity decided vote last.
   This keeps a consistently wound model's winding (a face of a self-intersecting fold
   follows its surface) and settles contact faces between touching solids;
4. **visible sides** — the side a viewer sees wins over the patch vote and over layer
   semantics: every face of an *open* patch, except one-sided faces whose cluster's own
   rays already show their side clearly, is tested with rays of its own
   (:mod:`meshvis.repair.evidence`).  A patch of several faces first takes, as a whole,
   the side its tested faces see where their rays pooled decide it (the patch vote
   counts only the faces the cut settled on one side); then each face takes the side
   its own evidence shows where that evidence is decisive (a face whose rays lean against
   its side near the 4x line gets more rays until they tell on which side of it the face
   is); a flagged face (it crosses another surface, across which its patch does not speak
   for it) also takes the side a sign test says is seen more often.  Faces of closed
   patches follow their patch: a closed patch bounds a volume, and a face of it whose
   back pokes out through the surface is a self-intersection, not a face turned the wrong
   way.

   A scene standing on a ground (:func:`meshvis.repair.evidence.stands_on_ground`: seen
   from below, it is mostly a floor at its lowest level) is seen from above its ground
   only: a ray that leaves it downward does not count as seen (the ``upper-hemisphere``
   region's viewers), so a courtyard floor whose underside opens onto the empty space
   below the scene faces up.

   There, a face whose evidence would take it away from the side its patch shows (most
   of the patch's area) keeps that side where viewers above the ground see it
   (:func:`_seen_from_above`): a wall seen from both sides from above, more often
   through its other side, keeps the winding of the walls it belongs to.

The evidence does not depend on how a face comes in wound: the cut and every ray are
drawn on the canonically wound model (:func:`classify_for_orient`,
:mod:`meshvis.geometry.winding`), each face's rays from a stream of its own
(:class:`meshvis.repair.evidence.RayStream`); the input's winding is kept only where the
evidence leaves a face open (with its patch), and it does not vote.  So orienting
``orient``'s output again changes nothing.

Both copies of a sheet stored twice with opposite winding (double-sided by duplication,
:mod:`meshvis.geometry.duplicates`) are written as they are.

Options for the undecided cases:

* faces seen from both sides (both sides outside, wholly or at some of their sample
  points: sheets, leaves, the ground of a scene): ``keep`` (default) leaves them as they
  are unless their own rays see one side decisively more often (4x); they neither vote
  on their patch nor follow its vote, and where nothing decides them they keep the
  winding most of their patch's undecided faces have (:func:`_kept_with_patch`);
  ``duplicate`` emits both orientations of the two-sided ones, ``strongest`` lets the
  side with the larger escaping ray share (outside weight per area, Eq. 7) win;
* flagged faces whose sample points disagree: by area ``majority`` (default) or
  ``duplicate``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis import _validate
from meshvis.errors import ParameterError
from meshvis.geometry.duplicates import in_opposite_copy
from meshvis.graphcut.classify import Classification, classify
from meshvis.graphcut.clusters import Clustering
from meshvis.io.up_axis import up_vector
from meshvis.rays.caster import VISIBILITY_OFFSET
from meshvis.repair.layers import LayerResult, layers
from meshvis.soup import Soup

# status codes per input face
ONE_SIDED, TWO_SIDED, HIDDEN, CONFLICT, DEGENERATE = 0, 1, 2, 3, 4
STATUS_NAMES = ("one-sided", "two-sided", "hidden", "conflict", "degenerate")
#: a flagged face (it crosses another surface) is not spoken for by its patch's winding
#: across that surface: its own rays turn it where the side they see more often wins a
#: sign test at this level (:func:`meshvis.repair.evidence.significant`), not only at 4x.
#: Unflagged faces keep the 4x rule: the two sides of a scan differ a little everywhere
CROSSING_LEVEL = 1e-3
#: flagged faces whose own rays barely escaped (fewer than
#: :data:`meshvis.repair.evidence.MIN_ESCAPES`) would be left to the cut's sample points,
#: which disagree between seeds there: the largest get the last round's rays, at most this
#: many times the rays of the first round, the rest the doubling rounds of
#: :func:`meshvis.repair.evidence.until_decisive` under the same cap.  A lone face (a patch
#: of one face) gets those rounds whatever the cut said: only its own rays speak for it
UNSEEN_SHARE = 0.25
#: a flagged face whose sign test leans to the side it does not show (below this level, but
#: not below :data:`CROSSING_LEVEL`) gets :data:`LEANING_RAYS` more rays before the test
#: decides, so that a large face near the level does not take its side by the seed
LEANING_LEVEL = 0.05
#: rays per leaning face: about 2.5x the escapes it had, so that a face seen 1.5x as often
#: from one side ends far from the test's edge
LEANING_RAYS = 4096
#: ... for at most this many times the rays of the first round, largest faces first
LEANING_SHARE = 0.5
#: a cluster whose hidden side escapes at least this share of the opening threshold does
#: not speak for its faces: near the threshold the cut labels it differently from seed to
#: seed, so its faces are tested with rays of their own
OPENING_NEAR = 0.5
#: an open patch of several faces whose faces' own rays, pooled (area times escape
#: share), see one side this many times as much as the other shows that side as a whole
#: (the per-face dominance of :mod:`meshvis.repair.evidence`): the patch vote counts only
#: the faces the cut settled on one side, which can be a few faces against the rest
POOLED_DOMINANCE = 4.0
#: rays through the side of its patch of a face about to leave it, on a scene seen from
#: above its ground: that side is seen from above where at least
#: :data:`~meshvis.repair.evidence.MIN_ESCAPES` of them escape upward (0.8 %; the walls of
#: the monastery's courtyards let 1-5 % of the rays through their less seen side escape)
ABOVE_RAYS = 1024
#: orient's cut gives a flagged face one sample point per this many times the model's mean
#: face area, at least one and at most ``samples_per_face``
#: (:func:`meshvis.graphcut.nodes.sample_counts`): most flagged faces of a large assembly
#: are small and their points vote alike, and orient's own rays test a face after the cut.
#: The removals' cut keeps every point (``classify``'s default): there each small face's
#: label decides whether it is removed, and fewer points showed more wrong faces.
POINT_AREA = 1.0


@dataclass
class OrientResult:
    """Result of :func:`orient`.

    Attributes
    ----------
    soup : Soup
        The oriented output (input faces, some flipped, plus any duplicates).
    source : (k,) int64
        Input face of every output face
    flipped : (m,) bool
        Input faces written turned over
    duplicated : (m,) bool
        Input faces written in both orientations
    status : (m,) int8
        One of ``STATUS_NAMES`` per input face
    parity_faces : int
        Hidden faces whose side came from ray parity (:func:`parity_side`)
    patch_faces : int
        Faces turned to agree with the vote of their patch
    visibility : dict
        The per-face visibility test: faces ``tested``, faces ``turned``
        to show the side a viewer sees, ``rays`` cast, ``pooled_patches`` (patches
        given the side their faces' rays see, pooled), ``ground`` (seen from above its
        ground only), ``kept_seen_from_above`` (faces kept on their patch's side,
        seen from above the ground: :func:`_seen_from_above`)
    double_sided : int
        Faces kept as they are because they are one copy of a sheet stored
        twice with opposite winding (:mod:`meshvis.geometry.duplicates`)
    view : Visibility or None
        The from-region visibility of :func:`orient_from` (then
        ``classification`` is None)
    input_side : (m,) int8 or None
        The side of each face of ``classification.soup`` that is the input's front:
        :func:`orient` classifies the faces in their canonical winding
        (:func:`classify_for_orient`), so a face listed the other way round there has its
        input front on side 1.
    """

    soup: Soup
    source: np.ndarray
    flipped: np.ndarray
    duplicated: np.ndarray
    status: np.ndarray
    classification: Classification | None
    layers: LayerResult | None
    parity_faces: int = 0
    patch_faces: int = 0
    visibility: dict | None = None
    double_sided: int = 0
    view: Any = None  # the :class:`meshvis.visibility.Visibility` of :func:`orient_from`
    input_side: np.ndarray | None = None

    def report(self, per_face: bool = True) -> dict:
        """The JSON-ready report: counts, the classification's summary, per-face arrays."""
        counts = np.bincount(self.status, minlength=len(STATUS_NAMES))
        d = {
            "input_faces": int(len(self.status)),
            "output_faces": int(self.soup.n_faces),
            "flipped": int(self.flipped.sum()),
            "duplicated": int(self.duplicated.sum()),
            "status_counts": {n: int(c) for n, c in zip(STATUS_NAMES, counts)},
        }
        if self.view is not None:  # oriented toward a region (:func:`orient_from`): no cut
            d["view"] = self.view.report(per_face=False)
            if per_face:
                d["per_face"] = {
                    "flipped": self.flipped,
                    "status": np.asarray(STATUS_NAMES)[self.status],
                    "seen_front": self.view.seen_side[:, 0],
                    "seen_back": self.view.seen_side[:, 1],
                }
            return d
        assert self.classification is not None  # every result without a view has a cut
        d["classification"] = self.classification.report(per_face=False)
        if self.layers is not None:
            d["layers"] = self.layers.report(per_face=False)
        else:
            d["layers"] = "skipped: no hidden faces"
        d["parity_faces"] = (
            self.parity_faces if self.parity_faces else "skipped: every hidden face had a vote"
        )
        d["patch_faces"] = self.patch_faces
        d["double_sided_copies"] = self.double_sided
        vis = self.visibility or {"tested": 0, "turned": 0, "rays": 0}
        d["visibility"] = dict(vis) if vis["tested"] else "skipped: every face is on a closed patch"
        if per_face:
            rows = np.arange(len(self.status))
            side = (
                np.zeros(len(rows), np.int64) if self.input_side is None else self.input_side.astype(np.int64)
            )
            outside = self.classification.outside
            d["per_face"] = {
                "flipped": self.flipped,
                "duplicated": self.duplicated,
                "status": np.asarray(STATUS_NAMES)[self.status],  # names, not codes
                "outside_front": outside[rows, side],  # the sides of the input's winding
                "outside_back": outside[rows, 1 - side],
            }
        return d


def _check(name: str, value: str, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        raise ParameterError(f"{name} must be one of {', '.join(allowed)}; got {value!r}")


def strongest_side(c: Classification) -> np.ndarray:
    """(m,) side (0/1) with the larger escaping share ``w_o / A`` (Eq. 7), per face."""
    w = c.graph.weights.w_out / np.maximum(c.nodes.area, 1e-300)
    return (c.face_labels_from(w)[:, 1] > c.face_labels_from(w)[:, 0]).astype(np.int8)


def surface_vote(
    c: Classification, outer: np.ndarray, decided: np.ndarray, clustering: Clustering
) -> tuple[np.ndarray, np.ndarray]:
    """Side that should face front for every face, voted over its orientable surface patch.

    Faces joined by manifold edges (after welding; flagged faces and degenerate slivers
    included, :func:`_joining`) form patches
    whose sides split into two consistent sets (the orientation double cover of
    :func:`meshvis.graphcut.clusters.cluster_sides`).  Each decided face votes with its area for the
    set its outer side belongs to.  ``clustering`` is those patches' clustering
    (``patches(c).clustering``).

    Returns
    -------
    side : (m,) int8
        The side of each face in the winning set (0 where there is no vote)
    decisive : (m,) bool
        The face's patch has votes and they are not tied
    """
    node = clustering.side_node
    votes = np.zeros(clustering.n_nodes)
    d = np.flatnonzero(decided & (node[:, 0] >= 0))
    np.add.at(votes, node[d, outer[d]], c.soup.areas[d])
    ok = node[:, 0] >= 0
    side = np.zeros(len(outer), np.int8)
    decisive = np.zeros(len(outer), bool)
    v0, v1 = votes[node[ok, 0]], votes[node[ok, 1]]
    side[ok] = (v1 > v0).astype(np.int8)
    decisive[ok] = v0 != v1
    return side, decisive


def parity_side(
    c: Classification, faces: np.ndarray, seed: int = 0, rays: int = 9, max_crossings: int = 64
) -> np.ndarray:
    """Outer side of ``faces`` by ray parity against their own body, where parity tells it.

    From each face's centroid, ``rays`` cosine-distributed rays leave each of its two
    sides (the back's rays mirror the front's), and every crossing of a face of the same
    body (the face's component over all welded edges, non-manifold ones included) is
    counted, coincident copies once each: an even count means the ray started out of the
    body (Jordan's parity rule).  The side with more such rays is the outer side; where
    both sides have as many (a sheet inside a closed body, whose rays cross it an odd
    number of times from either side), parity does not tell, and the face gets -1.
    Meant for the few hidden faces that visibility leaves open: two-sided at their layer,
    on a patch that no one-sided face votes for (a sliver cut off by non-manifold edges
    where solids touch).

    Parameters
    ----------
    c : Classification
        The classification of the model.
    faces : (k,) int
        Faces to decide
    seed : int
        Seed of the ray directions.
    rays : int
        Rays per face and side.
    max_crossings : int
        Crossings followed per ray at most.

    Returns
    -------
    (k,) int8
        0 when the front should face out, 1 when the back should, -1 when parity does not
        tell.
    """
    from meshvis.geometry.adjacency import components, duplicate_faces, edges, face_adjacency
    from meshvis.rays.samples import cosine_hemisphere

    faces = np.asarray(faces, np.int64)
    if len(faces) == 0:
        return np.zeros(0, np.int8)
    soup, caster = c.soup, c.caster
    body = components(soup.n_faces, face_adjacency(edges(c.pre.faces_welded), manifold_only=False))[1]
    # Embree reports one of several coincident copies, and the next step jumps past them
    # all: a hit counts as many crossings as its copy group has faces of the ray's body
    group = duplicate_faces(c.pre.faces_welded).astype(np.int64)
    nb = np.int64(body.max() + 1)
    keys, per_key = np.unique(group * nb + body, return_counts=True)

    def own_copies(face: np.ndarray, of_body: np.ndarray) -> np.ndarray:
        k = group[face] * nb + of_body
        i = np.minimum(np.searchsorted(keys, k), len(keys) - 1)
        return np.where(keys[i] == k, per_key[i], 0)

    f = np.repeat(faces, rays)
    front = cosine_hemisphere(soup.normals[f], np.random.default_rng(seed))
    f = np.concatenate([f, f])
    d = np.concatenate([front, -front])
    side = np.repeat(np.array([0, 1], np.int8), len(front))
    o = caster.push_off(soup.triangles[f].mean(axis=1), f, side)
    step = caster.offset * caster.diagonal
    odd = np.zeros(len(f), bool)
    live = np.arange(len(f))
    for _ in range(max_crossings):  # one pass per crossing depth, all rays together
        h = caster.intersect(o[live], d[live])
        hit = h.hit
        crossed = np.where(hit, own_copies(np.where(hit, h.face, 0), body[f[live]]), 0)
        odd[live] ^= crossed % 2 == 1
        o[live[hit]] = h.points(o[live], d[live])[hit] + d[live[hit]] * step
        live = live[hit]
        if len(live) == 0:
            break
    out_of_body = (~odd).reshape(2, len(faces), rays).sum(axis=2)  # per side, per face
    return np.where(out_of_body[0] == out_of_body[1], -1, out_of_body[1] > out_of_body[0]).astype(np.int8)


@dataclass(frozen=True)
class Patches:
    """Orientable surface patches: faces joined by manifold edges (after welding).

    Attributes
    ----------
    clustering : Clustering
        The orientation double cover (:func:`meshvis.graphcut.clusters.cluster_sides`)
        over every face with three distinct welded corners (:func:`_joining`)
    closed : (m,) bool
        The face's patch is closed: every edge of every face of it is a
        manifold edge between two faces of the patch
    size : (m,) int64
        Faces in the face's patch (0 for a face in none)
    """

    clustering: Clustering
    closed: np.ndarray
    size: np.ndarray


def patches(c: Classification) -> Patches:
    """The orientable patches of the classified model and which of them are closed."""
    from meshvis.geometry.adjacency import edges
    from meshvis.graphcut.clusters import cluster_sides, manifold_face_pairs

    table = edges(c.pre.faces_welded)
    cl = cluster_sides(table, _joining(c))
    patch = cl.cluster
    edge_ok = (table.face_edge >= 0) & (table.count[np.maximum(table.face_edge, 0)] == 2)
    open_patch = np.zeros(max(cl.n_clusters, 1), bool)
    open_patch[patch[~edge_ok.all(axis=1) & (patch >= 0)]] = True
    f, g, _ = manifold_face_pairs(table)
    across = patch[f] != patch[g]  # a manifold edge leaving the patch (degenerate or split face)
    for side in (f[across], g[across]):
        open_patch[patch[side][patch[side] >= 0]] = True
    closed = (patch >= 0) & ~open_patch[np.maximum(patch, 0)]
    size = np.bincount(patch[patch >= 0], minlength=max(cl.n_clusters, 1))
    return Patches(cl, closed, np.where(patch >= 0, size[np.maximum(patch, 0)], 0))


def _patch_side(p: Patches, shows: np.ndarray, areas: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(k,) int8: the side (0 front, 1 back) of each face that most of its patch's area shows.

    ``shows`` is the side each face is written with as its front; a face shows that
    side's node.  ``faces`` themselves do not vote (a degenerate face has no area); where
    the vote is tied (nothing else votes), -1.
    """
    node = p.clustering.side_node
    voters = np.setdiff1d(np.flatnonzero(node[:, 0] >= 0), faces)
    shown = node[voters, np.asarray(shows, np.int64)[voters]]
    area = np.bincount(shown, areas[voters], p.clustering.n_nodes)
    a0, a1 = area[node[faces, 0]], area[node[faces, 1]]
    return np.where(a0 == a1, -1, a1 > a0).astype(np.int8)


def _joining(c: Classification) -> np.ndarray:
    """(m,) bool: the faces that join their neighbours into a patch.

    Every face with three distinct welded corners, degenerate slivers included: a sliver
    has no side of its own, but its edges still tell how its neighbours are wound, and
    leaving it out cuts a consistently wound surface into patches voted on their own (on
    zdm2, 214 hidden faces came back turned apart from the rest of their surface).
    """
    from meshvis.geometry.adjacency import collapsed

    return ~collapsed(c.pre.faces_welded)


def _closed_body(c: Classification) -> np.ndarray:
    """(m,) bool: the face's body has no boundary edge.

    The body is the face's component over all welded edges, non-manifold ones included.
    """
    from meshvis.geometry.adjacency import components, edges, face_adjacency

    table = edges(c.pre.faces_welded)
    body = components(c.soup.n_faces, face_adjacency(table, manifold_only=False))[1]
    edge = np.maximum(table.face_edge, 0)
    at_boundary = ((table.count[edge] == 1) & (table.face_edge >= 0)).any(axis=1)
    open_body = np.zeros(int(body.max()) + 1, bool)
    open_body[body[at_boundary]] = True
    return ~open_body[body]


def _own_sides(
    c: Classification, two_sided: str, given: np.ndarray, both: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Status of every face, the side its own labels put in front, and the faces they leave open.

    ``given`` is the side of each face that is the input's front; faces the labels do not
    decide (faces seen from both sides, ``both``, under ``keep``; flagged faces whose
    sample points are outside as much on either side; hidden faces until
    :func:`_hidden_sides`) keep it and are returned as undecided.
    """
    o = c.outside
    m = c.soup.n_faces
    out0, out1 = o[:, 0] > 0, o[:, 1] > 0
    full0, full1 = o[:, 0] >= 1, o[:, 1] >= 1
    agree = (np.isin(o[:, 0], (0.0, 1.0))) & (np.isin(o[:, 1], (0.0, 1.0)))
    status = np.full(m, ONE_SIDED, np.int8)
    status[agree & full0 & full1] = TWO_SIDED
    status[~out0 & ~out1] = HIDDEN
    status[~agree & (out0 | out1)] = CONFLICT
    status[c.degenerate] = DEGENERATE
    outer = np.asarray(given, np.int8).copy()  # side that should become the front
    one = status == ONE_SIDED
    outer[one] = full1[one]
    conflict = (status == CONFLICT) & (o[:, 1] != o[:, 0]) & ~both
    outer[conflict] = (o[conflict, 1] > o[conflict, 0]).astype(np.int8)
    undecided = ~one & ~conflict
    if two_sided == "strongest":
        ts = status == TWO_SIDED
        outer[ts] = strongest_side(c)[ts]
        undecided &= ~ts
    return status, outer, undecided


def _hidden_sides(
    c: Classification,
    p: Patches,
    status: np.ndarray,
    outer: np.ndarray,
    semantics: str,
    undecided: np.ndarray,
) -> tuple[LayerResult | None, np.ndarray, np.ndarray]:
    """Sides of the hidden faces by layer semantics, patch vote and ray parity (in place).

    Returns the layers (None when nothing is hidden), the faces that are one-sided at their
    own layer, and the faces whose side ray parity decided.  A hidden face none of them
    decides keeps the side ``outer`` gives it (the input's front) and stays ``undecided``;
    the others leave it.
    """
    m = c.soup.n_faces
    hidden = status == HIDDEN
    own_layer = np.zeros(m, bool)
    by_parity = np.zeros(m, bool)
    if not hidden.any():
        return None, own_layer, by_parity
    lay = layers(c.soup, classification=c, visibility="object")
    side = lay.outer_side[hidden]
    own = (side == 0) | (side == 1)  # one-sided at its own layer
    own_layer[np.flatnonzero(hidden)[own]] = True
    outer[own_layer] = lay.outer_side[own_layer]
    vote, decisive = surface_vote(c, outer, (status == ONE_SIDED) | own_layer, p.clustering)
    # a shell faces outward as a whole: where the face's patch has a clear vote it wins
    # over the face's own side (contact faces between touching solids see both ways)
    outer[hidden & decisive] = vote[hidden & decisive]
    # faces two-sided at their layer on a patch without a vote (a sliver of surface cut
    # off by non-manifold edges where solids touch): ray parity against their own body,
    # where that body is closed (parity means nothing on an open one: those faces keep
    # their winding, as do those whose two sides parity cannot tell apart)
    open_ = hidden & ~own_layer & ~decisive & _closed_body(c)
    faces = np.flatnonzero(open_)
    if len(faces):
        side = parity_side(c, faces, seed=int(c.params.get("seed", 0)))
        told = side >= 0
        outer[faces[told]] = side[told]
        by_parity[faces[told]] = True
    undecided &= ~(own_layer | (hidden & decisive) | by_parity)
    if semantics == "cavity":
        # shells of even layers face inward; a face whose side nothing decided keeps it
        even = hidden & (lay.layer % 2 == 0) & ~undecided
        outer[even] = 1 - outer[even]
    return lay, own_layer, by_parity


def _whole_patches(
    c: Classification,
    p: Patches,
    status: np.ndarray,
    outer: np.ndarray,
    own_layer: np.ndarray,
    by_parity: np.ndarray,
    movable: np.ndarray,
    both: np.ndarray,
) -> tuple[np.ndarray, int]:
    """Turn every patch as a whole (in place).

    Each face of a patch with a clear vote takes the patch's side.  Voters: one-sided
    faces with their area, flagged faces whose sample points disagree with their area
    times the margin; only where none of them votes, the faces one-sided at their own
    layer (hidden faces) with their area; only where none of those votes either, the
    hidden faces whose side ray parity decided, with their area.
    Faces seen from both sides (``both``) neither vote nor follow the vote.
    Returns the faces of patches with a clear vote, and how many of them changed side.
    """
    o = c.outside
    node = p.clustering.side_node
    ok = node[:, 0] >= 0
    conflict = (status == CONFLICT) & ~both
    seen = c.soup.areas * (status == ONE_SIDED)
    seen[conflict] = c.soup.areas[conflict] * np.abs(o[conflict, 1] - o[conflict, 0])
    side = outer.copy()
    voted = np.zeros(len(outer), bool)
    # what is seen from outside votes first; faces one-sided only at a deeper layer
    # decide the patches that no face of layer 1 votes for; the hidden faces whose side
    # parity decided keep the patches that neither decides whole (on the Ferrari, parity
    # alone turned 7-11 faces of each of 20 hidden 12-face patches).  Faces that keep the
    # input's winding for lack of evidence do not vote: their vote would be the input's
    for weight in (seen, c.soup.areas * own_layer, c.soup.areas * by_parity):
        votes = np.zeros(p.clustering.n_nodes)
        d = np.flatnonzero(ok & (weight > 0))
        np.add.at(votes, node[d, outer[d]], weight[d])
        v0, v1 = votes[node[ok, 0]], votes[node[ok, 1]]
        now = np.zeros(len(outer), bool)
        now[ok] = v0 != v1
        now &= ~voted
        side[now] = (v1 > v0)[now[ok]].astype(np.int8)
        voted |= now
    voted &= movable & ~both
    change = voted & (side != outer)
    outer[voted] = side[voted]
    return voted, int(change.sum())


def _clearly_one_sided(c: Classification, outer: np.ndarray) -> np.ndarray:
    """(m,) bool: clustered faces whose cluster's own rays already speak for them.

    The cluster escapes more than 4 times (the evidence dominance of
    :mod:`meshvis.repair.evidence`) as often through the side they show as through the
    other (from the classification's own rays), and the other side escapes less than
    :data:`OPENING_NEAR` of the opening threshold: near that threshold the cut labels the
    cluster differently from seed to seed, and its faces are tested on their own.
    """
    from meshvis.repair.evidence import DOMINANCE

    counts = c.counts
    share = counts.escaped / np.maximum(counts.cast - counts.discarded, 1)
    node = c.nodes.side_node
    ok = node[:, 0] >= 0
    rows = np.flatnonzero(ok)
    shown = share[node[rows, outer[rows]]]
    other = share[node[rows, 1 - outer[rows]]]
    clear = np.zeros(len(outer), bool)
    clear[rows] = shown > DOMINANCE * other
    opening = c.params.get("opening")
    if opening:
        clear[rows] &= other < OPENING_NEAR * opening
    return clear


def _visible_sides(
    c: Classification,
    p: Patches,
    status: np.ndarray,
    outer: np.ndarray,
    movable: np.ndarray,
    undecided: np.ndarray,
    both: np.ndarray,
    seed: int,
    ground: np.ndarray | None = None,
) -> tuple[np.ndarray, dict]:
    """Let the side a viewer sees win (in place).

    Every movable face of an open patch is tested on its own
    (:func:`meshvis.repair.evidence.seen_counts`), except one-sided faces whose cluster's
    own rays already show their side clearly, and takes the side seen more often where its
    evidence is decisive (:func:`meshvis.repair.evidence.decisive`: a face seen less than
    4x as often from one side keeps its side).  A flagged face (it crosses another surface,
    across which its patch does not speak for it) also takes the side seen significantly
    more often (:data:`CROSSING_LEVEL`), unless it is seen from both sides (``both``: its
    own decisive evidence alone turns it).  Flagged faces and faces seen
    from both sides whose rays barely escaped, and flagged faces whose test leans to one
    side without passing, get more rays first (:data:`UNSEEN_SHARE`, then rounds for the
    faces that round does not reach; lone faces
    :func:`meshvis.repair.evidence.until_decisive`, :data:`LEANING_LEVEL`); and every face
    whose rays lean against the side it shows near the 4x line gets rounds until they tell
    on which side of it the face is (:func:`meshvis.repair.evidence.until_settled`).
    Faces of closed patches are left to their patch: a closed patch bounds a volume, and a
    face of it whose back pokes out through the surface is a self-intersection, not a face
    turned the wrong way.

    Before the faces are tested one by one, a patch of several faces takes the side its
    tested faces see, pooled, where that is decisive (:func:`_pooled_patches`); its faces
    seen from both sides add their rays but keep their side.

    ``ground`` is the up direction of the ground a scene stands on, or None: on a ground,
    the rays that leave the model downward do not count as seen
    (:class:`meshvis.repair.evidence.RayStream`).

    ``undecided`` marks the faces that show the input's front for lack of evidence: the
    rounds treat them as showing neither side, so that which faces get more rays, and so
    every verdict, is the same however the input is wound.

    Returns the faces whose side this decided, and the report: faces ``tested``, faces
    ``turned``, ``rays`` cast and ``pooled_patches``, the patches the pooled evidence
    decided.
    """
    from meshvis.repair import evidence

    clear = _clearly_one_sided(c, outer) & (status == ONE_SIDED)
    test = np.flatnonzero(movable & ~p.closed & ~clear)
    decided = np.zeros(len(outer), bool)
    if len(test) == 0:
        return decided, {"tested": 0, "turned": 0, "rays": 0, "pooled_patches": 0}
    before = outer.copy()
    # a stream of rays per face, seeded from the classification's seed: by which faces it
    # gives more rays, the test shifts no other face's rays
    stream = evidence.RayStream(seed, c.soup.n_faces, ground)

    def shown() -> np.ndarray:  # the side each tested face shows; -1: none yet
        return np.where(undecided[test], -1, outer[test]).astype(np.int64)

    # the rays start as close to their faces as the reference's: pushed by the caster's
    # default, pandora faces 7640 and 7772 looked seen from both sides about equally through
    # surfaces within about 1e-5 diagonals of their fronts (the recount sees their fronts
    # 7-8x less than their backs)
    caster = c.caster.with_offset(VISIBILITY_OFFSET)
    escaped, cast = evidence.seen_counts(c.soup, caster, test, shown(), stream)
    flagged = c.flagged[test]
    crossing = flagged & ~both[test]  # a face seen from both sides: no sign test
    # faces whose rays barely escaped get more first: a lone face (its patch is the face
    # alone), which nothing else speaks for, doubling rounds until its rays decide it;
    # the other faces that only their own rays decide (flagged, or seen from both sides)
    # one capped round, the largest first, and those it does not reach doubling rounds
    # under the same cap
    unsettled = np.isin(status[test], (TWO_SIDED, CONFLICT))  # the cut did not settle them
    few = escaped.sum(axis=1) < evidence.MIN_ESCAPES
    lone = p.size[test] == 1
    unseen = np.flatnonzero((flagged | unsettled) & few & ~lone)
    reached = evidence.more_rays(
        c.soup, caster, test, escaped, cast, unseen, evidence.LAST_RAYS, UNSEEN_SHARE, stream
    )
    evidence.until_decisive(c.soup, caster, test, escaped, cast, np.flatnonzero(lone & few), shown(), stream)
    missed = np.setdiff1d(unseen, reached)
    evidence.until_decisive(c.soup, caster, test, escaped, cast, missed, shown(), stream, UNSEEN_SHARE)
    leaning = (
        crossing
        & (evidence.more_seen(escaped, shown()) != shown())
        & evidence.significant(escaped, LEANING_LEVEL)
        & ~evidence.significant(escaped, CROSSING_LEVEL)
    )
    evidence.more_rays(
        c.soup, caster, test, escaped, cast, np.flatnonzero(leaning), LEANING_RAYS, LEANING_SHARE, stream
    )
    # a patch of several faces turns as a whole where its faces' rays, pooled, decide it;
    # then each face leaves its patch only on evidence of its own
    pooled = _pooled_patches(c, p, test, escaped, cast, outer, movable, clear, both)
    undecided = undecided & ~pooled
    # a face whose rays lean against its side near the 4x line gets rounds until they settle
    left_out = evidence.until_settled(
        c.soup, caster, test, escaped, cast, np.arange(len(test)), shown(), stream
    )
    sure = evidence.decisive(escaped)
    sure |= crossing & evidence.significant(escaped, CROSSING_LEVEL)
    outer[test[sure]] = evidence.more_seen(escaped, shown())[sure]
    decided[test[sure]] = True
    turned = outer != before
    report = {
        "tested": len(test),
        "turned": int(turned.sum()),
        "rays": int(cast.sum()),
        "settle_left_out": left_out,
        "pooled_patches": len(np.unique(p.clustering.cluster[pooled])),
    }
    return decided | pooled, report


def _seen_from_above(
    c: Classification,
    p: Patches,
    outer: np.ndarray,
    movable: np.ndarray,
    undecided: np.ndarray,
    seed: int,
    up: np.ndarray,
) -> int:
    """Give a face leaving its patch its patch's side where viewers above the ground see it (in place).

    On a scene seen from above its ground, a face whose evidence shows the side its patch
    does not show (the side most of the area of the patch's ``movable`` faces shows, as
    decided or kept, the face's own included) goes back to its patch's side where that
    side is seen from above the ground: at least :data:`~meshvis.repair.evidence.MIN_ESCAPES` of
    :data:`ABOVE_RAYS` rays through it escape upward.  The evidence against it then
    comes from viewers above who see the face's other side more often (a wall seen
    from both sides): a viewer above may see either side, and the patch keeps its
    winding whole, as faces seen from both sides keep theirs under ``two_sided="keep"``.

    Returns the faces given back to their patch.
    """
    from meshvis.repair import evidence

    node, patch = p.clustering.side_node, p.clustering.cluster
    rows = np.flatnonzero(movable & (patch >= 0) & (p.size > 1) & ~p.closed)
    shown = node[rows, np.asarray(outer, np.int64)[rows]]
    votes = np.bincount(shown, c.soup.areas[rows], p.clustering.n_nodes)
    v0, v1 = votes[node[rows, 0]], votes[node[rows, 1]]
    side = (v1 > v0).astype(np.int64)
    away = (v0 != v1) & (outer[rows] != side) & ~undecided[rows]
    leaving, side = rows[away], side[away]
    if len(leaving) == 0:
        return 0
    stream = evidence.RayStream(seed, c.soup.n_faces, up)
    caster = c.caster.with_offset(VISIBILITY_OFFSET)
    escaped = evidence.escapes(c.soup, caster, leaving, ABOVE_RAYS, stream, through=side)
    seen = escaped[np.arange(len(leaving)), side] >= evidence.MIN_ESCAPES
    outer[leaving[seen]] = side[seen]
    return int(seen.sum())


def _kept_with_patch(
    p: Patches, outer: np.ndarray, given: np.ndarray, undecided: np.ndarray, areas: np.ndarray
) -> None:
    """Give every face left open the side its patch's open faces show as the input winds them (in place).

    A face that no evidence decides keeps the input's winding, but as part of its patch:
    it takes the side of the patch (the orientation double cover's node) on which most of
    the area of the patch's open faces shows its front in the input.  A consistently
    wound patch keeps its winding; a patch wound either way (a soup, 30 % of its faces
    turned over) comes back with the winding most of its faces had.  Done again on the
    output, every open face of a patch already shows that side: nothing changes.
    """
    node = p.clustering.side_node
    rows = np.flatnonzero(undecided & (node[:, 0] >= 0) & (p.size > 1))
    kept = given[rows].astype(np.int64)
    votes = np.bincount(node[rows, kept], areas[rows], p.clustering.n_nodes)
    other = votes[node[rows, 1 - kept]] > votes[node[rows, kept]]
    outer[rows] = np.where(other, 1 - kept, kept)


def _pooled_patches(
    c: Classification,
    p: Patches,
    test: np.ndarray,
    escaped: np.ndarray,
    cast: np.ndarray,
    outer: np.ndarray,
    movable: np.ndarray,
    clear: np.ndarray,
    both: np.ndarray,
) -> np.ndarray:
    """Give every open patch of several faces the side its tested faces see, pooled (in place).

    The patch vote of :func:`_whole_patches` counts only the faces the cut settled on one
    side; in a patch seen rarely, or from one side here and the other there, a few of them
    decide for all, and in a patch the cut calls hidden none does.  Each face's own rays
    (:func:`meshvis.repair.evidence.seen_counts`) estimate how much of its area is seen
    through each side (its escape share); summed over the patch, each face's front
    counting for the side of the patch it lies on (a patch the input does not wind
    consistently has faces with their fronts on either side), they are the patch's own
    evidence, and where it is decisive (:data:`POOLED_DOMINANCE`, at least
    :data:`~meshvis.repair.evidence.MIN_ESCAPES` escapes) the patch shows the side it sees
    more, as a whole.  A patch with a face whose cluster's rays already show its side
    (``clear``) is left to them.

    Returns (m,) bool: the faces of the patches the pooled evidence decided.
    """
    from meshvis.repair.evidence import MIN_ESCAPES

    patch, node = p.clustering.cluster, p.clustering.side_node
    n = max(p.clustering.n_clusters, 1)
    pool = (patch >= 0) & (p.size > 1)
    rows = np.flatnonzero(pool[test])
    faces = test[rows]
    weight = c.soup.areas[faces] / np.maximum(cast[rows], 1)
    # the share seen through each side of the patch: a face's front is one of the patch's
    # two sides (node), its back the other
    nodes = p.clustering.n_nodes
    seen = np.bincount(node[faces, 0], weight * escaped[rows, 0], nodes)
    seen += np.bincount(node[faces, 1], weight * escaped[rows, 1], nodes)
    escapes = np.bincount(patch[faces], escaped[rows].sum(axis=1), n)
    at = np.flatnonzero(pool)
    front, back = seen[node[at, 0]], seen[node[at, 1]]
    sure = (escapes[patch[at]] >= MIN_ESCAPES) & (
        np.maximum(front, back) >= POOLED_DOMINANCE * np.minimum(front, back)
    )
    left = np.zeros(n, bool)
    left[patch[clear & pool]] = True
    sure &= ~left[patch[at]] & movable[at] & ~both[at]
    decided = np.zeros(len(outer), bool)
    decided[at[sure]] = True
    outer[at[sure]] = (back > front)[sure]
    return decided


def classify_for_orient(model: Any, **classify_kw: Any) -> Classification:
    """The classification :func:`orient` makes of a model: of its faces wound canonically.

    Every face is classified in its canonical winding
    (:func:`meshvis.geometry.winding.canonically_wound`), so that the random rays of the
    cut are the same however the model's faces come in wound: a model and the model
    :func:`orient` made of it get the same cut, and orienting an oriented model changes
    nothing.  Pass it to :func:`orient` as ``classification`` to reuse it.

    Parameters
    ----------
    model : Soup, trimesh object, (vertices, faces) or path
        Anything :func:`meshvis.classify` accepts.
    **classify_kw
        Passed to :func:`meshvis.classify`; ``point_area`` is :data:`POINT_AREA` unless
        given.

    Returns
    -------
    Classification
        Of the canonically wound copy of the model (its ``soup``).

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box()
    >>> c = classify_for_orient(box, seed=0)
    >>> bool((orient(box, classification=c).flipped == orient(box, seed=0).flipped).all())
    True
    """
    from meshvis.geometry.winding import canonically_wound
    from meshvis.io import as_soup

    _validate.keywords(classify_kw, classify)
    classify_kw.setdefault("point_area", POINT_AREA)
    return classify(canonically_wound(as_soup(model)), **classify_kw)


def _input_side(soup: Soup, classified: Soup) -> np.ndarray:
    """(m,) int8: the side of each face of ``classified`` that is the front of ``soup``'s face.

    Raises ParameterError when the two are not the same faces (up to their corner order).
    """
    from meshvis.geometry.duplicates import winding_parity

    f, g = soup.faces, classified.faces
    if f.shape != g.shape or not np.array_equal(np.sort(f, axis=1), np.sort(g, axis=1)):
        raise ParameterError("the classification is of another model (its faces differ)")
    return (winding_parity(f) != winding_parity(g)).astype(np.int8)


def orient(
    model: Any,
    *,
    front: str = "ccw",
    two_sided: str = "keep",
    semantics: str = "layer",
    conflicts: str = "majority",
    ground: bool | None = False,
    up: Any = None,
    classification: Classification | None = None,
    **classify_kw: Any,
) -> OrientResult:
    """Turn every face so that its front side faces the outside.

    A face's side comes from evidence that does not depend on how the face came in wound
    (the cut and the rays run on the canonically wound model, :func:`classify_for_orient`);
    the input's winding is kept only where the evidence leaves a face open.  So orienting
    the output again changes nothing.

    Parameters
    ----------
    model : Soup, trimesh object, (vertices, faces) or path
        Anything :func:`meshvis.classify` accepts.
    front : {"ccw", "cw"}
        Winding of the front side: counter-clockwise (the usual convention) or clockwise.
    two_sided : {"keep", "duplicate", "strongest"}
        Faces with both sides outside (see the module docstring).
    semantics : {"layer", "cavity"}
        Hidden shells face outward at their layer, or every second layer inward.
    conflicts : {"majority", "duplicate"}
        Flagged faces whose sample points disagree: the area majority, or both orientations.
    ground : bool or None
        True: the model is a scene standing on a ground, seen from above it only (the rays
        of the visible-sides step that leave it downward do not count); None: where
        :func:`meshvis.repair.evidence.stands_on_ground` says so; False (default): seen
        from every direction, as the graph cut sees it.  Seen from above its ground, a
        face does not leave its patch's side where viewers above the ground see that side
        (:func:`_seen_from_above`).
    up : None, "x", "y", "z" or (3,) float
        The up direction of the ground; None: the model's own (``Soup.up``).
    classification : Classification, optional
        A classification of the same model to reuse, from :func:`classify_for_orient` (or
        :func:`meshvis.classify`: then its random rays depend on the input's winding).
    **classify_kw
        Passed to :func:`meshvis.classify` (``seed``, ``rays_per_node``, ...).

    Returns
    -------
    OrientResult

    Raises
    ------
    ParameterError
        An option is unknown, or ``classification`` is of another model.

    Examples
    --------
    >>> import trimesh, numpy as np
    >>> m = trimesh.creation.icosphere(2); f = m.faces.copy(); f[::3] = f[::3, ::-1]
    >>> r = orient((m.vertices, f), seed=0)
    >>> int(r.flipped.sum()) == len(f[::3])
    True
    >>> bool(orient(r.soup, seed=0).flipped.any())  # orienting the output changes nothing
    False
    """
    from meshvis.io import as_soup

    _validate.repair_args(classification, Classification, classify_kw, classify)
    _check("front", front, ("ccw", "cw"))
    _check("two_sided", two_sided, ("keep", "duplicate", "strongest"))
    _check("semantics", semantics, ("layer", "cavity"))
    _check("conflicts", conflicts, ("majority", "duplicate"))
    soup = as_soup(model)
    c = classification or classify_for_orient(soup, **classify_kw)
    given = _input_side(soup, c.soup)
    m = soup.n_faces
    # seen from both sides: both sides outside, wholly or at some of their sample points
    both = (c.outside > 0).all(axis=1) & ~c.degenerate & (two_sided == "keep")
    status, outer, undecided = _own_sides(c, two_sided, given, both)
    p = patches(c)
    lay, own_layer, by_parity = _hidden_sides(c, p, status, outer, semantics, undecided)
    # kept two-sided faces follow their patch and decisive evidence of their own; the
    # other options decided them on purpose, and degenerate faces have no side
    movable = (status != DEGENERATE) & ((status != TWO_SIDED) | (two_sided == "keep"))
    voted, n_patch = _whole_patches(c, p, status, outer, own_layer, by_parity, movable, both)
    undecided &= ~voted
    seed = int(c.params.get("seed", 0))
    # a scene standing on a ground is seen from above it only (no viewer below the ground)
    up_dir = up_vector(up, soup)
    if ground is None:
        from meshvis.repair.evidence import stands_on_ground

        ground = stands_on_ground(c.soup, c.caster, up_dir)
    seen, visibility = _visible_sides(
        c, p, status, outer, movable, undecided, both, seed, up_dir if ground else None
    )
    visibility["ground"] = bool(ground)
    undecided &= ~seen
    _kept_with_patch(p, outer, given, undecided, c.soup.areas)
    # seen from above its ground, a face seen through both sides keeps its patch's side
    visibility["kept_seen_from_above"] = (
        _seen_from_above(c, p, outer, movable, undecided, seed, up_dir) if ground else 0
    )
    flip = outer != given
    if front == "cw":
        flip = ~flip
    dup = np.zeros(m, bool)
    if two_sided == "duplicate":
        dup |= status == TWO_SIDED
    if conflicts == "duplicate":
        dup |= status == CONFLICT
    # degenerate faces, and kept two-sided faces that nothing decided, are written
    # untouched; but a sliver, whose edges join its patch, then shows the side its patch
    # shows
    untouched = both & undecided & (outer == given)
    # both copies of a sheet stored twice with opposite winding stay as they are.  Only
    # here: whether two copies are opposite depends on the input's winding (a first run
    # may turn one of two copies wound alike), and the steps above, whose ray budgets
    # count the faces they test, must not
    paired = in_opposite_copy(
        np.where(given[:, None] == 1, c.pre.faces_welded[:, [0, 2, 1]], c.pre.faces_welded)
    )
    flip[untouched | paired | (status == DEGENERATE)] = False
    sliver = np.flatnonzero((status == DEGENERATE) & (p.clustering.cluster >= 0))
    side = _patch_side(p, given ^ flip, c.soup.areas, sliver)
    flip[sliver] = (side >= 0) & (side != given[sliver])
    extra = np.flatnonzero(dup)
    source = np.concatenate([np.arange(m), extra])
    out = soup.subset(source).flipped(np.concatenate([flip, ~flip[extra]]))
    return OrientResult(
        out,
        source,
        flip,
        dup,
        status,
        c,
        lay,
        int(by_parity.sum()),
        n_patch,
        visibility,
        int(paired.sum()),
        input_side=given,
    )


def orient_from(
    model: Any,
    region: Any = "outside",
    *,
    front: str = "ccw",
    budget: int | None = None,
    seed: int = 0,
    up: Any = None,
) -> OrientResult:
    """Turn every face toward the side that viewers in ``region`` see.

    For scenes meant to be seen from inside (a level, a room) the outside of the graph cut
    is the wrong reference: the viewers are in a region.  Every face seen from the region
    through one side only gets that side as its front; faces seen through both sides
    (``two-sided``) or through neither (``hidden``) keep their winding.  No classification
    is run.

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model.
    region : str or region object
        Where the viewers are (:func:`meshvis.visibility.regions.parse_region`), e.g.
        ``"box:x0,y0,z0,x1,y1,z1"``.
    front : {"ccw", "cw"}
        Winding of the front side.
    budget : int, optional
        Ray budget of :func:`meshvis.visible_from` (default: its own).
    seed : int
        Seed of the one random generator.
    up : None, "x", "y", "z" or (3,) float
        Up direction for an ``upper-hemisphere`` region; None: the model's own (``Soup.up``).

    Returns
    -------
    OrientResult
        ``view`` holds the visibility; ``classification`` is None.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> room = trimesh.creation.box(extents=(4, 4, 4))  # faces wound outward
    >>> r = orient_from((room.vertices, room.faces), "box:-0.5,-0.5,-0.5,0.5,0.5,0.5", seed=0)
    >>> bool(r.flipped.all())  # seen from inside the room, every wall turns to face in
    True
    """
    from meshvis.io import as_soup
    from meshvis.visibility import visible_from

    _check("front", front, ("ccw", "cw"))
    soup = as_soup(model)
    vis = visible_from(soup, region, budget=budget, seed=seed, up=up, per_side=True)
    seen = np.asarray(vis.seen_side)
    only_front, only_back = seen[:, 0] & ~seen[:, 1], seen[:, 1] & ~seen[:, 0]
    status = np.where(seen.all(axis=1), TWO_SIDED, np.where(seen.any(axis=1), ONE_SIDED, HIDDEN))
    status[soup.areas <= 0] = DEGENERATE
    flip = only_front if front == "cw" else only_back
    m = soup.n_faces
    return OrientResult(
        soup.flipped(flip),
        np.arange(m),
        flip,
        np.zeros(m, bool),
        status.astype(np.int8),
        None,
        None,
        view=vis,
    )
