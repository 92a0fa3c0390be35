"""What is wrong with a model: the numbers behind ``meshvis info``.

:func:`analyse` is the one pass over a model that both ``meshvis info`` (:func:`diagnose`)
and the graph cut (:func:`meshvis.graphcut.preprocess.preprocess`) run, so that both report
the same counts.  :func:`diagnose` runs the connectivity analysis of :mod:`meshvis.geometry.adjacency` and the
conservative intersection / coplanarity tests of :mod:`meshvis.geometry.intersect` (the same
preprocessing the graph cut uses, appendix H §2) and returns plain JSON-ready values, with
the time each stage took.  :func:`format_report` turns them into a short table.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshvis._threads import default_threads
from meshvis.geometry import adjacency, duplicates, intersect
from meshvis.io import as_soup
from meshvis.soup import Soup

#: a face whose smallest altitude is at most this fraction of the diagonal is degenerate:
#: it is not classified (it has no side worth a ray) and ``info`` counts it as degenerate
DEGENERATE_TOL = 1e-9

Progress = Callable[[str, float], None]


@dataclass
class Analysis:
    """One pass over a model's connectivity and defects, shared by ``info`` and ``classify``.

    Attributes
    ----------
    faces_welded : (m, 3) int32 or int64
        Welded corner ids (:func:`adjacency.weld`)
    table : EdgeTable
        The edges of the welded faces.
    degenerate : (m,) bool
        Smallest altitude at most :data:`DEGENERATE_TOL` times the
        diagonal, or zero area
    collapsed : (m,) bool
        Two corners welded into one (weld tolerance)
    duplicate_first : (m,) int64
        The first copy of every face (:func:`adjacency.duplicate_faces`).
    flags : dict or None
        The flags of :func:`intersect.intersection_flags`; None when not run.
    seconds : dict
        Time of each step (the edges are built alongside the steps after the weld: their
        seconds overlap the others')
    """

    faces_welded: np.ndarray
    table: adjacency.EdgeTable
    degenerate: np.ndarray
    collapsed: np.ndarray
    duplicate_first: np.ndarray
    flags: dict | None
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def counts(self) -> dict[str, int | None]:
        """The defect counts both ``info`` and the classification report."""
        f = self.flags
        m = len(self.degenerate)
        return {
            "degenerate_faces": int(self.degenerate.sum()),
            "collapsed_faces": int(self.collapsed.sum()),
            "duplicate_faces": int((self.duplicate_first != np.arange(m)).sum()),
            "intersecting_faces": None if f is None else int(f["intersects"].sum()),
            "coplanar_faces": None if f is None else int(f["coplanar"].sum()),
            "too_close_faces": None if f is None else int(f["too_close"].sum()),
        }


def analyse(
    soup: Soup,
    *,
    eps: float | None = None,
    weld_tol: float = adjacency.WELD_TOL,
    intersections: bool = True,
    progress: Progress | None = None,
    vertex_groups: adjacency.VertexGroups | None = None,
) -> Analysis:
    """Weld, edges, degenerate, duplicate and intersecting faces of a soup, in one pass.

    Parameters
    ----------
    soup : Soup
        The model.
    eps : float, optional
        Distance tolerance of the intersection tests (fraction of the diagonal; default
        :data:`meshvis.geometry.intersect.EPS`).
    weld_tol : float
        Weld tolerance (fraction of the diagonal).
    intersections : bool
        Run the intersection / coplanarity tests (the slowest step).
    progress : callable, optional
        ``progress(stage, fraction)``, called between the steps.
    vertex_groups : VertexGroups, optional
        :func:`adjacency.group_vertices` of the soup, when the caller has them (the
        classification's Embree scene is built on them).

    Returns
    -------
    Analysis
    """
    report = progress or (lambda stage, fraction: None)
    seconds: dict[str, float] = {}
    t = time.perf_counter()

    def lap(name: str, fraction: float) -> None:
        nonlocal t
        now = time.perf_counter()
        seconds[name] = round(now - t, 4)
        t = now
        report("analyse", fraction)

    report("analyse", 0.0)
    v, f = soup.vertices, soup.faces
    _, fw = adjacency.weld(v, f, weld_tol, vertex_groups)
    lap("weld", 0.15)
    # the edges need only the welded faces: they are built in a thread of their own while
    # the rest runs (numpy's sorts release the GIL), so that the second core has work
    # during the single-threaded steps of the intersection tests (in this thread when
    # meshvis may use one core, as in the workers of ``meshvis batch``)
    seconds["edges"] = 0.0
    with ThreadPoolExecutor(1, "meshvis-edges") if default_threads() > 1 else _Inline() as side:
        edges = side.submit(_timed, adjacency.edges, fw)
        collapsed = adjacency.collapsed(fw)
        degenerate = adjacency.degenerate_faces(v, f, tol=DEGENERATE_TOL, zero_area=True)
        lap("degenerate", 0.3)
        first = adjacency.duplicate_faces(fw)
        lap("duplicates", 0.35)
        flags = None
        if intersections:
            flags = intersect.intersection_flags(
                v,
                f,
                eps,
                faces_welded=fw,
                duplicate_first=first,
                progress=lambda x: report("analyse", 0.35 + 0.65 * x),
            )
            lap("intersections", 1.0)
        table, seconds["edges"] = edges.result()
    report("analyse", 1.0)
    return Analysis(fw, table, degenerate, collapsed, first, flags, seconds)


class _Inline:
    """An executor that runs the work when it is submitted (one thread)."""

    def __enter__(self) -> _Inline:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def submit(self, work: Callable[..., Any], *args: Any) -> Future:
        done: Future = Future()
        done.set_result(work(*args))
        return done


def _timed(work: Callable[..., Any], *args: Any) -> tuple[Any, float]:
    """``work(*args)`` and the seconds it took."""
    t = time.perf_counter()
    out = work(*args)
    return out, round(time.perf_counter() - t, 4)


def diagnose(
    model: Any,
    *,
    eps: float = intersect.EPS,
    weld_tol: float = adjacency.WELD_TOL,
    intersections: bool = True,
    progress: Progress | None = None,
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
    progress : callable, optional
        ``progress(stage, fraction)``, as for :func:`meshvis.classify`.

    Returns
    -------
    dict
        ``faces``, ``vertices`` (stored), ``welded_vertices``, ``parts``, ``components``
        (faces connected through shared edges; collapsed faces left out), ``edges``,
        ``boundary_edges`` (one face), ``nonmanifold_edges`` (more than two faces),
        ``degenerate_faces`` (smallest altitude at most :data:`DEGENERATE_TOL` times the
        diagonal, or zero area: the faces the classification leaves out),
        ``collapsed_faces`` (two corners welded into one), ``double_sided_pairs`` (faces stored
        twice with opposite winding, :mod:`meshvis.geometry.duplicates`), ``duplicate_faces`` (redundant
        copies of a face: same welded corners, either winding), ``intersecting_faces``,
        ``coplanar_faces`` (overlapping a coplanar face), ``too_close_faces`` (a non-adjacent
        face within ``eps``), ``winding_consistent`` and ``inconsistent_edges`` (manifold
        edges traversed twice in the same direction), ``closed`` (no boundary edge),
        ``edge_manifold`` (no non-manifold edge), ``bounds`` ([min, max] corners),
        ``diagonal``, ``area``, ``eps`` and ``weld_tol`` (absolute, model units), ``path``,
        ``seconds`` (per stage) and ``total_seconds``.  The defect counts are those of
        :attr:`Analysis.counts`, the same pass the classification runs.

    Examples
    --------
    >>> import trimesh
    >>> d = diagnose(trimesh.creation.box())
    >>> d["closed"], d["degenerate_faces"], d["intersecting_faces"]
    (True, 0, 0)
    """
    t_all = time.perf_counter()
    t = time.perf_counter()
    soup = as_soup(model)
    seconds = {"load": round(time.perf_counter() - t, 4)}
    a = analyse(soup, eps=eps, weld_tol=weld_tol, intersections=intersections, progress=progress)
    seconds.update(a.seconds)
    t = time.perf_counter()
    m = soup.n_faces
    _, label = adjacency.components(m, adjacency.face_adjacency(a.table, manifold_only=False))
    n_comp = len(np.unique(label[~a.collapsed]))
    seconds["components"] = round(time.perf_counter() - t, 4)
    return _summary(soup, a, n_comp, eps, weld_tol, seconds, time.perf_counter() - t_all)


def _summary(
    soup: Soup, a: Analysis, n_comp: int, eps: float, weld_tol: float, seconds: dict, total: float
) -> dict:
    """The JSON-ready dictionary of :func:`diagnose`."""
    table, m, diag = a.table, soup.n_faces, soup.diagonal
    n_boundary = int(table.boundary.sum())
    n_nonmanifold = int(table.nonmanifold.sum())
    n_inconsistent = int((~table.consistent).sum())
    return {
        "path": None if soup.path is None else os.fspath(soup.path),
        "faces": int(m),
        "vertices": int(soup.n_vertices),
        "welded_vertices": int(a.faces_welded.max()) + 1 if m else 0,
        "parts": int(soup.n_parts),
        "components": int(n_comp),
        "edges": int(len(table.count)),
        "boundary_edges": n_boundary,
        "nonmanifold_edges": n_nonmanifold,
        **a.counts,
        "double_sided_pairs": int(len(duplicates.opposite_copies(a.faces_welded))),
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
        "total_seconds": round(total, 4),
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
    ("collapsed_faces", "faces collapsed by welding"),
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
