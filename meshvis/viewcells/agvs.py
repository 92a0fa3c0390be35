"""Adaptive global visibility sampling (AGVS, ``000_*.txt``): the PVS of every view cell at once.

:func:`pvs` runs in batches (AGVS §4.6).  Each batch draws samples from the distributions
of :mod:`.strategies` in the proportions of the adaptive mixture (:mod:`.mixture`), casts
them both ways and adds the faces at the ends of each free segment to every cell it pierces
(:mod:`.sampler`).  After every batch the pixel-error estimate (:mod:`.estimate`) is
updated; the run stops when it is below ``target_error`` (with enough rays behind it), at
the ray ``budget`` or after ``seconds``.  Every batch leaves a complete PVS for every cell:
the run can stop at any time, and the history says how converged it was.

With ``cells="auto"`` a coarse pass of view space-direction samples builds the cells by
render cost first (:mod:`.hierarchy`); its samples are then the run's first batch.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from meshvis import _validate, limits
from meshvis.errors import ParameterError
from meshvis.io import as_soup
from meshvis.rays.caster import VISIBILITY_OFFSET, RayCaster
from meshvis.viewcells import strategies as st
from meshvis.viewcells.cells import ViewCells, parse_cells
from meshvis.viewcells.estimate import ErrorEstimate
from meshvis.viewcells.hierarchy import COARSE_SAMPLES, Segments, auto_cells, clipped
from meshvis.viewcells.mixture import Mixture
from meshvis.viewcells.result import PVS, model_key
from meshvis.viewcells.sampler import GlobalSampler
from meshvis.viewcells.viewspace import ViewSpace, check_view_space, default_view_space

#: rays per batch (AGVS §4.6 batches samples; the mixture and the estimate move once per batch)
BATCH_RAYS = 1 << 20
#: default target of the pixel-error estimate, wrong pixels per million
TARGET_ERROR = 5.0
#: default ray budget, a cap only: the estimate normally ends the run before
DEFAULT_BUDGET = 1 << 30


def pvs(
    model,
    cells="auto",
    *,
    view_space: str | ViewSpace = "auto",
    budget: int | None = None,
    seconds: float | None = None,
    target_error: float = TARGET_ERROR,
    visibility_filter: bool = False,
    seed: int = 0,
    up=None,
    caster: RayCaster | None = None,
    progress: Callable[[str, float], None] | None = None,
) -> PVS:
    """The potentially visible set of every view cell, by adaptive global visibility sampling.

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model.
    cells : str or ViewCells
        ``"auto"`` or ``"auto:N"``: N cells (default 64) built by render cost (002);
        ``"grid:NX,NY,NZ"``: a uniform grid over the view space's box; a path to a JSON
        list of boxes ``[x0, y0, z0, x1, y1, z1]``; or ViewCells.  Cells with no view
        space in them are left out.
    view_space : str or ViewSpace
        ``"auto"``: the bounding box, above the ground for scenes standing on one;
        ``"box"``: the bounding box; ``"box:x0,y0,z0,x1,y1,z1"``: that box.
    budget : int, optional
        Rays to cast at most (the last batch may pass it by less than a batch); default a
        cap of :data:`DEFAULT_BUDGET` that the target normally ends the run before.
    seconds : float, optional
        Stop after this much time (checked after every batch; the set then depends on the
        machine's speed).
    target_error : float
        Stop when the pixel-error estimate (AGVS §4.5) is at most this many wrong pixels per
        million with enough rays behind it (0: never).
    visibility_filter : bool
        Extend each PVS by the faces near its faces, by the sampling density (AGVS §5).
    seed : int
        Seed of the one random generator: the same model, options and seed give the same
        PVS when the run ends by its budget or its target (not by ``seconds``).
    up : None, "x", "y", "z" or (3,) float
        The up direction of the ground (None: the model's own, ``Soup.up``).
    caster : RayCaster, optional
        A caster of the same model to reuse.
    progress : callable, optional
        ``progress(stage, fraction)``.

    Returns
    -------
    PVS

    Raises
    ------
    ParameterError
        Malformed cells or view space, a negative budget or time.

    Examples
    --------
    >>> import trimesh
    >>> result = pvs(trimesh.creation.box(), "grid:2,1,1", view_space="box:-2,-2,-2,2,2,2", budget=40000)
    >>> result.cells.n_cells, int(result.sizes().min())
    (2, 12)
    """
    t_start = time.perf_counter()
    cpu_start = time.process_time()
    seed = _validate.seed(seed)
    if budget is not None:
        budget = _validate.integer("budget", budget, 0)
    if seconds is not None:
        seconds = _validate.real("seconds", seconds, 0.0)
    target_error = _validate.real("target_error", target_error, 0.0)
    _validate.callback("progress", progress)
    soup = as_soup(model)
    caster = caster or RayCaster(soup, offset=VISIBILITY_OFFSET)
    vs = default_view_space(soup, view_space, up=up, caster=caster)
    spec = parse_cells(cells, vs)
    rng = np.random.default_rng(seed)
    budget = DEFAULT_BUDGET if budget is None else budget
    tell = progress or (lambda stage, fraction: None)

    coarse, auto_info = None, None
    if isinstance(spec, tuple):
        tell("view cells", 0.0)
        coarse = st.uniform(vs, COARSE_SAMPLES, rng)
        built, auto_info, traced = _auto(vs, soup, coarse, spec[1], caster, rng)
        vc = built
    else:
        vc = spec
    _check_memory(vc, soup.n_faces)
    sampler = GlobalSampler(vc, caster)
    surface = st.SurfacePoints(soup)
    push = caster.offset * caster.diagonal
    walls = st.CellWalls(vc, push)
    mixture = Mixture(st.STRATEGIES)
    estimate = ErrorEstimate()
    stats = {n: {"samples": 0, "rays": 0, "contribution": 0, "seconds": 0.0} for n in st.STRATEGIES}
    history: dict[str, list] = {
        "seconds": [],
        "cpu_seconds": [],
        "rays": [],
        "mean_pvs": [],
        "estimate_per_million": [],
        "probabilities": [],
    }
    batches: dict[str, list] = {"seconds": [], "cpu_seconds": [], "rays": []}
    sizes = np.zeros(vc.n_cells, np.int64)
    rays = 0

    def record(name: str, res) -> None:
        nonlocal rays
        s = stats[name]
        s["samples"] += res.samples
        s["rays"] += res.rays
        s["contribution"] += res.contribution
        s["seconds"] += res.seconds
        rays += res.rays
        mixture.update(name, res.contribution, res.rays)
        if name == "uniform":
            estimate.add(res.own_rays, res.own_contributing)

    def end_batch(p: dict) -> None:
        cell, _, when = sampler.log
        fresh = when == sampler.batch
        np.add.at(sizes, cell[fresh], 1) if fresh.any() else None
        now = time.perf_counter() - t_start
        cpu = time.process_time() - cpu_start
        history["seconds"].append(now)
        history["cpu_seconds"].append(cpu)
        history["rays"].append(rays)
        history["mean_pvs"].append(float(sizes.mean()))
        history["estimate_per_million"].append(estimate.per_million)
        history["probabilities"].append({k: round(v, 4) for k, v in p.items()})
        batches["seconds"].append(now)
        batches["cpu_seconds"].append(cpu)
        batches["rays"].append(rays)
        sampler.batch += 1

    if coarse is not None:
        record("uniform", sampler.cast([coarse], rng, traced=traced)[0])
        end_batch({"uniform": 1.0})

    # The next batch is drawn, then traced in a thread while this one walks the cells: the
    # walk and the Python work overlap Embree's rays.  Drawing uses the state before this
    # batch's walk (mutations lag one batch), so the order of every step is fixed.
    stopped = ""
    with ThreadPoolExecutor(1, "meshvis-pvs") as tracer:
        pending = None
        while True:
            elapsed = time.perf_counter() - t_start
            stopped = _stop(rays, budget, elapsed, seconds, estimate, target_error)
            tell("sampling", _fraction(rays, budget, elapsed, seconds, estimate, target_error))
            upcoming = None
            # the batch in flight counts against the budget
            if not stopped and not (pending is not None and rays + pending[2] >= budget):
                available = dict.fromkeys(st.STRATEGIES, True)
                available["mutation"] = available["silhouette"] = len(sampler.buffer) > 0
                available["border"] = len(sampler.border) > 0
                available["adjacent"] = len(sampler.spread) > 0 and vc.n_cells > 1
                p = mixture.probabilities(available)
                parts = []
                for name in st.STRATEGIES:
                    k = int(p[name] * BATCH_RAYS / st.RAYS_PER_SAMPLE[name])
                    if k > 0:
                        t = time.perf_counter()
                        parts.append(
                            (
                                name,
                                _draw(name, k, vs, surface, walls, sampler, rng, caster, push),
                                time.perf_counter() - t,
                            )
                        )
                planned = sum(2 * len(x.origin) + x.rays for _, x, _ in parts)
                upcoming = (parts, tracer.submit(_trace_parts, sampler, parts), planned, p)
            if pending is not None:
                parts, future, _, p = pending
                both, trace_seconds = future.result()
                total_rays = max(sum(2 * len(x.origin) + x.rays for _, x, _ in parts), 1)
                results = sampler.cast([x for _, x, _ in parts], rng, traced=both)
                for (name, samples, draw_seconds), res in zip(parts, results):
                    share = trace_seconds * (2 * len(samples.origin) + samples.rays) / total_rays
                    res.seconds += draw_seconds + share
                    record(name, res)
                end_batch(p)
            pending = upcoming
            if pending is None:
                break
    stopped = (
        stopped
        or _stop(rays, budget, time.perf_counter() - t_start, seconds, estimate, target_error)
        or "budget"
    )

    filtered = None
    if visibility_filter:
        from meshvis.viewcells.filter import visibility_filter as apply_filter

        tell("filter", 0.0)
        filtered = apply_filter(sampler, soup)
    seconds_total = time.perf_counter() - t_start
    summary = {
        "seed": seed,
        "seconds": seconds_total,
        "rays": {**{n: stats[n]["rays"] for n in st.STRATEGIES}, "total": rays},
        "strategies": stats,
        "stopped": stopped,
        "estimate": {
            "per_million": estimate.per_million,
            "window_rays": estimate.window,
            "enough_rays": estimate.enough,
            "target_per_million": target_error,
        },
        "history": history,
        "left_out": _left_out(vc, sampler, soup),
    }
    if auto_info is not None:
        summary["auto_cells"] = auto_info
    if filtered is not None:
        summary["filter"] = filtered
    return PVS(
        cells=vc,
        bits=sampler.bits,
        n_faces=soup.n_faces,
        part_id=soup.part_id,
        part_names=list(soup.part_names),
        sides=sampler.sides,
        key=model_key(soup),
        summary=summary,
        log=sampler.log,
        batches=batches,
    )


def check_arguments(cells, view_space, seed: int = 0) -> None:
    """Refuse malformed ``cells``, ``view_space`` and ``seed`` before any model is read.

    Raises
    ------
    ParameterError
        What :func:`pvs` would refuse about these arguments (a cells file is read and its
        boxes checked; their fit to the view space is checked by :func:`pvs`).
    """
    _validate.seed(seed)
    probe = ViewSpace(np.zeros(3), np.ones(3))
    if not isinstance(view_space, ViewSpace):
        check_view_space(view_space)
    if isinstance(cells, str) and cells.strip().lower().endswith(".json"):
        from meshvis.viewcells.cells import read_boxes

        read_boxes(cells.strip())
    elif isinstance(cells, str) and cells.strip().lower().startswith("grid:"):
        shape = parse_cells(cells, probe)
        assert isinstance(shape, ViewCells)
    elif not isinstance(cells, ViewCells):
        parse_cells(cells, probe)


def _auto(vs: ViewSpace, soup, coarse: st.Samples, n: int, caster, rng):
    """The cells by render cost from the coarse samples (and their traced rays, for reuse)."""
    from meshvis.viewcells.sampler import Traced

    o, d = coarse.origin, coarse.direction
    k = len(o)
    hits = caster.intersect(np.concatenate([o, o]), np.concatenate([d, -d]))
    traced = Traced(hits.face[:k], hits.face[k:], hits.distance[:k], hits.distance[k:], hits.side)
    segments = Segments(o, d, -traced.t_back, traced.t_fwd, traced.face_back, traced.face_fwd)
    ab = clipped(segments, np.arange(k), vs.lo, vs.hi)
    t0, t1 = ab[:, 0], ab[:, 1]
    valid = (t0 <= t1) & ((traced.face_back >= 0) | (traced.face_fwd >= 0))
    segs = Segments(o[valid], d[valid], t0[valid], t1[valid], traced.face_back[valid], traced.face_fwd[valid])
    cells, info = auto_cells(vs, segs, o, n, n_faces=soup.n_faces, rng=rng)
    return cells, info, traced


def _trace_parts(sampler: GlobalSampler, parts: list):
    """Trace the samples of every distribution of a batch in one call; the rays and the time."""
    t = time.perf_counter()
    if sum(len(x.origin) for _, x, _ in parts) == 0:
        return None, 0.0
    both = sampler.trace(
        st.Samples(
            np.concatenate([x.origin for _, x, _ in parts]),
            np.concatenate([x.direction for _, x, _ in parts]),
        )
    )
    return both, time.perf_counter() - t


def _check_memory(cells: ViewCells, n_faces: int) -> None:
    """Refuse a PVS bit set beyond :data:`meshvis.limits.MAX_PVS_BITS`."""
    bits = cells.n_cells * 64 * max(1, -(-n_faces // 64))
    if bits > limits.MAX_PVS_BITS:
        raise ParameterError(
            f"{cells.n_cells} cells x {n_faces} faces is {bits} PVS bits, more than the cap "
            f"MAX_PVS_BITS of meshvis.limits ({limits.MAX_PVS_BITS}); use fewer cells"
        )


def _draw(name: str, k: int, vs, surface, walls, sampler: GlobalSampler, rng, caster, push) -> st.Samples:
    if name == "uniform":
        return st.uniform(vs, k, rng)
    if name == "object":
        return st.object_direction(surface, k, rng, push)
    if name == "two-point":
        return st.two_point(vs, surface, k, rng)
    if name == "wall":
        return st.wall(walls, surface, k, rng)
    if name == "mutation":
        return st.two_point_mutation(sampler.buffer, k, rng)
    if name == "silhouette":
        return st.silhouette_mutation(sampler.buffer, k, rng, caster, push)
    if name == "adjacent":
        if sampler.adjacent is None:
            sampler.adjacent = sampler.cells.adjacent()
        return st.adjacent_cell(
            sampler.spread, k, rng, sampler.bits, sampler.adjacent, sampler.cells, surface, push
        )
    if sampler.neighbours is None:
        sampler.neighbours = st.face_neighbours(caster.soup)
    return st.border_mutation(sampler.border, k, rng, sampler.bits, sampler.neighbours, surface)


def _stop(rays, budget, elapsed, seconds, estimate: ErrorEstimate, target) -> str:
    if target > 0 and estimate.enough and estimate.per_million <= target:
        return "target error"
    if rays >= budget:
        return "budget"
    if seconds is not None and elapsed >= seconds:
        return "time"
    return ""


def _fraction(rays, budget, elapsed, seconds, estimate: ErrorEstimate, target) -> float:
    f = rays / budget if budget > 0 else 1.0
    if seconds:
        f = max(f, elapsed / seconds)
    if target > 0 and np.isfinite(estimate.per_million) and estimate.per_million > 0:
        f = max(f, min(1.0, np.log(1e6 / estimate.per_million) / np.log(1e6 / target)))
    return float(min(f, 1.0))


def _left_out(cells: ViewCells, sampler: GlobalSampler, soup) -> dict:
    """What the run left out: leaves of the tree with no view space, faces no cell sees."""
    leaves = (cells.axis < 0) & (cells.cell < 0)
    seen = np.bitwise_or.reduce(sampler.bits, axis=0) if cells.n_cells else np.zeros(1, np.uint64)
    in_any = np.unpackbits(seen.view(np.uint8), bitorder="little")[: soup.n_faces].astype(bool)
    area = soup.areas
    return {
        "tree_leaves_without_view_space": int(leaves.sum()),
        "faces_no_cell_sees": int((~in_any).sum()),
        "area_share_no_cell_sees": float(area[~in_any].sum() / max(float(area.sum()), 1e-300)),
        "zero_area_faces_never_drawn": int((soup.areas <= 0).sum()),
    }
