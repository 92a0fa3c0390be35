"""The cases of the stability benchmark (:mod:`meshvis.eval.bench.stability`).

Each case classifies a stressed model, compares it with the untouched one and says PASS
or FAIL with its figure.
"""

from __future__ import annotations

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
from meshvis.graphcut.mincut import Cut, cut_value, rounding_bound
from meshvis.graphcut.weights import DEFAULT_OPENING
from meshvis.rays.caster import DEFAULT_OFFSET
from meshvis.soup import Soup

from .stability_models import (
    add_duplicates,
    add_near_coplanar,
    add_zero_area,
    perturb_corners,
    similarity,
    split_into_slivers,
)

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
    """Measure the share of the area whose per-face side labels agree.

    Parameters
    ----------
    reference : (m, 2) bool
        Side-outside labels of the reference (``Classification.side_outside``).
    other : (m, 2) bool
        Side-outside labels to compare.
    areas : (m,) float64
        Face areas (of the reference model).

    Returns
    -------
    float
        In [0, 1]: ``Σ_f A_f [ref_f == other_f] / Σ_f A_f`` where a face agrees when both of
        its sides do; 1.0 for a model of zero area.
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
    """Name the floats of a classification that are NaN or infinite.

    Checked: every float and float array in ``c.report(per_face=True)``, the node areas,
    the per-face outside fractions, every array of the graph weights (Eq. 5–9, before and
    after the cosine filter) and the cut value.

    Parameters
    ----------
    c : Classification
        The classification.

    Returns
    -------
    list of str
        The path of every non-finite value (with the count for arrays); empty when all are
        finite.
    """
    bad: list[str] = []
    _walk_floats(c.report(per_face=True), "report", bad)
    _walk_floats(asdict(c.graph.weights), "weights", bad)
    _walk_floats({"node_area": c.nodes.area, "outside": c.outside, "cut_value": c.cut.value}, "", bad)
    return bad


def aspect_ratios(soup: Soup) -> np.ndarray:
    """Compute every face's longest edge over its smallest altitude, ``L_max² / (2 A)``.

    Parameters
    ----------
    soup : Soup
        The model.

    Returns
    -------
    (m,) float64
        The aspect ratios; inf for zero-area faces.
    """
    t = soup.triangles
    e = np.linalg.norm(t[:, [1, 2, 0]] - t, axis=2)
    lmax = e.max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(soup.areas > 0, lmax**2 / (2 * soup.areas), np.inf)


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
    """Run group 1: classification under uniform scale, far translation, rotation, and a rerun.

    Per model, the rerun must agree exactly with the reference classification and every
    transformed copy on :data:`AGREEMENT` of the area.

    Parameters
    ----------
    models : dict of str to Soup
        The models, by name.
    scales : iterable of float
        The uniform scale factors.
    rays_per_node : int
        Ray budget of every classification.
    seed : int
        Seed of every classification and of the rotation.

    Returns
    -------
    list of CaseResult
        One timed case per model and variant.
    """
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
                    group="similarity",
                    name=f"{name}: {label}",
                    passed=ok,
                    figure=f"agreement {100 * agree:.4f}% of area (need >= {100 * need:g}%)"
                    + _finite_note(bad),
                    values={"agreement": agree, "required": need, "nonfinite": bad, "faces": soup.n_faces},
                )

            out.append(_timed(case))
    return out


def _sliver_case(name: str, soup: Soup, ref: Classification, rays_per_node: int, seed: int) -> CaseResult:
    """Faces split into slivers: every piece must keep the label of the face it was cut from."""
    m = soup.n_faces
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
        group="degenerate",
        name=f"{name}: slivers (aspect ratio up to {ar:.1e})",
        passed=agree >= AGREEMENT and not bad,
        figure=f"agreement {100 * agree:.4f}% of area; {n_flip} of {int(sliver.sum())} slivers "
        f"differ from their face" + _finite_note(bad),
        values={
            "agreement": agree,
            "max_aspect_ratio": ar,
            "slivers": int(sliver.sum()),
            "slivers_differing": n_flip,
            "nonfinite": bad,
        },
    )


def _appended_case(
    name: str,
    soup: Soup,
    ref: Classification,
    label: str,
    make: Callable[[], Soup],
    extra: Callable[[Classification], dict],
    rays_per_node: int,
    seed: int,
) -> CaseResult:
    """Append faces to the model (``make``) and check that the original faces keep their labels.

    ``extra`` adds figures of the classification.
    """
    m = soup.n_faces
    s = make()
    c = classify(s, rays_per_node=rays_per_node, seed=seed)
    agree = area_agreement(ref.side_outside, c.side_outside[:m], soup.areas)
    bad = nonfinite(c)
    info = extra(c)
    tail = "; ".join(f"{k.replace('_', ' ')} {v}" for k, v in info.items())
    return CaseResult(
        group="degenerate",
        name=f"{name}: {label}",
        passed=agree >= AGREEMENT and not bad,
        figure=f"original faces agree on {100 * agree:.4f}% of area; {tail}" + _finite_note(bad),
        values={"agreement": agree, "added_faces": s.n_faces - m, **info, "nonfinite": bad},
    )


def _perturbed_case(name: str, soup: Soup, ref: Classification, rays_per_node: int, seed: int) -> CaseResult:
    """Corners unwelded and moved by 1e-9 x size: the labels must not change."""
    s = perturb_corners(soup, 1e-9, seed=seed)
    c = classify(s, rays_per_node=rays_per_node, seed=seed)
    agree = area_agreement(ref.side_outside, c.side_outside, soup.areas)
    bad = nonfinite(c)
    return CaseResult(
        group="degenerate",
        name=f"{name}: corners unwelded and moved by 1e-9 x size",
        passed=agree >= AGREEMENT and not bad,
        figure=f"agreement {100 * agree:.4f}% of area; {int(c.flagged.sum())} faces flagged"
        + _finite_note(bad),
        values={"agreement": agree, "nonfinite": bad},
    )


def degenerate_cases(models: dict[str, Soup], rays_per_node: int, seed: int) -> list[CaseResult]:
    """Run group 2: slivers, zero-area faces, duplicates, near-coplanar copies, perturbed corners.

    Parameters
    ----------
    models : dict of str to Soup
        The models, by name.
    rays_per_node : int
        Ray budget of every classification.
    seed : int
        Seed of every classification and of the stresses.

    Returns
    -------
    list of CaseResult
        Five timed cases per model.
    """
    out = []
    budget = dict(rays_per_node=rays_per_node, seed=seed)
    for name, soup in models.items():
        ref = classify(soup, rays_per_node=rays_per_node, seed=seed)
        m = soup.n_faces
        appended = [
            (
                "zero-area faces (+10%)",
                lambda soup=soup: add_zero_area(soup, seed=seed),
                lambda c, m=m: {
                    "degenerate_faces": int(c.degenerate.sum()),
                    "added_classified_outside": int(c.side_outside[m:].any(axis=1).sum()),
                },
            ),
            (
                "duplicate faces (+10% same, +10% reversed)",
                lambda soup=soup: add_duplicates(soup, seed=seed),
                lambda c: {"flagged_faces": int(c.flagged.sum())},
            ),
            (
                "near-coplanar copies 1e-7 x size away (+10%)",
                lambda soup=soup: add_near_coplanar(soup, 1e-7, seed=seed),
                lambda c: {"flagged_faces": int(c.flagged.sum())},
            ),
        ]
        out.append(_timed(lambda: _sliver_case(name, soup, ref, **budget)))
        for label, make, extra in appended:
            out.append(_timed(lambda: _appended_case(name, soup, ref, label, make, extra, **budget)))
        out.append(_timed(lambda: _perturbed_case(name, soup, ref, **budget)))
    return out


def _side_nodes(c: Classification, faces: np.ndarray, side: int) -> np.ndarray:
    """All nodes (cluster and sample-point nodes) of the given side of ``faces``."""
    nodes = c.nodes
    cl = nodes.side_node[faces, side]
    cl = cl[cl >= 0]
    q = nodes.flagged_index[faces]
    q = q[q >= 0]
    pts = nodes.points_of(q)
    return np.unique(np.concatenate([cl, nodes.point_node(pts, np.full(len(pts), side))]))


def escape_share(
    c: Classification, faces: np.ndarray, side: int, n_rays: int, seed: int = 0, per_node: bool = False
) -> float | tuple[float, np.ndarray, np.ndarray]:
    """Measure the share of the cosine rays from one side of ``faces`` that escape the model.

    Casts about ``n_rays`` rays with the classifier's own sampling
    (:func:`meshvis.graphcut.sampling.sample_round`: area-uniform origins pushed off by the ray
    offset, cosine directions), spread over the nodes of that side in proportion to their
    area.  The result is the area-weighted escape share ``Σ escaped / Σ counted``: what
    the ``opening`` threshold of :func:`meshvis.graphcut.weights.inside_prior` is compared with,
    node by node.

    Parameters
    ----------
    c : Classification
        The classification whose nodes and ray caster are used.
    faces : (k,) int
        The faces.
    side : {0, 1}
        The side of the faces (0 = front).
    n_rays : int
        About this many rays in all (at least one per node of positive area).
    seed : int
        Seed of the rays.
    per_node : bool
        Also return the share of every node.

    Returns
    -------
    share : float
        The escape share; 0.0 when no ray was counted.
    nodes : (n,) int64
        Only with ``per_node``: the nodes of that side of ``faces``.
    node_shares : (n,) float64
        Only with ``per_node``: the escape share of each of them.
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

    Parameters
    ----------
    widths : iterable of float
        Crack widths, fractions of the box diagonal.
    cell : float
        Triangle size of the box.
    rays_per_node : int
        Ray budget of the classifications.
    seed : int
        Seed of the models, the classifications and the measuring rays.
    share_rays : int
        Extra rays that measure the escape share of the box's inner sides.
    opening : float
        The ``opening`` threshold of the classification.

    Returns
    -------
    list of dict
        One per width, with: ``width``; ``inner_outside`` (share of the inner box's area
        with an outside side: the leak); ``box_inner_side_outside`` (share of the box sheet
        whose inner side is outside); ``share_classifier`` (area-weighted escape share of
        the box's inner sides as the classifier saw it) and ``share_measured`` (from
        ``share_rays`` extra rays), with its smallest and largest value over the walls
        (``share_measured_min``/``_max``, nodes of at least 1 % of the area); the inner
        sides' total outside link ``w_out``, inside prior ``w_in`` and both after the cosine
        filter (``cap_out``, ``cap_in``); ``paper_inner_outside`` (the leak with
        ``opening=None``, the paper's unfaded prior); ``flagged`` faces, ``rays`` and
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
    """Measure the share of straight rays that pass through a slit of width ``w`` × diagonal, as Embree sees it.

    The model: two coplanar rectangles in z = 0 spanning x ∈ [−1, 1], y ∈ [−0.2, 0.2]
    (diagonal D ≈ 2.04), cut by a slit of width ``w D`` centred at ``x = position``.  Rays
    start above the plane at points uniform over the slit's width and go straight down.
    The share that misses both rectangles is the slit's transmission: 1 for a wide slit,
    0 for a slit the float32 scene has closed.  Two positions are tried because the
    float32 spacing of the normalised coordinate differs between them (``spacing``).

    Parameters
    ----------
    widths : iterable of float
        Slit widths, fractions of D.
    positions : iterable of float
        x of the slit's centre.
    n_rays : int
        Rays per width and position.
    seed : int
        Seed of the ray origins.

    Returns
    -------
    list of dict
        ``width``, ``position``, ``spacing`` (float32 spacing at the slit, in units of D),
        ``transmitted``.
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
    """Measure the escape share of the cracked box's inner sides for narrow cracks, per ray offset.

    For every ray ``offset`` (fraction of the diagonal) and crack ``width``, the share is
    measured with :func:`escape_share` from about ``n_rays`` rays.  ``share / width`` is
    constant while the crack is much wider than the offset; it drops once the crack is
    narrower, because rays from the two walls that form a slit start further inside than
    the slit is wide and can no longer leave through it.

    Parameters
    ----------
    widths : iterable of float
        Crack widths, fractions of the box diagonal.
    offsets : iterable of float
        Ray offsets, fractions of the diagonal.
    n_rays : int
        Measuring rays per width and offset.
    cell : float
        Triangle size of the box.
    seed : int
        Seed of the models and the classifications (the measuring rays use ``seed + 1``).

    Returns
    -------
    list of dict
        ``width``, ``offset``, ``share``, ``share_per_width``, ``escaped`` (rays).
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
    """Run group 3: from which crack width the interior leaks; passes when leaking is monotone in the width.

    The figures behind the explanation come with it: the escape shares, the terminal
    weights of the box's inner sides before and after the cosine filter, the leak under
    the paper's unfaded prior, the float32 slit probe (:func:`slit_transmission`) and the
    ray-offset probe (:func:`offset_probe`, default offset and ten times smaller).

    Parameters
    ----------
    widths : iterable of float
        Crack widths of the sweep (:func:`crack_sweep`).
    cell : float
        Triangle size of the box.
    rays_per_node : int
        Ray budget of the classifications.
    seed : int
        Seed of everything random.
    share_rays : int
        Measuring rays of the escape share.
    slit_widths : iterable of float
        Widths of the float32 slit probe (empty: no probe).
    offset_widths : iterable of float
        Crack widths of the ray-offset probe (empty: no probe).
    offset_rays : int
        Measuring rays of the ray-offset probe (0: no probe).

    Returns
    -------
    CaseResult
        The case, with the sweep as its table and the probes in its values.
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
        group="cracks",
        name="cracked box with an inner box, crack width sweep",
        passed=monotone and not bad,
        figure=fig + _finite_note(bad),
        values={
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
    """Cut the final graph of ``c`` with the three solvers and compare.

    The compiled Boykov–Kolmogorov solver (``bk``, the default) and PyMaxflow run the same
    algorithm on the same float capacities: their values agree to the summation order and
    their labels are the same (the source side of a maximum flow's residual graph is
    unique) up to exact ties between minimum cuts, which float rounding breaks either way.
    The scipy solver cuts integer capacities ``rint(cap × scale)``.  Each rounded capacity
    is off by at most ``0.5 / scale``; comparing each solver's cut under both capacity
    sets gives ``|value_scipy − value_pymaxflow| ≤ 0.5 k / scale`` with *k* the larger
    number of directed capacities crossing either cut (every node crosses with exactly
    one terminal link): :func:`meshvis.graphcut.mincut.rounding_bound` with that *k*.

    Parameters
    ----------
    c : Classification
        The classification whose graph is cut.

    Returns
    -------
    dict
        The three values, the scipy difference and its bound, the nodes the ``bk`` labels
        differ on from PyMaxflow's and the cut value of the ``bk`` labels, the weight span (orders of magnitude of
        the positive edge weights and of all positive capacities), the capacities rounded
        to zero (count, share of their sum in the exact cut value), the nodes and faces
        labelled differently and the area agreement.
    """
    w = c.graph.weights
    pm: Cut = c.graph.cut("pymaxflow")
    sc: Cut = c.graph.cut("scipy")
    bk: Cut = c.graph.cut("bk")
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
        "value_bk": bk.value,
        "bk_nodes_differing": int(np.sum(bk.outside != pm.outside)),
        "bk_labels_cut": cut_value(bk.outside, w.edges_i, w.edges_j, w.cap_ij, w.cap_ji, w.cap_out, w.cap_in),
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
    """Run group 4: both max-flow solvers on the same graph.

    A case passes when the cut values agree within the rounding bound, the labels on
    :data:`AGREEMENT` of the area, no value is non-finite and, for the models of
    ``require_span``, the edge weights span at least :data:`WEIGHT_ORDERS` orders of
    magnitude.

    Parameters
    ----------
    models : dict of str to Soup
        The models, by name.
    rays_per_node : int
        Ray budget of every classification.
    seed : int
        Seed of every classification.
    require_span : set of str
        Names of the models whose weights must span :data:`WEIGHT_ORDERS` orders (their
        parts' outcome is tabulated).

    Returns
    -------
    list of CaseResult
        One timed case per model.
    """
    out = []
    for name, soup in models.items():

        def case(name=name, soup=soup) -> CaseResult:
            c = classify(soup, rays_per_node=rays_per_node, seed=seed)
            r = compare_solvers(c)
            bad = nonfinite(c)
            slack = 1e-9 * max(r["value_pymaxflow"], 1e-300)  # float summation order
            ok_value = r["difference"] <= r["bound"] + slack
            # the compiled solver: the same maximum flow, and its labels a cut of that value
            ok_bk = abs(r["value_bk"] - r["value_pymaxflow"]) <= slack
            ok_bk &= abs(r["bk_labels_cut"] - r["value_pymaxflow"]) <= slack
            ok_span = name not in require_span or r["edge_weight_orders"] >= WEIGHT_ORDERS
            ok = ok_value and ok_bk and ok_span and r["agreement"] >= AGREEMENT and not bad
            fig = (
                f"edge weights span {r['edge_weight_orders']:.1f} orders; cut {r['value_pymaxflow']:.6g} vs "
                f"{r['value_scipy']:.6g}, |diff| {r['difference']:.2e} <= bound {r['bound']:.2e}: "
                f"{'yes' if ok_value else 'NO'}; labels agree on {100 * r['agreement']:.4f}% of area; "
                f"rounding lost {r['capacities_rounded_to_zero']} of {r['capacities']} capacities "
                f"({r['lost_share_of_cut']:.1e} of the cut), {r['faces_differing']} faces "
                f"({r['area_differing']:.1e} of area) labelled differently; bk: cut {r['value_bk']:.6g}, "
                f"labels differ from pymaxflow on {r['bk_nodes_differing']} nodes{'' if ok_bk else ', VALUE DIFFERS'}"
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
                group="weights",
                name=f"{name}: pymaxflow vs scipy (integer) on one graph",
                passed=ok,
                figure=fig + _finite_note(bad),
                values={**r, "nonfinite": bad},
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
    """Run group 5: one triangle, two triangles, one quad; empty file, no faces, one zero-area triangle.

    The models are written as OBJ files and read back through :func:`meshvis.classify`'s
    path argument, so reading is part of the test.  The first three must have both sides
    of every face outside; the last three must raise a one-line ModelError naming the file.

    Parameters
    ----------
    rays_per_node : int
        Ray budget of every classification.
    seed : int
        Seed of every classification.
    folder : str, optional
        Where the temporary folder of the files is made (default the system's).

    Returns
    -------
    list of CaseResult
        Six timed cases.
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
                    group="tiny",
                    name=label,
                    passed=ok and not bad,
                    figure=fig + _finite_note(bad),
                    values={
                        "faces": c.soup.n_faces,
                        "sides_outside": int(c.side_outside.sum()),
                        "nonfinite": bad,
                    },
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
                        group="tiny",
                        name=label,
                        passed=ok,
                        figure=f"ModelError: {msg.replace(tmp, '<tmp>')}",
                        values={"error": type(exc).__name__, "names_file": path in msg},
                    )
                except Exception as exc:  # anything else is a bug
                    return CaseResult(
                        group="tiny",
                        name=label,
                        passed=False,
                        figure=f"{type(exc).__name__} instead of ModelError: {exc}",
                        values={"error": type(exc).__name__},
                    )
                return CaseResult(
                    group="tiny", name=label, passed=False, figure="no error raised", values={"error": None}
                )

            out.append(_timed(error_case))
    return out
