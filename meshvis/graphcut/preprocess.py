"""Preprocessing of appendix H §2: flags, welding for adjacency, and triangle clusters.

Only the required steps run (flags and clustering); the optional re-triangulation of
intersections and removal of coplanar faces are not performed, so the output always keeps
the input's faces.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from meshvis.geometry.adjacency import WELD_TOL, VertexGroups
from meshvis.geometry.diagnostics import DEGENERATE_TOL, Analysis, analyse
from meshvis.graphcut.clusters import Clustering, cluster_sides
from meshvis.soup import Soup

__all__ = ["DEGENERATE_TOL", "Preprocessed", "preprocess"]


@dataclass
class Preprocessed:
    """Per-face flags and clusters.

    Attributes
    ----------
    intersects, coplanar, too_close, degenerate, flagged : (m,) bool
        ``flagged`` = (intersects | coplanar) and not degenerate: these faces get
        sample-point nodes.  ``too_close`` faces only may not join a cluster across an
        edge (appendix H §2, edge flag rule 4): each is its own single-face cluster.
    partner_pairs : (k, 2) int64
        The face pairs behind the flags
    clustering : Clustering
        The patches of consistently oriented faces.
    faces_welded : (m, 3) int64
        The faces on welded corners.
    analysis : Analysis
        The pass shared with ``meshvis info`` (its ``counts``)
    """

    intersects: np.ndarray
    coplanar: np.ndarray
    too_close: np.ndarray
    degenerate: np.ndarray
    flagged: np.ndarray
    partner_pairs: np.ndarray
    clustering: Clustering
    faces_welded: np.ndarray
    analysis: Analysis


def preprocess(
    soup: Soup,
    *,
    eps: float | None = None,
    weld_tol: float = WELD_TOL,
    progress: Callable[[str, float], None] | None = None,
    vertex_groups: VertexGroups | None = None,
) -> Preprocessed:
    """Flag difficult faces and cluster the others (appendix H §2).

    Parameters
    ----------
    soup : Soup
        The model
    eps : float, optional
        Distance tolerance of the intersection/coplanarity tests (fraction of the diagonal).
    weld_tol : float
        Weld tolerance for adjacency (fraction of the diagonal).
    progress : callable, optional
        ``progress(stage, fraction)`` of the analysis pass.
    vertex_groups : VertexGroups, optional
        The soup's bit-identical vertex groups, when the caller has them (the Embree
        scene's, :attr:`meshvis.rays.caster.RayCaster.vertex_groups`).

    Returns
    -------
    Preprocessed
    """
    analysis = analyse(soup, eps=eps, weld_tol=weld_tol, progress=progress, vertex_groups=vertex_groups)
    flags, faces_welded, degenerate = analysis.flags, analysis.faces_welded, analysis.degenerate
    assert flags is not None  # analyse() tests intersections unless told not to
    flagged = (flags["intersects"] | flags["coplanar"]) & ~degenerate
    pairs = np.concatenate([flags["intersect_pairs"], flags["coplanar_pairs"], flags["close_pairs"]]).astype(
        np.int64
    )
    clustering = cluster_sides(analysis.table, ~flagged & ~degenerate, ~flags["too_close"])
    return Preprocessed(
        intersects=flags["intersects"],
        coplanar=flags["coplanar"],
        too_close=flags["too_close"],
        degenerate=degenerate,
        flagged=flagged,
        partner_pairs=pairs.reshape(-1, 2),
        clustering=clustering,
        faces_welded=faces_welded,
        analysis=analysis,
    )
