"""Conservative from-point visibility on real scenes: no visible face left out, and how tight.

For each scene, ten viewpoints (:func:`viewpoints_of`: five inside, in open space, and five
outside, around it), and for each:

* the **reference**: ``--rays`` (default 10^7) uniformly random rays from the point, traced
  by Embree; a face a ray hits first is seen (cached in ``--cache``, keyed by the model's
  bytes, the point, the rays and the seed);
* the **conservative set** (:func:`meshvis.visibility.conservative.conservative_from`);
* **misses**: faces (and sides) the reference sees that the set leaves out -- must be 0;
* the **area ratio**: the set's area over the area the reference sees (1 is tight);
* the **aimed reference**, a stronger sampled set where the random rays fall short: the
  reference, plus what a jittered grid of :data:`LEAF_RAYS` x :data:`LEAF_RAYS` rays
  through each frustum the set keeps open at its subdivision limit hits first (faces seen
  through narrow gaps, where those frusta are), plus what :data:`AIMED` rays aimed at
  random points of each face of the set still unseen hit first (faces whose corners lie
  on one line are not aimed at: such a ray runs along the surface).  Every face it counts was
  hit first by a ray from the point, in the float32 Embree scene and again in float64
  (rays aimed at gaps are where float32 passes between faces sharing an edge): still a
  lower bound of the exact set;
* misses against each reference, and the area ratio against each (``ratio``, ``ratio*``);
* where the excess over the aimed reference comes from, as shares of its area: ``limit``,
  kept only by frusta at the subdivision limit
  (:attr:`~meshvis.visibility.conservative.ConservativeSet.at_limit`); ``parts``, hidden
  along the aimed rays by two or more parts (faces joined across edges) that no one
  blocker can span;
* frusta traced; of them, at the limit without a blocker (``open``) and, of those, covered
  by the union of the triangles meeting them (``fused``, occluder fusion);
* seconds and CPU seconds (all threads), frusta per second of each.

``--sweep`` adds the error against run time: the area ratio and frusta of the first scene's
points at several subdivision limits.  ``--throughput`` measures frusta per second over the
first scene's viewpoints on one thread (``MESHVIS_THREADS=1``; wall and CPU time) and on all
threads, side by side.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import time

import numpy as np

from meshvis.eval.bench.real_models import add_models_argument, models_folder

#: the scenes, relative to the parent of ``--models``
SCENES = (
    "real/pybullet__samurai_monastry.obj",
    "real2/zdm2_level.glb",
    "real2/pandora_level.obj",
    "real2/so101_arm_assembly.ply",
)
#: viewpoints per scene inside (in open space) and outside
INSIDE, OUTSIDE = 5, 5
#: reference rays per viewpoint
RAYS = 10_000_000
#: an inside point is in open space when at least this share of random rays from it hit
#: something, and at least this share of those hit a front side (faces wound towards the
#: space the scene encloses)
INSIDE_HITS, INSIDE_FRONT = 0.5, 0.75
#: rays of that test, and candidate points tried
PROBE_RAYS, CANDIDATES = 256, 400
#: outside viewpoints: on a sphere of this many bounding-sphere radii around the centre
OUTSIDE_RADIUS = 1.5
#: subdivision limits of ``--sweep``
SWEEP_LEVELS = (7, 9, 11, 13)
#: rays aimed at each face of the set that the reference did not see
AIMED = 64
#: rays along each side of a frustum kept open at the limit (a jittered grid through it)
LEAF_RAYS = 8
#: bump when the reference changes
VERSION = 1


def viewpoints_of(soup, caster, seed: int = 0) -> list[tuple[str, np.ndarray]]:
    """Five viewpoints inside the scene's open space and five outside it: ``(kind, point)``.

    Inside: random points of the bounding box, kept when :data:`INSIDE_HITS` of
    :data:`PROBE_RAYS` random rays hit the scene and :data:`INSIDE_FRONT` of those a front
    side (best ones first if fewer qualify among :data:`CANDIDATES`).  Outside: a Fibonacci
    sphere of :data:`OUTSIDE_RADIUS` bounding-sphere radii around the box centre.
    """
    from meshvis.rays.samples import uniform_sphere

    rng = np.random.default_rng(seed)
    lo, hi = soup.bounds
    candidates = lo + rng.random((CANDIDATES, 3)) * (hi - lo)
    d = uniform_sphere(PROBE_RAYS, rng)
    score = np.zeros(CANDIDATES)
    for i, p in enumerate(candidates):
        h = caster.intersect(np.broadcast_to(p, d.shape), d)
        hit = h.face >= 0
        front = float((h.side[hit] == 0).mean()) if hit.any() else 0.0
        score[i] = front if hit.mean() >= INSIDE_HITS else -1.0
    order = np.argsort(-score, kind="stable")
    good = [i for i in order if score[i] >= INSIDE_FRONT][:INSIDE]
    inside = good + [i for i in order if i not in good][: INSIDE - len(good)]
    centre, radius = 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))
    k = np.arange(OUTSIDE) + 0.5
    z = 1 - 2 * k / OUTSIDE
    phi = np.pi * (3 - np.sqrt(5)) * k
    ring = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], axis=1)
    return [("inside", candidates[i]) for i in inside] + [
        ("outside", centre + OUTSIDE_RADIUS * radius * r) for r in ring
    ]


def reference_seen(scene, point: np.ndarray, rays: int, seed: int, cache: str | None) -> np.ndarray:
    """(m, 2) bool: the sides that ``rays`` uniformly random rays from ``point`` hit first (cached)."""
    from meshvis.io import atomic_write
    from meshvis.visibility.conservative import sample_views
    from meshvis.visibility.viewpoints import Viewpoint, cube_roots

    soup = scene.soup
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(soup.vertices, np.float64).tobytes())
    h.update(np.ascontiguousarray(soup.faces, np.int64).tobytes())
    h.update(repr((VERSION, np.asarray(point, np.float64).tobytes(), int(rays), int(seed))).encode())
    path = os.path.join(cache, f"conservative-ref-{h.hexdigest()[:24]}.npz") if cache else None
    if path and os.path.isfile(path):
        with np.load(path) as data:
            return np.unpackbits(data["seen"])[: 2 * soup.n_faces].reshape(-1, 2).astype(bool)
    seen = sample_views(
        scene, [Viewpoint(np.asarray(point, np.float64), cube_roots())], rays, np.random.default_rng(seed)
    )
    if path:
        os.makedirs(cache, exist_ok=True)
        with atomic_write(path, "wb") as fh:
            np.savez_compressed(fh, seen=np.packbits(seen.ravel()))
    return seen


def aimed_seen(
    scene, point: np.ndarray, faces: np.ndarray, rays: int, rng: np.random.Generator, part: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Rays aimed at random points of each of ``faces``: what they see, and what hides the faces.

    Returns ``(seen, parts)``: (m, 2) bool, the sides that ``rays`` rays aimed at random
    points of each of ``faces`` hit first (confirmed in float64:
    :func:`~meshvis.visibility.conservative.confirm_hits`); (len(faces),) int64, how many parts (``part``,
    a label per face) those rays hit first, the face itself left out.  A face hidden by
    two parts or more can only be proved hidden by their union.
    """
    from meshvis.rays.samples import uniform_in_triangles
    from meshvis.visibility.conservative import FILLER_WIDTH, confirm_hits

    out = np.zeros((scene.soup.n_faces, 2), bool)
    parts = np.zeros(len(faces), np.int64)
    # a ray aimed at a face whose corners lie on one line runs along the surface, through
    # the joint that face closes: such faces are not aimed at (other rays may hit them)
    tri = scene.triangles[faces]
    longest = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(axis=1)
    flat = 2.0 * scene.soup.areas[faces] <= FILLER_WIDTH * scene.soup.diagonal * longest
    per = max(1, (1 << 20) // max(rays, 1))
    for lo in range(0, len(faces), per):
        chunk = faces[lo : lo + per][~flat[lo : lo + per]]
        if len(chunk) == 0:
            continue
        target = uniform_in_triangles(np.repeat(scene.triangles[chunk], rays, axis=0), rng)
        d = target - point
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        hits = scene.caster.intersect(np.broadcast_to(point, d.shape), d)
        confirm_hits(scene, point, d, hits.face, hits.side, out)
        ok = hits.face >= 0
        label = np.where(ok, part[np.maximum(hits.face, 0)], -1).reshape(len(chunk), rays)
        label[hits.face.reshape(len(chunk), rays) == chunk[:, None]] = -1
        label.sort(axis=1)
        distinct = (label[:, 1:] != label[:, :-1]) & (label[:, 1:] >= 0)
        parts[lo : lo + per][~flat[lo : lo + per]] = (label[:, 0] >= 0) + distinct.sum(axis=1)
    return out, parts


def run_scene(
    path: str, *, rays: int, seed: int, cache: str | None, max_level: int, leaf_rays: int = LEAF_RAYS
) -> list[dict]:
    """Every viewpoint of one scene: misses, area ratios, where the excess comes from, frusta, time."""
    from meshvis.geometry.adjacency import components, edges, face_adjacency
    from meshvis.io import load
    from meshvis.visibility.conservative import FrustumScene, conservative_from, sample_frusta

    soup = load(path)
    t = time.perf_counter()
    scene = FrustumScene.build(soup)
    build = time.perf_counter() - t
    # parts: faces joined across edges, the most one blocker can span
    part = components(soup.n_faces, face_adjacency(edges(scene.welded), manifold_only=False))[1]
    points = viewpoints_of(soup, scene.caster, seed)
    regions = ["points:" + ",".join(repr(float(x)) for x in p) for _, p in points]
    conservative_from(soup, regions[0], max_level=min(max_level, 6), scene=scene)  # compiled, warm
    rows = []
    for i, ((kind, point), region) in enumerate(zip(points, regions)):
        seen = reference_seen(scene, point, rays, seed + 1 + i, cache)
        cpu = time.process_time()
        c = conservative_from(soup, region, max_level=max_level, scene=scene)
        cpu = time.process_time() - cpu
        may = c.visible_side
        area = soup.areas
        # the aimed reference: rays through the open frusta, then at the faces still unseen
        leaf = sample_frusta(scene, point, c.open_frusta[0], leaf_rays, np.random.default_rng(seed + 200 + i))
        strong = seen | leaf
        gap = np.flatnonzero(may.any(axis=1) & ~strong.any(axis=1))
        aimed, parts = aimed_seen(scene, point, gap, AIMED, np.random.default_rng(seed + 100 + i), part)
        strong |= aimed
        seen_area = float(area[seen.any(axis=1)].sum())
        strong_area = float(area[strong.any(axis=1)].sum())
        may_area = float(area[may.any(axis=1)].sum())
        # the excess over the aimed reference, and why it is kept
        hidden = ~strong.any(axis=1)[gap]
        excess = max(float(area[gap[hidden]].sum()), 1e-300)
        rows.append(
            {
                "model": os.path.basename(path),
                "kind": kind,
                "point": [float(x) for x in point],
                "faces": int(soup.n_faces),
                "seen_faces": int(seen.any(axis=1).sum()),
                "conservative_faces": int(may.any(axis=1).sum()),
                "missed_faces": int((seen.any(axis=1) & ~may.any(axis=1)).sum()),
                "missed_sides": int((seen & ~may).sum()),
                "area_ratio": may_area / seen_area if seen_area > 0 else float("nan"),
                "leaf_faces": int((leaf.any(axis=1) & ~seen.any(axis=1)).sum()),
                "aimed_faces": int((strong.any(axis=1) & ~seen.any(axis=1)).sum()),
                "aimed_seen_faces": int(strong.any(axis=1).sum()),
                "missed_faces_aimed": int((strong.any(axis=1) & ~may.any(axis=1)).sum()),
                "missed_sides_aimed": int((strong & ~may).sum()),
                "area_ratio_aimed": may_area / strong_area if strong_area > 0 else float("nan"),
                "excess_at_limit": float(area[gap[hidden & c.at_limit[gap]]].sum()) / excess,
                "excess_several_parts": float(area[gap[hidden & (parts >= 2)]].sum()) / excess,
                "frusta": int(c.frusta["traced"]),
                "open": int(c.frusta["open"]),
                "fused": int(c.frusta["fused"]),
                "seconds": c.seconds,
                "cpu_seconds": cpu,
                "scene_seconds": build,
            }
        )
    return rows


def sweep(path: str, *, rays: int, seed: int, cache: str | None, levels=SWEEP_LEVELS) -> list[dict]:
    """Area ratio, frusta and time of one scene's viewpoints at several subdivision limits."""
    from meshvis.io import load
    from meshvis.visibility.conservative import FrustumScene, conservative_from

    soup = load(path)
    scene = FrustumScene.build(soup)
    points = viewpoints_of(soup, scene.caster, seed)
    seen = [reference_seen(scene, p, rays, seed + 1 + i, cache) for i, (_, p) in enumerate(points)]
    out = []
    for level in levels:
        ratios, frusta, seconds, missed = [], 0, 0.0, 0
        for (_, point), s in zip(points, seen):
            region = "points:" + ",".join(repr(float(x)) for x in point)
            c = conservative_from(soup, region, max_level=level, scene=scene)
            area = soup.areas
            ratios.append(float(area[c.visible].sum()) / float(area[s.any(axis=1)].sum()))
            frusta += c.frusta["traced"]
            seconds += c.seconds
            missed += int((s.any(axis=1) & ~c.visible).sum())
        out.append(
            {
                "max_level": level,
                "area_ratio": float(np.mean(ratios)),
                "frusta": frusta,
                "seconds": seconds,
                "missed": missed,
            }
        )
    return out


def throughput(path: str, *, seed: int, max_level: int) -> dict:
    """Frusta per second over the scene's viewpoints: on one thread (wall and CPU time), and on all.

    The CPU time of the one-thread run is what one core gives whatever else the machine
    runs; wall times depend on the load, printed beside them.
    """
    from meshvis._threads import default_threads
    from meshvis.io import load
    from meshvis.visibility.conservative import FrustumScene, conservative_from

    soup = load(path)
    scene = FrustumScene.build(soup)
    regions = [
        "points:" + ",".join(repr(float(x)) for x in p) for _, p in viewpoints_of(soup, scene.caster, seed)
    ]
    conservative_from(soup, regions[0], max_level=min(max_level, 6), scene=scene)  # compiled, warm
    out = {}
    old = os.environ.get("MESHVIS_THREADS")
    try:
        for threads in (1, default_threads()):
            os.environ["MESHVIS_THREADS"] = str(threads)
            frusta, wall, cpu = 0, time.perf_counter(), time.process_time()
            for region in regions:
                frusta += conservative_from(soup, region, max_level=max_level, scene=scene).frusta["traced"]
            wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
            out[f"{threads} thread" + ("s" if threads > 1 else "")] = {
                "frusta": frusta,
                "seconds": wall,
                "cpu_seconds": cpu,
                "per_second": frusta / wall,
                "per_cpu_second": frusta / cpu,
            }
    finally:
        if old is None:
            os.environ.pop("MESHVIS_THREADS", None)
        else:
            os.environ["MESHVIS_THREADS"] = old
    return out


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench conservative`` to ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The benchmark's sub-parser.
    """
    from meshvis.visibility.conservative import DEFAULT_MAX_LEVEL

    p.add_argument("scenes", nargs="*", help=f"scene files (default: {', '.join(SCENES)})")
    p.add_argument("--rays", type=int, default=RAYS, help=f"reference rays per viewpoint (default {RAYS})")
    p.add_argument("--max-level", type=int, default=DEFAULT_MAX_LEVEL, help="subdivision limit")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--leaf-rays",
        type=int,
        default=LEAF_RAYS,
        help=f"aimed reference: rays along each side of an open frustum (default {LEAF_RAYS})",
    )
    p.add_argument(
        "--sweep", action="store_true", help="area ratio against frusta at several limits (first scene)"
    )
    p.add_argument(
        "--throughput", action="store_true", help="frusta per second, one thread and all (first scene)"
    )
    p.add_argument(
        "--cache",
        default=os.path.join(os.path.expanduser("~"), ".cache", "meshvis"),
        help="folder of the cached references (default ~/.cache/meshvis)",
    )
    p.add_argument("--json", metavar="FILE", help="also write every number as JSON")
    add_models_argument(p)


def main(args: argparse.Namespace) -> int:
    """CLI entry of ``meshvis bench conservative``: prints one table per part."""
    base = os.path.dirname(os.path.abspath(models_folder(args.models_dir)))
    paths = args.scenes or [os.path.join(base, s) for s in SCENES]
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    result: dict = {"load": load, "rays": args.rays, "max_level": args.max_level}
    print(
        f"reference: {args.rays} random rays per viewpoint; aimed reference: it, {args.leaf_rays}x{args.leaf_rays} "
        f"rays through each open frustum, {AIMED} at each face still unseen; max level {args.max_level}; load {load:.1f}"
    )
    head = (
        f"{'scene':<28} {'point':<8} {'faces':>7} {'seen':>7} {'seen*':>7} {'in set':>7} {'missed':>6} "
        f"{'miss*':>6} {'ratio':>6} {'ratio*':>6} {'limit':>6} {'parts':>6} {'frusta':>9} {'open':>8} {'fused':>8} "
        f"{'time':>7} {'frusta/s':>9} {'CPU':>7} {'per CPU s':>9}"
    )
    print(head)
    rows = []
    for path in paths:
        scene_rows = run_scene(
            path,
            rays=args.rays,
            seed=args.seed,
            cache=args.cache,
            max_level=args.max_level,
            leaf_rays=args.leaf_rays,
        )
        for r in scene_rows:
            print(
                f"{r['model'][:28]:<28} {r['kind']:<8} {r['faces']:>7} {r['seen_faces']:>7} "
                f"{r['aimed_seen_faces']:>7} {r['conservative_faces']:>7} {r['missed_faces']:>6} "
                f"{r['missed_faces_aimed']:>6} {r['area_ratio']:>6.2f} {r['area_ratio_aimed']:>6.2f} "
                f"{r['excess_at_limit']:>6.0%} {r['excess_several_parts']:>6.0%} {r['frusta']:>9} "
                f"{r['open']:>8} {r['fused']:>8} {r['seconds']:>6.2f}s {r['frusta'] / r['seconds']:>9.0f} "
                f"{r['cpu_seconds']:>6.2f}s {r['frusta'] / r['cpu_seconds']:>9.0f}"
            )
        mean = float(np.mean([r["area_ratio"] for r in scene_rows]))
        mean_aimed = float(np.mean([r["area_ratio_aimed"] for r in scene_rows]))
        at_limit = float(np.mean([r["excess_at_limit"] for r in scene_rows]))
        several = float(np.mean([r["excess_several_parts"] for r in scene_rows]))
        frusta = sum(r["frusta"] for r in scene_rows)
        wall = sum(r["seconds"] for r in scene_rows)
        cpu = sum(r["cpu_seconds"] for r in scene_rows)
        print(
            f"{os.path.basename(path)[:28]:<28} {'all':<8} {'':>7} {'':>7} {'':>7} {'':>7} "
            f"{sum(r['missed_faces'] for r in scene_rows):>6} {sum(r['missed_faces_aimed'] for r in scene_rows):>6} "
            f"{mean:>6.2f} {mean_aimed:>6.2f} {at_limit:>6.0%} {several:>6.0%} {frusta:>9} "
            f"{sum(r['open'] for r in scene_rows):>8} {sum(r['fused'] for r in scene_rows):>8} "
            f"{wall:>6.2f}s {frusta / wall:>9.0f} "
            f"{cpu:>6.2f}s {frusta / cpu:>9.0f}"
        )
        rows += scene_rows
    result["rows"] = rows
    if args.sweep:
        result["sweep"] = sweep(paths[0], rays=args.rays, seed=args.seed, cache=args.cache)
        print(f"\nerror against run time, {os.path.basename(paths[0])} (all its viewpoints)")
        print(f"{'max level':>9} {'mean ratio':>10} {'frusta':>10} {'seconds':>8} {'missed':>7}")
        for s in result["sweep"]:
            print(
                f"{s['max_level']:>9} {s['area_ratio']:>10.3f} {s['frusta']:>10} {s['seconds']:>8.1f} {s['missed']:>7}"
            )
    if args.throughput:
        result["throughput"] = throughput(paths[0], seed=args.seed, max_level=args.max_level)
        print(
            f"\nthroughput, {os.path.basename(paths[0])}, its {INSIDE + OUTSIDE} viewpoints, load {os.getloadavg()[0]:.1f}"
        )
        for k, t in result["throughput"].items():
            print(
                f"{k:>10}: {t['frusta']} frusta in {t['seconds']:.2f} s ({t['per_second']:.0f}/s), "
                f"{t['cpu_seconds']:.2f} CPU s ({t['per_cpu_second']:.0f} per CPU second)"
            )
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(result, fh, indent=1)
    return 0
