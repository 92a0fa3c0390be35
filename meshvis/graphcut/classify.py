"""Inside/outside classification of every triangle side by visibility graph cut (appendix H).

Pipeline (DESIGN.md §4)::

    soup → vertex groups → Embree scene → preprocess (flags, welding, clusters)
         → half-space nodes → visibility sampling
         → weights (Eq. 5–9) → s-t min cut → per-(face, side) labels

Sampling is *progressive*: rays are cast in rounds and the loop stops as soon as a round
changes the labels of less than ``tolerance`` of the total area, when no node is left
undecided, or when the ray budget ``rays_per_node`` is spent.  The first round samples
every node; later rounds double the rays of the undecided nodes only — those whose label
changed in the last round, those on the cut (linked to a node of the other label), those
whose escape share is within a factor of two of the ``opening`` threshold and, after the
first round, those whose two terminal links are within a factor of two — in the spirit of
adaptive global visibility sampling (AGVS).  A sample-point node whose vote is decided
with a margin (:func:`settled_nodes`) casts no more rays of its own, and each round says
how many it left out.  A clean closed model stops after
one small round.  Stages a model does not need (point nodes when nothing is
flagged, hint rays without hints) are skipped, and the result says so; so are the nodes
that the max flow settles before its search (their terminal link outweighs all their
edges, :mod:`~meshvis.graphcut.boykov_kolmogorov`), counted per round and in the cut
stage's note.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshvis import _validate
from meshvis._version import __version__
from meshvis.errors import ModelError, ParameterError
from meshvis.geometry.adjacency import VertexGroups, group_vertices
from meshvis.graphcut.hints import Hints, hint_weights
from meshvis.graphcut.mincut import DEFAULT_SOLVER, SOLVERS, Cut, VisibilityGraph
from meshvis.graphcut.nodes import NodeSet, build_nodes
from meshvis.graphcut.preprocess import Preprocessed, preprocess
from meshvis.graphcut.sampling import VisibilityCounts, sample_round
from meshvis.graphcut.weights import DEFAULT_OPENING, graph_weights
from meshvis.io import as_soup
from meshvis.rays.caster import DEFAULT_OFFSET, RayCaster
from meshvis.soup import Soup

#: rays of the first progressive round, per node (before the cluster-size factor)
FIRST_ROUND_RAYS = 4
#: upper bound of the per-node ray multiplier of large clusters
CLUSTER_RAY_FACTOR_MAX = 64
#: standard deviations of the escape share within which a node counts as undecided
#: against the opening threshold (:func:`opening_undecided`)
OPENING_Z = 3.0
#: no escape in n rays bounds the escape share below this / n with 99.9 % (-ln 1e-3)
ZERO_ESCAPE_BOUND = 6.9
#: a sample-point node is settled, and gets no more rays, once its net terminal link outweighs this many
#: times all the capacity of its edges (:func:`settled_nodes`) ...
SETTLED_MARGIN = 2.0
#: ... with at least this many of its own rays counted
SETTLED_MIN_RAYS = 8


def sees_others(hits) -> np.ndarray:
    """(n,) bool: some ray of the node hit another node (off-diagonal hits)."""
    h = hits.tocsr()
    return np.asarray(h.sum(axis=1)).ravel() - h.diagonal() > 0


@dataclass
class Stage:
    """One pipeline stage in the report: whether it ran, why not, and its time."""

    name: str
    ran: bool
    seconds: float = 0.0
    note: str = ""


@dataclass
class Classification:
    """Result of :func:`classify`.

    Attributes
    ----------
    outside : (m, 2) float64
        Per input face and side (0 = front/counter-clockwise, 1 = back): 1.0 outside,
        0.0 inside; for flagged (intersecting/coplanar) faces, the outside fraction of the
        side's sample-point area.
    degenerate : (m,) bool
        Zero-area faces (not classified; both sides reported inside)
    flagged : (m,) bool
        Faces classified through sample points
    cluster : (m,) int64
        Cluster id (-1 for flagged and degenerate faces)
    nodes, graph, counts, cut : NodeSet, VisibilityGraph, VisibilityCounts, Cut
        The internals, for inspection and layer peeling.
    stages : list of Stage
        The stages run or skipped, with their times.
    rounds : list of dict
        Per-round statistics.
    """

    soup: Soup
    outside: np.ndarray
    degenerate: np.ndarray
    flagged: np.ndarray
    cluster: np.ndarray
    nodes: NodeSet
    graph: VisibilityGraph
    counts: VisibilityCounts
    cut: Cut
    caster: RayCaster
    pre: Preprocessed
    stages: list[Stage] = field(default_factory=list)
    rounds: list[dict] = field(default_factory=list)
    params: dict = field(default_factory=dict)

    # ---------------------------------------------------------------- derived per-face views
    @property
    def side_outside(self) -> np.ndarray:
        """(m, 2) bool: a side counts as outside when more than half of it is."""
        return self.outside > 0.5

    @property
    def hidden(self) -> np.ndarray:
        """(m,) bool: no side outside."""
        return ~np.any(self.side_outside, axis=1)

    @property
    def two_sided(self) -> np.ndarray:
        """(m,) bool: both sides outside."""
        return np.all(self.side_outside, axis=1)

    def face_labels_from(self, node_outside: np.ndarray) -> np.ndarray:
        """(m, 2) outside fractions for a node labelling (e.g. from a later cut)."""
        return face_labels(self.nodes, node_outside, self.soup.n_faces, self.degenerate)

    @property
    def n_rays(self) -> int:
        """Rays cast in all: node rays, reverse (confirmation) rays and hint rays."""
        return int(self.counts.rays + self.counts.reverse_rays + self.params.get("hint_rays", 0))

    def report(self, per_face: bool = True) -> dict:
        """A JSON-ready dictionary: counts, stages, rounds, timings, parameters, arrays."""
        d = {
            "version": __version__,
            "faces": self.soup.n_faces,
            "nodes": self.graph.n,
            "cluster_nodes": self.nodes.n_cluster,
            "point_nodes": self.nodes.n - self.nodes.n_cluster,
            # sample points a full count on every flagged face would have added
            "sample_points_left_out": self.nodes.samples * len(self.nodes.flagged) - self.nodes.n_points,
            "clusters": int(self.pre.clustering.n_clusters),
            "edges": self.graph.n_edges,
            "flagged_faces": int(self.flagged.sum()),
            # the counts of the analysis pass `meshvis info` runs too
            **self.pre.analysis.counts,
            "rays": int(self.counts.rays),
            "reverse_rays": int(self.counts.reverse_rays),
            "hint_rays": int(self.params.get("hint_rays", 0)),
            "discarded_rays": int(self.counts.discarded.sum()),
            "rounds": self.rounds,
            "cut_value": self.cut.value,
            "solver": self.cut.solver,
            "stages": [s.__dict__ for s in self.stages],
            "embree_seconds": self.counts.time_embree,
            "sampling_seconds": self.counts.time_total,
            "embree_share_of_sampling": self.counts.time_embree / self.counts.time_total
            if self.counts.time_total
            else 0.0,
            "params": self.params,
            "outside_area_fraction": float(
                (self.side_outside.any(axis=1) * self.soup.areas).sum() / max(self.soup.total_area, 1e-300)
            ),
        }
        if per_face:
            d["per_face"] = {
                "outside_front": self.outside[:, 0],
                "outside_back": self.outside[:, 1],
                "flagged": self.flagged,
                "degenerate": self.degenerate,
                "cluster": self.cluster,
            }
        return d

    def summary(self) -> str:
        """A few lines for the terminal."""
        r = self.report(per_face=False)
        lines = [
            f"{r['faces']} faces: {r['clusters']} clusters, {r['flagged_faces']} flagged "
            f"({r['intersecting_faces']} intersecting, {r['coplanar_faces']} coplanar), {r['degenerate_faces']} degenerate",
            f"graph: {r['nodes']} nodes ({r['cluster_nodes']} cluster, {r['point_nodes']} point), {r['edges']} edges",
            f"rays: {r['rays']} + {r['reverse_rays']} reverse + {r['hint_rays']} hint in {len(self.rounds)} round(s); "
            f"Embree share of sampling {100 * r['embree_share_of_sampling']:.0f}%",
        ]
        for s in self.stages:
            lines.append(f"  {s.name:<12} {'%.3f s' % s.seconds if s.ran else 'skipped':>10}  {s.note}")
        return "\n".join(lines)


def face_labels(nodes: NodeSet, node_outside: np.ndarray, m: int, degenerate: np.ndarray) -> np.ndarray:
    """Map node labels back to input faces: (m, 2) outside fractions (see Classification)."""
    out = np.zeros((m, 2))
    clustered = nodes.side_node[:, 0] >= 0
    out[clustered] = node_outside[nodes.side_node[clustered]]
    if len(nodes.flagged):
        first, count = nodes.point_start[:-1], nodes.point_count
        for s in (0, 1):
            lab = node_outside[nodes.n_cluster + 2 * np.arange(nodes.n_points) + s].astype(np.float64)
            out[nodes.flagged, s] = np.add.reduceat(lab, first) / count
    out[degenerate] = 0.0
    return out


def ray_allocation(nodes: NodeSet, rays: int, point_rays: int) -> np.ndarray:
    """Rays per node: ``rays`` times a factor √(faces in node), capped; ``point_rays`` per sample point.

    A cluster node of many triangles gets more rays than a single sample point, so that
    its origins cover its area, but not proportionally more (its weights are sums).

    Parameters
    ----------
    nodes : NodeSet
        The half-space nodes.
    rays : int
        Rays of a one-face cluster node.
    point_rays : int
        Rays of each sample-point node (``rays`` gives every one-face node the same).

    Returns
    -------
    (n,) int64 array
        Rays of each node; 0 for nodes without area.
    """
    factor = np.clip(np.ceil(np.sqrt(nodes.n_faces)), 1, CLUSTER_RAY_FACTOR_MAX).astype(np.int64)
    alloc = rays * factor
    alloc[nodes.n_cluster :] = point_rays
    alloc[nodes.area <= 0] = 0
    return alloc


def settled_nodes(weights, counted: np.ndarray) -> np.ndarray:
    """(n,) bool: nodes whose vote is decided with a margin; they get no more rays.

    A node whose net link to one terminal exceeds the capacity of all its edges is on
    that terminal's side of every minimum cut (the settling of
    :mod:`~meshvis.graphcut.boykov_kolmogorov`); one that exceeds it
    :data:`SETTLED_MARGIN` times, on at least :data:`SETTLED_MIN_RAYS` rays of its own,
    stays there while its estimates move within their spread, so more rays of its own
    would not change the cut.  Its neighbours still cast theirs.

    Parameters
    ----------
    weights : Weights
        The graph's capacities (:func:`~meshvis.graphcut.weights.graph_weights`).
    counted : (n,) int
        Rays of each node counted so far (cast minus discarded).

    Returns
    -------
    (n,) bool

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> w = SimpleNamespace(edges_i=np.array([0]), edges_j=np.array([1]), cap_ij=np.array([1.0]),
    ...     cap_ji=np.array([1.0]), cap_out=np.array([5.0, 1.5]), cap_in=np.array([0.0, 0.0]))
    >>> settled_nodes(w, np.array([8, 8])).tolist()
    [True, False]
    """
    n = len(weights.cap_out)
    i, j = weights.edges_i, weights.edges_j
    leaving = np.bincount(i, weights.cap_ij, n) + np.bincount(j, weights.cap_ji, n)
    entering = np.bincount(i, weights.cap_ji, n) + np.bincount(j, weights.cap_ij, n)
    net = weights.cap_out - weights.cap_in
    decided = (net > SETTLED_MARGIN * leaving) | (-net > SETTLED_MARGIN * entering)
    return decided & (np.asarray(counted) >= SETTLED_MIN_RAYS)


def opening_undecided(
    escaped: np.ndarray,
    counted: np.ndarray,
    opening: float | None,
    n_faces: np.ndarray,
    sees_others: np.ndarray,
) -> np.ndarray:
    """(n,) bool: nodes whose escape share cannot yet be told above or below ``opening``.

    The share of ``n`` rays is binomial: a node is undecided while ``opening`` lies within
    :data:`OPENING_Z` standard deviations of its share (the deviation taken at the larger of
    the share and the threshold, so that both sides are refined alike), or within a factor of
    two of it.  A node none of whose rays escaped is decided once ``-ln(1e-3) / n`` (the
    99.9 % bound of its share) is below ``opening``, when it is a single face or sample
    point (there are many, and the prior holds for them) or when all its rays came back to
    itself (``sees_others`` False: a closed shell's inside, which settles in its first round).
    Undecided nodes keep receiving rays, and the sampling does not stop while one is left
    with budget: otherwise whether a crack near the threshold leaks depends on the seed.
    """
    if opening is None:
        return np.zeros(len(escaped), bool)
    n = np.maximum(counted, 1)
    share = escaped / n
    p = np.maximum(share, opening)
    band = OPENING_Z * np.sqrt(p * (1 - p) / n)
    # no escape in n rays bounds the share below ZERO_ESCAPE_BOUND / n (99.9 %); a node
    # whose rays all came back to itself (a closed shell's inside) is decided all the same
    unbounded = (escaped == 0) & (n_faces > 1) & (ZERO_ESCAPE_BOUND / n > opening) & sees_others
    return (
        ((escaped > 0) | unbounded)
        & (counted > 0)
        & ((np.abs(share - opening) <= band) | ((share > 0.5 * opening) & (share < 2 * opening)))
    )


def classify(
    model: Any,
    *,
    rays_per_node: int = 32,
    seed: int = 0,
    hints: Hints | dict | None = None,
    samples_per_face: int = 4,
    point_area: float | None = None,
    rays_per_point: int | None = None,
    sampling_scheme: int = 2,
    use_filter: bool = True,
    opening: float | None = DEFAULT_OPENING,
    progressive: bool = True,
    tolerance: float = 1e-3,
    solver: str = DEFAULT_SOLVER,
    offset: float | None = None,
    caster: RayCaster | None = None,
    progress: Callable[[str, float], None] | None = None,
) -> Classification:
    """Classify both sides of every triangle as inside or outside.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (vertices, faces) or path
        The model.
    rays_per_node : int
        Ray budget per half-space node (before the cluster factor, see
        :func:`ray_allocation`); progressive sampling may stop earlier
    seed : int
        Seed of the one random generator; same input and seed give identical output.
    hints : Hints or dict, optional
        Inside/outside points and boxes (:class:`~meshvis.graphcut.hints.Hints`).
    samples_per_face : int
        The most sample points of an intersecting/coplanar face (appendix H §3.1).
    point_area : float or None
        None (default): every flagged face carries ``samples_per_face`` sample points.
        A number: a flagged face carries one sample point per this many times the mean
        face area, at least one and at most ``samples_per_face``
        (:func:`meshvis.graphcut.nodes.sample_counts`); the report counts the points so
        left out (``orient`` classifies so, :data:`meshvis.repair.orient.POINT_AREA`).
    rays_per_point : int, optional
        Ray budget of each sample-point node (default ``rays_per_node``).
        Most rays of a model with many intersecting faces come from their sample points;
        ``rays_per_node // samples_per_face`` gives a flagged face's side the budget of an
        unflagged face's, at a measured cost in accuracy (``meshvis bench real --rays-per-point``).
    sampling_scheme : {1, 2}
        1 (uniform) or 2 (uniform + edges, default).
    use_filter : bool
        Apply the directed cosine filter (Eq. 8–9).
    opening : float or None
        A side whose escaping ray share exceeds this is not pulled inside by the
        prior of its opposite side (an opening, not a crack; see
        :func:`meshvis.graphcut.weights.inside_prior`); None follows the paper exactly
    progressive : bool
        Sample in rounds and stop when labels settle (else one full round).
    tolerance : float
        Stop when a round changes less than this fraction of the total side area.
    solver : {"bk", "pymaxflow", "scipy"}
        "bk" (compiled Boykov–Kolmogorov), "pymaxflow" (the same through PyMaxflow,
        the same labels) or "scipy" (integer capacities)
    offset : float, optional
        Push of ray origins off surfaces, relative to the bounding-box diagonal.
    caster : RayCaster, optional
        A prebuilt :class:`~meshvis.rays.caster.RayCaster` of the same model to reuse.
    progress : callable, optional
        Called as ``progress(stage, fraction)``.

    Returns
    -------
    Classification

    Raises
    ------
    ModelError
        The model is unusable, or every face is degenerate (nothing to classify).
    ParameterError
        An argument is out of its range.

    Examples
    --------
    >>> import trimesh
    >>> c = classify(trimesh.creation.icosphere(2), seed=1)
    >>> bool(c.side_outside[:, 0].all() and not c.side_outside[:, 1].any())
    True
    """
    _validate.classify_args(
        rays_per_node,
        seed,
        samples_per_face,
        sampling_scheme,
        opening,
        tolerance,
        solver,
        offset,
        progress,
        rays_per_point=rays_per_point,
    )
    _validate.instance("caster", caster, RayCaster, optional=True)
    if point_area is not None:
        _validate.real("point_area", point_area, 0.0, open_lo=True)
    if rays_per_node < 1:
        raise ParameterError(f"rays_per_node must be at least 1, got {rays_per_node}")
    if samples_per_face < 1:
        raise ParameterError(f"samples_per_face must be at least 1, got {samples_per_face}")
    if solver not in SOLVERS:
        raise ParameterError(f"unknown solver {solver!r}; choose one of {', '.join(SOLVERS)}")
    if opening is not None and not 0 < opening <= 1:
        raise ParameterError(f"opening must be in (0, 1] or None, got {opening}")
    if not 0 <= tolerance < 1:
        raise ParameterError("tolerance must be in [0, 1)")
    hints = Hints.coerce(hints)
    soup = as_soup(model)
    if rays_per_point is None:
        rays_per_point = rays_per_node
    # what the options may ask of this input is bounded before the analysis runs
    _validate.ray_budget(soup, rays_per_node, rays_per_point, samples_per_face)
    rng = np.random.default_rng(seed)
    stages: list[Stage] = []
    report = progress or (lambda stage, frac: None)
    groups = _vertex_groups(soup, caster, stages)
    caster = _scene(soup, caster, offset, groups, stages, report)
    pre = _preprocess(soup, groups, stages, report)
    nodes = _nodes(soup, pre, caster, samples_per_face, point_area, sampling_scheme, stages)
    hint_out, hint_in, hint_rays = _hints(caster, nodes, hints, rng, stages)
    loop = _Sampling(
        caster, nodes, soup, pre.degenerate, rng, hint_out, hint_in, use_filter, opening, solver, report
    )
    loop.run(rays_per_node, rays_per_point, progressive, tolerance)
    stages += loop.stages(use_filter)
    report("done", 1.0)
    params = {
        "rays_per_node": rays_per_node,
        "seed": seed,
        "samples_per_face": samples_per_face,
        "point_area": point_area,
        "rays_per_point": rays_per_point,
        "sampling_scheme": sampling_scheme,
        "use_filter": use_filter,
        "opening": opening,
        "progressive": progressive,
        "tolerance": tolerance,
        "solver": solver,
        "offset": caster.offset,
        "hint_rays": hint_rays,
    }
    return Classification(
        soup=soup,
        outside=loop.labels,
        degenerate=pre.degenerate,
        flagged=pre.flagged,
        cluster=pre.clustering.cluster,
        nodes=nodes,
        graph=loop.graph,
        counts=loop.counts,
        cut=loop.cut,
        caster=caster,
        pre=pre,
        stages=stages,
        rounds=loop.rounds,
        params=params,
    )


# ---------------------------------------------------------------------- the stages of classify
def _vertex_groups(soup: Soup, caster: RayCaster | None, stages: list[Stage]) -> VertexGroups:
    """The bit-identical vertex groups: the scene's vertex buffer and the weld's first step."""
    if caster is not None and caster.soup is soup:
        stages.append(Stage("groups", False, 0.0, "vertex groups of the given caster"))
        return caster.vertex_groups
    t = time.perf_counter()
    groups = group_vertices(soup.vertices, soup.faces)
    note = f"{len(groups.first)} distinct of {len(groups.used)} used vertices"
    stages.append(Stage("groups", True, time.perf_counter() - t, note))
    return groups


def _scene(
    soup: Soup,
    caster: RayCaster | None,
    offset: float | None,
    groups: VertexGroups,
    stages: list[Stage],
    report,
) -> RayCaster:
    """The Embree scene on the vertex groups (or the caller's prebuilt one)."""
    t = time.perf_counter()
    report("scene", 0.0)
    if caster is None:
        push = DEFAULT_OFFSET if offset is None else offset
        caster = RayCaster(soup, offset=push, vertex_groups=groups)
    stages.append(Stage("scene", True, time.perf_counter() - t, "Embree scene on the normalised copy"))
    return caster


def _preprocess(soup: Soup, vertex_groups, stages: list[Stage], report) -> Preprocessed:
    """Flags and clusters (appendix H §2); every face degenerate is a :class:`ModelError`."""
    t = time.perf_counter()
    report("preprocess", 0.0)
    pre = preprocess(
        soup, progress=lambda stage, frac: report("preprocess", frac), vertex_groups=vertex_groups
    )
    if pre.degenerate.all():  # no side has an area: there is no graph to cut
        what = "the only face is" if soup.n_faces == 1 else f"all {soup.n_faces} faces are"
        raise ModelError(f"{what} degenerate (zero area): nothing to classify", soup.path)
    note = f"{pre.clustering.n_clusters} clusters, {int(pre.flagged.sum())} flagged faces"
    stages.append(Stage("preprocess", True, time.perf_counter() - t, note))
    return pre


def _nodes(
    soup: Soup,
    pre: Preprocessed,
    caster: RayCaster,
    samples: int,
    point_area: float | None,
    scheme: int,
    stages: list[Stage],
) -> NodeSet:
    """Half-space nodes: cluster sides and the sample points of flagged faces."""
    t = time.perf_counter()
    off_abs = caster.offset * caster.diagonal
    nodes = build_nodes(
        soup.triangles,
        soup.normals,
        soup.areas,
        pre.clustering,
        pre.flagged,
        pre.partner_pairs,
        samples=samples,
        scheme=scheme,
        offset=off_abs,
        proximity=2 * off_abs,
        duplicate_first=pre.analysis.duplicate_first,
        point_area=point_area,
    )
    left_out = samples * len(nodes.flagged) - nodes.n_points
    point_note = (
        f"{nodes.n_points} sample points ({left_out} left out on small faces)"
        if nodes.n_points
        else "skipped point nodes: no flagged faces"
    )
    stages.append(Stage("nodes", True, time.perf_counter() - t, f"{nodes.n} nodes; {point_note}"))
    return nodes


def _hints(caster: RayCaster, nodes: NodeSet, hints: Hints | None, rng, stages: list[Stage]):
    """Terminal weights from user hints: (hint_out, hint_in, rays), or (None, None, 0)."""
    if hints is None or hints.empty:
        stages.append(Stage("hints", False, 0.0, "no hints given"))
        return None, None, 0
    t = time.perf_counter()
    hint_out, hint_in, hint_rays = hint_weights(caster, nodes, hints, rng)
    stages.append(Stage("hints", True, time.perf_counter() - t, f"{hint_rays} rays from hints"))
    return hint_out, hint_in, hint_rays


class _Sampling:
    """Progressive visibility sampling and cutting: the state carried from round to round."""

    def __init__(
        self, caster, nodes, soup, degenerate, rng, hint_out, hint_in, use_filter, opening, solver, report
    ):
        self.caster, self.nodes, self.soup, self.degenerate, self.rng = caster, nodes, soup, degenerate, rng
        self.hint_out, self.hint_in, self.use_filter, self.opening = hint_out, hint_in, use_filter, opening
        self.solver, self.report = solver, report
        self.counts = VisibilityCounts(nodes.n)
        self.rounds: list[dict] = []
        self.t_sample = self.t_cut = 0.0
        self.stop_reason = "single round"
        self.left_out = 0  # rays the settled nodes did not cast (their next round's)
        self.graph = self.cut = self.labels = None

    def run(self, rays_per_node: int, rays_per_point: int, progressive: bool, tolerance: float) -> None:
        """Cast rounds of rays and cut after each until the labels settle (module notes)."""
        nodes = self.nodes
        budget = ray_allocation(nodes, rays_per_node, rays_per_point)
        cast = np.zeros(nodes.n, np.int64)
        if progressive:
            give = ray_allocation(
                nodes, min(FIRST_ROUND_RAYS, rays_per_node), min(FIRST_ROUND_RAYS, rays_per_point)
            )
        else:
            give = budget.copy()
        prev = prev_nodes = None
        while True:
            t_sample, t_cut = self.t_sample, self.t_cut
            self._sample(give, cast, budget)
            cast += give
            self._cut()
            changed = self._changed(prev)
            self.rounds.append(
                {
                    "rays": int(self.counts.rays),
                    "nodes_sampled": int((give > 0).sum()),
                    "edges": self.graph.n_edges,
                    "settled_nodes": self.cut.settled,
                    "changed_area_fraction": changed,
                    "sampling_seconds": self.t_sample - t_sample,
                    "cut_seconds": self.t_cut - t_cut,
                }
            )
            if not progressive:
                break
            counted = self.counts.cast - self.counts.discarded
            near_threshold = opening_undecided(
                self.counts.escaped, counted, self.opening, nodes.n_faces, sees_others(self.counts.hits)
            ) & (cast < budget)
            # only clusters of several faces (the sheets around a crack) hold the loop open
            held = (near_threshold & (nodes.n_faces > 1)).any()
            if changed is not None and changed <= tolerance and not held:
                self.stop_reason = (
                    f"converged after {len(self.rounds)} rounds (change {changed:.2e} <= {tolerance:g})"
                )
                break
            active = self._undecided(prev_nodes)
            # a sample point whose vote is decided with a margin casts no more rays of its own;
            # a cluster's escape shares are also orient's evidence, and keep their rays
            settled = active & settled_nodes(self.graph.weights, counted) & nodes.is_point & ~near_threshold
            self.rounds[-1]["settled_left_out"] = int(settled.sum())
            self.rounds[-1]["rays_left_out"] = int(np.minimum(cast, budget - cast)[settled].sum())
            self.left_out += self.rounds[-1]["rays_left_out"]
            active = (active & ~settled) | near_threshold
            give = np.where(active, np.minimum(cast, budget - cast), 0)
            # a node undecided against the opening threshold gets its whole remaining budget at
            # once: it is settled in one more round instead of one doubling per round
            give[near_threshold] = (budget - cast)[near_threshold]
            prev, prev_nodes = self.labels, self.cut.outside
            if not active.any():
                self.stop_reason = f"settled after {len(self.rounds)} round(s): no node left undecided"
                break
            if give.sum() == 0:
                self.stop_reason = f"ray budget reached after {len(self.rounds)} rounds"
                break

    def _sample(self, give: np.ndarray, cast: np.ndarray, budget: np.ndarray) -> None:
        t = time.perf_counter()
        stage, total, done = f"sampling {len(self.rounds) + 1}", max(float(give.sum()), 1.0), [0]
        self.report(stage, 0.0)

        def step(rays: int) -> None:  # the progress of this round, batch by batch
            done[0] += rays
            self.report(stage, done[0] / total)

        sample_round(self.caster, self.nodes, give, self.rng, self.counts, progress=step)
        self.t_sample += time.perf_counter() - t

    def _cut(self) -> None:
        """Weights (Eq. 5-9) from the counts so far, the min cut and the face labels."""
        t = time.perf_counter()
        c, nodes = self.counts, self.nodes
        weights = graph_weights(
            c.hits,
            c.cast - c.discarded,
            c.escaped,
            nodes.area,
            nodes.opposite,
            nodes.is_point,
            hint_out=self.hint_out,
            hint_in=self.hint_in,
            use_filter=self.use_filter,
            opening=self.opening,
        )
        self.graph = VisibilityGraph(nodes.n, weights)
        self.cut = self.graph.cut(self.solver)
        self.labels = face_labels(nodes, self.cut.outside, self.soup.n_faces, self.degenerate)
        self.t_cut += time.perf_counter() - t

    def _changed(self, prev: np.ndarray | None) -> float | None:
        """Fraction of the side area whose label changed since the previous round."""
        if prev is None:
            return None
        soup = self.soup
        return float(
            (np.abs(self.labels - prev).sum(axis=1) * soup.areas).sum() / max(2 * soup.total_area, 1e-300)
        )

    def _undecided(self, prev_nodes: np.ndarray | None) -> np.ndarray:
        """Nodes that get more rays: label changed, on the cut, or (first round) near a tie."""
        outside, w = self.cut.outside, self.graph.weights
        active = np.zeros(self.nodes.n, bool) if prev_nodes is None else outside != prev_nodes
        across = outside[w.edges_i] != outside[w.edges_j]
        active[w.edges_i[across]] = True
        active[w.edges_j[across]] = True
        if prev_nodes is None:
            # after the first round also every node whose terminal links are close to a tie
            margin = np.abs(w.cap_out - w.cap_in) <= 0.5 * np.maximum(w.cap_out, w.cap_in)
            active |= margin & (np.maximum(w.cap_out, w.cap_in) > 0)
        return active

    def stages(self, use_filter: bool) -> list[Stage]:
        c = self.counts
        return [
            Stage(
                "sampling",
                True,
                self.t_sample,
                f"{c.rays} rays + {c.reverse_rays} reverse; {self.stop_reason}"
                + (f"; settled nodes left out {self.left_out} rays" if self.left_out else ""),
            ),
            Stage(
                "cut",
                True,
                self.t_cut,
                f"{self.graph.n_edges} edges, solver {self.cut.solver}, filter {'on' if use_filter else 'off'}"
                + (
                    f"; {self.cut.settled} of {self.nodes.n} nodes settled before the search"
                    if self.cut.settled
                    else ""
                ),
            ),
        ]
