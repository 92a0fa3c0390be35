"""What is wrong with a model: the numbers behind ``meshvis info``.

:func:`diagnose` runs the connectivity analysis of :mod:`meshvis.geometry.adjacency` and the
conservative intersection / coplanarity tests of :mod:`meshvis.geometry.intersect` (the same
preprocessing the graph cut uses, appendix H §2) and returns plain JSON-ready values, with
the time each stage took.  :func:`format_report` turns them into a short table.
"""

from __future__ import annotations

import os
import time
from typing import Any

import numpy as np

from meshvis.geometry import adjacency, duplicates, intersect
from meshvis.io import as_soup


def diagnose(
    model: Any,
    *,
    eps: float = intersect.EPS,
    weld_tol: float = adjacency.WELD_TOL,
    intersections: bool = True,
) -> dict:
    """Count the defects of a model.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (vertices, faces) or path
        Anything :func:`meshvis.soup.as_soup` accepts.
    eps : float
        Distance tolerance of the intersection and coplanarity tests, as a fraction of the
        bounding-box diagonal (see :mod:`meshvis.geometry.intersect`).
    weld_tol : float
        Vertices closer than ``weld_tol`` times the diagonal count as one for adjacency.
    intersections : bool
        Run the (slowest) intersection / coplanarity stage.  When ``False`` its counts are
        ``None``.

    Returns
    -------
    dict
        ``faces``, ``vertices`` (stored), ``welded_vertices``, ``parts``, ``components``
        (faces connected through shared edges; collapsed faces left out), ``edges``,
        ``boundary_edges`` (one face), ``nonmanifold_edges`` (more than two faces),
        ``degenerate_faces`` (smallest altitude below the weld tolerance, or collapsed),
        ``double_sided_pairs`` (faces stored twice with opposite winding,
        :mod:`meshvis.geometry.duplicates`), ``duplicate_faces`` (redundant copies of a face: same welded corners, either
        winding), ``intersecting_faces``, ``coplanar_faces`` (overlapping a coplanar face),
        ``too_close_faces`` (a non-adjacent face within ``eps``), ``winding_consistent`` and
        ``inconsistent_edges`` (manifold edges traversed twice in the same direction),
        ``closed`` (no boundary edge), ``edge_manifold`` (no non-manifold edge),
        ``bounds`` ([min, max] corners), ``diagonal``, ``area``, ``eps`` and ``weld_tol``
        (absolute, model units), ``path``, ``seconds`` (per stage) and ``total_seconds``.
    """
    seconds: dict[str, float] = {}
    t_all = time.perf_counter()

    def lap(name: str, t0: float) -> float:
        now = time.perf_counter()
        seconds[name] = round(now - t0, 4)
        return now

    t = time.perf_counter()
    soup = as_soup(model)
    t = lap("load", t)
    v, f = soup.vertices, soup.faces
    m = soup.n_faces
    diag = soup.diagonal

    _, fw = adjacency.weld(v, f, weld_tol)
    t = lap("weld", t)

    table = adjacency.edges(fw)
    consistent = table.consistent
    t = lap("edges", t)

    keep = ~adjacency.collapsed(fw)
    _, label = adjacency.components(m, adjacency.face_adjacency(table, manifold_only=False))
    n_comp = len(np.unique(label[keep]))
    t = lap("components", t)

    degenerate = adjacency.degenerate_faces(v, f, weld_tol, faces_welded=fw)
    t = lap("degenerate", t)

    first = adjacency.duplicate_faces(fw)
    t = lap("duplicates", t)

    inter = copl = close = None
    if intersections:
        flags = intersect.intersection_flags(v, f, eps, faces_welded=fw)
        inter = int(flags["intersects"].sum())
        copl = int(flags["coplanar"].sum())
        close = int(flags["too_close"].sum())
        t = lap("intersections", t)

    n_boundary = int(table.boundary.sum())
    n_nonmanifold = int(table.nonmanifold.sum())
    n_inconsistent = int((~consistent).sum())
    return {
        "path": None if soup.path is None else os.fspath(soup.path),
        "faces": int(m),
        "vertices": int(soup.n_vertices),
        "welded_vertices": int(fw.max()) + 1 if m else 0,
        "parts": int(soup.n_parts),
        "components": int(n_comp),
        "edges": int(len(table.count)),
        "boundary_edges": n_boundary,
        "nonmanifold_edges": n_nonmanifold,
        "degenerate_faces": int(degenerate.sum()),
        "duplicate_faces": int((first != np.arange(m)).sum()),
        "double_sided_pairs": int(len(duplicates.opposite_copies(fw))),
        "intersecting_faces": inter,
        "coplanar_faces": copl,
        "too_close_faces": close,
        "winding_consistent": n_inconsistent == 0,
        "inconsistent_edges": n_inconsistent,
        "closed": n_boundary == 0,
        "edge_manifold": n_nonmanifold == 0,
        "bounds": soup.bounds.tolist(),
        "diagonal": float(diag),
        "area": float(soup.total_area),
        "eps": float(eps * diag),
        "weld_tol": float(weld_tol * diag),
        "seconds": seconds,
        "total_seconds": round(time.perf_counter() - t_all, 4),
    }


_ROWS = [
    ("faces", "faces"),
    ("vertices", "vertices (stored)"),
    ("welded_vertices", "vertices (welded)"),
    ("parts", "parts"),
    ("components", "connected components"),
    ("edges", "edges"),
    ("boundary_edges", "boundary edges"),
    ("nonmanifold_edges", "non-manifold edges"),
    ("closed", "closed (no boundary edge)"),
    ("winding_consistent", "winding consistent"),
    ("inconsistent_edges", "inconsistently wound edges"),
    ("degenerate_faces", "degenerate faces"),
    ("duplicate_faces", "duplicate faces"),
    ("double_sided_pairs", "double-sided pairs (copies with opposite winding)"),
    ("intersecting_faces", "faces intersecting another"),
    ("coplanar_faces", "faces overlapping a coplanar one"),
    ("too_close_faces", "faces near a non-adjacent one"),
]


def _fmt(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return f"{value:,}"
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def format_report(d: dict) -> str:
    """A plain-text table of a :func:`diagnose` result (one ``label  value`` line per item)."""
    rows = [(label, _fmt(d.get(key))) for key, label in _ROWS]
    lo, hi = d["bounds"]
    rows.append(("bounding box min", " ".join(f"{x:.6g}" for x in lo)))
    rows.append(("bounding box max", " ".join(f"{x:.6g}" for x in hi)))
    rows.append(("diagonal", _fmt(d["diagonal"])))
    rows.append(("tolerance (eps / weld)", f"{d['eps']:.3g} / {d['weld_tol']:.3g}"))
    times = ", ".join(f"{k} {v:.2f}" for k, v in d["seconds"].items())
    rows.append(("seconds", f"{d['total_seconds']:.2f} ({times})"))
    width = max(len(label) for label, _ in rows)
    lines = [d["path"]] if d.get("path") else []
    lines += [f"{label:<{width}}  {value}" for label, value in rows]
    return "\n".join(lines)
