"""Inside removal on real scenes, judged by false pixels and the dense reference (DESIGN.md §10).

For every real model with hidden geometry: the dense random reference (cached), meshvis
``remove-interior`` with ``visibility`` object / view / both, a converged guided search
(:func:`converged_search`; the share of what it removes that ``view`` removes too), random
sampling with the rays of view, and MeshLab ambient occlusion on both sides.  Per method:
removed area, share of the reference-hidden area removed, share of the area that no search
saw removed (:func:`unseen_by_all`), false pixels per million (mean and worst view, over the
whole sphere and, for scenes standing on the ground, over the views from above), rays and
time; and the curve of false pixels against rays for guided and random sampling (GVS Fig. 8).

The area that no search saw estimates the truly hidden area better than the reference alone:
every search only ever certifies a face as visible (a traced free line of sight), so a face
that the dense reference or any of ``K`` converged guided searches with the seeds
``seed + 1 .. seed + K`` saw is visible, and what none of them saw shrinks towards the
truly hidden area as ``K`` grows.  A method that removes exactly the faces it did not see
removes a share of it that rises towards 100 % with ``K``.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import numpy as np

from meshvis.eval.baselines import pymeshlab_ao
from meshvis.eval.bench.real_models import add_models_argument, models_folder
from meshvis.eval.false_pixels import SIZE, VIEWS, face_pixels, false_pixels, fibonacci_sphere
from meshvis.eval.reference import reference
from meshvis.graphcut.classify import classify
from meshvis.io import load
from meshvis.repair.remove import remove_interior
from meshvis.visibility import visible_from

#: (file under the shared models folder, up axis, stands on the ground)
MODELS = (
    ("real/pybullet__samurai_monastry.obj", "y", True),
    ("real2/so101_arm_assembly.ply", "z", False),
    ("real/cycloidal.ply", "z", False),
    ("real/CesiumMilkTruck.glb", "y", True),
    ("real2/zdm2_level.glb", "y", True),
    ("real2/pandora_level.obj", "y", True),
    ("real2/van_gogh_room.glb", "y", True),
    ("real2/mannequiny.glb", "z", True),
    ("real2/ferrari348_lowpoly.glb", "y", True),
    ("real2/dutch_ship.glb", "y", False),
)
QUICK = (
    "real/CesiumMilkTruck.glb",
    "real2/van_gogh_room.glb",
    "real2/ferrari348_lowpoly.glb",
    "real2/mannequiny.glb",
)
AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
#: random sampling for the curve gets this many times the rays of guided sampling
CURVE_RANDOM_FACTOR = 4
#: the converged search that ``view`` is judged against: a tenth of GVS's face count and
#: the default area threshold per million rays, with the next seed (with the same seed the
#: default search would be the start of it and agree by construction)
CONVERGED_MIN_NEW = 5.0
CONVERGED_MIN_NEW_AREA = 1e-5
#: converged searches (seeds seed+1 .. seed+K) whose sightings, with the reference's, make
#: the estimate of the truly hidden area (:func:`unseen_by_all`); more searches cost
#: minutes per scene and move the estimate little (the run reports every K)
SEARCHES = 3
#: the methods whose share of the area no search saw is reported for every K = 1 .. SEARCHES
BY_K_METHODS = ("object (graph cut)", "view (guided, outside)", "both")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench real`` to ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The benchmark's sub-parser.
    """
    p.add_argument(
        "--only",
        nargs="*",
        metavar="MODEL",
        help="model files or names (default: the real scenes with hidden geometry)",
    )
    add_models_argument(p)
    p.add_argument("--quick", action="store_true", help="four small models only")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--searches",
        type=int,
        default=SEARCHES,
        metavar="K",
        help=f"converged searches (seeds seed+1 .. seed+K) that with the reference estimate the truly"
        f" hidden area (default {SEARCHES})",
    )
    p.add_argument(
        "--cache",
        default=os.path.join(os.path.expanduser("~"), ".cache", "meshvis"),
        help="folder of the cached references and pixel tables (default ~/.cache/meshvis)",
    )
    p.add_argument(
        "--views", type=int, default=VIEWS, help=f"viewpoints of the false pixels (default {VIEWS})"
    )
    p.add_argument("--size", type=int, default=SIZE, help=f"image size of the false pixels (default {SIZE})")
    p.add_argument("--curve", metavar="PNG", help="plot false pixels against rays, guided and random")
    p.add_argument(
        "--worst", metavar="FOLDER", help="pictures of the worst views of object and both per model"
    )
    p.add_argument("--json", metavar="FILE", help="also write every number as JSON")
    p.add_argument(
        "--rays-per-point",
        type=int,
        default=None,
        metavar="R",
        help="ray budget per sample point of the graph cut (object and both; default: each mode's own, "
        "rays_per_node for object and rays_per_node // samples_per_face for both)",
    )


def main(args: argparse.Namespace) -> int:
    """Run ``meshvis bench real`` on the selected models and print and store the results.

    Parameters
    ----------
    args : argparse.Namespace
        The options of :func:`add_arguments`.

    Returns
    -------
    int
        Exit status 0.
    """
    from meshvis.io.jsonfile import write_json

    todo = _selection(args)
    os.makedirs(args.cache, exist_ok=True)
    results = []
    for path, up, ground in todo:
        r = run_model(
            path,
            AXES[up],
            ground,
            seed=args.seed,
            searches=args.searches,
            cache=args.cache,
            worst=args.worst,
            views=args.views,
            size=args.size,
            rays_per_point=args.rays_per_point,
        )
        print(format_model(r), flush=True)
        results.append(r)
    if args.curve:
        plot_curves(results, args.curve)
    if args.json:
        write_json(args.json, {"machine": _machine(), "results": results})
    return 0


def _selection(args) -> list[tuple[str, str, bool]]:
    folder = models_folder(args.models_dir).parent
    known = {name: (up, ground) for name, up, ground in MODELS}
    if args.only:
        out = []
        for m in args.only:
            name = next((k for k in known if k.endswith(os.path.basename(m))), None)
            up, ground = known.get(name, ("z", False))
            out.append((m if os.path.isfile(m) else str(folder / m), up, ground))
        return out
    names = QUICK if args.quick else [m[0] for m in MODELS]
    return [(str(folder / n), *known[n]) for n in names]


def _machine() -> dict:
    import embreex

    return {
        "python": platform.python_version(),
        "machine": platform.machine(),
        "cores": os.cpu_count(),
        "numpy": np.__version__,
        "embreex": getattr(embreex, "__version__", "?"),
    }


def run_model(
    path: str,
    up,
    ground: bool,
    *,
    seed: int = 0,
    searches: int = SEARCHES,
    cache: str = ".",
    worst: str | None = None,
    views: int = VIEWS,
    size: int = SIZE,
    rays_per_point: int | None = None,
) -> dict:
    """Every method on one model; one dict of rows and curves.

    Parameters
    ----------
    path : str
        The model file.
    up : (3,) float
        Up direction (for the upper views and the upper-hemisphere search).
    ground : bool
        The scene stands on the ground: also judge the upper views and search from above.
    seed : int
        Seed of every method; the converged searches use ``seed + 1 .. seed + searches``.
    searches : int
        Converged searches of the estimate of the truly hidden area (:func:`unseen_by_all`), at least 1.
    cache : str
        Folder of the cached references and pixel tables.
    worst : str, optional
        Folder for the pictures of the worst views.
    views : int
        Viewpoints of the false pixels.
    size : int
        Image size of the false pixels.
    rays_per_point : int, optional
        Ray budget per sample point of the graph cut (:func:`meshvis.classify`) of the
        object mode and of both; by default each mode's own (``rays_per_node``, and for
        both :func:`meshvis.repair.remove_modes.cut_rays_per_point`).

    Returns
    -------
    dict
        The rows (one per method), curves and summary numbers, as stored in the JSON output.
    """
    soup = load(path)
    stem = Path(path).stem
    ref = reference(soup, seed=seed, cache=os.path.join(cache, f"{stem}.seed{seed}.npz"))
    suffix = "" if (views, size) == (VIEWS, SIZE) else f".{views}x{size}"
    table = face_pixels(soup, views=views, size=size, cache=os.path.join(cache, f"{stem}.pixels{suffix}.npz"))
    ref_hidden = ~ref.seen
    rows = {"reference (dense random)": (ref.seen, int(ref.rays.sum()), ref.seconds)}

    t = time.perf_counter()
    c = classify(soup, seed=seed, rays_per_point=rays_per_point)
    obj = remove_interior(soup, classification=c, visibility="object")
    t_obj = time.perf_counter() - t
    rows["object (graph cut)"] = (obj.keep, int(c.report(per_face=False)["rays"]), t_obj)

    region = "upper-hemisphere" if ground else "outside"
    t = time.perf_counter()
    view = remove_interior(soup, visibility="view", region="outside", seed=seed)
    rows["view (guided, outside)"] = (view.keep, view.visibility.rays["total"], time.perf_counter() - t)

    # both as the command runs it: its own cut, whose sample points get less unless a
    # budget is given (then the object mode's cut is the same and is reused)
    t = time.perf_counter()
    if rays_per_point is None:
        both = remove_interior(soup, visibility="both", seed=seed)
        t_both = time.perf_counter() - t
    else:
        both = remove_interior(soup, classification=c, visibility="both", seed=seed)
        t_both = t_obj + time.perf_counter() - t
    c_both = both.classification
    assert c_both is not None  # "both" always cuts
    rays_both = both.visibility.rays["total"] + int(c_both.report(per_face=False)["rays"])
    rows["both"] = (both.keep, rays_both, t_both)

    convs, conv_seconds = [], []
    for k in range(1, max(int(searches), 1) + 1):
        t = time.perf_counter()
        convs.append(converged_search(soup, seed + k))
        conv_seconds.append(time.perf_counter() - t)
    conv = convs[0]
    rows["view converged (5 faces, seed+1)"] = (conv.seen, conv.rays["total"], conv_seconds[0])
    unseen = [unseen_by_all(ref.seen, [c.seen for c in convs[:k]]) for k in range(1, len(convs) + 1)]

    t = time.perf_counter()
    rand = visible_from(soup, budget=view.visibility.rays["total"], seed=seed, method="random")
    rows["random, rays of view"] = (rand.seen, rand.rays["total"], time.perf_counter() - t)

    ao = pymeshlab_ao(soup, both_sides=True)
    if ao.ok:
        rows["MeshLab AO both sides"] = (ao.values, 64 * 2 * soup.n_faces, ao.seconds)

    out_rows = []
    for name, (keep, rays, seconds) in rows.items():
        out_rows.append(
            _judge(
                name, soup.areas, keep, ref_hidden, unseen[-1], table, up if ground else None, rays, seconds
            )
        )
    if ground:
        t = time.perf_counter()
        hemi = remove_interior(soup, visibility="view", region=region, up=up, seed=seed)
        out_rows.append(
            _judge(
                "view (guided, upper-hemisphere)",
                soup.areas,
                hemi.keep,
                ref_hidden,
                unseen[-1],
                table,
                up,
                hemi.visibility.rays["total"],
                time.perf_counter() - t,
            )
        )
    curves = _curves(soup, view.visibility, table, seed)
    result = {
        "model": stem,
        "faces": soup.n_faces,
        "rays_per_point": c.params["rays_per_point"],
        "rays_per_point_both": c_both.params["rays_per_point"],
        "ground": ground,
        "up": list(up),
        "reference_hidden_area": float(soup.areas[ref_hidden].sum() / soup.total_area),
        "rows": out_rows,
        "curves": curves,
        "view_over_object_time": rows["view (guided, outside)"][2] / max(t_obj, 1e-9),
        "view_stopped": view.visibility.stopped,
        "converged_stopped": conv.stopped,
        "view_removes_of_converged": share_removed(soup.areas, view.keep, conv.seen),
        "searches": len(convs),
        "converged_rays": [c.rays["total"] for c in convs],
        "converged_seconds": conv_seconds,
        "unseen_area": [float(soup.areas[u].sum() / soup.total_area) for u in unseen],
        "unseen_removed_by_k": {
            name: [share_removed(soup.areas, rows[name][0], ~u) for u in unseen] for name in BY_K_METHODS
        },
    }
    if worst:
        os.makedirs(worst, exist_ok=True)
        result["worst_picture"] = worst_view_picture(
            soup, {"object": ~obj.keep, "both": ~both.keep}, table, os.path.join(worst, f"{stem}.png")
        )
    return result


def converged_search(soup, seed: int):
    """From-outside guided search run to convergence (:data:`CONVERGED_MIN_NEW`, :data:`CONVERGED_MIN_NEW_AREA`).

    Parameters
    ----------
    soup : Soup
    seed : int

    Returns
    -------
    Visibility
    """
    from meshvis import limits

    return visible_from(
        soup,
        budget=limits.MAX_RAYS,
        seed=seed,
        min_new=CONVERGED_MIN_NEW,
        min_new_area=CONVERGED_MIN_NEW_AREA,
    )


def unseen_by_all(reference_seen: np.ndarray, searches_seen: list[np.ndarray]) -> np.ndarray:
    """Faces that neither the reference nor any of the searches saw: the estimate of the truly hidden.

    Parameters
    ----------
    reference_seen : (m,) bool
        Faces the dense reference saw.
    searches_seen : list of (m,) bool
        Faces each converged search saw.

    Returns
    -------
    (m,) bool

    Examples
    --------
    >>> unseen_by_all(np.array([1, 0, 0, 0], bool), [np.array([0, 1, 0, 0], bool)]).tolist()
    [False, False, True, True]
    """
    seen = np.asarray(reference_seen, bool).copy()
    for s in searches_seen:
        seen |= np.asarray(s, bool)
    return ~seen


def share_removed(areas: np.ndarray, keep: np.ndarray, kept_by_other: np.ndarray) -> float:
    """Share of the area another method removes that ``keep`` removes too.

    Parameters
    ----------
    areas : (m,) float
    keep : (m,) bool
        Faces the judged method keeps.
    kept_by_other : (m,) bool
        Faces the other method keeps.

    Returns
    -------
    float
        1.0 when the other method removes nothing.

    Examples
    --------
    >>> share_removed(np.ones(4), np.array([0, 0, 1, 1], bool), np.array([0, 1, 1, 1], bool))
    1.0
    """
    other = ~np.asarray(kept_by_other, bool)
    total = float(areas[other].sum())
    return float(areas[other & ~np.asarray(keep, bool)].sum()) / total if total else 1.0


def _judge(name, areas, keep, ref_hidden, unseen, table, up, rays, seconds) -> dict:
    removed = ~np.asarray(keep, bool)
    total = max(float(areas.sum()), 1e-300)
    hidden_area = float(areas[ref_hidden].sum())
    fp = false_pixels(table, removed)
    row = {
        "method": name,
        "removed_area": float(areas[removed].sum()) / total,
        "reference_hidden_removed": float(areas[removed & ref_hidden].sum()) / hidden_area
        if hidden_area
        else 1.0,
        "unseen_removed": share_removed(areas, keep, ~unseen),
        "false_pixels_mean": fp["mean"],
        "false_pixels_worst": fp["worst"],
        "rays": int(rays),
        "seconds": float(seconds),
    }
    if up is not None:
        fu = false_pixels(table, removed, up=up)
        row["false_pixels_up_mean"], row["false_pixels_up_worst"] = fu["mean"], fu["worst"]
    return row


def _curves(soup, guided, table, seed: int) -> dict:
    """False pixels after r rays, from the ray count at which each face was first seen."""
    budget = CURVE_RANDOM_FACTOR * guided.rays["total"]
    # no stop rule: the curve runs to the budget
    rand = visible_from(soup, budget=budget, seed=seed, method="random", min_new=0.0, min_new_area=0.0)
    return {"guided": curve(guided, table), "random": curve(rand, table)}


def curve(vis, table) -> dict:
    """False pixels (mean) of removing every face not seen after r rays, on a log grid of r.

    Parameters
    ----------
    vis : Visibility
    table : FacePixels

    Returns
    -------
    dict
        ``rays`` and ``false_pixels_mean``, lists of 40 or fewer.
    """
    total = max(vis.rays["total"], 1)
    grid = np.unique(np.geomspace(max(total / 1000, 1), total, 40).astype(np.int64))
    fs = vis.first_seen
    fps = [false_pixels(table, ~((fs >= 0) & (fs <= r)))["mean"] for r in grid]
    return {"rays": grid.tolist(), "false_pixels_mean": fps}


def plot_curves(results: list[dict], path: str) -> None:
    """One panel per model: false pixels per million against rays, log-log (GVS Fig. 8)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = len(results)
    cols = min(n, 3)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    for ax, r in zip(axes.ravel(), results):
        for name, style in (("guided", "-"), ("random", "--")):
            cv = r["curves"][name]
            ax.loglog(cv["rays"], np.maximum(cv["false_pixels_mean"], 0.1), style, label=name)
        ref = next(x for x in r["rows"] if x["method"].startswith("reference"))
        ax.axhline(max(ref["false_pixels_mean"], 0.1), color="grey", lw=0.8, label="dense reference")
        ax.axvline(ref["rays"], color="grey", lw=0.8, ls=":")
        ax.set_title(f"{r['model']} ({r['faces']} faces)", fontsize=9)
        ax.set_xlabel("rays")
        ax.set_ylabel("false pixels per million (mean)")
        ax.legend(fontsize=7)
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    fig.tight_layout()
    from meshvis.io import atomic_write

    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=110)
    plt.close(fig)


def worst_view_picture(soup, removed: dict, table, path: str, size: int = 512) -> dict:
    """The original model from the view with the most false pixels of each removal, side by side.

    Parameters
    ----------
    removed : dict of (m,) bool
        Method name -> deleted faces; each panel shows its own worst view, the deleted faces
        that show there in red, marked with a ring (single pixels are too small to see).
    """
    from scipy import ndimage

    from meshvis.rays.camera import Camera
    from meshvis.rays.render import render, save_png

    lo, hi = soup.bounds
    center, radius = 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))
    panels, info = [], {}
    for name, gone in removed.items():
        fp = false_pixels(table, gone)
        v = max(fp["worst_view"], 0)
        d = fibonacci_sphere(len(table.model_pixels))[v]
        up = (0.0, 0.0, 1.0) if abs(d[2]) < 0.9 else (0.0, 1.0, 0.0)
        cam = Camera(center + 3 * radius * d, center, up, orthographic=True, ortho_height=2 * radius)
        r = render(soup, cam, size=(size, size), color_by=None)
        img = r.image.copy()
        bad = (r.face >= 0) & gone[np.maximum(r.face, 0)]
        ring = ndimage.binary_dilation(bad, iterations=6) & ~ndimage.binary_dilation(bad, iterations=4)
        img[ring] = (240, 150, 30)
        img[bad] = (230, 30, 30)
        panels.append(img)
        info[name] = {"view": v, "false_pixels": fp["worst"]}
    save_png(np.concatenate(panels, axis=1), path)
    return {"path": path, **info}


def format_model(r: dict) -> str:
    """Format one model's results as the lines the benchmark prints.

    Parameters
    ----------
    r : dict
        One model's results, as stored in the JSON output.

    Returns
    -------
    str
        The printed block.
    """
    lines = [
        f"{r['model']}: {r['faces']} faces, reference-hidden area {100 * r['reference_hidden_area']:.1f} %, "
        f"view/object time {r['view_over_object_time']:.2f}",
        f"  view stopped: {r['view_stopped']}; converged search stopped: {r['converged_stopped']}; "
        f"view removes {100 * r['view_removes_of_converged']:.1f} % of the area the converged search removes",
        "  area no search saw (reference and K converged searches), K = 1..{}: {}".format(
            r["searches"], ", ".join(f"{100 * a:.2f} %" for a in r["unseen_area"])
        ),
    ]
    for name, shares in r["unseen_removed_by_k"].items():
        lines.append(f"    {name} removes of it: " + ", ".join(f"{100 * x:.1f} %" for x in shares))
    head = f"  {'method':34s} {'removed':>8s} {'ref-hid':>8s} {'unseen':>8s} {'fp mean':>9s} {'fp worst':>9s}"
    head += f" {'up mean':>8s} {'up worst':>8s} {'rays':>12s} {'s':>7s}"
    lines.append(head)
    for x in r["rows"]:
        up = (
            f" {x['false_pixels_up_mean']:8.1f} {x['false_pixels_up_worst']:8.1f}"
            if "false_pixels_up_mean" in x
            else f" {'-':>8s} {'-':>8s}"
        )
        lines.append(
            f"  {x['method']:34s} {100 * x['removed_area']:7.1f}% {100 * x['reference_hidden_removed']:7.1f}%"
            f" {100 * x['unseen_removed']:7.1f}%"
            f" {x['false_pixels_mean']:9.1f} {x['false_pixels_worst']:9.1f}{up} {x['rays']:12d} {x['seconds']:7.1f}"
        )
    return "\n".join(lines)
