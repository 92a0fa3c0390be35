"""Preprocessing of appendix H §2: flags, welding for adjacency, and triangle clusters.

Only the required steps run (flags and clustering); the optional re-triangulation of
intersections and removal of coplanar faces are not performed, so the output always keeps
the input's faces.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.geometry.adjacency import WELD_TOL, degenerate_faces, edges, weld
from meshvis.geometry.intersect import intersection_flags
from meshvis.graphcut.clusters import Clustering, cluster_sides
from meshvis.soup import Soup

#: a face whose smallest altitude is below this fraction of the diagonal is not classified
DEGENERATE_TOL = 1e-9


@dataclass
class Preprocessed:
    """Per-face flags and clusters.

    Attributes
    ----------
    intersects, coplanar, too_close, degenerate, flagged : (m,) bool
        ``flagged`` = (intersects | coplanar) and not degenerate: these faces get
        sample-point nodes.  ``too_close`` faces only may not join a cluster across an
        edge (appendix H §2, edge flag rule 4): each is its own single-face cluster.
    partner_pairs : (k, 2) int64, the face pairs behind the flags
    clustering : Clustering
    faces_welded : (m, 3) int64
    """

    intersects: np.ndarray
    coplanar: np.ndarray
    too_close: np.ndarray
    degenerate: np.ndarray
    flagged: np.ndarray
    partner_pairs: np.ndarray
    clustering: Clustering
    faces_welded: np.ndarray


def preprocess(soup: Soup, *, eps: float | None = None, weld_tol: float = WELD_TOL) -> Preprocessed:
    """Flag difficult faces and cluster the others (appendix H §2).

    Parameters
    ----------
    soup : the model
    eps : distance tolerance of the intersection/coplanarity tests (fraction of the diagonal)
    weld_tol : weld tolerance for adjacency (fraction of the diagonal)
    """
    _, faces_welded = weld(soup.vertices, soup.faces, weld_tol)
    flags = intersection_flags(soup.vertices, soup.faces, eps, faces_welded=faces_welded)
    degenerate = degenerate_faces(soup.vertices, soup.faces, tol=DEGENERATE_TOL) | (soup.areas <= 0)
    flagged = (flags["intersects"] | flags["coplanar"]) & ~degenerate
    pairs = np.concatenate([flags["intersect_pairs"], flags["coplanar_pairs"], flags["close_pairs"]]).astype(
        np.int64
    )
    clustering = cluster_sides(edges(faces_welded), ~flagged & ~degenerate, ~flags["too_close"])
    return Preprocessed(
        intersects=flags["intersects"],
        coplanar=flags["coplanar"],
        too_close=flags["too_close"],
        degenerate=degenerate,
        flagged=flagged,
        partner_pairs=pairs.reshape(-1, 2),
        clustering=clustering,
        faces_welded=faces_welded,
    )
