"""Layer peeling (appendix H §5, "Layer Computation").

Layer 1 is every face with an outside side after the first cut.  Then the nodes of the
layer-1 faces (in particular their inside nodes) are tied to the source and the graph is
cut again: what becomes outside now is layer 2 — what one sees once layer 1 is gone.
Repeat until every face has a layer or ``max_layers`` is reached.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis import _validate
from meshvis.graphcut.classify import Classification, classify
from meshvis.soup import Soup


@dataclass
class LayerResult:
    """Result of :func:`layers`.

    Attributes
    ----------
    layer : (m,) int64 array
        Layer index per input face (1 = outer); faces that no cut reached (never seen by any ray:
        sealed off) get ``n_layers + 1`` and are counted in ``unreached``.
    outer_side : (m,) int8 array
        The side that is outside at the face's layer (0 front, 1 back, 2 both, -1 for unreached
        faces).
    n_layers : int
        Number of layers found.
    soup : Soup
        The model the layers are of.
    unreached : int
        Faces that no cut reached.
    classification : Classification
        The classification the layers were peeled from.
    seconds : float
        Time of the peeling (the classification not included).
    """

    soup: Soup
    layer: np.ndarray
    outer_side: np.ndarray
    n_layers: int
    unreached: int
    classification: Classification
    seconds: float

    def report(self, per_face: bool = True) -> dict:
        """The JSON report: layer counts, timings, and per face ``layer`` when ``per_face``."""
        d = {
            "layers": self.n_layers,
            "faces_per_layer": np.bincount(self.layer, minlength=self.n_layers + 2)[1:].tolist(),
            "unreached_faces": self.unreached,
            "layer_seconds": self.seconds,
            "classification": self.classification.report(per_face=False),
        }
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
        p = (q[:, None] * c.nodes.samples + np.arange(c.nodes.samples)).ravel()
        mask[c.nodes.n_cluster + 2 * p] = True
        mask[c.nodes.n_cluster + 2 * p + 1] = True
    return mask


def layers(
    model: Any,
    *,
    max_layers: int | None = None,
    classification: Classification | None = None,
    progress=None,
    **classify_kw: Any,
) -> LayerResult:
    """Peel the model into nested layers.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, tuple of (vertices, faces) or path
        Anything :func:`meshvis.classify` accepts.
    max_layers : int, optional
        Stop after this many layers (the rest get layer ``max_layers + 1``).
    classification : Classification, optional
        Reuse an existing classification of the same model.
    progress : callable, optional
        Progress callback, passed to :func:`meshvis.classify`.
    **classify_kw
        Passed to :func:`meshvis.classify` (``seed``, ``rays_per_node``, ...).

    Returns
    -------
    LayerResult
        Layer and outer side of every face.

    Examples
    --------
    >>> import trimesh, numpy as np
    >>> a, b = trimesh.creation.icosphere(2), trimesh.creation.icosphere(2)
    >>> v = np.vstack([a.vertices, 0.5 * b.vertices]); f = np.vstack([a.faces, b.faces + len(a.vertices)])
    >>> r = layers((v, f), seed=0)
    >>> r.n_layers, sorted(set(r.layer.tolist()))
    (2, [1, 2])
    """
    _validate.repair_args(classification, Classification, classify_kw, classify)
    max_layers = None if max_layers is None else _validate.integer("max_layers", max_layers, 1)
    c = classification or classify(model, **classify_kw)
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
    return LayerResult(c.soup, layer, outer_side, k, unreached, c, time.perf_counter() - t0)
