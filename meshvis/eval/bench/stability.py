"""Stability of the classification on stiff and extreme inputs (similarity transforms, slivers, cracks, ...).

``meshvis bench stability [--quick] [--json FILE]`` runs five groups of cases.  Each case
classifies a stressed model and compares it with the classification of the untouched
model (same seed), prints PASS or FAIL with the figure it was judged on, and the command
returns 1 when any case fails:

1. *similarity* — uniform scale 1e-6 … 1e6, translation by 1e6 × the size, a rotation, and
   a plain rerun: per-face side labels must agree on at least 99.9 % of the area (a rerun
   must agree exactly: same input and seed give the same output);
2. *degenerate* — slivers of aspect ratio up to 1e6, zero-area faces, duplicate faces,
   near-coplanar duplicates 1e-7 × size away, corners perturbed by 1e-9 × size: the
   original faces keep their labels on at least 99.9 % of their area;
3. *cracks* — a single-sheet box with slits of width 1e-1 … 1e-8 × size around a closed
   box: the width from which the interior leaks (the inner box turns outside), with the
   measured escape share of the box's inner sides next to the ``opening`` threshold, the
   terminal weights before and after the cosine filter, the leak under the paper's
   unfaded prior, and a probe of the slit width the float32 scene closes; it passes when
   leaking is monotone in the width;
4. *weights* — tiny lone triangles and closed cubes (1e-6 × size and up) beside large
   shells, so that edge weights span more than 12 orders of magnitude: the float solver
   (PyMaxflow) and the integer solver (scipy) cut the same graph; their cut values must
   agree within :func:`meshvis.graphcut.mincut.rounding_bound` and their labels on 99.9 % of the
   area; what the integer rounding loses is reported;
5. *tiny* — one triangle, two triangles, one quad (both sides of every face outside); an
   empty file, a file without faces and a single zero-area triangle (a clean
   :class:`~meshvis.errors.ModelError` naming the file).

Every case also checks that no float in the classification report, the node areas and the
graph weights (before and after the cosine filter) is NaN or infinite.

``--quick`` runs fewer scales and widths on smaller models (well under a minute).  The
explanation of the crack threshold is in ``docs/stability.md``.
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from meshvis.errors import ModelError
from meshvis.eval import generators
from meshvis.graphcut.classify import Classification, classify
from meshvis.graphcut.mincut import Cut, rounding_bound
from meshvis.graphcut.weights import DEFAULT_OPENING
from meshvis.rays.caster import DEFAULT_OFFSET
from meshvis.soup import Soup

#: a stressed classification must agree with the untouched one on this share of the area
AGREEMENT = 0.999

#: uniform scales of the similarity group
SCALES_FULL = (1e-6, 1e-3, 1e3, 1e6)
SCALES_QUICK = (1e-6, 1e6)
#: translation of the similarity group, in units of the model's diagonal
TRANSLATION = 1e6
#: crack widths (fractions of the box diagonal); the brief's range is 1e-2 … 1e-6, the
#: wider widths locate the leak, 1e-7 goes below the intersection tolerance
CRACK_WIDTHS_FULL = (1e-1, 5e-2, 3e-2, 2e-2, 1.5e-2, 1.2e-2, 1e-2, 3e-3, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
CRACK_WIDTHS_QUICK = (3e-2, 1e-2, 1e-4, 1e-6)
#: slit widths of the float32 probe (fractions of the diagonal)
SLIT_WIDTHS_FULL = (1e-5, 1e-6, 5e-7, 3e-7, 2e-7, 1.5e-7, 1e-7, 5e-8, 1e-8)
SLIT_WIDTHS_QUICK = (1e-6, 2e-7, 1e-7, 1e-8)
#: crack widths and rays of the ray-offset probe (full run only)
OFFSET_WIDTHS = (1e-4, 3e-5, 1e-5, 3e-6)
OFFSET_RAYS = 6_000_000
#: rays cast from the inner sides of the cracked box to measure their escape share
SHARE_RAYS_FULL = 2_000_000
SHARE_RAYS_QUICK = 200_000
#: edge lengths of the tiny cubes of the weights case, fractions of the model's diagonal
TINY_SIZES = (1e-6, 1e-5, 1e-4, 1e-3, 1e-2)
#: the weights case must really span this many orders of magnitude
WEIGHT_ORDERS = 12
TINY_NAME = "tiny triangles and cubes beside large spheres"


# ============================================================================ results
@dataclass
class CaseResult:
    """One stability case.

    Attributes
    ----------
    group, name : where the case belongs and what it stresses
    passed : bool
    figure : the number(s) the case is judged on, as printed
    values : machine-readable numbers behind ``figure`` (for ``--json``)
    seconds : wall time of the case
    table : optional rows printed under the case (the crack sweep)
    """

    group: str
    name: str
    passed: bool
    figure: str
    values: dict = field(default_factory=dict)
    seconds: float = 0.0
    table: list[dict] = field(default_factory=list)


# ============================================================================ measures
def area_agreement(reference: np.ndarray, other: np.ndarray, areas: np.ndarray) -> float:
    """Share of the area whose per-face side labels agree.

    Parameters
    ----------
    reference, other : (m, 2) bool, side-outside labels (``Classification.side_outside``)
    areas : (m,) float64, face areas (of the reference model)

    Returns
    -------
    float in [0, 1]: ``Σ_f A_f [ref_f == other_f] / Σ_f A_f`` where a face agrees when both
    of its sides do; 1.0 for a model of zero area.
    """
    same = np.all(np.asarray(reference, bool) == np.asarray(other, bool), axis=1)
    total = float(np.sum(areas))
    return float(np.sum(areas[same]) / total) if total > 0 else 1.0


def _walk_floats(obj: Any, path: str, out: list[str]) -> None:
    """Append the path of every non-finite float found in nested dicts, lists and arrays."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            _walk_floats(v, f"{path}.{k}" if path else str(k), out)
    elif isinstance(obj, (list, tuple)):
        for k, v in enumerate(obj):
            _walk_floats(v, f"{path}[{k}]", out)
    elif isinstance(obj, np.ndarray):
        if np.issubdtype(obj.dtype, np.floating) and not np.all(np.isfinite(obj)):
            out.append(f"{path} ({int(np.sum(~np.isfinite(obj)))} values)")
    elif isinstance(obj, (float, np.floating)):
        if not math.isfinite(float(obj)):
            out.append(path)


def nonfinite(c: Classification) -> list[str]:
    """Names of the floats of a classification that are NaN or infinite (empty when all are finite).

    Checked: every float and float array in ``c.report(per_face=True)``, the node areas,
    the per-face outside fractions, every array of the graph weights (Eq. 5–9, before and
    after the cosine filter) and the cut value.
    """
    bad: list[str] = []
    _walk_floats(c.report(per_face=True), "report", bad)
    _walk_floats(asdict(c.graph.weights), "weights", bad)
    _walk_floats({"node_area": c.nodes.area, "outside": c.outside, "cut_value": c.cut.value}, "", bad)
    return bad


def aspect_ratios(soup: Soup) -> np.ndarray:
    """Per face: longest edge over smallest altitude, ``L_max² / (2 A)`` (inf for zero area)."""
    t = soup.triangles
    e = np.linalg.norm(t[:, [1, 2, 0]] - t, axis=2)
    lmax = e.max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(soup.areas > 0, lmax**2 / (2 * soup.areas), np.inf)


# ============================================================================ stressed models
def _with(soup: Soup, vertices: np.ndarray, faces: np.ndarray, parent: np.ndarray) -> Soup:
    """A soup of new geometry whose faces inherit the attributes of their ``parent`` faces."""
    return Soup(
        vertices,
        faces,
        part_id=soup.part_id[parent],
        part_names=list(soup.part_names),
        source_face=soup.source_face[parent],
        material_id=soup.material_id[parent],
        materials=list(soup.materials),
        path=soup.path,
    )


def similarity(soup: Soup, kind: str, amount: float = 1.0, seed: int = 0) -> Soup:
    """The soup under a similarity transform.

    Parameters
    ----------
    kind : "scale" (uniform, about the origin, factor ``amount``), "translate" (by
        ``amount`` × diagonal along (1, 2, 3)/|(1, 2, 3)|) or "rotate" (a random rotation
        drawn from ``seed``)
    """
    m = np.eye(4)
    if kind == "scale":
        m[:3, :3] *= amount
    elif kind == "translate":
        d = np.array([1.0, 2.0, 3.0])
        m[:3, 3] = amount * soup.diagonal * d / np.linalg.norm(d)
    elif kind == "rotate":
        q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
        q = q * np.sign(np.diag(r))
        if np.linalg.det(q) < 0:
            q[:, 0] = -q[:, 0]
        m[:3, :3] = q
    else:
        raise ValueError(f"unknown similarity {kind!r}")
    return soup.transformed(m)


def split_into_slivers(
    soup: Soup, fraction: float = 0.25, t_min: float = 1e-6, t_max: float = 1e-2, seed: int = 0
) -> tuple[Soup, np.ndarray]:
    """Split a ``fraction`` of the faces in two at a point very close to a corner.

    Face (a, b, c) becomes (a, p, c) and (p, b, c) with ``p = a + t (b − a)``, ``t``
    log-uniform in ``[t_min, t_max]`` (the first split uses ``t_min`` exactly): the first
    piece is a sliver of aspect ratio about ``1/t``.  Both pieces keep the winding.  The
    split point also leaves a T-junction on the neighbour across edge ab.

    Returns
    -------
    soup, parent : the new soup and, per new face, the index of the face it came from
    """
    rng = np.random.default_rng(seed)
    m = soup.n_faces
    idx = np.flatnonzero(rng.random(m) < fraction)
    if len(idx) == 0:
        idx = np.array([0])
    t = 10.0 ** rng.uniform(np.log10(t_min), np.log10(t_max), len(idx))
    t[0] = t_min
    a, b = soup.triangles[idx, 0], soup.triangles[idx, 1]
    fa, fb, fc = soup.faces[idx].T
    fp = soup.n_vertices + np.arange(len(idx))
    keep = np.setdiff1d(np.arange(m), idx)
    faces = np.concatenate([soup.faces[keep], np.stack([fa, fp, fc], 1), np.stack([fp, fb, fc], 1)])
    parent = np.concatenate([keep, idx, idx])
    vertices = np.concatenate([soup.vertices, a + t[:, None] * (b - a)])
    return _with(soup, vertices, faces, parent), parent


def add_zero_area(soup: Soup, fraction: float = 0.1, seed: int = 0) -> Soup:
    """Append zero-area faces: half collapsed to a corner (a, a, a), half collinear (a, mid(ab), b).

    The original faces keep their indices ``0 .. m-1``.
    """
    rng = np.random.default_rng(seed)
    k = max(2, int(fraction * soup.n_faces))
    src = rng.choice(soup.n_faces, k, replace=False)
    f = soup.faces[src]
    half = k // 2
    point = np.repeat(f[:half, :1], 3, axis=1)
    mid = soup.n_vertices + np.arange(k - half)
    line = np.stack([f[half:, 0], mid, f[half:, 1]], 1)
    mids = 0.5 * (soup.vertices[f[half:, 0]] + soup.vertices[f[half:, 1]])
    parent = np.concatenate([np.arange(soup.n_faces), src])
    return _with(
        soup, np.concatenate([soup.vertices, mids]), np.concatenate([soup.faces, point, line]), parent
    )


def add_duplicates(soup: Soup, fraction: float = 0.1, seed: int = 0) -> Soup:
    """Append exact duplicates of a ``fraction`` of the faces, and reversed duplicates of as many others."""
    rng = np.random.default_rng(seed)
    k = max(1, int(fraction * soup.n_faces))
    src = rng.permutation(soup.n_faces)[: 2 * k]
    same, rev = src[:k], src[k:]
    faces = np.concatenate([soup.faces, soup.faces[same], soup.faces[rev][:, ::-1]])
    return _with(soup, soup.vertices, faces, np.concatenate([np.arange(soup.n_faces), same, rev]))


def add_near_coplanar(soup: Soup, offset: float = 1e-7, fraction: float = 0.1, seed: int = 0) -> Soup:
    """Append copies of a ``fraction`` of the faces moved ``offset`` × diagonal along their normal."""
    rng = np.random.default_rng(seed)
    k = max(1, int(fraction * soup.n_faces))
    src = rng.choice(soup.n_faces, k, replace=False)
    moved = soup.triangles[src] + (offset * soup.diagonal) * soup.normals[src][:, None, :]
    faces = np.concatenate([soup.faces, soup.n_vertices + np.arange(3 * k).reshape(k, 3)])
    return _with(
        soup,
        np.concatenate([soup.vertices, moved.reshape(-1, 3)]),
        faces,
        np.concatenate([np.arange(soup.n_faces), src]),
    )


def perturb_corners(soup: Soup, amount: float = 1e-9, seed: int = 0) -> Soup:
    """Unweld every corner and move it by a uniform random vector of at most ``amount`` × diagonal per axis.

    Neighbouring faces then no longer share corners exactly: hairline cracks and overlaps
    of about ``amount`` appear along every edge (the faces keep their order).
    """
    rng = np.random.default_rng(seed)
    v = soup.triangles.reshape(-1, 3)
    v = v + rng.uniform(-1.0, 1.0, v.shape) * amount * soup.diagonal
    return _with(soup, v, np.arange(3 * soup.n_faces).reshape(-1, 3), np.arange(soup.n_faces))


def _cube(center: np.ndarray, size: float) -> tuple[np.ndarray, np.ndarray]:
    """A closed axis-aligned cube of edge ``size`` (12 outward triangles)."""
    import trimesh

    b = trimesh.creation.box(extents=(size, size, size))
    return np.asarray(b.vertices) + center, np.asarray(b.faces)


def _triangle(center: np.ndarray, size: float, normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One equilateral triangle of edge ``size`` centred at ``center``, facing ``normal``."""
    n = normal / np.linalg.norm(normal)
    u = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    ang = 2 * np.pi * np.arange(3) / 3
    r = size / np.sqrt(3.0)
    return center + r * (np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * v), np.array([[0, 1, 2]])


def tiny_beside_huge(sizes: Iterable[float] = TINY_SIZES, subdivisions: int = 2, hole: bool = True) -> Soup:
    """Large nested spheres with tiny lone triangles and tiny closed cubes beside them.

    The outer sphere (radius 1, one face removed when ``hole``: a small crack, so that the
    min cut is not trivially zero) encloses a sphere of radius 0.5.  For every ``size`` (a
    fraction of ``D`` = 2√3, about the diagonal) a lone triangle and a closed cube of edge
    ``size × D`` float outside the outer sphere (radius 1.15) and between the spheres
    (radius 0.75).  Node areas then range from about 12 (the outer sphere) down to
    ``(√3/4)(1e-6 D)²`` ≈ 5e-12, and the edge weights (Eq. 5) over 12 orders of magnitude.

    Returns
    -------
    Soup with one part per piece: ``outer``, ``inner``, ``{out,in}_{tri,cube}_<size>``
    """
    import trimesh

    sizes = list(sizes)
    outer = trimesh.creation.icosphere(subdivisions, radius=1.0)
    of = np.asarray(outer.faces)[1:] if hole else np.asarray(outer.faces)
    inner = trimesh.creation.icosphere(subdivisions, radius=0.5)
    pieces: list[tuple[np.ndarray, np.ndarray, str]] = [
        (np.asarray(outer.vertices), of, "outer"),
        (np.asarray(inner.vertices), np.asarray(inner.faces), "inner"),
    ]
    D = 2.0 * np.sqrt(3.0)
    for k, s in enumerate(sizes):
        ang = 2 * np.pi * k / len(sizes)
        d = np.array([np.cos(ang), np.sin(ang), 0.3])
        d /= np.linalg.norm(d)
        e = np.array([-d[1], d[0], 0.0]) * 0.08  # cube and triangle side by side
        for where, radius in (("out", 1.15), ("in", 0.75)):
            pieces.append((*_triangle(radius * d - e, s * D, d), f"{where}_tri_{s:g}"))
            pieces.append((*_cube(radius * d + e, s * D), f"{where}_cube_{s:g}"))
    v, f, pid, off = [], [], [], 0
    for i, (pv, pf, _) in enumerate(pieces):
        v.append(pv)
        f.append(pf + off)
        pid.append(np.full(len(pf), i))
        off += len(pv)
    return Soup(
        np.concatenate(v), np.concatenate(f), part_id=np.concatenate(pid), part_names=[p[2] for p in pieces]
    )


# ============================================================================ cases
def _timed(fn: Callable[[], CaseResult]) -> CaseResult:
    t = time.perf_counter()
    r = fn()
    r.seconds = time.perf_counter() - t
    return r


def _finite_note(bad: list[str]) -> str:
    return "" if not bad else f"; NON-FINITE: {', '.join(bad[:3])}" + (" …" if len(bad) > 3 else "")


def similarity_cases(
    models: dict[str, Soup], scales: Iterable[float], rays_per_node: int, seed: int
) -> list[CaseResult]:
    """Group 1: classification under uniform scale, far translation, rotation, and a rerun."""
    out = []
    for name, soup in models.items():
        ref = classify(soup, rays_per_node=rays_per_node, seed=seed)
        variants: list[tuple[str, Callable[[], Soup], float]] = [
            ("rerun (same input, same seed)", lambda: soup, 1.0)
        ]
        variants += [(f"scale {s:g}", lambda s=s: similarity(soup, "scale", s), AGREEMENT) for s in scales]
        variants += [
            (
                f"translate {TRANSLATION:g} x size",
                lambda: similarity(soup, "translate", TRANSLATION),
                AGREEMENT,
            ),
            ("rotate (random)", lambda: similarity(soup, "rotate", seed=seed), AGREEMENT),
        ]
        for label, make, need in variants:

            def case(label=label, make=make, need=need) -> CaseResult:
                c = classify(make(), rays_per_node=rays_per_node, seed=seed)
                agree = area_agreement(ref.side_outside, c.side_outside, soup.areas)
                bad = nonfinite(c) + nonfinite(ref)
                ok = agree >= need and not bad
                return CaseResult(
                    "similarity",
                    f"{name}: {label}",
                    ok,
                    f"agreement {100 * agree:.4f}% of area (need >= {100 * need:g}%)" + _finite_note(bad),
                    {"agreement": agree, "required": need, "nonfinite": bad, "faces": soup.n_faces},
                )

            out.append(_timed(case))
    return out


def degenerate_cases(models: dict[str, Soup], rays_per_node: int, seed: int) -> list[CaseResult]:
    """Group 2: slivers, zero-area faces, duplicates, near-coplanar copies, perturbed corners."""
    out = []
    for name, soup in models.items():
        ref = classify(soup, rays_per_node=rays_per_node, seed=seed)
        m = soup.n_faces

        def sliver_case() -> CaseResult:
            s, parent = split_into_slivers(soup, seed=seed)
            c = classify(s, rays_per_node=rays_per_node, seed=seed)
            # every piece is compared with the face it was cut from, weighted by its own area
            agree = area_agreement(ref.side_outside[parent], c.side_outside, s.areas)
            k = s.n_faces - m  # faces were split: [untouched, slivers (k), remainders (k)]
            pos = np.arange(s.n_faces)
            sliver = (pos >= m - k) & (pos < m)
            n_flip = int(np.sum(np.any(ref.side_outside[parent] != c.side_outside, axis=1) & sliver))
            ar = float(aspect_ratios(s).max())
            bad = nonfinite(c)
            return CaseResult(
                "degenerate",
                f"{name}: slivers (aspect ratio up to {ar:.1e})",
                agree >= AGREEMENT and not bad,
                f"agreement {100 * agree:.4f}% of area; {n_flip} of {int(sliver.sum())} slivers "
                f"differ from their face" + _finite_note(bad),
                {
                    "agreement": agree,
                    "max_aspect_ratio": ar,
                    "slivers": int(sliver.sum()),
                    "slivers_differing": n_flip,
                    "nonfinite": bad,
                },
            )

        def appended_case(
            label: str, make: Callable[[], Soup], extra: Callable[[Classification], dict]
        ) -> CaseResult:
            s = make()
            c = classify(s, rays_per_node=rays_per_node, seed=seed)
            agree = area_agreement(ref.side_outside, c.side_outside[:m], soup.areas)
            bad = nonfinite(c)
            info = extra(c)
            tail = "; ".join(f"{k.replace('_', ' ')} {v}" for k, v in info.items())
            return CaseResult(
                "degenerate",
                f"{name}: {label}",
                agree >= AGREEMENT and not bad,
                f"original faces agree on {100 * agree:.4f}% of area; {tail}" + _finite_note(bad),
                {"agreement": agree, "added_faces": s.n_faces - m, **info, "nonfinite": bad},
            )

        out.append(_timed(sliver_case))
        out.append(
            _timed(
                lambda: appended_case(
                    "zero-area faces (+10%)",
                    lambda: add_zero_area(soup, seed=seed),
                    lambda c: {
                        "degenerate_faces": int(c.degenerate.sum()),
                        "added_classified_outside": int(c.side_outside[m:].any(axis=1).sum()),
                    },
                )
            )
        )
        out.append(
            _timed(
                lambda: appended_case(
                    "duplicate faces (+10% same, +10% reversed)",
                    lambda: add_duplicates(soup, seed=seed),
                    lambda c: {"flagged_faces": int(c.flagged.sum())},
                )
            )
        )
        out.append(
            _timed(
                lambda: appended_case(
                    "near-coplanar copies 1e-7 x size away (+10%)",
                    lambda: add_near_coplanar(soup, 1e-7, seed=seed),
                    lambda c: {"flagged_faces": int(c.flagged.sum())},
                )
            )
        )

        def perturbed_case() -> CaseResult:
            s = perturb_corners(soup, 1e-9, seed=seed)
            c = classify(s, rays_per_node=rays_per_node, seed=seed)
            agree = area_agreement(ref.side_outside, c.side_outside, soup.areas)
            bad = nonfinite(c)
            return CaseResult(
                "degenerate",
                f"{name}: corners unwelded and moved by 1e-9 x size",
                agree >= AGREEMENT and not bad,
                f"agreement {100 * agree:.4f}% of area; {int(c.flagged.sum())} faces flagged"
                + _finite_note(bad),
                {"agreement": agree, "nonfinite": bad},
            )

        out.append(_timed(perturbed_case))
    return out


def _side_nodes(c: Classification, faces: np.ndarray, side: int) -> np.ndarray:
    """All nodes (cluster and sample-point nodes) of the given side of ``faces``."""
    nodes = c.nodes
    cl = nodes.side_node[faces, side]
    cl = cl[cl >= 0]
    q = nodes.flagged_index[faces]
    q = q[q >= 0]
    pts = (q[:, None] * nodes.samples + np.arange(nodes.samples)).ravel()
    return np.unique(np.concatenate([cl, nodes.point_node(pts, np.full(len(pts), side))]))


def escape_share(
    c: Classification, faces: np.ndarray, side: int, n_rays: int, seed: int = 0, per_node: bool = False
) -> float | tuple[float, np.ndarray, np.ndarray]:
    """Measured share of the cosine rays from one side of ``faces`` that escape the model.

    Casts about ``n_rays`` rays with the classifier's own sampling
    (:func:`meshvis.graphcut.sampling.sample_round`: area-uniform origins pushed off by the ray
    offset, cosine directions), spread over the nodes of that side in proportion to their
    area.  The result is the area-weighted escape share ``Σ escaped / Σ counted``: what
    the ``opening`` threshold of :func:`meshvis.graphcut.weights.inside_prior` is compared with,
    node by node.

    Returns
    -------
    share, or ``(share, nodes, node_shares)`` when ``per_node``
    """
    from meshvis.graphcut.sampling import VisibilityCounts, sample_round

    nodes = _side_nodes(c, faces, side)
    area = c.nodes.area[nodes]
    give = np.zeros(c.nodes.n, np.int64)
    give[nodes] = np.maximum(1, np.rint(n_rays * area / max(area.sum(), 1e-300))).astype(np.int64)
    give[c.nodes.area <= 0] = 0
    counts = VisibilityCounts(c.nodes.n)
    sample_round(c.caster, c.nodes, give, np.random.default_rng(seed), counts)
    counted = (counts.cast - counts.discarded)[nodes]
    share = float(counts.escaped[nodes].sum() / counted.sum()) if counted.sum() else 0.0
    if not per_node:
        return share
    return share, nodes, counts.escaped[nodes] / np.maximum(counted, 1)


def crack_sweep(
    widths: Iterable[float],
    cell: float,
    rays_per_node: int,
    seed: int,
    share_rays: int,
    opening: float = DEFAULT_OPENING,
) -> list[dict]:
    """Classify :func:`meshvis.eval.generators.cracked_box` for every crack width.

    Returns
    -------
    list of dict, one per width, with: ``width``; ``inner_outside`` (share of the inner
    box's area with an outside side: the leak); ``box_inner_side_outside`` (share of the
    box sheet whose inner side is outside); ``share_classifier`` (area-weighted escape
    share of the box's inner sides as the classifier saw it) and ``share_measured``
    (from ``share_rays`` extra rays), with its smallest and largest value over the walls
    (``share_measured_min``/``_max``, nodes of at least 1 % of the area); the inner sides' total outside link ``w_out``,
    inside prior ``w_in`` and both after the cosine filter; ``paper_inner_outside``
    (the leak with ``opening=None``, the paper's unfaded prior); ``flagged`` faces and
    ``nonfinite`` names.
    """
    rows = []
    for w in widths:
        truth = generators.cracked_box(cell=cell, crack_width=w, seed=seed)
        s = truth.soup
        inner = s.part_id == s.part_names.index("inner_box")
        box = np.flatnonzero(~inner)
        c = classify(s, rays_per_node=rays_per_node, seed=seed, opening=opening)
        A = s.areas
        nodes = _side_nodes(c, box, 1)
        counted = (c.counts.cast - c.counts.discarded)[nodes]
        wt = c.graph.weights
        paper = classify(s, rays_per_node=rays_per_node, seed=seed, opening=None)
        measured, measured_nodes, node_share = escape_share(c, box, 1, share_rays, seed, per_node=True)
        big = c.nodes.area[measured_nodes] >= 0.01 * c.nodes.area[measured_nodes].sum()
        rows.append(
            {
                "width": w,
                "inner_outside": float((c.side_outside[inner].any(axis=1) * A[inner]).sum() / A[inner].sum()),
                "box_inner_side_outside": float((c.side_outside[box, 1] * A[box]).sum() / A[box].sum()),
                "share_classifier": float(c.counts.escaped[nodes].sum() / max(counted.sum(), 1)),
                "share_measured": measured,
                # spread over the walls (nodes of at least 1 % of the inner-side area)
                "share_measured_min": float(node_share[big].min()),
                "share_measured_max": float(node_share[big].max()),
                "w_out": float(wt.w_out[nodes].sum()),
                "w_in": float(wt.w_in[nodes].sum()),
                "cap_out": float(wt.cap_out[nodes].sum()),
                "cap_in": float(wt.cap_in[nodes].sum()),
                "paper_inner_outside": float(
                    (paper.side_outside[inner].any(axis=1) * A[inner]).sum() / A[inner].sum()
                ),
                "flagged": int(c.flagged.sum()),
                "rays": c.n_rays,
                "nonfinite": nonfinite(c) + nonfinite(paper),
            }
        )
    return rows


def slit_transmission(
    widths: Iterable[float], positions: Iterable[float] = (0.9, 0.3), n_rays: int = 20_000, seed: int = 0
) -> list[dict]:
    """Share of straight rays that pass through a slit of width ``w`` × diagonal, as Embree sees it.

    The model: two coplanar rectangles in z = 0 spanning x ∈ [−1, 1], y ∈ [−0.2, 0.2]
    (diagonal D ≈ 2.04), cut by a slit of width ``w D`` centred at ``x = position``.  Rays
    start above the plane at points uniform over the slit's width and go straight down.
    The share that misses both rectangles is the slit's transmission: 1 for a wide slit,
    0 for a slit the float32 scene has closed.  Two positions are tried because the
    float32 spacing of the normalised coordinate differs between them (``spacing``).

    Returns
    -------
    list of dict: ``width``, ``position``, ``spacing`` (float32 spacing at the slit, in
    units of D), ``transmitted``
    """
    from meshvis.rays.caster import RayCaster

    rows = []
    D = float(np.hypot(2.0, 0.4))
    for x0 in positions:
        for w in widths:
            h = 0.5 * w * D
            V = np.array(
                [
                    [-1, -0.2, 0],
                    [x0 - h, -0.2, 0],
                    [x0 - h, 0.2, 0],
                    [-1, 0.2, 0],
                    [x0 + h, -0.2, 0],
                    [1, -0.2, 0],
                    [1, 0.2, 0],
                    [x0 + h, 0.2, 0],
                ],
                float,
            )
            rc = RayCaster((V, np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])))
            rng = np.random.default_rng(seed)
            o = np.stack(
                [
                    x0 + rng.uniform(-0.5, 0.5, n_rays) * w * D,
                    rng.uniform(-0.15, 0.15, n_rays),
                    np.full(n_rays, 0.1),
                ],
                axis=1,
            )
            hit = rc.intersect(o, np.broadcast_to([0.0, 0.0, -1.0], o.shape)).face >= 0
            u = np.float32((x0 - rc.center[0]) * rc.scale)
            rows.append(
                {
                    "width": w,
                    "position": x0,
                    "spacing": float(np.spacing(u)),
                    "transmitted": float(1.0 - hit.mean()),
                }
            )
    return rows


def offset_probe(
    widths: Iterable[float], offsets: Iterable[float], n_rays: int, cell: float = 0.1, seed: int = 0
) -> list[dict]:
    """Escape share of the cracked box's inner sides for narrow cracks, with two ray offsets.

    For every ray ``offset`` (fraction of the diagonal) and crack ``width``, the share is
    measured with :func:`escape_share` from about ``n_rays`` rays.  ``share / width`` is
    constant while the crack is much wider than the offset; it drops once the crack is
    narrower, because rays from the two walls that form a slit start further inside than
    the slit is wide and can no longer leave through it.

    Returns
    -------
    list of dict: ``width``, ``offset``, ``share``, ``share_per_width``, ``escaped`` (rays)
    """
    rows = []
    for off in offsets:
        for w in widths:
            s = generators.cracked_box(cell=cell, crack_width=w, seed=seed).soup
            box = np.flatnonzero(s.part_id == s.part_names.index("box"))
            c = classify(s, rays_per_node=4, seed=seed, offset=off, progressive=False)
            e = escape_share(c, box, 1, n_rays, seed + 1)
            rows.append(
                {
                    "width": w,
                    "offset": off,
                    "share": e,
                    "share_per_width": e / w,
                    "escaped": int(round(e * n_rays)),
                }
            )
    return rows


def crack_case(
    widths: Iterable[float],
    cell: float,
    rays_per_node: int,
    seed: int,
    share_rays: int,
    slit_widths: Iterable[float] = (),
    offset_widths: Iterable[float] = (),
    offset_rays: int = 0,
) -> CaseResult:
    """Group 3: from which crack width the interior leaks; passes when leaking is monotone in the width.

    The figures behind the explanation come with it: the escape shares, the terminal
    weights of the box's inner sides before and after the cosine filter, the leak under
    the paper's unfaded prior, the float32 slit probe (:func:`slit_transmission`) and the
    ray-offset probe (:func:`offset_probe`, default offset and ten times smaller).
    """
    widths = sorted(widths, reverse=True)
    rows = crack_sweep(widths, cell, rays_per_node, seed, share_rays)
    slits = slit_transmission(sorted(slit_widths, reverse=True), seed=seed) if slit_widths else []
    offsets = (
        offset_probe(
            sorted(offset_widths, reverse=True), (DEFAULT_OFFSET, DEFAULT_OFFSET / 10), offset_rays, seed=seed
        )
        if offset_widths and offset_rays
        else []
    )
    leak = np.array([r["inner_outside"] for r in rows])
    # narrower cracks may not leak more than wider ones (1e-3 of the area for rounding)
    monotone = bool(np.all(np.diff(leak) <= 1e-3))
    bad = [n for r in rows for n in r["nonfinite"]]
    leaking = [r["width"] for r in rows if r["inner_outside"] > 0.5]
    holding = [r["width"] for r in rows if r["inner_outside"] <= 0.5]
    if leaking and holding:
        fig = f"interior leaks from width {min(leaking):g} x size up; holds at {max(holding):g} and below"
    elif leaking:
        fig = f"interior leaks at every width tried (down to {min(leaking):g})"
    else:
        fig = f"interior holds at every width tried (up to {max(holding):g})"
    fig += "; monotone" if monotone else "; NOT MONOTONE"
    return CaseResult(
        "cracks",
        "cracked box with an inner box, crack width sweep",
        monotone and not bad,
        fig + _finite_note(bad),
        {
            "leak_from": min(leaking) if leaking else None,
            "holds_to": max(holding) if holding else None,
            "monotone": monotone,
            "nonfinite": bad,
            "cell": cell,
            "share_rays": share_rays,
            "slit_transmission": slits,
            "offset_probe": offsets,
        },
        table=rows,
    )


def _cut_edges(outside: np.ndarray, w) -> int:
    """Directed capacities (edges and terminal links, zero or not) that cross the cut ``outside``."""
    o = np.asarray(outside, bool)
    return int(np.sum(o[w.edges_i] & ~o[w.edges_j]) + np.sum(o[w.edges_j] & ~o[w.edges_i]) + len(o))


def compare_solvers(c: Classification) -> dict:
    """Cut the final graph of ``c`` with both solvers and compare.

    The scipy solver cuts integer capacities ``rint(cap × scale)``.  Each rounded capacity
    is off by at most ``0.5 / scale``; comparing each solver's cut under both capacity
    sets gives ``|value_scipy − value_pymaxflow| ≤ 0.5 k / scale`` with *k* the larger
    number of directed capacities crossing either cut (every node crosses with exactly
    one terminal link): :func:`meshvis.graphcut.mincut.rounding_bound` with that *k*.

    Returns
    -------
    dict with both values, their difference, the bound, the weight span (orders of
    magnitude of the positive edge weights and of all positive capacities), the
    capacities rounded to zero (count, share of their sum in the exact cut value), the
    nodes and faces labelled differently and the area agreement.
    """
    w = c.graph.weights
    pm: Cut = c.graph.cut("pymaxflow")
    sc: Cut = c.graph.cut("scipy")
    k = max(_cut_edges(pm.outside, w), _cut_edges(sc.outside, w))
    bound = rounding_bound(k, sc.scale)
    caps = np.concatenate([w.cap_ij, w.cap_ji, w.cap_out, w.cap_in])
    pos = caps[caps > 0]
    lost = pos[np.rint(pos * sc.scale) == 0]
    ew = w.w[w.w > 0]
    fp, fs = c.face_labels_from(pm.outside) > 0.5, c.face_labels_from(sc.outside) > 0.5
    differ = np.any(fp != fs, axis=1)
    A = c.soup.areas
    return {
        "value_pymaxflow": pm.value,
        "value_scipy": sc.value,
        "difference": abs(sc.value - pm.value),
        "bound": bound,
        "cut_edges": k,
        "scale": sc.scale,
        "edge_weight_orders": float(np.log10(ew.max() / ew.min())) if len(ew) else 0.0,
        "capacity_orders": float(np.log10(pos.max() / pos.min())) if len(pos) else 0.0,
        "capacities_rounded_to_zero": int(len(lost)),
        "capacities": int(len(pos)),
        "lost_share_of_cut": float(lost.sum() / pm.value) if pm.value > 0 else 0.0,
        "nodes_differing": int(np.sum(pm.outside != sc.outside)),
        "faces_differing": int(differ.sum()),
        "area_differing": float(A[differ].sum() / A.sum()),
        "agreement": area_agreement(fp, fs, A),
    }


def weight_cases(
    models: dict[str, Soup], rays_per_node: int, seed: int, require_span: set[str]
) -> list[CaseResult]:
    """Group 4: both max-flow solvers on the same graph (weights spanning 12+ orders for the tiny-cube model)."""
    out = []
    for name, soup in models.items():

        def case(name=name, soup=soup) -> CaseResult:
            c = classify(soup, rays_per_node=rays_per_node, seed=seed)
            r = compare_solvers(c)
            bad = nonfinite(c)
            slack = 1e-9 * max(r["value_pymaxflow"], 1e-300)  # float summation order
            ok_value = r["difference"] <= r["bound"] + slack
            ok_span = name not in require_span or r["edge_weight_orders"] >= WEIGHT_ORDERS
            ok = ok_value and ok_span and r["agreement"] >= AGREEMENT and not bad
            fig = (
                f"edge weights span {r['edge_weight_orders']:.1f} orders; cut {r['value_pymaxflow']:.6g} vs "
                f"{r['value_scipy']:.6g}, |diff| {r['difference']:.2e} <= bound {r['bound']:.2e}: "
                f"{'yes' if ok_value else 'NO'}; labels agree on {100 * r['agreement']:.4f}% of area; "
                f"rounding lost {r['capacities_rounded_to_zero']} of {r['capacities']} capacities "
                f"({r['lost_share_of_cut']:.1e} of the cut), {r['faces_differing']} faces "
                f"({r['area_differing']:.1e} of area) labelled differently"
            )
            if not ok_span:
                fig += f"; SPAN BELOW {WEIGHT_ORDERS} ORDERS"
            table = []
            if name in require_span:
                # how each tiny cube came out (pymaxflow): its outer and inner sides
                for p, pname in enumerate(soup.part_names):
                    sel = soup.part_id == p
                    table.append(
                        {
                            "part": pname,
                            "faces": int(sel.sum()),
                            "front_outside": float(c.side_outside[sel, 0].mean()),
                            "back_outside": float(c.side_outside[sel, 1].mean()),
                        }
                    )
            return CaseResult(
                "weights",
                f"{name}: pymaxflow vs scipy (integer) on one graph",
                ok,
                fig + _finite_note(bad),
                {**r, "nonfinite": bad},
                table=table,
            )

        out.append(_timed(case))
    return out


_OBJ = {
    "one triangle": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "two triangles (folded at 90 degrees)": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\n",
    "one quad": "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
}
#: inputs that must fail with a clean ModelError naming the file
_BAD_OBJ = {
    "empty file": "",
    "file with vertices but no faces": "v 0 0 0\nv 1 0 0\nv 0 1 0\n",
    "one zero-area triangle": "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
}


def tiny_cases(rays_per_node: int, seed: int, folder: str | None = None) -> list[CaseResult]:
    """Group 5: one triangle, two triangles, one quad; empty file, no faces, one zero-area triangle.

    The models are written as OBJ files and read back through :func:`meshvis.classify`'s
    path argument, so reading is part of the test.
    """
    out = []
    with tempfile.TemporaryDirectory(dir=folder) as tmp:
        for label, text in _OBJ.items():

            def case(label=label, text=text) -> CaseResult:
                path = os.path.join(tmp, label.split(" (")[0].replace(" ", "_") + ".obj")
                with open(path, "w") as fh:
                    fh.write(text)
                c = classify(path, rays_per_node=rays_per_node, seed=seed)
                bad = nonfinite(c)
                ok = bool(c.side_outside.all())
                fig = (
                    f"{c.soup.n_faces} face(s), {int(c.side_outside.sum())} of {2 * c.soup.n_faces} sides "
                    f"outside (expected all: a lone sheet is seen from both sides)"
                )
                return CaseResult(
                    "tiny",
                    label,
                    ok and not bad,
                    fig + _finite_note(bad),
                    {"faces": c.soup.n_faces, "sides_outside": int(c.side_outside.sum()), "nonfinite": bad},
                )

            out.append(_timed(case))

        for label, text in _BAD_OBJ.items():

            def error_case(label=label, text=text) -> CaseResult:
                path = os.path.join(tmp, label.replace(" ", "_") + ".obj")
                with open(path, "w") as fh:
                    fh.write(text)
                try:
                    classify(path, rays_per_node=rays_per_node, seed=seed)
                except ModelError as exc:
                    msg = str(exc)
                    ok = path in msg and "\n" not in msg
                    return CaseResult(
                        "tiny",
                        label,
                        ok,
                        f"ModelError: {msg.replace(tmp, '<tmp>')}",
                        {"error": type(exc).__name__, "names_file": path in msg},
                    )
                except Exception as exc:  # anything else is a bug
                    return CaseResult(
                        "tiny",
                        label,
                        False,
                        f"{type(exc).__name__} instead of ModelError: {exc}",
                        {"error": type(exc).__name__},
                    )
                return CaseResult("tiny", label, False, "no error raised", {"error": None})

            out.append(_timed(error_case))
    return out


# ============================================================================ the run
def run(
    quick: bool = False,
    seed: int = 0,
    rays_per_node: int = 32,
    progress: Callable[[CaseResult], None] | None = None,
) -> dict:
    """Run every stability case.

    Parameters
    ----------
    quick : fewer scales and crack widths, smaller models, fewer measuring rays
    seed : seed of every classification (stressed and untouched models use the same)
    rays_per_node : ray budget of every classification
    progress : called with each :class:`CaseResult` as soon as it is known

    Returns
    -------
    dict with ``cases`` (list of :class:`CaseResult` as dicts), ``passed``, ``failed``,
    ``quick``, ``seed``, ``rays_per_node``, ``seconds``, ``machine``.
    """
    t0 = time.perf_counter()
    results: list[CaseResult] = []

    def emit(rs: list[CaseResult]) -> None:
        for r in rs:
            results.append(r)
            if progress is not None:
                progress(r)

    shells = generators.nested_shells(2, "sphere", subdivisions=3, seed=seed).soup
    cracked = generators.cracked_box(cell=0.1 if quick else 0.05, crack_width=1e-3, seed=seed).soup
    base = {"nested spheres": shells, "cracked box": cracked}
    if not quick:
        base["house"] = generators.house(seed=seed).soup
    emit(similarity_cases(base, SCALES_QUICK if quick else SCALES_FULL, rays_per_node, seed))
    emit(
        degenerate_cases(
            {"nested spheres": shells} if quick else {"nested spheres": shells, "house": base["house"]},
            rays_per_node,
            seed,
        )
    )
    emit(
        [
            _timed(
                lambda: crack_case(
                    CRACK_WIDTHS_QUICK if quick else CRACK_WIDTHS_FULL,
                    0.1 if quick else 0.05,
                    rays_per_node,
                    seed,
                    SHARE_RAYS_QUICK if quick else SHARE_RAYS_FULL,
                    SLIT_WIDTHS_QUICK if quick else SLIT_WIDTHS_FULL,
                    () if quick else OFFSET_WIDTHS,
                    OFFSET_RAYS,
                )
            )
        ]
    )
    wmodels = {TINY_NAME: tiny_beside_huge(), "cracked box": cracked}
    if not quick:
        wmodels["house"] = base["house"]
    emit(weight_cases(wmodels, rays_per_node, seed, require_span={TINY_NAME}))
    emit(tiny_cases(rays_per_node, seed))
    import platform

    cases = [asdict(r) for r in results]
    return {
        "quick": quick,
        "seed": seed,
        "rays_per_node": rays_per_node,
        "passed": sum(r.passed for r in results),
        "failed": sum(not r.passed for r in results),
        "seconds": time.perf_counter() - t0,
        "machine": {
            "python": platform.python_version(),
            "platform": platform.platform(),
            "processor": platform.processor() or platform.machine(),
            "cpus": os.cpu_count(),
        },
        "cases": cases,
    }


def format_case(r: CaseResult | dict) -> str:
    """One line (plus a table for the crack sweep and the tiny-cube parts) for a case."""
    d = asdict(r) if isinstance(r, CaseResult) else r
    line = f"{'PASS' if d['passed'] else 'FAIL'}  [{d['group']}] {d['name']}: {d['figure']}  ({d['seconds']:.2f} s)"
    rows = d.get("table") or []
    if rows and "width" in rows[0]:
        line += (
            "\n      width     inner box out  inner sides out  escape share: classifier  measured (walls min..max)"
            "  w_out -> filtered   w_in -> filtered   paper prior: inner out  flagged"
        )
        for t in rows:
            line += (
                f"\n      {t['width']:<9.2g} {100 * t['inner_outside']:>11.1f}%  {100 * t['box_inner_side_outside']:>14.1f}%"
                f"  {t['share_classifier']:>18.5f}  {t['share_measured']:.2e} ({t['share_measured_min']:.2e}"
                f"..{t['share_measured_max']:.2e})"
                f"  {t['w_out']:8.3g} -> {t['cap_out']:<8.3g} {t['w_in']:8.3g} -> {t['cap_in']:<8.3g}"
                f" {100 * t['paper_inner_outside']:>18.1f}%  {t['flagged']:>7d}"
            )
        slits = d.get("values", {}).get("slit_transmission") or []
        if slits:
            line += (
                "\n      float32 probe: straight rays across a slit, share transmitted (slit at two places)"
            )
            for x0 in sorted({t["position"] for t in slits}, reverse=True):
                sel = [t for t in slits if t["position"] == x0]
                line += f"\n      float32 spacing {sel[0]['spacing']:.2e} x D: " + ", ".join(
                    f"{t['width']:g}: {100 * t['transmitted']:.0f}%" for t in sel
                )
        probe = d.get("values", {}).get("offset_probe") or []
        if probe:
            line += "\n      ray-offset probe: escape share / width of the inner sides (escaped rays)"
            for off in sorted({t["offset"] for t in probe}, reverse=True):
                sel = [t for t in probe if t["offset"] == off]
                line += f"\n      offset {off:g} x D: " + ", ".join(
                    f"{t['width']:g}: {t['share_per_width']:.2f} ({t['escaped']})" for t in sel
                )
    elif rows and "part" in rows[0]:
        line += "\n      part            faces  front outside  back outside"
        for t in rows:
            line += f"\n      {t['part']:<15} {t['faces']:>5d}  {t['front_outside']:>13.2f}  {t['back_outside']:>12.2f}"
    return line


def format(result: dict) -> str:
    """The printed report: one line per case, then the count."""
    lines = [format_case(c) for c in result["cases"]]
    total = result["passed"] + result["failed"]
    lines.append(
        f"stability{' (quick)' if result['quick'] else ''}: {result['passed']} of {total} cases passed, "
        f"{result['failed']} failed ({result['seconds']:.1f} s)"
    )
    return "\n".join(lines)


# ============================================================================ command line
def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``meshvis bench stability``."""
    parser.add_argument(
        "--quick", action="store_true", help="reduced set (fewer scales and widths, smaller models)"
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of every classification (default 0)")
    parser.add_argument("--rays-per-node", type=int, default=32, help="ray budget per node (default 32)")
    parser.add_argument("--json", metavar="FILE", help="also write every number as JSON")


def main(args: argparse.Namespace) -> int:
    """Run the cases, print one line each as they finish and the count; 1 if any case failed."""
    from meshvis.io.jsonfile import write_json

    result = run(
        quick=bool(getattr(args, "quick", False)),
        seed=int(getattr(args, "seed", 0)),
        rays_per_node=int(getattr(args, "rays_per_node", 32)),
        progress=lambda r: print(format_case(r), flush=True),
    )
    total = result["passed"] + result["failed"]
    print(
        f"stability{' (quick)' if result['quick'] else ''}: {result['passed']} of {total} cases passed, "
        f"{result['failed']} failed ({result['seconds']:.1f} s)"
    )
    if getattr(args, "json", None):
        write_json(args.json, result)
    return 1 if result["failed"] else 0
