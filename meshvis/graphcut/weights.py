"""Edge and terminal weights of the visibility graph (appendix H, Eq. 5–9).

Notation: node *i* has area ``A_i`` and ``n_i`` counted rays, ``n_ij`` of which landed on
node *j*.  ``T_ij = A_i n_ij / n_i`` is the power-exchange estimate from *i*'s rays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from meshvis.graphcut import _kernels

#: escape share above which a side counts as open to the outside (see :func:`inside_prior`):
#: between what defects let out (hairline cracks, a few missing faces, the bunny's holes)
#: and what real openings do (``meshvis bench stability`` sweeps crack widths)
DEFAULT_OPENING = 0.03


@dataclass
class Weights:
    """Symmetric edge weights and terminal weights, before and after filtering.

    Attributes
    ----------
    edges_i : (k,) int64 array
        First end of each undirected edge.
    edges_j : (k,) int64 array
        Second end (``edges_i < edges_j``; each edge once).
    w : (k,) float64 array
        Edge weight w(i, j) (Eq. 5).
    w_out : (n,) float64 array
        Link to OUTSIDE (Eq. 7).
    w_in : (n,) float64 array
        Link to INSIDE (``w_in(opp(i)) = w_o(i)`` plus hints).
    cap_ij : (k,) float64 array
        Capacity ``i → j`` after the cosine filter (Eq. 8–9).
    cap_ji : (k,) float64 array
        Capacity ``j → i`` after the cosine filter.
    cap_out : (n,) float64 array
        Filtered OUTSIDE link.
    cap_in : (n,) float64 array
        Filtered INSIDE link.
    """

    edges_i: np.ndarray
    edges_j: np.ndarray
    w: np.ndarray
    w_out: np.ndarray
    w_in: np.ndarray
    cap_ij: np.ndarray
    cap_ji: np.ndarray
    cap_out: np.ndarray
    cap_in: np.ndarray


def edge_weights(
    hits: sp.spmatrix, counted: np.ndarray, area: np.ndarray, is_point: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eq. 5: ``w(i,j) = ½ (A_i n_ij/n_i + A_j n_ji/n_j)``.

    When exactly one end is a point node (a hit snapped to a sample point of an
    intersected/coplanar triangle), only the term estimated from the other end's rays is
    used: those rays start uniformly over their node, whereas a point node's rays all
    start at one point (appendix H §3.2.2).  Self-links are dropped.

    Parameters
    ----------
    hits : (n, n) scipy.sparse matrix
        ``n_ij``: rays from node i that hit node j.
    counted : (n,) float array
        ``n_i``: rays counted for node i.
    area : (n,) float array
        ``A_i``: node area.
    is_point : (n,) bool array
        Sample-point nodes.

    Returns
    -------
    i : (k,) int64 array
        First end of each undirected edge.
    j : (k,) int64 array
        Second end, ``i < j``; each edge once.
    w : (k,) float64 array
        Edge weight.
    """
    h = sp.csr_matrix(hits)
    h.sum_duplicates()  # sorted, unique column indices per row
    return _kernels.merged_edge_weights(
        h.indptr.astype(np.int64),
        h.indices.astype(np.int64),
        np.asarray(h.data, np.float64),
        np.asarray(counted),
        np.asarray(area, np.float64),
        np.asarray(is_point, bool),
    )


def outside_weights(escaped: np.ndarray, counted: np.ndarray, area: np.ndarray) -> np.ndarray:
    """Eq. 7: ``w_o(i) = A_i (1 − Σ_j n_ij / n_i)`` = ``A_i × escaped_i / n_i``."""
    return np.where(counted > 0, area * escaped / np.maximum(counted, 1), 0.0)


def inside_prior(
    w_out: np.ndarray,
    escaped: np.ndarray,
    counted: np.ndarray,
    opposite: np.ndarray,
    opening: float | None = DEFAULT_OPENING,
) -> np.ndarray:
    """Inside links without hints: ``w_in(opp(i)) = w_o(i)``, faded by the own escape share.

    The prior is appendix H §3.2.1.

    The paper's prior says "if the other side of this geometry escapes, this side is the
    inside of a thin object".  That is right for closed shells and for shells with small
    cracks, but it also declares the inside of a cup or of a room with a large doorway
    inside, although it is reachable from far away (the object-based definition, DESIGN.md
    §4).  For a convex enclosure the share of a side's cosine rays that escape equals
    ``A_opening / A_enclosure``, so a threshold on that share is exactly the line between a
    crack and an opening.  We therefore scale the prior of node *j* by
    ``max(0, 1 − e_j / opening)`` with ``e_j = escaped_j / n_j``: a side that escapes less
    than ``opening`` keeps (most of) the paper's prior, one that escapes more is not pulled
    inside.  ``opening=None`` reproduces the paper exactly.
    """
    w_in = w_out[opposite].copy()
    if opening is None:
        return w_in
    if opening <= 0:
        raise ValueError("opening must be positive (or None)")
    share = np.where(counted > 0, escaped / np.maximum(counted, 1), 0.0)
    return w_in * np.clip(1.0 - share / opening, 0.0, 1.0)


def cosine_filter(w: np.ndarray, w_max: np.ndarray) -> np.ndarray:
    """Eq. 9: ``½ (1 + cos(π − π w / w_max)) · w`` (0 where ``w_max`` is 0).

    Evaluated as ``sin²(π r / 2) · w`` with ``r = w / w_max``, the same function: the
    literal form cancels to exactly 0 for ``r`` below about 1e-8 (1 + cos(π − x) rounds
    to 0), which would cut a weak link completely instead of damping it — a small part
    seen by a large cluster would then be unreachable from it.
    """
    # in place on one float array (and the mask): the same operations in the same order as
    # ``sin(0.5 π clip(w / w_max, 0, 1))² · w``, so the same bits
    ratio = np.zeros(np.shape(w), np.float64)
    np.divide(w, w_max, out=ratio, where=w_max > 0)
    np.clip(ratio, 0.0, 1.0, out=ratio)
    ratio *= 0.5 * np.pi
    np.sin(ratio, out=ratio)
    np.square(ratio, out=ratio)
    ratio *= w
    return ratio


def graph_weights(
    hits: sp.spmatrix,
    counted: np.ndarray,
    escaped: np.ndarray,
    area: np.ndarray,
    opposite: np.ndarray,
    is_point: np.ndarray,
    *,
    hint_out: np.ndarray | None = None,
    hint_in: np.ndarray | None = None,
    use_filter: bool = True,
    opening: float | None = DEFAULT_OPENING,
) -> Weights:
    """All weights of the graph: Eq. 5, Eq. 7, ``w_in(opp(i)) = w_o(i)``, and the filter.

    The filter is directed: node *i* scales every link it has by its own
    ``w_max(i) = max(max_j w(i,j), w_o(i), w_in(i))`` (Eq. 8), so ``cap(i→j)`` and
    ``cap(j→i)`` may differ.  Terminal links are filtered with the same ``w_max(i)``.

    Parameters
    ----------
    hits : (n, n) scipy.sparse matrix
        ``n_ij``: rays from node i that hit node j.
    counted : (n,) float array
        ``n_i``: rays counted for node i.
    escaped : (n,) float array
        Rays from node i that hit nothing.
    area : (n,) float array
        ``A_i``: node area.
    opposite : (n,) int array
        ``opp(i)``: the node on the other side of the same geometry.
    is_point : (n,) bool array
        Sample-point nodes.
    hint_out : (n,) float array, optional
        Extra OUTSIDE weights from user hints (appendix H §3.2.1).
    hint_in : (n,) float array, optional
        Extra INSIDE weights from user hints.
    use_filter : bool
        Apply the directed cosine filter of Eq. 8–9.
    opening : float or None
        Escape share above which a side counts as open (see :func:`inside_prior`); None
        applies the paper's ``w_in(opp(i)) = w_o(i)`` unchanged.

    Returns
    -------
    Weights
        The weights before and after the filter.
    """
    i, j, w = edge_weights(hits, counted, area, is_point)
    w_out = outside_weights(escaped, counted, area)
    w_in = inside_prior(w_out, escaped, counted, opposite, opening)
    if hint_out is not None:
        w_out = w_out + hint_out
    if hint_in is not None:
        w_in = w_in + hint_in
    if not use_filter:
        return Weights(i, j, w, w_out, w_in, w.copy(), w.copy(), w_out.copy(), w_in.copy())
    w_max = np.maximum(w_out, w_in)
    _kernels.edge_maxima(w_max, i, j, w)
    return Weights(
        i,
        j,
        w,
        w_out,
        w_in,
        cap_ij=cosine_filter(w, w_max[i]),
        cap_ji=cosine_filter(w, w_max[j]),
        cap_out=cosine_filter(w_out, w_max),
        cap_in=cosine_filter(w_in, w_max),
    )
