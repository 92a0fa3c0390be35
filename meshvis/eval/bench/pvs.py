"""PVS for view cells: AGVS's pixel error against time next to per-cell guided and random sampling.

For each level (default: zdm2, pandora and the monastery, each in its default view space):

1. :func:`meshvis.viewcells.pvs` on ``--cells`` (default ``auto:64``) until its default stop rule
   or ``--time`` (default 300 s), keeping the history of every batch;
2. the judge (:mod:`meshvis.viewcells.judge`): face-ID buffers of the whole scene from
   ``--points`` random viewpoints of the view space (six 90° views each) and a
   ``--path``-point walkthrough; the wrong pixels per million of every view for the PVS as
   it was at log-spaced moments of the run (the error-against-time curve), and the
   on-the-fly estimate (AGVS §4.5) beside the measured error;
3. per-cell random sampling (AGVS §7's REF: a random cell, a random point in it, a random
   direction; the hit counts for that cell only), judged when it has used as many CPU
   seconds as AGVS had at each point of AGVS's curve;
4. per-cell guided sampling: :func:`meshvis.visible_from` with a ``box:`` region per cell,
   (a) on every cell with a ray budget per cell of 1/16, 1/4 and 1 times AGVS's rays shared out,
   (b) to its own stop rule on ``--gvs-cells`` random cells, extrapolated to all cells by
   the mean time per cell (as AGVS §7 does for GVS), and the time AGVS took to reach the
   same mean PVS size on those cells;
5. the render cost Σ P(cell)·|PVS(cell)| of the auto cells next to a uniform grid of the
   same count (:func:`meshvis.viewcells.cells.grid_shape`) run with AGVS's rays.

Times are wall-clock seconds of this process with the CPU seconds beside (the machine is
shared: the load is printed); every method runs in the same process on the same caster.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import time

import numpy as np

from meshvis.eval.bench.real_models import add_models_argument, models_folder

#: levels under the shared models folder
MODELS = ("real2/zdm2_level.glb", "real2/pandora_level.obj", "real/pybullet__samurai_monastry.obj")
#: AGVS's time cap (s), the issue's budget for all cells
SECONDS = 300.0
#: random cells that get a converged per-cell guided search
GVS_CELLS = 8
#: per-cell guided sampling with these shares of AGVS's rays, shared out over the cells
GVS_SHARES = (1 / 16, 0.25, 1.0)
#: points of the error-against-time curve
SNAPSHOTS = 10
#: the estimate is compared with the measured error below this (wrong pixels per million)
COMPARE_BELOW = 100.0
#: bump when the sampler changes, so that cached runs are not reused
RUN_VERSION = 4


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench pvs`` to ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The benchmark's sub-parser.
    """
    from meshvis.viewcells import judge

    p.add_argument("levels", nargs="*", help=f"level files (default: {', '.join(MODELS)})")
    p.add_argument("--cells", default="auto:64", help="view cells of the AGVS run")
    p.add_argument("--time", type=float, default=SECONDS, help="AGVS's time cap in seconds")
    p.add_argument("--rays", type=int, help="AGVS's ray budget (instead of the stop rule and the time)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--filter",
        action="store_true",
        help="run AGVS with the visibility filter and judge its PVS with and without the filter's faces",
    )
    p.add_argument("--points", type=int, default=judge.VIEWPOINTS, help="random viewpoints (six views each)")
    p.add_argument("--path", type=int, default=judge.PATH_POINTS, help="walkthrough points (one view each)")
    p.add_argument("--size", type=int, default=judge.SIZE, help="pixels along each side of a view")
    p.add_argument(
        "--gvs-cells",
        type=int,
        default=GVS_CELLS,
        help="cells of the converged per-cell guided search (0: none)",
    )
    p.add_argument(
        "--parts",
        default=",".join(PARTS),
        help="what to measure: agvs (the run and its curve), random, gvs (guided on every cell), converged "
        "(guided to its stop rule on --gvs-cells cells), grid (a uniform grid of the same count); the AGVS run "
        "is cached in --cache, so the parts can run one at a time",
    )
    p.add_argument(
        "--cache",
        default=os.path.join(os.path.expanduser("~"), ".cache", "meshvis"),
        help="folder of the cached view tables (default ~/.cache/meshvis)",
    )
    p.add_argument("--json", metavar="FILE", help="also write the numbers as JSON")
    p.add_argument("--curve", metavar="PICTURE.png", help="plot the error against time of every level")
    add_models_argument(p)


def main(args: argparse.Namespace) -> int:
    """Run ``meshvis bench pvs`` and print its tables."""
    from meshvis.io.jsonfile import write_json

    base = os.path.dirname(os.path.abspath(models_folder(args.models_dir)))
    paths = args.levels or [os.path.join(base, m) for m in MODELS]
    os.makedirs(args.cache, exist_ok=True)
    print(f"load {_load()}")
    results = []
    for path in paths:
        r = run_level(path, args)
        print(format_level(r), flush=True)
        results.append(r)
    if args.curve:
        plot_curves(results, args.curve)
    if args.json:
        write_json(args.json, {"results": results})
    return 0


def _clock() -> tuple[float, float]:
    return time.perf_counter(), time.process_time()


def _since(start: tuple[float, float]) -> tuple[float, float]:
    return time.perf_counter() - start[0], time.process_time() - start[1]


#: the parts of the benchmark (each needs the AGVS run, cached in ``--cache`` by the first)
PARTS = ("agvs", "random", "gvs", "converged", "grid")
#: the random-sampling curve stops at this many CPU seconds (its points are at AGVS's CPU seconds)
RANDOM_CPU_SECONDS = 120.0
#: the grid of the same count gets this share of AGVS's rays (and is compared with the auto
#: cells' PVS after as many rays)
GRID_SHARE = 0.25


def run_level(path: str, args: argparse.Namespace) -> dict:
    """The parts ``args.parts`` of the module notes on one level."""
    import warnings

    from meshvis.io import load
    from meshvis.rays.caster import VISIBILITY_OFFSET, RayCaster
    from meshvis.viewcells import judge

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        soup = load(path)
    caster = RayCaster(soup, offset=VISIBILITY_OFFSET)
    parts = set(args.parts.split(","))
    unknown = parts - set(PARTS)
    if unknown:
        from meshvis.errors import ParameterError

        raise ParameterError(f"unknown parts {sorted(unknown)}; choose from {', '.join(PARTS)}")
    result, run = _agvs_run(soup, args, caster)
    cells = result.cells
    out: dict = {"level": os.path.basename(path), "faces": int(soup.n_faces), "parts": sorted(parts), **run}
    out.update(
        cells=cells.n_cells,
        cells_kind=cells.kind,
        view_space=cells.view_space.describe(),
        mean_pvs=float(result.sizes().mean()),
        expected_cost=result.expected_cost(),
    )
    table = _views(soup, cells.view_space, args, caster)
    out["views"] = int(table.n_views)
    out["final"] = judge.summary(judge.pixel_errors(table, cells, result.bits), table)
    if "filter" in result.summary:
        # the log holds the sampled entries only: its last state is the PVS before the filter
        sampled = result.bits_at(len(result.batches["seconds"]) - 1)
        out["filter"] = {
            **result.summary["filter"],
            "mean_pvs_sampled": float(_sizes(sampled).mean()),
            "sampled": judge.summary(judge.pixel_errors(table, cells, sampled), table),
        }
    out["agvs_curve"] = _agvs_curve(result, table)
    out["estimate_vs_measured"] = [
        {"seconds": p["seconds"], "estimate": p["estimate"], "measured": p["mean"]}
        for p in out["agvs_curve"]
        if p["mean"] < COMPARE_BELOW
    ]
    total = out["rays"]
    key = _run_key(soup, args)
    if "random" in parts:
        times = [p["cpu_seconds"] for p in out["agvs_curve"] if p["cpu_seconds"] <= RANDOM_CPU_SECONDS]
        out["random_curve"] = _part(
            args.cache,
            ("random", key, times),
            lambda: _random_curve(soup, cells, caster, table, times, args.seed),
        )
    if "gvs" in parts:
        out["gvs_curve"] = _part(
            args.cache,
            ("gvs", key, GVS_SHARES),
            lambda: [
                _gvs_all(soup, cells, caster, table, int(total * share / cells.n_cells), args.seed)
                for share in GVS_SHARES
            ],
        )
    if "converged" in parts and args.gvs_cells > 0:
        out["gvs_converged"] = _gvs_converged(soup, result, caster, args.gvs_cells, args.seed)
    if "grid" in parts and cells.kind.startswith("auto"):
        out["grid"] = _grid(soup, result, caster, table, int(total * GRID_SHARE), args.seed)
    return out


def _run_key(soup, args) -> str:
    """The cache key of the AGVS run of this level and options."""
    from meshvis.viewcells.result import model_key

    return hashlib.sha256(
        repr(
            (model_key(soup), args.cells, args.rays, None if args.rays else args.time, args.seed, RUN_VERSION)
            + (("filter",) if args.filter else ())
        ).encode()
    ).hexdigest()[:20]


def _part(cache: str, what: tuple, compute):
    """A part's numbers, cached as JSON by ``what`` (its name, the run's key, its settings).

    The curves of per-cell random and guided sampling take minutes each: cached, they can
    run one per benchmark call and still be drawn together by a last call with ``--curve``.
    """
    from meshvis.io import atomic_write

    path = os.path.join(cache, f"pvs-part-{hashlib.sha256(repr(what).encode()).hexdigest()[:20]}.json")
    if os.path.isfile(path):
        with open(path) as fh:
            return json.load(fh)
    value = compute()
    with atomic_write(path, "w") as fh:
        json.dump(value, fh)
    return value


def _agvs_run(soup, args, caster):
    """The AGVS run of this level and options: computed and cached, or read from the cache.

    Returns the result (with its log) and the run's measures: seconds, CPU seconds, rays,
    why it stopped and the machine's load when it ran.
    """
    from meshvis.io import atomic_write
    from meshvis.viewcells import PVS, pvs

    key = _run_key(soup, args)
    path = os.path.join(args.cache, f"pvs-run-{key}.npz")
    log_path = os.path.join(args.cache, f"pvs-run-{key}.log.npz")
    if os.path.isfile(path) and os.path.isfile(log_path):
        result = PVS.load(path, soup)
        with np.load(log_path) as d:
            result.log = (d["cell"], d["face"], d["batch"])
            result.batches = {
                "seconds": d["seconds"].tolist(),
                "cpu_seconds": d["cpu_seconds"].tolist(),
                "rays": d["rays"].tolist(),
            }
            run = json.loads(str(d["run"]))
        return result, run
    load = _load()
    start = _clock()
    run_args = {"budget": args.rays, "target_error": 0.0} if args.rays else {"seconds": args.time}
    result = pvs(soup, args.cells, seed=args.seed, caster=caster, visibility_filter=args.filter, **run_args)
    wall, cpu = _since(start)
    run = {
        "seconds": wall,
        "cpu_seconds": cpu,
        "rays": int(result.summary["rays"]["total"]),
        "stopped": result.summary["stopped"],
        "load_before": load,
        "load_after": _load(),
    }
    result.save(path)
    assert result.log is not None and result.batches is not None
    with atomic_write(log_path, "wb") as fh:
        np.savez_compressed(
            fh,
            cell=result.log[0],
            face=result.log[1],
            batch=result.log[2],
            seconds=np.asarray(result.batches["seconds"]),
            cpu_seconds=np.asarray(result.batches["cpu_seconds"]),
            rays=np.asarray(result.batches["rays"]),
            run=np.array(json.dumps(run)),
        )
    return result, run


def _load() -> list[float]:
    """The machine's load averages (1, 5, 15 minutes); empty where /proc is missing."""
    try:
        with open("/proc/loadavg") as fh:
            return [float(x) for x in fh.read().split()[:3]]
    except OSError:
        return []


def _views(soup, view_space, args, caster):
    """The judge's table of this level and view space, cached by the model, view space and options."""
    from meshvis.viewcells import judge
    from meshvis.viewcells.result import model_key

    h = hashlib.sha256()
    h.update(model_key(soup).encode())
    for k, v in sorted(view_space.arrays().items()):
        h.update(k.encode() + np.ascontiguousarray(v).tobytes())
    h.update(repr((args.points, args.path, args.size, args.seed, 1)).encode())
    cache = os.path.join(args.cache, f"pvs-views-{h.hexdigest()[:20]}.npz")
    if os.path.isfile(cache):
        with np.load(cache) as d:
            return judge.ViewTable(
                d["view"], d["face"], d["pixels"], d["position"], d["walkthrough"], int(d["size"])
            )
    t = judge.render_views(
        soup,
        view_space,
        points=args.points,
        path=args.path,
        size=args.size,
        seed=args.seed + 1,
        caster=caster,
    )
    from meshvis.io import atomic_write

    with atomic_write(cache, "wb") as fh:
        np.savez_compressed(
            fh,
            view=t.view,
            face=t.face,
            pixels=t.pixels,
            position=t.position,
            walkthrough=t.walkthrough,
            size=t.size,
        )
    return t


def _agvs_curve(result, table) -> list[dict]:
    """The judged error of the PVS at log-spaced batches of the run, with the estimate then."""
    from meshvis.viewcells import judge

    n = len(result.batches["seconds"])
    picks = np.unique(np.round(np.geomspace(1, n, SNAPSHOTS)).astype(int) - 1)
    h = result.summary["history"]
    out = []
    for b in picks:
        bits = result.bits_at(int(b))
        s = judge.summary(judge.pixel_errors(table, result.cells, bits), table)
        sizes = _sizes(bits)
        out.append(
            {
                "batch": int(b),
                "seconds": float(result.batches["seconds"][b]),
                "cpu_seconds": float(result.batches["cpu_seconds"][b]),
                "rays": int(result.batches["rays"][b]),
                "estimate": float(h["estimate_per_million"][b]),
                "mean_pvs": float(sizes.mean()),
                **s,
            }
        )
    return out


def _sizes(bits) -> np.ndarray:
    from meshvis.viewcells import _kernels

    return _kernels.count_rows(bits)


def _random_curve(soup, cells, caster, table, checkpoints: list[float], seed: int) -> list[dict]:
    """Per-cell random sampling (AGVS §7's REF), judged when it has used the given CPU seconds."""
    from meshvis.rays.samples import uniform_sphere
    from meshvis.viewcells import judge

    rng = np.random.default_rng(seed)
    bits = np.zeros((cells.n_cells, max(1, -(-soup.n_faces // 64))), np.uint64)
    vs = cells.view_space
    rays = 0
    out = []
    start = _clock()
    chunk = 1 << 18
    for target in checkpoints:
        while _since(start)[1] < target:
            k = chunk
            cell = rng.integers(0, cells.n_cells, k)
            o = cells.cell_lo[cell] + rng.random((k, 3)) * (cells.cell_hi[cell] - cells.cell_lo[cell])
            keep = vs.contains(o)
            o, cell = o[keep], cell[keep]
            face = caster.intersect(o, uniform_sphere(len(o), rng)).face
            hit = face >= 0
            f, c = face[hit], cell[hit]
            np.bitwise_or.at(bits, (c, f >> 6), np.left_shift(np.uint64(1), (f & 63).astype(np.uint64)))
            rays += k
        wall, cpu = _since(start)
        s = judge.summary(judge.pixel_errors(table, cells, bits), table)
        out.append(
            {"seconds": wall, "cpu_seconds": cpu, "rays": rays, "mean_pvs": float(_sizes(bits).mean()), **s}
        )
    return out


def _box(cells, c: int) -> str:
    return "box:" + ",".join(f"{x:.17g}" for x in np.concatenate([cells.cell_lo[c], cells.cell_hi[c]]))


def _gvs_all(soup, cells, caster, table, budget: int, seed: int) -> dict:
    """Per-cell guided sampling on every cell with ``budget`` rays each; judged."""
    from meshvis.viewcells import judge
    from meshvis.visibility import visible_from

    bits = np.zeros((cells.n_cells, max(1, -(-soup.n_faces // 64))), np.uint64)
    start = _clock()
    rays = 0
    for c in range(cells.n_cells):
        vis = visible_from(soup, _box(cells, c), budget=max(budget, 1), seed=seed + c, caster=caster)
        f = np.flatnonzero(vis.seen)
        np.bitwise_or.at(
            bits, (np.full(len(f), c), f >> 6), np.left_shift(np.uint64(1), (f & 63).astype(np.uint64))
        )
        rays += int(vis.rays["total"])
    wall, cpu = _since(start)
    s = judge.summary(judge.pixel_errors(table, cells, bits), table)
    return {
        "budget_per_cell": budget,
        "seconds": wall,
        "cpu_seconds": cpu,
        "rays": rays,
        "mean_pvs": float(_sizes(bits).mean()),
        **s,
    }


def _gvs_converged(soup, result, caster, k: int, seed: int) -> dict:
    """Per-cell guided sampling to its stop rule on ``k`` random cells, extrapolated to all.

    Returns the mean time per cell, the mean PVS size over those cells, and the time AGVS's
    PVS of the same cells took to reach that mean size (from its log).
    """
    from meshvis.visibility import visible_from

    cells = result.cells
    rng = np.random.default_rng(seed + 7)
    pick = np.sort(rng.choice(cells.n_cells, size=min(k, cells.n_cells), replace=False))
    sizes, walls, cpus = [], [], []
    for c in pick:
        start = _clock()
        vis = visible_from(soup, _box(cells, int(c)), seed=seed + int(c), caster=caster)
        wall, cpu = _since(start)
        walls.append(wall)
        cpus.append(cpu)
        sizes.append(int(vis.seen.sum()))
    target = float(np.mean(sizes))
    # AGVS's mean PVS over the picked cells after each batch, from its log
    cell, _, when = result.log
    mine = np.isin(cell, pick)
    per_batch = np.bincount(when[mine], minlength=len(result.batches["seconds"])).cumsum() / len(pick)
    reached = np.flatnonzero(per_batch >= target)
    agvs_time = float(result.batches["seconds"][reached[0]]) if len(reached) else None
    agvs_cpu = float(result.batches["cpu_seconds"][reached[0]]) if len(reached) else None
    total = float(np.mean(walls)) * cells.n_cells
    total_cpu = float(np.mean(cpus)) * cells.n_cells
    return {
        "cells": pick.tolist(),
        "mean_pvs": target,
        "seconds_per_cell": float(np.mean(walls)),
        "cpu_seconds_per_cell": float(np.mean(cpus)),
        "extrapolated_seconds": total,
        "extrapolated_cpu_seconds": total_cpu,
        "agvs_seconds_to_same_mean_pvs": agvs_time,
        "agvs_cpu_seconds_to_same_mean_pvs": agvs_cpu,
        "agvs_mean_pvs_final_same_cells": float(per_batch[-1]),
        "ratio": (agvs_time / total) if agvs_time is not None else None,
        "cpu_ratio": (agvs_cpu / total_cpu) if agvs_cpu is not None else None,
    }


def _grid(soup, result, caster, table, rays: int, seed: int) -> dict:
    """AGVS on a uniform grid of the same cell count with ``rays``, next to the auto cells after as many."""
    from meshvis.viewcells import judge, pvs
    from meshvis.viewcells.cells import ViewCells, grid_shape

    vs = result.cells.view_space
    shape = grid_shape(vs, result.cells.n_cells)
    grid = ViewCells.grid(vs, shape)
    start = _clock()
    g = pvs(soup, grid, budget=rays, target_error=0.0, seed=seed, caster=caster)
    wall, cpu = _since(start)
    done = int(g.summary["rays"]["total"])
    at = int(np.searchsorted(np.asarray(result.batches["rays"]), done))
    at = min(at, len(result.batches["rays"]) - 1)
    auto_bits = result.bits_at(at)
    s = judge.summary(judge.pixel_errors(table, g.cells, g.bits), table)
    a = judge.summary(judge.pixel_errors(table, result.cells, auto_bits), table)
    return {
        "shape": list(shape),
        "cells": g.cells.n_cells,
        "rays": done,
        "seconds": wall,
        "cpu_seconds": cpu,
        "expected_cost": g.expected_cost(),
        "mean_pvs": float(g.sizes().mean()),
        "auto_rays": int(result.batches["rays"][at]),
        "auto_expected_cost": result.expected_cost(auto_bits),
        "auto_mean": a["mean"],
        "auto_worst": a["worst"],
        **s,
    }


def format_level(r: dict) -> str:
    """The tables of one level."""
    lines = [
        f"\n{r['level']}: {r['faces']} faces, {r['cells']} cells ({r['cells_kind']}), view space {r['view_space']['kind']}"
        + (" above the ground" if "ground" in r["view_space"] else ""),
        f"AGVS: {r['seconds']:.1f} s ({r['cpu_seconds']:.1f} s CPU; load {r['load_before']} before, "
        f"{r['load_after']} after), {r['rays']} rays, stopped: {r['stopped']}; "
        f"mean PVS {r['mean_pvs']:.0f}; {r['views']} views: mean {r['final']['mean']:.2f}, worst "
        f"{r['final']['worst']:.0f} wrong pixels per million (walkthrough: mean "
        f"{r['final'].get('walkthrough_mean', 0):.2f}, worst {r['final'].get('walkthrough_worst', 0):.0f})",
        "",
        f"{'method':<22} {'seconds':>8} {'CPU s':>8} {'rays':>12} {'mean PVS':>9} {'mean':>9} {'worst':>8} {'estimate':>9}",
    ]
    for p in r["agvs_curve"]:
        lines.append(
            f"{'AGVS':<22} {p['seconds']:>8.1f} {p['cpu_seconds']:>8.1f} {p['rays']:>12} {p['mean_pvs']:>9.0f} {p['mean']:>9.2f} "
            f"{p['worst']:>8.0f} {p['estimate']:>9.2f}"
        )
    for p in r.get("random_curve", []):
        lines.append(
            f"{'per-cell random':<22} {p['seconds']:>8.1f} {p['cpu_seconds']:>8.1f} {p['rays']:>12} {p['mean_pvs']:>9.0f} "
            f"{p['mean']:>9.2f} {p['worst']:>8.0f}"
        )
    for p in r.get("gvs_curve", []):
        lines.append(
            f"{'per-cell guided':<22} {p['seconds']:>8.1f} {p['cpu_seconds']:>8.1f} {p['rays']:>12} {p['mean_pvs']:>9.0f} "
            f"{p['mean']:>9.2f} {p['worst']:>8.0f}"
        )
    g = r.get("gvs_converged")
    if g:
        t = g["agvs_seconds_to_same_mean_pvs"]
        lines.append(
            f"per-cell guided to its stop rule on {len(g['cells'])} cells: {g['seconds_per_cell']:.1f} s per cell "
            f"({g['cpu_seconds_per_cell']:.1f} s CPU), {g['extrapolated_seconds']:.0f} s "
            f"({g['extrapolated_cpu_seconds']:.0f} s CPU) for all cells; mean PVS "
            f"{g['mean_pvs']:.0f}; AGVS reached it on those cells after "
            + (
                f"{t:.1f} s, {g['agvs_cpu_seconds_to_same_mean_pvs']:.1f} s CPU (ratio {g['ratio']:.3f}, "
                f"CPU ratio {g['cpu_ratio']:.3f})"
                if t is not None
                else f"-- (it ended at {g['agvs_mean_pvs_final_same_cells']:.0f})"
            )
        )
    fl = r.get("filter")
    if fl:
        lines.append(
            f"visibility filter: {fl['added']} entries added ({fl['mean_added']:.0f} per cell), mean PVS "
            f"{fl['mean_pvs_sampled']:.0f} -> {r['mean_pvs']:.0f}; error mean {fl['sampled']['mean']:.2f} -> "
            f"{r['final']['mean']:.2f}, worst {fl['sampled']['worst']:.0f} -> {r['final']['worst']:.0f} per million"
        )
    if r["estimate_vs_measured"]:
        ratios = [
            p["estimate"] / p["measured"] if p["measured"] > 0 else np.inf for p in r["estimate_vs_measured"]
        ]
        lines.append(
            f"estimate / measured below {COMPARE_BELOW:.0f} per million: "
            + ", ".join(f"{x:.2f}" for x in ratios)
        )
    gr = r.get("grid")
    if gr:
        lines.append(
            f"render cost Σ P·|PVS|: auto cells {gr['auto_expected_cost']:.0f} after {gr['auto_rays']} rays "
            f"(error mean {gr['auto_mean']:.2f}, worst {gr['auto_worst']:.0f}); grid {'x'.join(map(str, gr['shape']))} "
            f"{gr['expected_cost']:.0f} after {gr['rays']} rays (error mean {gr['mean']:.2f}, worst {gr['worst']:.0f})"
        )
    return "\n".join(lines)


def plot_curves(results: list[dict], path: str) -> None:
    """Mean (solid) and worst (dotted) wrong pixels per million against CPU seconds, one panel per level."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from meshvis.io import atomic_write

    fig, axes = plt.subplots(1, len(results), figsize=(5 * len(results), 4), squeeze=False)
    for ax, r in zip(axes[0], results):
        for name, key, marker, colour in (
            ("AGVS", "agvs_curve", "o", "C0"),
            ("per-cell random", "random_curve", "s", "C1"),
            ("per-cell guided", "gvs_curve", "^", "C2"),
        ):
            pts = [p for p in r.get(key, []) if p["mean"] > 0]
            if pts:
                cpu = [p["cpu_seconds"] for p in pts]
                ax.plot(cpu, [p["mean"] for p in pts], marker + "-", color=colour, label=f"{name}, mean")
                ax.plot(cpu, [p["worst"] for p in pts], marker + ":", color=colour, label=f"{name}, worst")
        est = [p for p in r["agvs_curve"] if np.isfinite(p["estimate"]) and p["estimate"] > 0]
        ax.plot([p["cpu_seconds"] for p in est], [p["estimate"] for p in est], "k.", label="AGVS estimate")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("CPU seconds")
        ax.set_ylabel("wrong pixels per million")
        ax.set_title(r["level"])
        ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=110)
    plt.close(fig)
