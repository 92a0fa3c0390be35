"""Layer peeling: by sight (the default), or by the graph cut (appendix H §5).

* ``visibility="view"``: layer 1 is every face a guided search from the region (default
  ``outside``) sees (:func:`meshvis.visible_from`, the faces the default
  :func:`meshvis.remove_interior` keeps); layer *k* is every face such a search sees once
  layers 1 .. k-1 are taken out of the scene (the search asks about the remaining faces
  only, and rays pass where the peeled faces were).  The faces no search sees form the last
  bucket, ``n_layers + 1``.  Each layer's search ends with the removal's rescue pass
  (:func:`~meshvis.visibility.check.rescue_pass`, ``rescue_rays`` random rays from every face
  left that it did not see and that is next to a face it saw, fewer from the others; a face
  one of them sees from joins the layer), so layer 1 is the default removal's kept faces.
* ``visibility="object"`` (the paper's "Layer Computation"): layer 1 is every face with an
  outside side after the first cut.  Then the nodes of the layer-1 faces (in particular
  their inside nodes) are tied to the source and the graph is cut again: what becomes
  outside now is layer 2.

Both repeat until no face is added or ``max_layers`` is reached.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshvis import _validate
from meshvis.errors import ParameterError
from meshvis.graphcut.classify import Classification, classify
from meshvis.io import as_soup
from meshvis.rays.caster import VISIBILITY_OFFSET, RayCaster
from meshvis.repair.remove_modes import (
    DEFAULT_LAYER_VISIBILITY,
    DEFAULT_TRANSPARENT,
    LAYER_MODES,
    RESCUE_RAYS,
)
from meshvis.soup import Soup
from meshvis.visibility import Visibility, parse_region, visible_from
from meshvis.visibility.check import rescue_pass
from meshvis.visibility.walls import walls


@dataclass
class LayerResult:
    """Result of :func:`layers`.

    Attributes
    ----------
    layer : (m,) int64 array
        Layer index per input face (1 = outer); faces that no cut reached or no search saw
        get ``n_layers + 1`` and are counted in ``unreached``.
    outer_side : (m,) int8 array
        The side that is outside (by the cut) or seen (by sight) at the face's layer (0 front,
        1 back, 2 both, -1 for unreached faces).
    n_layers : int
        Number of layers found.
    soup : Soup
        The model the layers are of.
    unreached : int
        Faces that no cut reached.
    classification : Classification or None
        The classification the layers were peeled from (``visibility="object"``).
    seconds : float
        Time of the peeling (the classification not included).
    mode : str
        The ``visibility`` that peeled the layers.
    searches : list of Visibility
        By sight: the search of each layer (the last one found nothing new, unless
        ``max_layers`` stopped the peeling).
    see_through : int
        By sight: faces that sight passed through (see-through materials).
    """

    soup: Soup
    layer: np.ndarray
    outer_side: np.ndarray
    n_layers: int
    unreached: int
    classification: Classification | None
    seconds: float
    mode: str = "object"
    searches: list[Visibility] = field(default_factory=list)
    see_through: int = 0

    def report(self, per_face: bool = True) -> dict:
        """The JSON report: layer counts, timings, and per face ``layer`` when ``per_face``."""
        d: dict = {
            "visibility": self.mode,
            "layers": self.n_layers,
            "faces_per_layer": np.bincount(self.layer, minlength=self.n_layers + 2)[1:].tolist(),
            "unreached_faces": self.unreached,
            "layer_seconds": self.seconds,
        }
        if self.classification is not None:
            d["classification"] = self.classification.report(per_face=False)
        if self.searches:
            d["see_through_faces"] = self.see_through
            d["searches"] = [
                {k: v.report(per_face=False)[k] for k in ("rays", "stopped", "seconds", "seen_faces")}
                for v in self.searches
            ]
        if per_face:
            d["per_face"] = {"layer": self.layer, "outer_side": self.outer_side}
        return d


def _face_outside_any(c: Classification, node_outside: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per face: does any node of the face lie outside, and the side that does (2 = both)."""
    frac = c.face_labels_from(node_outside)
    out = frac > 0
    side = np.where(out[:, 0] & out[:, 1], 2, np.where(out[:, 0], 0, np.where(out[:, 1], 1, -1)))
    # for partly outside faces (sample points), the side with more outside area wins
    partial = (
        out[:, 0]
        & out[:, 1]
        & (np.abs(frac[:, 0] - frac[:, 1]) > 0)
        & ~((frac[:, 0] == 1) & (frac[:, 1] == 1))
    )
    side[partial] = np.where(frac[partial, 0] >= frac[partial, 1], 0, 1)
    return np.any(out, axis=1), side.astype(np.int8)


def face_nodes_mask(c: Classification, faces: np.ndarray) -> np.ndarray:
    """Boolean node mask of every node (both sides, all sample points) of ``faces``."""
    mask = np.zeros(c.nodes.n, bool)
    faces = np.asarray(faces)
    sn = c.nodes.side_node[faces]
    mask[sn[sn >= 0]] = True
    q = c.nodes.flagged_index[faces]
    q = q[q >= 0]
    if len(q):
        p = c.nodes.points_of(q)
        mask[c.nodes.n_cluster + 2 * p] = True
        mask[c.nodes.n_cluster + 2 * p + 1] = True
    return mask


def layers(
    model: Any,
    *,
    max_layers: int | None = None,
    visibility: str = DEFAULT_LAYER_VISIBILITY,
    region="outside",
    budget: int | None = None,
    up=None,
    transparent: str = DEFAULT_TRANSPARENT,
    classification: Classification | None = None,
    progress=None,
    rescue_rays: int = RESCUE_RAYS,
    **classify_kw: Any,
) -> LayerResult:
    """Peel the model into nested layers (module notes).

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, tuple of (vertices, faces) or path
        Anything :func:`meshvis.classify` accepts.
    max_layers : int, optional
        Stop after this many layers (the rest get layer ``max_layers + 1``).
    visibility : {"view", "object"}
        Peel by sight from ``region`` (default
        :data:`~meshvis.repair.remove_modes.DEFAULT_LAYER_VISIBILITY`) or by the graph cut.
    region : str or Region
        Where viewers may be (by sight; see :func:`meshvis.parse_region`).
    budget : int, optional
        Ray budget of each layer's search (by sight; default :func:`meshvis.visible_from`'s).
    up : None, "x", "y", "z" or (3,) float
        Up direction of an ``"upper-hemisphere"`` region; None: the model's own (``Soup.up``).
    transparent : {"see-through", "opaque"}
        Whether faces of see-through materials let sight through (by sight).
    classification : Classification, optional
        Reuse an existing classification of the same model (by the cut).
    progress : callable, optional
        Called as ``progress(layer, faces with a layer, faces)`` after every layer.
    rescue_rays : int
        By sight: the rescue pass's rays from every face next to a seen one, as in
        :func:`meshvis.remove_interior` (0: no rescue pass).
    **classify_kw
        Passed to :func:`meshvis.classify` (``seed``, ``rays_per_node``, ...); ``seed``
        also seeds the searches.

    Returns
    -------
    LayerResult
        Layer and outer side of every face.

    Raises
    ------
    ParameterError
        Unknown ``visibility`` or ``transparent``, ``max_layers`` below 1, a negative
        ``rescue_rays``.

    Examples
    --------
    >>> import trimesh, numpy as np
    >>> a, b = trimesh.creation.icosphere(2), trimesh.creation.icosphere(2)
    >>> v = np.vstack([a.vertices, 0.5 * b.vertices]); f = np.vstack([a.faces, b.faces + len(a.vertices)])
    >>> r = layers((v, f), seed=0)
    >>> r.n_layers, sorted(set(r.layer.tolist()))
    (2, [1, 2])
    >>> layers((v, f), visibility="object", seed=0).n_layers
    2
    """
    _validate.repair_args(classification, Classification, classify_kw, classify)
    max_layers = None if max_layers is None else _validate.integer("max_layers", max_layers, 1)
    rescue_rays = _validate.integer("rescue_rays", rescue_rays, 0)
    if visibility not in LAYER_MODES:
        raise ParameterError(f"unknown visibility {visibility!r}; choose one of {', '.join(LAYER_MODES)}")
    if visibility == "view":
        seed = int(classify_kw.get("seed", 0))
        return _layers_by_sight(
            model, max_layers, region, budget, up, transparent, seed, progress, rescue_rays
        )
    c = classification or classify(model, **classify_kw)
    return _layers_by_cut(c, max_layers, progress)


def _layers_by_sight(
    model, max_layers, region, budget, up, transparent, seed: int, progress, rescue_rays: int
) -> LayerResult:
    """Layer k: what a search sees of the faces left once layers 1 .. k-1 are out of the scene."""
    soup = as_soup(model)
    t0 = time.perf_counter()
    m = soup.n_faces
    clear = walls(soup, transparent)
    blocking = np.ones(m, bool) if clear is None else clear
    layer = np.zeros(m, np.int64)
    outer_side = np.full(m, -1, np.int8)
    active = soup.areas > 0  # a face of zero area is never seen
    bound = parse_region(region, up=up).bind(soup)
    searches: list[Visibility] = []
    k = 0
    while (layer[active] == 0).any() and (max_layers is None or k < max_layers):
        left = layer == 0
        caster = RayCaster(soup, offset=VISIBILITY_OFFSET, walls=blocking & left)
        # layer 1 is the search of the default removal, face for face
        asked = None if k == 0 else left & active
        vis = visible_from(soup, region, budget=budget, seed=seed, up=up, faces=asked, caster=caster)
        searches.append(vis)
        unseen = left & active & ~vis.seen
        seen_side = vis.seen_side
        if rescue_rays:
            rescue = rescue_pass(
                caster, bound, unseen, vis.seen & left, rays=rescue_rays, seed=seed, search=vis
            )
            seen_side = seen_side | rescue.seen_side
        new = seen_side.any(axis=1) & left & active
        if not new.any():
            break
        k += 1
        layer[new] = k
        seen = seen_side[new]
        outer_side[new] = np.where(seen.all(axis=1), 2, np.argmax(seen, axis=1))
        if progress is not None:
            progress(k, int((layer > 0).sum()), m)
    rest = layer == 0
    unreached = int((rest & active).sum())
    layer[rest] = k + 1
    see_through = 0 if clear is None else int((~clear).sum())
    return LayerResult(
        soup, layer, outer_side, k, unreached, None, time.perf_counter() - t0, "view", searches, see_through
    )


def _layers_by_cut(c: Classification, max_layers: int | None, progress) -> LayerResult:
    """Layer k: the faces outside once the nodes of layers 1 .. k-1 are tied to the source."""
    t0 = time.perf_counter()
    m = c.soup.n_faces
    layer = np.zeros(m, np.int64)
    outer_side = np.full(m, -1, np.int8)
    tied = np.zeros(c.nodes.n, bool)
    node_outside = c.cut.outside
    k = 0
    active = ~c.degenerate
    while True:
        has_out, side = _face_outside_any(c, node_outside)
        new = has_out & (layer == 0) & active
        if not new.any():
            break
        k += 1
        layer[new] = k
        outer_side[new] = side[new]
        if progress is not None:
            progress(k, int((layer > 0).sum()), m)
        if (layer[active] > 0).all() or (max_layers is not None and k >= max_layers):
            break
        tied |= face_nodes_mask(c, np.flatnonzero(new)) | node_outside
        node_outside = c.graph.cut(c.cut.solver, tie_to_source=tied).outside
    rest = layer == 0
    unreached = int((rest & active).sum())
    layer[rest] = k + 1
    return LayerResult(c.soup, layer, outer_side, k, unreached, c, time.perf_counter() - t0, "object")
