"""From-region visibility: which face sides can a viewer in a region see (DESIGN.md §9).

:func:`visible_from` runs rounds.  Each round gives every face that is not seen yet a few
random seed rays (more per face in every round); ``method="guided"`` then propagates every
new sighting by adaptive border sampling and reverse sampling (GVS §3.4) until no new face
turns up, ``method="random"`` does not (the baseline).  The first round visits the faces in
a random order in chunks, so that faces found by propagation from an earlier chunk need no
seed rays at all; later rounds visit the unseen faces in a random order in chunks of about a
million rays, with view lines (GVS §3.1) cast between the chunks.  Two rules end the
search.  The view lines' rule: fewer than ``max_unseen`` per million of the lines that hit
the model first hit an unseen face (an estimate of the false pixels per million of removing
the unseen faces).  The seed rays' rule (GVS §3.5): after a chunk, the rays since its last
look (at least a million) found fewer than ``min_new`` new faces per million rays or less
than ``min_new_area`` of the model's area per million rays; when it holds, the rest of the
round is left out and it must hold again on the next round's first window
(:data:`CONFIRM_NEXT_ROUND`), after which only the view lines go on.  The search also stops
when every face is seen, or at the ray budget (by default only a cap: :func:`default_budget`).

A seen side is certain (a free line of sight was traced); an unseen one is an upper bound on
"hidden".
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from meshvis import _validate, limits
from meshvis.errors import ParameterError
from meshvis.geometry.adjacency import weld
from meshvis.io import as_soup
from meshvis.rays.caster import VISIBILITY_OFFSET, RayCaster
from meshvis.visibility.regions import Region, parse_region
from meshvis.visibility.sampling import Sightings, border_sampling, random_seeds, reverse_sampling, view_lines
from meshvis.visibility.walls import DEFAULT_TRANSPARENT, walls

if TYPE_CHECKING:
    from meshvis.visibility.conservative import ConservativeSet

#: the stage name of the search in ``progress(stage, fraction)``
PROGRESS_STAGE = "sight"
#: seed rays per unseen face in successive rounds
SEED_ROUNDS = (4, 16, 64, 256, 1024, 4096)
#: the first round visits the faces in this many chunks (propagation runs after each)
FIRST_ROUND_CHUNKS = 16
#: default stop rule: fewer new faces than this per million rays (GVS §3.5 uses 50) ...
MIN_NEW_PER_MILLION = 50.0
#: ... or less new visible area than this fraction of the model's area per million rays:
#: what a viewer misses is area, not a face count (on a finely tessellated model the small
#: faces found late keep the count up after the area has dried up; ``meshvis bench real``
#: measures the false pixels this leaves)
MIN_NEW_AREA_PER_MILLION = 1e-5
#: the stop rule must hold twice: at the end of a window, and again on the first window of
#: the next round, which gives the faces still unseen 4 x the seed rays (the rest of the
#: round is left out): faces seen through rare gaps get more than one round's seeds
CONFIRM_NEXT_ROUND = True
#: the stop rule is judged over at least this many rays (GVS counts new faces per million
#: rays) or, on small models, this many rays per face, whichever is fewer
STOP_WINDOW = 1_000_000
STOP_WINDOW_PER_FACE = 64
#: seed rounds after the first are cast in chunks of about this many rays, in a random
#: order, and the stop rule is judged after every chunk: a round of 1,024 or 4,096 rays per
#: face would otherwise run to its end (tens of millions of rays) before the rule is asked,
#: and a budget would cut it off at the faces of the lowest indices
ROUND_CHUNK_RAYS = 1 << 20
#: default budget, a cap only: the stop rule ends the search, the cap bounds its time on models
#: where faces keep turning up (rays per face asked about, at least 2**22 rays since small models
#: are cheap and faces seen through rare gaps need rays whatever the model's size, and at most
#: :data:`meshvis.limits.MAX_RAYS`)
MAX_RAYS_PER_FACE = 1024
DEFAULT_MIN_BUDGET = 1 << 22
#: with ``faces=``, sightings are propagated only on the faces asked about and on this many
#: rings of faces around them (faces sharing a vertex): spreading from every sighting would
#: search the whole visible model, and without the rings the faces seen only from a viewer
#: of their visible neighbours are lost
PROPAGATE_RINGS = 3
#: sightings propagated in one batch (bounded memory: ~100 rays each)
PROPAGATE_BATCH = 1 << 15
#: view lines cast per seed ray of the rounds after the first (interleaved with the seeds)
LINES_PER_SEED_RAY = 0.5
#: view lines traced per batch (bounded memory)
LINE_BATCH = 1 << 18
#: the lines' stop rule is judged over windows of this many lines that hit the model, or on
#: small models this many per face, whichever is fewer ...
LINE_WINDOW = 1 << 20
LINE_WINDOW_PER_FACE = 64
#: ... and holds when fewer than this many of those lines per million first hit a face not seen
#: yet (an estimate of the false pixels per million of removing the unseen faces)
MAX_UNSEEN_PER_MILLION = 10.0
#: seed rays after the first round and view lines: this share of them looks along a coordinate
#: plane (:func:`meshvis.visibility.regions.view_directions`); on the cycloidal drive, faces in
#: thin horizontal slots are seen by 3e-5 of uniform seed rays and by 6e-4 of plane ones
PLANE_SHARE = 0.25
METHODS = ("guided", "random")


@dataclass
class Visibility:
    """Result of :func:`visible_from`.

    Attributes
    ----------
    seen_side : (m, 2) bool
        Per input face and side (0 front, 1 back): a ray from the region saw it.
    rays_seen : (m, 2) int64
        Rays that saw each side.
    seed_rays : (m,) int64
        Random seed rays aimed at each face.
    area : (m,) float64
        Face areas.
    first_seen : (m,) int64
        Rays cast up to the end of the batch that first saw the face (-1: never seen); the faces
        seen with at most ``r`` rays are ``(first_seen >= 0) & (first_seen <= r)``.
    history : dict of lists
        ``rays``, ``visible_area``, ``faces_seen``, ``seconds`` after every batch: the
        visible area found against rays cast.
    rays : dict
        Rays traced per strategy (``random``, ``border``, ``reverse``) and in total.
    skipped : dict
        Faces that got no rays, by reason, and mutated rays refused by the region.
    region : Region
        Where the viewers are.
    method : str
        ``guided`` or ``random``.
    seed : int
        Seed of the random rays.
    seconds : float
        Wall time of the search.
    stopped : str
        Why sampling stopped: ``"all seen"``, ``"few new faces"``, ``"budget"``, ``"rounds done"``.
    see_through : int
        Faces that sight passed through (see-through materials, :mod:`meshvis.visibility.walls`).
    conservative : ConservativeSet or None
        With ``conservative=True``: the faces that may be seen from the viewpoints
        (:mod:`meshvis.visibility.conservative`).
    sighting : (m, 3) float64 or None
        Per face, the unit direction (from the viewer) of the ray that first saw it; zero
        for a face never seen or seen without a ray (inside the region).  A face seen only
        through a gap is seen along the gap: the rescue pass
        (:func:`meshvis.visibility.check.rescue_pass`) aims its unseen neighbours' rays
        along it.  None where no rays were traced (a loaded PVS).
    """

    seen_side: np.ndarray
    rays_seen: np.ndarray
    seed_rays: np.ndarray
    area: np.ndarray
    first_seen: np.ndarray
    history: dict
    rays: dict
    skipped: dict
    region: Region
    method: str
    seed: int
    seconds: float
    stopped: str = ""
    see_through: int = 0
    extra: dict = field(default_factory=dict)
    conservative: ConservativeSet | None = None
    sighting: np.ndarray | None = None

    @property
    def seen(self) -> np.ndarray:
        """(m,) bool: some side of the face was seen."""
        return np.asarray(self.seen_side.any(axis=1))

    @property
    def visible_area(self) -> float:
        """Total area of the faces seen."""
        return float(self.area[self.seen].sum())

    def report(self, per_face: bool = True) -> dict:
        """JSON-ready summary (and per-face arrays when ``per_face``)."""
        total = max(float(self.area.sum()), 1e-300)
        d = {
            "region": self.region.describe(),
            "method": self.method,
            "seed": self.seed,
            "faces": int(len(self.area)),
            "seen_faces": int(self.seen.sum()),
            "seen_area_fraction": self.visible_area / total,
            "rays": self.rays,
            "skipped": self.skipped,
            "stopped": self.stopped,
            "see_through_faces": self.see_through,
            "seconds": self.seconds,
            "history": self.history,
        }
        if self.conservative is not None:
            d["conservative"] = self.conservative.bracket(self.seen_side)
        if per_face:
            d["per_face"] = {
                "seen_front": self.seen_side[:, 0],
                "seen_back": self.seen_side[:, 1],
                "rays_seen_front": self.rays_seen[:, 0],
                "rays_seen_back": self.rays_seen[:, 1],
                "seed_rays": self.seed_rays,
            }
        return d


class _State:
    """What the sampling loop accumulates."""

    def __init__(self, soup, budget: int, min_new: float, min_new_area: float):
        m = soup.n_faces
        self.min_new = float(min_new)
        self.min_new_area = float(min_new_area) * float(soup.areas.sum())
        self.area = soup.areas
        self.seen_side = np.zeros((m, 2), bool)
        self.rays_seen = np.zeros((m, 2), np.int64)
        self.seed_rays = np.zeros(m, np.int64)
        self.first_seen = np.full(m, -1, np.int64)
        self.sighting = np.zeros((m, 3))
        self.rays = {"random": 0, "lines": 0, "border": 0, "reverse": 0}
        self.max_unseen = MAX_UNSEEN_PER_MILLION
        self.round = 0  # the round of seed rays under way
        self.refused = 0
        self.budget = budget
        self.history: dict[str, list] = {"rays": [], "visible_area": [], "faces_seen": [], "seconds": []}
        self.start = time.perf_counter()
        #: faces whose sightings are propagated
        self.spread = np.ones(m, bool)
        #: some side seen, and the count and area of those faces
        self.seen = np.zeros(m, bool)
        self.n_seen, self.seen_area = 0, 0.0
        #: ``progress(stage, fraction)``: told the share of the budget cast after every batch
        self.progress: Callable[[str, float], None] | None = None

    @property
    def cast(self) -> int:
        return sum(self.rays.values())

    @property
    def left(self) -> int:
        return self.budget - self.cast

    def record(self, s: Sightings) -> Sightings:
        """Count the sightings; return the first sighting of each face seen for the first time."""
        if len(s.face) == 0:
            return s
        np.add.at(self.rays_seen, (s.face, s.side.astype(np.int64)), 1)
        self.seen_side[s.face, s.side] = True
        fresh = ~self.seen[s.face]
        _, first = np.unique(s.face[fresh], return_index=True)
        new = s.subset(np.flatnonzero(fresh)[first])
        self.mark_seen(new.face, self.cast)
        self.sighting[new.face] = new.direction
        return new

    def mark_seen(self, faces: np.ndarray, rays: int) -> None:
        """Note faces seen for the first time after ``rays`` rays.

        Kept up to date here so that no batch scans all faces (on the monastery that scan
        took an eighth of the search).
        """
        self.seen[faces] = True
        self.first_seen[faces] = rays
        self.seen_area += float(self.area[faces].sum())
        self.n_seen += len(faces)

    def snapshot(self) -> None:
        h = self.history
        h["rays"].append(self.cast)
        h["visible_area"].append(self.seen_area)
        h["faces_seen"].append(self.n_seen)
        h["seconds"].append(time.perf_counter() - self.start)
        if self.progress is not None:  # the budget is a cap: the stop rule usually ends sooner
            done = max(self.round / len(SEED_ROUNDS), self.cast / max(self.budget, 1))
            self.progress(PROGRESS_STAGE, min(done, 1.0))


def visible_from(
    model,
    region: str | Region = "outside",
    *,
    budget: int | None = None,
    seed: int = 0,
    method: str = "guided",
    up=None,
    per_side: bool = False,
    faces: np.ndarray | None = None,
    min_new: float = MIN_NEW_PER_MILLION,
    min_new_area: float = MIN_NEW_AREA_PER_MILLION,
    caster: RayCaster | None = None,
    transparent: str = DEFAULT_TRANSPARENT,
    max_unseen: float = MAX_UNSEEN_PER_MILLION,
    conservative: bool = False,
    progress: Callable[[str, float], None] | None = None,
) -> Visibility:
    """Which sides of the model's faces a viewer in ``region`` can see.

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model.
    region : str or Region
        Where viewers may be (see :func:`meshvis.visibility.regions.parse_region`):
        ``"outside"``, ``"upper-hemisphere"``, ``"box:x0,y0,z0,x1,y1,z1"``,
        ``"points:x,y,z;..."``, ``"path:FILE.json"``.
    budget : int, optional
        Rays to trace before the search stops (its last propagation batch, sized to the
        rays left, may trace a few more).  Default:
        :func:`default_budget`, a cap that the stop rule
        (``min_new``) normally ends the search before.
    seed : int
        Seed of the one random generator; same model, region and seed give the same result.
    method : {"guided", "random"}
        GVS guided sampling, or plain random sampling (the baseline).
    up : None, "x", "y", "z" or (3,) float
        Up direction of ``"upper-hemisphere"`` when the region text gives none; None: the
        model's own (``Soup.up``: y for glTF and OBJ files, z otherwise).
    per_side : bool
        Keep seeding a face until both of its sides are seen (for orientation); by default a
        face gets no more seed rays once either side is seen (enough to know it is visible,
        and much cheaper: most faces have one hidden side).
    faces : (k,) int or (m,) bool, optional
        Only these faces get seed rays (the question is about them); propagation still
        records every face it meets.  Default: all faces.
    min_new : float
        Stop when a window of rays finds fewer new faces than this per million rays ...
    min_new_area : float
        ... or less new seen area than this fraction of the model's area per million rays
        (0 for either: that rule never stops the seed rays).
    max_unseen : float
        The view lines end the search when fewer than this many per million of those that hit
        the model first hit an unseen face (0: they go on to the budget).
    caster : RayCaster, optional
        A caster of the same model to reuse (its offset and its walls are not changed).
    transparent : {"see-through", "opaque"}
        Whether faces of see-through materials let sight pass (:mod:`meshvis.visibility.walls`;
        without ``caster``).
    conservative : bool
        Also bound the search from above: the faces that may be seen from the viewpoints of
        a ``points:`` or ``path:`` region, in ``result.conservative``
        (:func:`meshvis.visibility.conservative.bracket`; the search then looks from the
        viewpoints themselves).
    progress : callable, optional
        ``progress("sight", fraction)`` after every batch of rays, ``fraction`` the share of
        the rounds of seed rays begun or of the budget cast, whichever is larger (the stop
        rule usually ends the search before either); an exception it raises stops the
        search.

    Returns
    -------
    Visibility

    Raises
    ------
    ParameterError
        Unknown method or region, a budget below 1, a seed that is not an integer of at
        least 0, ``per_side`` not a bool.

    Examples
    --------
    >>> import trimesh
    >>> vis = visible_from(trimesh.creation.box(), seed=0)
    >>> bool(vis.seen_side[:, 0].all()), bool(vis.seen_side[:, 1].any())
    (True, False)
    """
    if method not in METHODS:
        raise ParameterError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    _validate.visibility_args(budget, seed, per_side, min_new, min_new_area)
    if conservative:
        from meshvis.visibility.conservative import bracket

        return bracket(
            model, region, search=visible_from, budget=budget, seed=seed, method=method, up=up,
            per_side=per_side, faces=faces, min_new=min_new, min_new_area=min_new_area, caster=caster,
            transparent=transparent, max_unseen=max_unseen,
        )  # fmt: skip
    soup = as_soup(model)
    region = parse_region(region, up=up).bind(soup)
    asked = np.ones(soup.n_faces, bool)
    if faces is not None:
        faces = np.asarray(faces)
        asked = faces.astype(bool) if faces.dtype == bool else np.isin(np.arange(soup.n_faces), faces)
        if asked.shape != (soup.n_faces,):
            raise ParameterError(f"faces must be {soup.n_faces} booleans or face indices")
    budget = default_budget(int(asked.sum())) if budget is None else int(budget)
    caster = caster or RayCaster(soup, offset=VISIBILITY_OFFSET, walls=walls(soup, transparent))
    rng = np.random.default_rng(seed)
    state = _State(soup, budget, min_new, min_new_area)
    state.max_unseen = float(max_unseen)
    state.progress = progress
    skipped = _presee(state, soup, region)
    if faces is not None:
        state.spread = _rings(soup, asked, PROPAGATE_RINGS)
        skipped["not asked about (no seed rays)"] = int((~asked).sum())
        skipped[f"not propagated from (more than {PROPAGATE_RINGS} rings from a face asked about)"] = int(
            (~state.spread).sum()
        )
    stopped = _run_rounds(state, caster, region, rng, method == "guided", per_side, asked)
    skipped.update(
        {
            "seen before any seed ray (found by propagation)": int(
                (state.seen_side.any(axis=1) & (state.seed_rays == 0) & asked).sum()
            )
            - skipped.get("inside the region (seen without rays)", 0),
            "mutated rays refused (no viewer of the region on their line)": state.refused,
        }
    )
    return Visibility(
        seen_side=state.seen_side,
        rays_seen=state.rays_seen,
        seed_rays=state.seed_rays,
        area=soup.areas.copy(),
        first_seen=state.first_seen,
        history=state.history,
        rays={**state.rays, "total": state.cast},
        skipped=skipped,
        region=region,
        method=method,
        seed=int(seed),
        seconds=time.perf_counter() - state.start,
        stopped=stopped,
        see_through=0 if caster.walls is None else int((~caster.walls).sum()),
        sighting=state.sighting,
    )


def default_budget(n_faces: int) -> int:
    """The default ray cap of :func:`visible_from` for ``n_faces`` faces asked about.

    Parameters
    ----------
    n_faces : int
        Faces that get seed rays.

    Returns
    -------
    int
        ``MAX_RAYS_PER_FACE x n_faces``, at least :data:`DEFAULT_MIN_BUDGET`, at most
        :data:`meshvis.limits.MAX_RAYS`.

    Examples
    --------
    >>> default_budget(10) == DEFAULT_MIN_BUDGET
    True
    """
    return int(min(max(MAX_RAYS_PER_FACE * int(n_faces), DEFAULT_MIN_BUDGET), limits.MAX_RAYS))


def _rings(soup, faces: np.ndarray, rings: int) -> np.ndarray:
    """(m,) bool: ``faces`` and the faces within ``rings`` shared (welded) vertices of them."""
    _, welded = weld(soup.vertices, soup.faces)
    out = faces.copy()
    for _ in range(rings):
        near = np.zeros(int(welded.max()) + 1 if welded.size else 0, bool)
        near[welded[out].ravel()] = True
        out |= near[welded].any(axis=1)
    return out


def _presee(state: _State, soup, region: Region) -> dict:
    """Faces that need no rays: zero area (nothing to see), inside the region (seen)."""
    skipped = {"zero area": int((soup.areas <= 0).sum())}
    inside = region.contains_faces(soup.triangles)
    if inside.any():
        state.seen_side[inside] = True
        state.mark_seen(np.flatnonzero(inside), 0)
        skipped["inside the region (seen without rays)"] = int(inside.sum())
    return skipped


def _run_rounds(state: _State, caster, region, rng, guided: bool, per_side: bool, asked: np.ndarray) -> str:
    """The rounds of seed rays and, from the second round on, the view lines (module notes)."""
    m = len(state.area)
    usable = (state.area > 0) & asked
    window = min(STOP_WINDOW, STOP_WINDOW_PER_FACE * max(int(usable.sum()), 1))
    lines = _Lines(state, caster, region, rng, asked, guided and LINES_PER_SEED_RAY > 0, int(usable.sum()))

    def unseen(faces):
        s = state.seen_side[faces]
        return ~s.all(axis=1) if per_side else ~s.any(axis=1)

    def found() -> tuple[int, float]:
        """Faces (sides with ``per_side``) seen among those asked about, and their area."""
        s = state.seen_side[asked]
        n = s.sum(axis=1) if per_side else s.any(axis=1)
        return int(n.sum()), float(state.area[asked] @ n)

    def all_seen() -> bool:
        return not (usable & unseen(np.arange(m))).any()

    seeds = _SeedWindow(state, found)
    held = ""  # the seeds' rule held: confirm on the first window of the next round
    stop = ""
    for r, per_face in enumerate(SEED_ROUNDS):
        state.round = r
        order = _round_order(state, rng, usable & unseen(np.arange(m)), r)
        if len(order) == 0:
            return "all seen"
        n_chunks = (
            FIRST_ROUND_CHUNKS if (r == 0 and guided) else -(-len(order) * per_face // ROUND_CHUNK_RAYS)
        )
        for chunk in np.array_split(order, max(n_chunks, 1)):
            todo = chunk[unseen(chunk)]
            if len(todo) == 0:
                continue
            todo = todo[: max(0, state.left // per_face)]
            if len(todo) == 0:
                return "budget"
            cast = state.cast
            seeds.run(
                lambda: _seed_chunk(state, caster, region, rng, np.sort(todo), per_face, guided, per_side)
            )
            if r > 0:  # every face has had its first round before the lines start
                lines.cast(int(LINES_PER_SEED_RAY * (state.cast - cast)))
                if lines.held:
                    return "few unseen pixels"
            if state.left <= 0:
                return "budget"
            if r > 0 and seeds.rays >= window:
                stop = seeds.judge()
                if stop and (held or not CONFIRM_NEXT_ROUND):
                    break
                held, stop = stop, ""
                if held:
                    break  # leave out the rest of the round; confirm on the next round's first window
        if stop or all_seen():
            break
    # the seeds are done: the view lines go on until their own rule holds
    while lines.active and state.left > 0 and not all_seen():
        lines.cast(LINE_BATCH)
    if all_seen():
        return "all seen"
    if state.left <= 0:
        return "budget"
    if lines.held:
        return "few unseen pixels"
    return stop or held or "rounds done"


class _SeedWindow:
    """The stop rule of the seed rays: new faces and area per million rays since the last look."""

    def __init__(self, state: _State, found):
        self.state = state
        self.found = found
        self.rays = 0  # seed rays and their propagation since the last look
        self.mark = found()

    def run(self, step) -> None:
        """Run one seed chunk (and its propagation), counting its rays."""
        before = self.state.cast
        step()
        self.rays += self.state.cast - before

    def judge(self) -> str:
        """The stop rule over the rays since the last look (a reason, or ''); start a new window."""
        now = self.found()
        per_million = 1e6 / max(self.rays, 1)
        reason = ""
        if (now[0] - self.mark[0]) * per_million < self.state.min_new:
            reason = "few new faces"
        elif (now[1] - self.mark[1]) * per_million < self.state.min_new_area:
            reason = "little new area"
        self.mark, self.rays = now, 0
        return reason


class _Lines:
    """View lines (GVS §3.1): random lines of sight from the region, their first hits propagated.

    A line whose first hit is a face not seen yet is a false pixel of removing the unseen
    faces, seen from a random view: the share of such lines among the lines that hit the
    model estimates the false pixels per million of the removal as it stands (before the
    line's own sighting is propagated).  The lines stop when that share, over a window of
    :data:`LINE_WINDOW` model hits, is below :data:`MAX_UNSEEN_PER_MILLION`.
    """

    def __init__(self, state: _State, caster, region, rng, asked: np.ndarray, active: bool, n_faces: int):
        self.state, self.caster, self.region, self.rng, self.asked = state, caster, region, rng, asked
        self.active = active
        self.window = min(LINE_WINDOW, LINE_WINDOW_PER_FACE * max(n_faces, 1))
        self.hits = 0  # lines that hit the model in the window
        self.unseen = 0  # ... whose first hit was a face asked about and not seen yet
        self.held = False  # the rule held on a window

    def cast(self, n: int) -> None:
        """Cast up to ``n`` lines (within the budget) and propagate what they find."""
        n = min(n, self.state.left)
        if not self.active or n <= 0:
            return
        for lo in range(0, n, LINE_BATCH):
            k = min(LINE_BATCH, n - lo)
            found, hits = view_lines(self.caster, self.region, k, self.rng, PLANE_SHARE)
            self.state.rays["lines"] += k
            self.hits += hits
            fresh = self.state.record(found)
            self.unseen += int(self.asked[fresh.face].sum())
            self.state.snapshot()
            _propagate(self.state, self.caster, self.region, fresh)
            if self.hits >= self.window:
                self.held = self.unseen * 1e6 / self.hits < self.state.max_unseen
                self.active = not self.held
                self.hits = self.unseen = 0
                if not self.active:
                    return


def _round_order(state: _State, rng, todo: np.ndarray, r: int) -> np.ndarray:
    """The faces still to seed in round ``r``, in a random order.

    A random order makes every window of the stop rule a fair sample of the round: in an
    order from large faces to small, the rule judged the first windows by the largest unseen
    faces, which in CAD assemblies are hidden inner walls, and stopped before the smaller
    faces seen through gaps had their seeds (docs/removal.md).
    """
    faces = np.flatnonzero(todo)
    return faces[rng.permutation(len(faces))]


def _seed_chunk(state: _State, caster, region, rng, todo, per_face: int, guided, per_side) -> None:
    """``per_face`` random seed rays to each face of ``todo``; propagate what they find."""
    faces = np.repeat(todo, per_face)
    # the side still to find: -1 (either) unless exactly one side is seen already
    one = state.seen_side[faces]
    want = np.where(one.any(axis=1), np.argmin(one, axis=1), -1).astype(np.int8) if per_side else None
    share = PLANE_SHARE if (guided and state.round > 0) else 0.0
    found, n_traced = random_seeds(caster, region, faces, rng, want, share)
    state.rays["random"] += n_traced
    state.seed_rays[todo] += per_face
    fresh = state.record(found)
    state.snapshot()
    if guided:
        _propagate(state, caster, region, fresh)


class _Queue:
    """Sightings first in, first out: taking a batch copies the batch, not the rest."""

    def __init__(self, first: Sightings):
        self.parts: list[Sightings] = []
        self.start = 0  # sightings of parts[0] already taken
        self.push(first)

    def __len__(self) -> int:
        return sum(len(p.face) for p in self.parts) - self.start

    def push(self, s: Sightings) -> None:
        if len(s.face):
            self.parts.append(s)

    def take(self, k: int) -> Sightings:
        """The next ``k`` sightings (fewer if the queue holds fewer)."""
        out = []
        while k > 0 and self.parts:
            head = self.parts[0]
            n = min(k, len(head.face) - self.start)
            out.append(head.subset(slice(self.start, self.start + n)))
            k -= n
            self.start += n
            if self.start == len(head.face):
                self.parts.pop(0)
                self.start = 0
        return Sightings.concat(out)


def _propagate(state: _State, caster, region, fresh: Sightings) -> None:
    """Border and reverse sampling from every new sighting, until nothing new turns up.

    Only sightings on ``state.spread`` are propagated (all faces, unless ``faces=`` asks about some).
    """
    queue = _Queue(fresh.subset(np.flatnonzero(state.spread[fresh.face])))
    while len(queue) and state.left > 0:
        batch = queue.take(min(PROPAGATE_BATCH, max(1, state.left // 64)))
        band, parent, n_band = border_sampling(caster, region, batch)
        state.rays["border"] += n_band
        mutated, n_rev, refused = reverse_sampling(caster, region, band, parent)
        state.rays["reverse"] += n_rev
        state.refused += refused
        new = state.record(Sightings.concat([band, mutated]))
        state.snapshot()
        queue.push(new.subset(np.flatnonzero(state.spread[new.face])))
