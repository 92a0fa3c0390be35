"""Closedness, bodies and nesting, and the truth of any closed model (:func:`from_closed_mesh`)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from meshvis.errors import ModelError
from meshvis.geometry.adjacency import WELD_TOL, components, edges, face_adjacency, weld
from meshvis.soup import Soup

from ._shapes import _compose, _Piece
from .truth import GroundTruth


def _welded(soup: Soup, tol: float = 0.0) -> np.ndarray:
    """(m, 3) welded corner ids (:func:`meshvis.geometry.adjacency.weld`; exact duplicates by default)."""
    return weld(soup.vertices, soup.faces, tol)[1]


def is_closed(soup: Soup, oriented: bool = True, tol: float = WELD_TOL) -> bool:
    """Tell whether the surface is closed once corners closer than ``tol`` x diagonal are merged.

    Closed means every edge is used an even number of times; *oriented* closed (the
    default) means every edge is crossed as often in one direction as in the other, i.e.
    the surface bounds a volume with consistent winding.  Non-manifold edges are allowed.

    Parameters
    ----------
    soup : Soup
        The model.
    oriented : bool
        Also require consistent winding.
    tol : float
        Weld distance as a fraction of the bounding-box diagonal (see
        :func:`meshvis.geometry.adjacency.weld`).

    Returns
    -------
    bool
        Whether the surface is (oriented) closed; False for a model without faces.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> from meshvis.io import as_soup
    >>> cube = as_soup(trimesh.creation.box())
    >>> is_closed(cube), is_closed(cube.subset(np.arange(1, 12)))
    (True, False)
    """
    if soup.n_faces == 0:
        return False
    table = edges(_welded(soup, tol))
    if oriented:
        forward = np.bincount(table.half_edge, weights=table.half_forward, minlength=len(table.count))
        return bool(np.all(2 * forward == table.count))
    return bool(np.all(table.count % 2 == 0))


def _components(soup: Soup, tol: float = WELD_TOL) -> np.ndarray:
    """(m,) label of the edge-connected component (body) of every face."""
    pairs = face_adjacency(edges(_welded(soup, tol)), manifold_only=False)
    return components(soup.n_faces, pairs)[1]


def _outward_bodies(soup: Soup) -> tuple[np.ndarray, np.ndarray]:
    """Find the body (edge-connected component) of every face and whether it faces out of it.

    A face's front faces out of its body when the body's signed volume (sum of
    ``v0 . (v1 x v2)``) is not negative.  Meaningful for closed, consistently wound bodies.
    """
    labels = _components(soup)
    t = soup.triangles - soup.bounds.mean(axis=0)
    vol = np.bincount(labels, np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])))
    return labels, (vol >= 0)[labels]


def _containment(
    pieces: Sequence[tuple[np.ndarray, np.ndarray]], eps: float, fast: bool = False
) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """How deep inside the closed pieces each face lies, and which faces are ambiguous.

    For every face of piece ``p`` the generalised winding number of all pieces (its own
    included) is evaluated at points pushed ``eps`` off the centroid to both sides and at
    the corners (pulled 2 % toward the centroid, pushed to the front).  The rounded front
    value is the depth: the number of pieces around the face, plus the folds of its own
    piece when that piece crosses itself (a face inside its own piece's volume cannot be
    seen).  The back value of a clean face is one more than the front.  A face is
    ambiguous when the two sides do not differ by one (it lies on another piece's surface)
    or a corner disagrees with the centroid (it straddles an intersection curve).
    """
    import igl

    wn = igl.fast_winding_number if fast else igl.winding_number
    # winding numbers add up over closed pieces: evaluate the whole model once
    offsets = np.cumsum([0] + [len(V) for V, _ in pieces[:-1]])
    Vall = np.ascontiguousarray(np.concatenate([V for V, _ in pieces]), np.float64)
    Fall = np.ascontiguousarray(
        np.concatenate([np.asarray(F, np.int64) + o for (_, F), o in zip(pieces, offsets)])
    )
    t = Vall[Fall]
    c = t.mean(axis=1)
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    corners = (c[:, None] + 0.98 * (t - c[:, None]) + eps * n[:, None]).reshape(-1, 3)
    w = np.asarray(wn(Vall, Fall, np.concatenate([c + eps * n, c - eps * n, corners])))
    m = len(Fall)
    front, back, corner = w[:m], w[m : 2 * m], w[2 * m :].reshape(m, 3)
    d = np.maximum(np.rint(front), 0).astype(np.int64)
    amb = (np.rint(back) - np.rint(front) != 1) | np.any(np.rint(corner) != np.rint(front)[:, None], axis=1)
    amb |= np.abs(front - np.rint(front)) > 0.25
    split = np.cumsum([len(F) for _, F in pieces])[:-1]
    depth, ambiguous = np.split(d, split), np.split(amb, split)
    return depth, ambiguous


def _closed_pieces_truth(
    pieces: Sequence[tuple[np.ndarray, np.ndarray]],
    parts: Sequence[str],
    name: str,
    notes: str,
    fast: bool = False,
) -> GroundTruth:
    """Truth of a set of closed, outward pieces that may overlap or nest.

    A face inside ``d`` other pieces is hidden when ``d > 0``; its layer is ``d + 1``
    (nesting depth; for overlapping pieces this is the depth of the overlap region).
    Visible faces are one-sided with the front outside.  Query points are pushed off
    the faces by 1e-6 of the bounding-box diagonal.
    """
    allv = np.concatenate([V[np.unique(F)] for V, F in pieces])
    eps = 1e-6 * float(np.linalg.norm(allv.max(axis=0) - allv.min(axis=0)))
    depth, amb = _containment(pieces, eps, fast)
    out = []
    for (V, F), part, d, a in zip(pieces, parts, depth, amb):
        vis = d == 0
        out.append(
            _Piece(
                V,
                F,
                part,
                outside=np.stack([vis, np.zeros_like(vis)], 1),
                layer=d + 1,
                outward=True,
                ambiguous=a,
            )
        )
    return _compose(out, name, notes)


#: fold-overs sharper than this (degrees) count as one surface stored twice
FOLD_DEGREES = 2.0


def _folded_onto_neighbour(soup: Soup, degrees: float = FOLD_DEGREES, max_fan: int = 8) -> np.ndarray:
    """(m,) bool: faces folded onto a neighbour across a shared edge.

    Two triangles ``(a, b, c)`` and ``(a, b, d)`` on one welded edge lie on each other when
    their planes agree within ``degrees`` and ``c``, ``d`` lie on the same side of the line
    ``ab``: the surface is there twice, as where a (slightly skew) quad is stored once per
    triangulation, or a triangle once per touching body.  Which copy faces which way is then
    not observable.  Every pair of faces on an edge is tested (edges with more than
    ``max_fan`` faces are skipped).  On the rib cage this finds 6,840 of the 6,872 faces
    of its coincident copies and 32 faces of slightly skew quads stored with both diagonals
    (planes 0.8-1.3 degrees apart); on cow, spot and the dog skin, nothing.
    """
    from meshvis.geometry.adjacency import edges

    tol = 1.0 - np.cos(np.radians(degrees))
    welded = _welded(soup, 0.0)
    table = edges(welded)
    start = np.searchsorted(table.half_edge, np.arange(len(table.count)))
    pairs = [
        np.stack([start[e] + i, start[e] + j], axis=1)
        for i in range(max_fan)
        for j in range(i + 1, max_fan)
        for e in [np.flatnonzero((table.count > j) & (table.count <= max_fan))]
    ]
    h = np.concatenate(pairs) if pairs else np.zeros((0, 2), np.int64)
    f, g = table.half_face[h[:, 0]], table.half_face[h[:, 1]]
    n = soup.normals
    keep = np.abs(np.einsum("ij,ij->i", n[f], n[g])) > 1 - tol
    f, g, ends = f[keep], g[keep], table.vertices[table.half_edge[h[keep, 0]]]

    def corner(face: np.ndarray, which: np.ndarray) -> np.ndarray:
        return soup.triangles[face, which.argmax(axis=1)]

    kf, kg = welded[f], welded[g]
    pa = corner(f, kf == ends[:, :1])
    pb = corner(f, kf == ends[:, 1:])
    cf = corner(f, (kf != ends[:, :1]) & (kf != ends[:, 1:]))  # the corners off the edge
    cg = corner(g, (kg != ends[:, :1]) & (kg != ends[:, 1:]))
    side_f = np.einsum("ij,ij->i", np.cross(pb - pa, cf - pa), n[f])
    side_g = np.einsum("ij,ij->i", np.cross(pb - pa, cg - pa), n[f])
    overlap = side_f * side_g > 0
    out = np.zeros(soup.n_faces, bool)
    out[f[overlap]] = True
    out[g[overlap]] = True
    return out


def from_closed_mesh(model: Any, name: str | None = None) -> GroundTruth:
    """Build the truth of a closed real model: every body outward and outside, nested ones hidden.

    The model must be closed with consistent winding (every directed edge matched by its
    reverse once coincident corners are merged).  Bodies are the edge-connected components;
    each is outward where its signed volume is positive.  A face whose outward side has
    winding number ``d`` (of all bodies, its own included) is hidden with layer ``d + 1``
    when ``d > 0``: it lies inside another body, or inside a fold of its own body when the
    surface crosses itself (``cow.obj`` does).  Faces that cross another face, straddle an
    intersection curve, touch another body's surface or are folded onto a neighbour (the
    same surface stored twice) are ambiguous.  For a clean single body this is simply: all
    faces layer 1, outside on the outward side.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (V, F) or path
        The model, as :func:`meshvis.as_soup` accepts it; its winding is kept.
    name : str, optional
        Name of the truth; default the file name without extension, or ``"closed_mesh"``.

    Returns
    -------
    GroundTruth
        The truth, faces in the model's order.

    Raises
    ------
    ModelError
        The model is not closed with consistent winding, or cannot be read.

    Examples
    --------
    >>> import trimesh
    >>> t = from_closed_mesh(trimesh.creation.icosphere(1), name="ball")
    >>> t.name, t.n_faces, t.n_layers, bool(t.outward.all())
    ('ball', 80, 1, True)
    """
    from meshvis.io import as_soup

    soup = as_soup(model)
    if not is_closed(soup, oriented=True):
        raise ModelError("the model is not closed with consistent winding; its truth is not known", soup.path)
    labels, outward = _outward_bodies(soup)
    flip = ~outward
    # make every body outward, find nesting, then restore the input winding
    fixed = soup.flipped(flip)
    order = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[order], np.arange(labels.max() + 2))
    bodies = []
    for b in range(labels.max() + 1):
        used, f = np.unique(fixed.faces[order[bounds[b] : bounds[b + 1]]], return_inverse=True)
        bodies.append((fixed.vertices[used], f.reshape(-1, 3)))
    depth, amb = _containment(bodies, 1e-6 * soup.diagonal, fast=True)
    d = np.empty(soup.n_faces, np.int64)
    a = np.empty(soup.n_faces, bool)
    d[order] = np.concatenate(depth)
    a[order] = np.concatenate(amb)
    # a face that crosses another is partly in front of and partly behind it: no single answer
    from meshvis.geometry.intersect import intersection_flags

    a |= intersection_flags(soup.vertices, soup.faces)["intersects"]
    a |= _folded_onto_neighbour(soup)
    vis = d == 0
    outside = np.stack([vis & outward, vis & ~outward], 1)
    nm = name or (os.path.splitext(os.path.basename(soup.path))[0] if soup.path else "closed_mesh")
    return GroundTruth(
        soup=soup,
        outside=outside,
        layer=d + 1,
        outward=outward,
        ambiguous=a,
        name=nm,
        notes="closed model: every body outward, nested bodies hidden",
    )
