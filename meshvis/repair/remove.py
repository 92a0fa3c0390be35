"""Inside removal (appendix H §5, "Inside Removal"), by sight, by the cut, or by both.

* ``visibility="view"`` (the default): every face that no line of sight from the region
  reached is removed (:func:`meshvis.visible_from`, DESIGN.md §9): what a viewer sees is
  kept, and what none sees goes, also where the cut would call it outside (the inside of
  an engine block open at one end, an inner shell joined to the outer one through holes).
* ``visibility="object"``: one classification; every face with an outside side -- or, for
  faces classified through sample points, at least one outside sample point -- is kept.
  Of a sheet stored twice with opposite winding (:mod:`meshvis.geometry.duplicates`) whose
  one side is hidden, only the copy facing the seen side counts as kept by the cut.
* ``visibility="both"``: a face is removed only when the cut calls it hidden *and* a
  guided search for a view of it failed (seed rays aimed at these faces only,
  propagation within a few rings of them; the report counts the faces left out).

In ``both`` the cut only proposes the faces that the search then tries to see, so its
sample points get less: unless ``rays_per_point`` is given, each sample point of an
intersecting face gets ``rays_per_node // samples_per_face`` rays, which gives a flagged
face's side the budget of an unflagged face's
(:func:`~meshvis.repair.remove_modes.cut_rays_per_point`).

Sight passes the faces of see-through materials unless ``transparent="opaque"``
(:mod:`meshvis.visibility.walls`): what shows through a windshield stays.  The cut does not
look at materials.

A removal by sight (``"view"``, ``"both"``) ends with a rescue pass
(:func:`meshvis.visibility.check.rescue_pass`): random rays from every face it is about to
remove, to random viewers of the region, ``rescue_rays`` of them from each face next to a
seen or rescued face and :data:`~meshvis.visibility.check.RESCUE_FIRST_RAYS` from the
others, and a few along the search's line of sight to each seen neighbour; a face one of
them sees from is kept, and the neighbours of a rescued face are also tried along its line
of sight.  The search stops once new views have become rare,
and a small face seen through a narrow gap can be one it never aimed at often enough; the
rescue gives every such face rays of its own.  Every removal then ends with a self-check: ``check_rays`` fresh random
rays from every removed face, from another stream than the rescue's; the report says how
many removed faces and how much of their area one of them saw.

``level="patch"`` or ``"part"`` removes a connected patch (faces sharing edges) or a named
part only when all its faces are hidden; ``keep_border=N`` keeps N rings of hidden faces
around kept ones.  Every input face ends up in exactly one of the two outputs, with a reason.
"""

from __future__ import annotations

import inspect
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis import _validate
from meshvis.errors import ParameterError
from meshvis.geometry.adjacency import components, edges, face_adjacency, weld
from meshvis.geometry.duplicates import hidden_copies, opposite_copies
from meshvis.graphcut.classify import Classification, classify
from meshvis.io import as_soup
from meshvis.rays.caster import VISIBILITY_OFFSET, RayCaster
from meshvis.repair.remove_modes import (
    CHECK_RAYS,
    DEFAULT_TRANSPARENT,
    DEFAULT_VISIBILITY,
    LEVELS,
    RESCUE_RAYS,
    VISIBILITY_MODES,
    cut_rays_per_point,
    reuse_note,
)
from meshvis.soup import Soup
from meshvis.visibility import Visibility, parse_region, visible_from
from meshvis.visibility.check import RESCUE_FIRST_RAYS, RESCUE_SHARE, SelfCheck, rescue_pass, self_check
from meshvis.visibility.walls import walls

#: reason of each face, by code
REASONS = (
    "kept: an outside side by the cut",
    "kept: seen from the region",
    "kept: hidden by the cut, but a view of it was found",
    "kept: its patch or part has a face that is kept",
    "kept: next to a kept face (keep_border)",
    "removed: no outside side by the cut",
    "removed: not seen from the region",
    "removed: hidden by the cut and no view of it was found",
    "kept: may be seen from the region (conservative set)",
    "removed: surely hidden from the region (outside the conservative set)",
    "kept: a ray of the rescue pass saw it",
)
_KEPT_CUT, _KEPT_SEEN, _KEPT_RESCUED, _KEPT_GROUP, _KEPT_BORDER, _GONE_CUT, _GONE_VIEW, _GONE_BOTH = range(8)
_KEPT_MAY, _GONE_SURELY, _KEPT_RESCUE = 8, 9, 10


@dataclass
class RemovalResult:
    """Result of :func:`remove_interior`.

    Attributes
    ----------
    kept, removed : Soup
        The faces kept and removed (attributes preserved)
    keep : (m,) bool
        Kept, per input face.
    classification : Classification or None
        The cut (``visibility="view"`` needs none).
    visibility : Visibility or None
        The from-region search (``"view"`` and ``"both"``)
    reason_code : (m,) int8
        Index into :data:`REASONS` per input face
    mode : str
        The ``visibility`` used
    soup : Soup
        The input model
    check : SelfCheck or None
        The self-check of the removed faces (None with ``check_rays=0``)
    see_through : int
        Faces that sight passed through (see-through materials)
    rescue : SelfCheck or None
        The rescue pass (removal by sight; None otherwise or with ``rescue_rays=0``): its
        ``seen`` faces are kept.
    """

    kept: Soup
    removed: Soup
    keep: np.ndarray
    classification: Classification | None
    visibility: Visibility | None
    reason_code: np.ndarray
    mode: str
    soup: Soup
    check: SelfCheck | None = None
    see_through: int = 0
    rescue: SelfCheck | None = None

    @property
    def reason(self) -> list[str]:
        """Why each input face was kept or removed."""
        return [REASONS[c] for c in self.reason_code]

    def report(self, per_face: bool = True) -> dict:
        """The JSON-ready report: counts, reasons, the classification and view summaries."""
        soup = self.soup
        d: dict[str, Any] = {
            "visibility": self.mode,
            "input_faces": int(len(self.keep)),
            "kept_faces": int(self.keep.sum()),
            "removed_faces": int((~self.keep).sum()),
            "removed_area_fraction": float((soup.areas * ~self.keep).sum() / max(soup.total_area, 1e-300)),
            "reasons": {REASONS[c]: int(n) for c, n in zip(*np.unique(self.reason_code, return_counts=True))},
            "see_through_faces": self.see_through,
        }
        if self.rescue is not None:
            d["rescue"] = self.rescue.report()
        if self.check is not None:
            d["self_check"] = self.check.report()
        if self.classification is not None:
            d["classification"] = self.classification.report(per_face=False)
        if self.visibility is not None:
            d["view"] = self.visibility.report(per_face=False)
        if per_face:
            d["per_face"] = {"keep": self.keep, "reason": self.reason}
            if self.classification is not None:
                d["per_face"]["outside_front"] = self.classification.outside[:, 0]
                d["per_face"]["outside_back"] = self.classification.outside[:, 1]
            if self.visibility is not None:
                d["per_face"]["seen"] = self.visibility.seen
            if self.check is not None:
                d["per_face"]["seen_by_check"] = self.check.seen
        return d

    def summary(self) -> list[str]:
        """The console lines: what was kept and removed, how the search stopped, the self-check."""
        clear = (
            f"; {self.see_through} faces of see-through materials let sight through"
            if self.see_through
            else ""
        )
        lines = [
            f"kept {int(self.keep.sum())}, removed {int((~self.keep).sum())} of {len(self.keep)} faces{clear}"
        ]
        if self.visibility is not None and self.visibility.stopped == "budget":
            lines.append(
                f"the search for views stopped at its ray budget ({self.visibility.rays['total']} rays) "
                "before its stop rule: some removed faces may be visible (raise --budget)"
            )
        if self.rescue is not None:
            r = self.rescue
            short = (
                f", {r.short_faces} next to one got fewer (the pass stopped at {RESCUE_SHARE:.0%} of the "
                "search's rays)"
                if r.short_faces
                else ""
            )
            lines.append(
                f"rescue: random rays from each of {r.faces} faces the search did not see "
                f"({r.rays_per_face} from the {r.full_faces} next to a seen face, {RESCUE_FIRST_RAYS} from the "
                f"others{short}; {r.rays} rays) found a view of {int(r.seen.sum())} of them (kept)"
            )
        if self.check is not None:
            lines.append(self.check.summary())
        return lines


def remove_interior(
    model: Any,
    *,
    classification: Classification | None = None,
    visibility: str = DEFAULT_VISIBILITY,
    region="outside",
    level: str = "face",
    keep_border: int = 0,
    budget: int | None = None,
    up=None,
    view: Visibility | None = None,
    transparent: str = DEFAULT_TRANSPARENT,
    check_rays: int = CHECK_RAYS,
    conservative: bool = False,
    rescue_rays: int = RESCUE_RAYS,
    **classify_kw: Any,
) -> RemovalResult:
    """Remove the faces that cannot be seen from outside (or from ``region``).

    Parameters
    ----------
    model : Soup, trimesh object, (vertices, faces) or path
        Anything :func:`meshvis.classify` accepts.
    classification : Classification, optional
        An existing classification of the same model to reuse (``"object"``, ``"both"``; in
        ``"both"``, one whose sample points got another ray budget than this function's own
        cut gives them is used as it is, with a warning: the faces kept can differ).
    visibility : {"view", "object", "both"}
        Sight from ``region`` alone (default
        :data:`~meshvis.repair.remove_modes.DEFAULT_VISIBILITY`), the graph cut alone, or
        both must call a face hidden.
    region : str or Region
        Where viewers may be, for ``"view"`` and ``"both"`` (see :func:`meshvis.parse_region`),
        or ``cells:PVS.npz``: the view cells of a PVS file (:func:`meshvis.pvs`).
    level : {"face", "patch", "part"}
        Remove single faces, or whole edge-connected patches / named parts whose faces are all hidden.
    keep_border : int
        Rings of hidden faces (sharing an edge) kept around the kept faces.
    budget : int, optional
        Ray budget of the from-region search (default: :func:`meshvis.visible_from`'s cap;
        its stop rule ends it).  A search stopped by the budget says so in the report.
    up : None, "x", "y", "z" or (3,) float
        Up direction of an ``"upper-hemisphere"`` region; None: the model's own
        (``Soup.up``: y for glTF and OBJ files, z otherwise).
    view : Visibility, optional
        Reuse a from-region search of the same model (``"view"`` only).
    transparent : {"see-through", "opaque"}
        Whether faces of see-through materials let sight through
        (:mod:`meshvis.visibility.walls`), in the search and the self-check.
    check_rays : int
        Fresh random rays from every removed face in the self-check (0: no check).
    conservative : bool
        Remove only the faces outside the conservative set from the viewpoints of
        ``region`` (``points:...`` or ``path:CAMERAS.json``;
        :func:`meshvis.visible_from` with ``conservative=True``): nothing visible from them
        is removed.  No cut; ``visibility`` is not used.
    rescue_rays : int
        Random rays from every face next to a seen face that a removal by sight (``"view"``,
        ``"both"``) is about to remove (the others get
        :data:`~meshvis.visibility.check.RESCUE_FIRST_RAYS`, or ``rescue_rays`` if fewer); a
        face one of them sees from is kept (0: no rescue pass).
    **classify_kw
        Passed to :func:`meshvis.classify` (``seed``, ``rays_per_node``, ...);
        in ``"both"`` an unset ``rays_per_point`` is ``rays_per_node // samples_per_face``
        (module notes); ``seed`` also seeds the search, and ``progress(stage, fraction)``
        follows it too (stage ``"sight"``)

    Returns
    -------
    RemovalResult

    Raises
    ------
    ParameterError
        Unknown mode, level or ``transparent``, ``keep_border`` not an integer of at least 0,
        a negative ``check_rays`` or ``rescue_rays``, a budget below 1.

    Examples
    --------
    >>> import trimesh, numpy as np
    >>> a, b = trimesh.creation.icosphere(2), trimesh.creation.icosphere(2)
    >>> v = np.vstack([a.vertices, 0.5 * b.vertices]); f = np.vstack([a.faces, b.faces + len(a.vertices)])
    >>> r = remove_interior((v, f), seed=0)  # visibility="view"
    >>> r.kept.n_faces, r.removed.n_faces, int(r.check.seen.sum())
    (320, 320, 0)
    >>> remove_interior((v, f), visibility="object", seed=0).removed.n_faces
    320
    >>> remove_interior((v, f), visibility="both", seed=0).removed.n_faces
    320
    """
    _validate.repair_args(classification, Classification, classify_kw, classify)
    if visibility not in VISIBILITY_MODES:
        raise ParameterError(
            f"unknown visibility {visibility!r}; choose one of {', '.join(VISIBILITY_MODES)}"
        )
    if level not in LEVELS:
        raise ParameterError(f"unknown level {level!r}; choose one of {', '.join(LEVELS)}")
    _validate.removal_args(keep_border, budget)
    check_rays = _validate.integer("check_rays", check_rays, 0)
    rescue_rays = _validate.integer("rescue_rays", rescue_rays, 0)
    seed = int(classify_kw.get("seed", 0))
    progress = classify_kw.get("progress")  # of the cut, and of the search by sight
    c: Classification | None = None
    vis: Visibility | None = None
    if conservative:
        soup = as_soup(model)
        caster = RayCaster(soup, offset=VISIBILITY_OFFSET, walls=walls(soup, transparent))
        vis = visible_from(soup, region, budget=budget, seed=seed, up=up, conservative=True, caster=caster)
        assert vis.conservative is not None
        keep = vis.conservative.visible.copy()
        code = np.where(keep, _KEPT_MAY, _GONE_SURELY)
        visibility = "conservative"
    elif visibility == "view":
        soup = as_soup(model)
        caster = RayCaster(soup, offset=VISIBILITY_OFFSET, walls=walls(soup, transparent))
        vis = view or _sight(soup, region, budget=budget, seed=seed, up=up, caster=caster, progress=progress)
        keep = vis.seen.copy()
        code = np.where(keep, _KEPT_SEEN, _GONE_VIEW)
    else:
        c = classification or classify(model, **_cut_keywords(visibility, classify_kw))
        note = reuse_note(c.params, visibility) if classification is not None else None
        if note:
            warnings.warn(note, stacklevel=2)
        soup = c.soup
        caster = _sight_caster(c, transparent)
        by_cut = _kept_by_cut(c)
        if visibility == "object":
            keep = by_cut
            code = np.where(keep, _KEPT_CUT, _GONE_CUT)
        else:
            vis = _sight(
                soup, region, budget=budget, seed=seed, up=up, faces=~by_cut, caster=caster, progress=progress
            )
            keep = by_cut | vis.seen
            code = np.where(by_cut, _KEPT_CUT, np.where(vis.seen, _KEPT_RESCUED, _GONE_BOTH))
    code = code.astype(np.int8)
    check = rescue = None
    by_rays = (check_rays or rescue_rays) and not _is_cells(region)  # cells: judged by meshvis bench pvs
    bound = parse_region(region, up=up).bind(soup) if by_rays else None
    if bound is not None and rescue_rays and visibility in ("view", "both"):
        rescue = rescue_pass(caster, bound, ~keep, keep, rays=rescue_rays, seed=seed, search=vis)
        code[rescue.seen] = _KEPT_RESCUE
        keep = keep | rescue.seen
    keep = _widen(soup, keep, code, level, int(keep_border))
    if bound is not None and check_rays:
        check = self_check(caster, bound, ~keep, rays=check_rays, seed=seed)
    see_through = 0 if caster.walls is None else int((~caster.walls).sum())
    return RemovalResult(
        soup.subset(keep),
        soup.subset(~keep),
        keep,
        c,
        vis,
        code,
        visibility,
        soup,
        check,
        see_through,
        rescue,
    )


def _sight_caster(c: Classification, transparent: str) -> RayCaster:
    """The scene that sight is traced against: the cut's, unless see-through faces must be left out.

    The cut's Embree scene is reused with the search's own ray offset; a model with
    see-through faces gets a scene without them (the cut itself traces them as walls).
    """
    clear = walls(c.soup, transparent)
    if clear is None:
        return c.caster.with_offset(VISIBILITY_OFFSET)
    return RayCaster(c.soup, offset=VISIBILITY_OFFSET, walls=clear, vertex_groups=c.caster.vertex_groups)


def _is_cells(region) -> bool:
    """:func:`meshvis.viewcells.removal.is_cells_region` (the layer above, imported when asked)."""
    from meshvis.viewcells.removal import is_cells_region

    return is_cells_region(region)


def _sight(soup: Soup, region, **search: Any) -> Visibility:
    """The from-region search, or what the view cells of a PVS file see (``cells:PVS.npz``)."""
    if _is_cells(region):
        from meshvis.viewcells.removal import cells_visibility

        return cells_visibility(soup, region)
    return visible_from(soup, region, **search)


def _cut_keywords(visibility: str, classify_kw: dict[str, Any]) -> dict[str, Any]:
    """The keywords of :func:`meshvis.classify` for the cut of ``visibility``.

    ``rays_per_point`` follows :func:`~meshvis.repair.remove_modes.cut_rays_per_point`,
    with :func:`meshvis.classify`'s defaults for what is not given (``both``: 32 // 4 = 8).

    Examples
    --------
    >>> _cut_keywords("both", {"seed": 1})["rays_per_point"]
    8
    >>> _cut_keywords("both", {"rays_per_node": 64, "rays_per_point": 32})["rays_per_point"]
    32
    >>> _cut_keywords("object", {})["rays_per_point"] is None  # classify: rays_per_node
    True
    """
    defaults = inspect.signature(classify).parameters
    rays = classify_kw.get("rays_per_node", defaults["rays_per_node"].default)
    samples = classify_kw.get("samples_per_face", defaults["samples_per_face"].default)
    budget = cut_rays_per_point(visibility, rays, samples, classify_kw.get("rays_per_point"))
    return {**classify_kw, "rays_per_point": budget}


def _kept_by_cut(c: Classification) -> np.ndarray:
    """Faces with an outside side by the cut.

    Of a sheet stored twice with opposite winding whose one side is hidden, only the copy
    facing the seen side.
    """
    keep = (c.outside > 0).any(axis=1)
    return keep & ~hidden_copies(opposite_copies(c.pre.faces_welded), c.outside)


def _widen(soup: Soup, keep: np.ndarray, code: np.ndarray, level: str, keep_border: int) -> np.ndarray:
    """Apply ``level`` and ``keep_border`` to ``keep`` (and ``code``, in place)."""
    if level == "face" and keep_border == 0:
        return keep
    _, welded = weld(soup.vertices, soup.faces)
    pairs = face_adjacency(edges(welded), manifold_only=False)
    if level != "face":
        group = soup.part_id if level == "part" else components(soup.n_faces, pairs)[1]
        any_kept = np.zeros(int(group.max()) + 1 if len(group) else 0, bool)
        any_kept[group[keep]] = True
        rescued = ~keep & any_kept[group]
        code[rescued] = _KEPT_GROUP
        keep = keep | rescued
    for _ in range(keep_border):
        near = np.zeros(len(keep), bool)
        near[pairs[keep[pairs[:, 0]], 1]] = True
        near[pairs[keep[pairs[:, 1]], 0]] = True
        ring = near & ~keep
        if not ring.any():
            break
        code[ring] = _KEPT_BORDER
        keep = keep | ring
    return keep
