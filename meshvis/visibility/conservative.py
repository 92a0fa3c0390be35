"""Conservative from-point visibility: a set of faces that surely holds every face a point sees (FastV).

Sampling (:func:`meshvis.visible_from`) proves faces visible; what it does not see is only
probably hidden.  This module answers the opposite question after FastV (``003_*.txt``,
DESIGN.md §12): which faces *may* be visible from a point, so that everything outside the
set is certainly hidden.  With the sampled set it brackets the truth, sampled ⊆ exact ⊆
conservative.

Per viewpoint (FastV §3.1): the directions it looks in are cut into small four-sided
frusta, a grid of ``2**base_level`` cells a side on each root (the six faces of a cube
map, or a camera's view, :mod:`.viewpoints`).  For each frustum the compiled kernel
(:mod:`._frusta_kernels`) looks for a *blocker*, a connected set of triangles that every
ray of the frustum provably hits, grown from the first hits of the frustum's centre and
corner rays (traced by Embree, one batch per level); its deepest point in the frustum is
the far plane (FastV §3.3), and every triangle meeting the frustum in front of it is kept
unless it lies behind the blocker.  A frustum without a blocker is split in four, level
by level (FastV §3.4), down to ``max_level``; there, occluder fusion (which FastV lacks)
looks for a union of triangles that covers the frustum, or the rays that reach one
triangle, without being joined across edges, and the frustum keeps every triangle it
meets that neither such a union nor a blocker hides.

A face is kept with the side that faces the point (both when the point lies within the
margin of its plane, or the face's corners lie on one line, :func:`fillers`).  Every test takes margins of ``tolerance`` times the scene's size
seen from the point (:func:`margins`), so that rounding -- ours, or the float32 scene that
Embree traces -- can only keep more.  Two consequences a user sees: a face that only
touches a visible one along the edge of an outline (the side of a box seen from above
touches its top) stays in the set, because a ray through that edge meets both; and a
crack between two faces that do not share their corners exactly lets the set see
through it, however thin.

>>> import trimesh
>>> box = trimesh.creation.box()  # from its centre a point sees the six sides' inner faces
>>> c = conservative_from(box, "points:0,0,0")
>>> bool(c.visible_side[:, 1].all()), bool(c.visible_side[:, 0].any())
(True, False)
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from meshvis import _validate
from meshvis.geometry.adjacency import edges, weld
from meshvis.geometry.bvh import Bvh, build_bvh
from meshvis.io import as_soup
from meshvis.rays.caster import RayCaster
from meshvis.rays.samples import uniform_sphere
from meshvis.soup import Soup
from meshvis.visibility import _frusta_kernels as fk
from meshvis.visibility.regions import Points, Region
from meshvis.visibility.viewpoints import Viewpoint, parse_viewpoints

#: each root starts as a grid of 2**DEFAULT_BASE_LEVEL x 2**DEFAULT_BASE_LEVEL frusta
DEFAULT_BASE_LEVEL = 4
#: frusta without a blocker are split down to this level (2**level cells on a root's side)
DEFAULT_MAX_LEVEL = 11
#: margin of every test, relative to the scene's size seen from the point: 16 float32
#: units of the Embree scene (about 6e-8), far above float64 rounding
DEFAULT_TOLERANCE = 1e-6
#: most triangles in one blocker (a longer walk gives up, and the frustum is split)
MAX_WALK = 64
#: frusta per kernel batch within a level (bounded memory for the seed rays)
BATCH = 1 << 16
#: highest subdivision level the frustum boxes represent exactly (dyadic float64)
LEVEL_CAP = 24
#: a face whose middle corner lies within this fraction of the diagonal of the line through
#: the other two joins a T-junction (:func:`fillers`); far below the margins of the tests
FILLER_WIDTH = 1e-7
#: rays per batch of :func:`sample_views`
SAMPLE_BATCH = 1 << 20
#: rays traced again in float64 per side that aimed rays hit (:func:`confirm_hits`)
CONFIRM = 4
#: rays in all of a camera path's views when cameras look into views and no budget is given
VIEW_RAYS = 1 << 22
#: frusta counted by outcome (:attr:`ConservativeSet.frusta`)
COUNTS = ("traced", "blocked", "split", "open", "fused", "empty")


@dataclass
class ConservativeSet:
    """Result of :func:`conservative_from`.

    Attributes
    ----------
    visible_side : (m, 2) bool
        Per input face and side (0 front, 1 back): may be seen from some viewpoint.
        Every side not in it is hidden from all of them.
    points : (k, 3) float64
        The viewpoints.
    point_faces : list of (n_i,) int64
        Faces in each viewpoint's set.
    point_sides : list of (n_i,) int8
        Their side: 0 front, 1 back, 2 both (the point is within the margin of the plane).
    area : (m,) float64
        Face areas.
    frusta : dict
        Frusta traced, in total and by outcome (``blocked``, ``split``, ``open`` at the
        limit, of which ``fused`` were covered by a union of triangles, ``empty``), and per
        viewpoint (``per_point``).
    at_limit : (m,) bool
        Faces in the set only because of the subdivision limit: from every viewpoint that
        keeps them, the first frustum to keep them was at the limit, without a blocker
        for the rays that reach them.  The other faces of the set lie in front of a
        blocker's far plane without being proved behind it.
    parameters : dict
        ``base_level``, ``max_level``, ``tolerance``.
    seconds : float
        Time taken.
    open_frusta : list of tuple
        Per viewpoint, its frusta at the limit without a blocker (covered by a union of
        triangles or not), where the set keeps what it cannot prove hidden: ``(roots, root, box)``, the viewpoint's (r, 3, 3) roots
        (``axis``, ``right``, ``up``), and each frustum's (k,) root and (k, 4) box
        ``u0, u1, w0, w1`` (its directions are ``axis + u right + w up``).
    """

    visible_side: np.ndarray
    points: np.ndarray
    point_faces: list
    point_sides: list
    area: np.ndarray
    frusta: dict
    parameters: dict
    seconds: float
    at_limit: np.ndarray
    open_frusta: list = field(default_factory=list)

    @property
    def visible(self) -> np.ndarray:
        """(m,) bool: some side of the face may be seen."""
        return np.asarray(self.visible_side.any(axis=1))

    @property
    def visible_area(self) -> float:
        """Area of the faces that may be seen."""
        return float(self.area[self.visible].sum())

    def point_side(self, i: int) -> np.ndarray:
        """(m, 2) bool: the set of viewpoint ``i`` per face and side."""
        out = np.zeros((len(self.area), 2), bool)
        faces, sides = self.point_faces[i], self.point_sides[i]
        out[faces, 0] = sides != 1
        out[faces, 1] = sides != 0
        return out

    def bracket(self, sampled_side: np.ndarray) -> dict:
        """The sampled and the conservative set side by side: counts, areas and the bracket.

        Parameters
        ----------
        sampled_side : (m, 2) bool
            Sides proved visible by sampling from the same viewpoints.

        Returns
        -------
        dict
            ``sampled_faces``, ``conservative_faces``, their areas, ``bracket_faces`` and
            ``bracket_area`` (in the conservative set, not seen: what any removal from these
            viewpoints may get wrong at most), ``area_ratio`` (conservative over sampled
            area), ``outside`` (faces seen but outside the set: 0 unless the viewpoints
            differ), frusta and seconds.
        """
        seen = np.asarray(sampled_side).any(axis=1)
        may = self.visible
        area = self.area
        seen_area, may_area = float(area[seen].sum()), float(area[may].sum())
        return {
            "sampled_faces": int(seen.sum()),
            "conservative_faces": int(may.sum()),
            "sampled_area": seen_area,
            "conservative_area": may_area,
            "bracket_faces": int((may & ~seen).sum()),
            "bracket_area": float(area[may & ~seen].sum()),
            "bracket_area_fraction": float(area[may & ~seen].sum()) / max(float(area.sum()), 1e-300),
            "area_ratio": may_area / seen_area if seen_area > 0 else None,
            "outside": int((seen & ~may).sum()),
            "frusta": self.frusta["traced"],
            "seconds": self.seconds,
        }

    def report(self, per_face: bool = True) -> dict:
        """JSON-ready summary (and per-face arrays when ``per_face``)."""
        total = max(float(self.area.sum()), 1e-300)
        d = {
            "points": self.points.tolist(),
            "faces": int(len(self.area)),
            "conservative_faces": int(self.visible.sum()),
            "conservative_area_fraction": self.visible_area / total,
            "per_point_faces": [int(len(f)) for f in self.point_faces],
            "frusta": self.frusta,
            "parameters": self.parameters,
            "seconds": self.seconds,
        }
        if per_face:
            d["per_face"] = {
                "may_see_front": self.visible_side[:, 0],
                "may_see_back": self.visible_side[:, 1],
            }
        return d


@dataclass(frozen=True)
class FrustumScene:
    """What the frusta of every viewpoint trace against, built once per model.

    Attributes
    ----------
    soup : Soup
        The model.
    triangles : (m, 3, 3) float64
        Its triangles' corners.
    welded : (m, 3) int64
        Corners welded where their coordinates are equal (no tolerance: a blocker's
        triangles must share their edges exactly).
    face_edge, edge_start, edge_face : ndarray of int64
        The edge of each face side and the faces of each edge.
    filler : (m,) int8
        :func:`fillers`.
    bvh : Bvh
        The float64 bounding volume hierarchy of the triangles.
    caster : RayCaster
        Traces the seed rays.
    """

    soup: Soup
    triangles: np.ndarray
    welded: np.ndarray
    face_edge: np.ndarray
    edge_start: np.ndarray
    edge_face: np.ndarray
    filler: np.ndarray
    bvh: Bvh
    caster: RayCaster

    @classmethod
    def build(cls, model, caster: RayCaster | None = None, weld_tolerance: float = 0.0) -> FrustumScene:
        """Weld, edge table, hierarchy and caster of ``model``."""
        soup = as_soup(model)
        triangles = np.ascontiguousarray(soup.triangles, np.float64)
        _, welded = weld(soup.vertices, soup.faces, tol=weld_tolerance)
        table = edges(welded)
        edge_start = np.searchsorted(table.half_edge, np.arange(len(table.count) + 1)).astype(np.int64)
        return cls(
            soup=soup,
            triangles=triangles,
            welded=np.ascontiguousarray(welded, np.int64),
            face_edge=np.ascontiguousarray(table.face_edge, np.int64),
            edge_start=edge_start,
            edge_face=np.ascontiguousarray(table.half_face, np.int64),
            filler=fillers(triangles, welded, FILLER_WIDTH * soup.diagonal),
            bvh=build_bvh(triangles),
            caster=caster or RayCaster(soup),
        )


def fillers(triangles: np.ndarray, welded: np.ndarray, width: float) -> np.ndarray:
    """(m,) int8: for each sliver whose corners lie on one line, the side that is its long edge; -1 for the others.

    Such slivers join T-junctions (a corner of one face on the edge of another) with three
    shared corners: the faces on either side of them close the surface, and a blocker may
    pass through them (:mod:`._frusta_kernels`).  A sliver is a face with three distinct
    welded corners whose middle corner lies within ``width`` of the line through the
    other two.

    Examples
    --------
    >>> t = np.array([[[0, 0, 0], [2, 0, 0], [1, 1e-9, 0]], [[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)
    >>> fillers(t, np.array([[0, 1, 2], [0, 2, 3]]), 1e-6).tolist()
    [0, -1]
    """
    distinct = (
        (welded[:, 0] != welded[:, 1]) & (welded[:, 1] != welded[:, 2]) & (welded[:, 2] != welded[:, 0])
    )
    out = np.full(len(triangles), -1, np.int8)
    idx = np.flatnonzero(distinct)
    t = triangles[idx]
    # the middle corner along the longest extent; the long edge is the side opposite to it
    axis = np.argmax(t.max(axis=1) - t.min(axis=1), axis=1)
    order = np.argsort(t[np.arange(len(idx)), :, axis], axis=1, kind="stable")
    k = np.arange(len(idx))
    lo, mid, hi = t[k, order[:, 0]], t[k, order[:, 1]], t[k, order[:, 2]]
    span = hi - lo
    length = np.linalg.norm(span, axis=1)
    off = np.linalg.norm(np.cross(mid - lo, span), axis=1) / np.where(length > 0, length, 1.0)
    sliver = (length > 0) & (off <= width)
    out[idx[sliver]] = ((order[sliver, 1] + 1) % 3).astype(np.int8)
    return out


def margins(scene: FrustumScene, position: np.ndarray, tolerance: float) -> tuple[float, float, float]:
    """The margins of the tests from ``position``: ``(delta, eta, mu)``.

    ``delta`` is a length, ``tolerance`` times the scene's size seen from the point (its
    bounding-box diagonal plus the point's distance to the box centre); ``eta`` an angle,
    ``tolerance`` radians; ``mu``, by which frusta, boxes and far depths are widened, is
    ``2 delta`` plus ``eta`` times the farthest corner of the box.
    """
    lo, hi = scene.soup.bounds if scene.soup.n_faces else (np.zeros(3), np.zeros(3))
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    reach = float(np.linalg.norm(corners - position, axis=1).max())
    size = float(np.linalg.norm(hi - lo)) + float(np.linalg.norm(0.5 * (lo + hi) - position))
    delta = tolerance * max(size, np.finfo(float).tiny)
    eta = tolerance
    return delta, eta, 2.0 * delta + eta * reach


def conservative_from(
    model,
    region: str | Region | list[Viewpoint],
    *,
    base_level: int = DEFAULT_BASE_LEVEL,
    max_level: int = DEFAULT_MAX_LEVEL,
    tolerance: float = DEFAULT_TOLERANCE,
    scene: FrustumScene | None = None,
    caster: RayCaster | None = None,
    fusion: bool = True,
) -> ConservativeSet:
    """The faces that may be seen from the viewpoints of ``region``, per face and side.

    Parameters
    ----------
    model : Soup, trimesh object, (vertices, faces) or path
        Anything :func:`meshvis.io.as_soup` accepts.
    region : str, Region or list of Viewpoint
        ``"points:x,y,z;..."`` (each point looks everywhere) or ``"path:CAMERAS.json"``
        (each camera looks into its view, or everywhere without a target; see
        :mod:`meshvis.visibility.viewpoints`), a Points region, or the viewpoints.
    base_level : int
        Each root starts as ``2**base_level`` x ``2**base_level`` frusta.
    max_level : int
        Frusta without a blocker are split down to ``2**max_level`` cells a side; a
        higher limit gives a tighter set and traces more frusta.
    tolerance : float
        Margin of the tests relative to the scene's size (:func:`margins`).
    scene : FrustumScene, optional
        A prepared scene of the same model to reuse.
    caster : RayCaster, optional
        A caster of the same model for the seed rays.
    fusion : bool
        At the subdivision limit, a frustum without a blocker hides what lies behind the
        union of the triangles that cover it (occluder fusion); ``False`` keeps everything
        it meets that no blocker hides, as FastV does.

    Returns
    -------
    ConservativeSet

    Raises
    ------
    ParameterError
        A region without viewpoints, a level out of range, a bad tolerance.

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box()
    >>> c = conservative_from(box, "points:0,0,5")  # above the box: its top, and the sides touching it
    >>> c.visible_side.sum(axis=0).tolist(), bool(c.visible_side[box.face_normals[:, 2] < -0.5].any())
    ([2, 8], False)
    """
    base_level = _validate.integer("base_level", base_level, 0, LEVEL_CAP)
    max_level = _validate.integer("max_level", max_level, base_level, LEVEL_CAP)
    tolerance = _validate.real("tolerance", tolerance, 1e-15, 0.1)
    start = time.perf_counter()
    views = region if isinstance(region, list) else parse_viewpoints(region)
    scene = scene or FrustumScene.build(model, caster)
    soup = scene.soup
    m = soup.n_faces
    visible_side = np.zeros((m, 2), bool)
    at_limit, in_front = np.zeros(m, bool), np.zeros(m, bool)
    point_faces, point_sides, per_point, open_frusta = [], [], [], []
    totals = dict.fromkeys(COUNTS, 0)
    for view in views:
        t0 = time.perf_counter()
        keep, counts, leaves = _trace_viewpoint(scene, view, base_level, max_level, tolerance, fusion)
        open_frusta.append((np.asarray(view.roots, np.float64), *leaves))
        faces = np.flatnonzero(keep)
        at_limit |= keep == fk.OPEN
        in_front |= keep == fk.BLOCKED
        sides = facing_sides(
            scene.triangles[faces], view.position, margins(scene, view.position, tolerance)[0]
        )
        sides[scene.filler[faces] >= 0] = 2  # corners on one line: no side to tell
        visible_side[faces, 0] |= sides != 1
        visible_side[faces, 1] |= sides != 0
        point_faces.append(faces)
        point_sides.append(sides)
        for k in totals:
            totals[k] += counts[k]
        per_point.append({**counts, "seconds": time.perf_counter() - t0})
    return ConservativeSet(
        visible_side=visible_side,
        points=np.array([v.position for v in views], np.float64).reshape(-1, 3),
        point_faces=point_faces,
        point_sides=point_sides,
        area=soup.areas.copy(),
        frusta={**totals, "per_point": per_point},
        parameters={
            "base_level": base_level,
            "max_level": max_level,
            "tolerance": tolerance,
            "fusion": fusion,
        },
        seconds=time.perf_counter() - start,
        at_limit=at_limit & ~in_front,
        open_frusta=open_frusta,
    )


def facing_sides(triangles: np.ndarray, position: np.ndarray, delta: float) -> np.ndarray:
    """(n,) int8: the side of each triangle that faces ``position`` (0 front, 1 back, 2 both).

    Both when moving the corners and the point by ``delta`` may put the point on the other
    side of the triangle's plane (or the triangle has no area): a ray from there meets it
    at a grazing angle, and rounding decides the side.  The side test is the sign of
    ``det[b - a, c - a, p - a]``; to first order, the moves change it by at most ``delta``
    times ``|n| + 2 |(c - a) x (p - a)| + 2 |(p - a) x (b - a)|`` (``n`` the normal), and the
    point is taken as in the plane within twice that.  A tiny face seen from afar tilts
    most.

    Examples
    --------
    >>> tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)
    >>> [int(facing_sides(tri, np.array(p, float), 1e-9)[0]) for p in ([0, 0, 1], [0, 0, -1], [5, 5, 0])]
    [0, 1, 2]
    """
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    n = np.cross(b - a, c - a)
    pa = position - a
    toward = np.einsum("ij,ij->i", n, pa)
    tilt = np.linalg.norm(np.cross(c - a, pa), axis=1) + np.linalg.norm(np.cross(pa, b - a), axis=1)
    near = np.abs(toward) <= 2.0 * delta * (np.linalg.norm(n, axis=1) + 2.0 * tilt)
    return np.where(near, 2, np.where(toward > 0, 0, 1)).astype(np.int8)


def base_frusta(n_roots: int, level: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``2**level`` x ``2**level`` grid of frusta on each root: ``(root, box)``.

    Examples
    --------
    >>> root, box = base_frusta(1, 1)
    >>> root.tolist(), box[0].tolist()
    ([0, 0, 0, 0], [-1.0, 0.0, -1.0, 0.0])
    """
    n = 1 << level
    edges_ = np.linspace(-1.0, 1.0, n + 1)
    i, j = np.divmod(np.arange(n * n), n)
    box = np.stack([edges_[i], edges_[i + 1], edges_[j], edges_[j + 1]], axis=1)
    root = np.repeat(np.arange(n_roots), n * n)
    return root, np.tile(box, (n_roots, 1))


def split_frusta(root: np.ndarray, box: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each frustum's four quarters: ``(root, box)`` with four rows per input row."""
    u0, u1, w0, w1 = box.T
    um, wm = 0.5 * (u0 + u1), 0.5 * (w0 + w1)
    quarters = np.stack(
        [
            np.stack([u0, um, w0, wm], axis=1),
            np.stack([um, u1, w0, wm], axis=1),
            np.stack([u0, um, wm, w1], axis=1),
            np.stack([um, u1, wm, w1], axis=1),
        ],
        axis=1,
    ).reshape(-1, 4)
    return np.repeat(root, 4), quarters


def _seed_rays(roots: np.ndarray, root: np.ndarray, box: np.ndarray) -> np.ndarray:
    """(n, 5, 3) unit directions of each frustum's centre and corner rays."""
    u0, u1, w0, w1 = box.T
    us = np.stack([0.5 * (u0 + u1), u0, u1, u1, u0], axis=1)
    ws = np.stack([0.5 * (w0 + w1), w0, w0, w1, w1], axis=1)
    r = roots[root]
    d = r[:, None, 0] + us[..., None] * r[:, None, 1] + ws[..., None] * r[:, None, 2]
    return d / np.linalg.norm(d, axis=2, keepdims=True)


def _trace_viewpoint(
    scene: FrustumScene,
    view: Viewpoint,
    base_level: int,
    max_level: int,
    tolerance: float,
    fusion: bool = True,
) -> tuple[np.ndarray, dict, tuple[np.ndarray, np.ndarray]]:
    """Trace one viewpoint's frusta level by level: the kept faces (m,) uint8, the counts, and the open frusta's ``(root, box)``."""
    from meshvis._threads import in_threads

    m = scene.soup.n_faces
    keep = np.zeros(m, np.uint8)
    counts = dict.fromkeys(COUNTS, 0)
    open_root, open_box = [np.zeros(0, np.int64)], [np.zeros((0, 4))]
    if m == 0:
        return keep, counts, (open_root[0], open_box[0])
    v = np.asarray(view.position, np.float64)
    delta, eta, mu = margins(scene, v, tolerance)
    roots = np.ascontiguousarray(view.roots, np.float64)
    bvh = scene.bvh
    root, box = base_frusta(len(roots), base_level)
    level = base_level
    while len(root):
        at_limit = np.full(len(root), level >= max_level)
        status = np.empty(len(root), np.int8)
        far = np.empty(len(root))
        for a in range(0, len(root), BATCH):
            b = min(a + BATCH, len(root))
            directions = _seed_rays(roots, root[a:b], box[a:b]).reshape(-1, 3)
            hits = scene.caster.intersect(np.broadcast_to(v, directions.shape), directions)
            seeds = np.ascontiguousarray(hits.face.reshape(-1, 5), np.int64)

            def work(i, j, a=a, seeds=seeds):
                s = slice(a + i, a + j)
                fk.trace_frusta(
                    v, roots, root[s], box[s], at_limit[s], seeds[i:j],
                    scene.triangles, scene.welded, scene.face_edge, scene.edge_start, scene.edge_face, scene.filler,
                    bvh.lo, bvh.hi, bvh.first, bvh.count, bvh.order,
                    delta, eta, mu, MAX_WALK, fusion, keep, status[s], far[s],
                )  # fmt: skip

            in_threads(work, b - a, rows_per_item=64)
        counts["traced"] += len(root)
        counts["blocked"] += int((status == fk.BLOCKED).sum())
        # at the limit without a blocker: kept open, or covered by a union (fused)
        at_open = (status == fk.OPEN) | (status == fk.FUSED)
        counts["open"] += int(at_open.sum())
        counts["fused"] += int((status == fk.FUSED).sum())
        open_root.append(root[at_open])
        open_box.append(box[at_open])
        counts["empty"] += int((status == fk.EMPTY).sum())
        split = status == fk.SPLIT
        counts["split"] += int(split.sum())
        root, box = split_frusta(root[split], box[split])
        level += 1
    return keep, counts, (np.concatenate(open_root).astype(np.int64), np.concatenate(open_box))


def sample_views(
    scene: FrustumScene, views: list[Viewpoint], rays: int, rng: np.random.Generator
) -> np.ndarray:
    """(m, 2) bool: the sides that ``rays`` random rays from each viewpoint hit first.

    Directions are uniform on the sphere for a viewpoint that looks everywhere and uniform
    over the view's image plane for a camera (as its pixels).  A hit is a proof of
    visibility; this is the sampled lower bound of a camera path's bracket, and the dense
    random reference of the benchmarks.

    Parameters
    ----------
    scene : FrustumScene
        The prepared model.
    views : list of Viewpoint
        Where the rays start, and the directions they take.
    rays : int
        Rays per viewpoint (cast in batches of :data:`SAMPLE_BATCH`).
    rng : numpy.random.Generator
        The random generator of the directions.

    Returns
    -------
    (m, 2) bool
    """
    seen = np.zeros((scene.soup.n_faces, 2), bool)
    for view in views:
        left = int(rays)
        while left > 0:
            n = min(left, SAMPLE_BATCH)
            left -= n
            if view.everywhere:
                d = uniform_sphere(n, rng)
            else:
                axis, right, up = view.roots[0]
                u, w = rng.uniform(-1.0, 1.0, (2, n))
                d = axis + u[:, None] * right + w[:, None] * up
                d /= np.linalg.norm(d, axis=1, keepdims=True)
            hits = scene.caster.intersect(np.broadcast_to(view.position, d.shape), d)
            ok = hits.face >= 0
            seen[hits.face[ok], hits.side[ok]] = True
    return seen


def sample_frusta(
    scene: FrustumScene,
    position: np.ndarray,
    frusta: tuple[np.ndarray, np.ndarray, np.ndarray],
    per_side: int,
    rng: np.random.Generator,
) -> np.ndarray:
    """(m, 2) bool: the sides that a jittered grid of rays through each of ``frusta`` hits first.

    Each frustum's box is cut into ``per_side`` x ``per_side`` cells and one ray leaves
    ``position`` through a uniformly random point of each cell.  Aimed at the frusta that
    :func:`conservative_from` keeps open at its limit (``open_frusta``), these rays find
    faces seen only through narrow gaps, which uniformly random rays rarely reach.  Every
    side counted was hit first by a ray, in the float32 Embree scene and again in float64
    (:func:`confirm_hits`): a sampled lower bound, like :func:`sample_views`.

    Parameters
    ----------
    scene : FrustumScene
        The prepared model.
    position : (3,) float64
        The viewpoint.
    frusta : tuple
        ``(roots, root, box)``: (r, 3, 3) roots, (k,) root and (k, 4) box of each frustum
        (:attr:`ConservativeSet.open_frusta`).
    per_side : int
        Rays along each side of a frustum's box (``per_side**2`` rays per frustum).
    rng : numpy.random.Generator
        The random generator of the jitter.

    Returns
    -------
    (m, 2) bool

    Examples
    --------
    >>> import trimesh
    >>> scene = FrustumScene.build(trimesh.creation.box())
    >>> roots = np.array([[[0, 0, 1], [1, 0, 0], [0, 1, 0]]], float)  # looking up +z
    >>> frusta = (roots, np.zeros(1, np.int64), np.array([[-0.1, 0.1, -0.1, 0.1]]))
    >>> seen = sample_frusta(scene, np.zeros(3), frusta, 4, np.random.default_rng(0))
    >>> seen.sum(axis=0).tolist()  # the top's inner side: one or both of its triangles
    [0, 2]
    """
    seen = np.zeros((scene.soup.n_faces, 2), bool)
    roots, root, box = frusta
    per_side = _validate.integer("per_side", per_side, 1, 1 << 10)
    cells = per_side * per_side
    step = max(1, SAMPLE_BATCH // cells)
    grid = (np.arange(cells) % per_side, np.arange(cells) // per_side)
    for a in range(0, len(root), step):
        r, b = root[a : a + step], box[a : a + step]
        s = (grid[0] + rng.random((len(r), cells))) / per_side  # (k, cells) in [0, 1)
        t = (grid[1] + rng.random((len(r), cells))) / per_side
        u = b[:, 0, None] + s * (b[:, 1] - b[:, 0])[:, None]
        w = b[:, 2, None] + t * (b[:, 3] - b[:, 2])[:, None]
        axis, right, up = roots[r, 0], roots[r, 1], roots[r, 2]
        d = axis[:, None] + u[..., None] * right[:, None] + w[..., None] * up[:, None]
        d = d.reshape(-1, 3)
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        hits = scene.caster.intersect(np.broadcast_to(position, d.shape), d)
        confirm_hits(scene, position, d, hits.face, hits.side, seen)
    return seen


def confirm_hits(
    scene: FrustumScene,
    position: np.ndarray,
    directions: np.ndarray,
    face: np.ndarray,
    side: np.ndarray,
    seen: np.ndarray,
    per_side: int = CONFIRM,
) -> None:
    """Mark in ``seen`` the sides that rays hit first, each confirmed by a float64 trace of the ray.

    Rays aimed at narrow gaps and thin faces are where the float32 Embree scene can pass
    between two faces that share an edge, and report a face behind them.  For each side
    not yet in ``seen`` that some rays hit (``face``, ``side``: -1 for a miss), up to
    ``per_side`` of those rays are traced again in float64 (:func:`._frusta_kernels.first_hits`);
    the side is marked when one of them meets the same face first.

    Parameters
    ----------
    scene : FrustumScene
        The prepared model.
    position : (3,) float64
        Where the rays start.
    directions : (n, 3) float64
        Their directions.
    face, side : (n,) int
        What Embree hit first along each (face -1: nothing).
    seen : (m, 2) bool
        The sides seen so far; the confirmed sides are added to it.
    per_side : int
        Rays traced again per side.
    """
    idx = np.flatnonzero(face >= 0)
    idx = idx[~seen[face[idx], side[idx]]]
    if len(idx) == 0:
        return
    key = face[idx].astype(np.int64) * 2 + side[idx]
    order = np.argsort(key, kind="stable")
    key = key[order]
    start = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    rank = np.arange(len(key)) - np.repeat(start, np.diff(np.r_[start, len(key)]))
    pick = idx[order[rank < per_side]]
    got = np.empty(len(pick), np.int64)
    bvh = scene.bvh
    fk.first_hits(
        np.asarray(position, np.float64), np.ascontiguousarray(directions[pick], np.float64),
        scene.triangles, bvh.lo, bvh.hi, bvh.first, bvh.count, bvh.order, got,
    )  # fmt: skip
    good = got == face[pick]
    seen[face[pick][good], side[pick][good]] = True


def bracket(model, region, *, search, max_level: int = DEFAULT_MAX_LEVEL, **search_kw):
    """The sampled set and the conservative set from the viewpoints of ``region``.

    What :func:`meshvis.visible_from` returns with ``conservative=True``: its search (the
    function ``search``, with ``search_kw``) looks from the viewpoints' positions (a
    camera path's cameras, not the lines between them), and the result carries the
    conservative set as ``conservative``.  Cameras that look into a view, not everywhere,
    cannot be searched by guided sampling; their sampled set is ``budget`` (default
    :data:`VIEW_RAYS`) random rays in each view (:func:`sample_views`).

    Parameters
    ----------
    model : Soup, trimesh object, (vertices, faces) or path
        Anything :func:`meshvis.io.as_soup` accepts.
    region : str or Region
        ``points:...`` or ``path:CAMERAS.json`` (:func:`conservative_from`).
    search : callable
        :func:`meshvis.visible_from`.
    max_level : int
        Subdivision limit of the frusta (:func:`conservative_from`).
    **search_kw
        ``budget``, ``seed``, ``method``, ``caster``, ... of the search.

    Returns
    -------
    Visibility
        The search's result, ``conservative`` set to the :class:`ConservativeSet`.
    """
    soup = as_soup(model)
    views = parse_viewpoints(region)
    scene = FrustumScene.build(soup, search_kw.pop("caster", None))
    positions = Points(points=np.array([v.position for v in views]))
    if all(v.everywhere for v in views):
        vis = search(soup, positions, caster=scene.caster, **search_kw)
    else:
        budget = search_kw.pop("budget", None)
        rays = VIEW_RAYS if budget is None else int(budget)
        # one ray: the search only builds the result, whose sets are replaced below
        vis = search(soup, positions, caster=scene.caster, **{**search_kw, "budget": 1})
        rng = np.random.default_rng(search_kw.get("seed", 0))
        vis.seen_side[:] = sample_views(scene, views, max(rays // len(views), 1), rng)
        vis.method = "random rays in the views"
        vis.rays = {"random": rays, "total": rays}
    vis.conservative = conservative_from(soup, views, max_level=max_level, scene=scene)
    return vis
