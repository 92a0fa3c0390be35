"""Inside removal and layers on real models, judged by false pixels and the hidden area (DESIGN.md §10).

For every model: the dense random reference and the *hidden* estimate (the faces that
neither the reference nor :data:`~meshvis.eval.reference.HIDDEN_SEARCHES` long searches with
their stop rules off saw: :func:`meshvis.eval.reference.hidden`), both cached; then

* the default removal (:func:`meshvis.remove_interior`, by sight) at every seed of
  ``--seeds``: removed area, share of the hidden area removed (also once the faces that any
  seed's search or rescue pass saw, which are visible, are taken out of the estimate), false pixels per million
  (mean and worst of the views, and for scenes on the ground the views from above), the
  self-check, rays, time and why the search stopped;
* at the first seed: the cut (``object``), ``both``, random sampling with the rays of the
  default search, MeshLab ambient occlusion, the layers by sight (keeping layer 1 alone:
  its false pixels and its share of the hidden area) and the cut's layers;
* the error of the default search against its rays and time (the search records when each
  face was first seen: removing what it had not seen after a share of its rays);
* the time of the default removal over the cut's (``view/object time``).

The summary at the end checks the targets of docs/removal.md on every model: at every
seed false pixels at most 30 per million on average and 300 in the worst view, at least
95 % of the hidden area removed; keeping layer 1 alone within the same bounds, and layer 1
holding at most 5 % of the hidden area.
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
from meshvis.eval.reference import HIDDEN_MAX_RAYS, HIDDEN_SEARCHES, hidden, reference
from meshvis.io import load
from meshvis.repair.layers import layers
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
    ("ai/step1x3d_oven.glb", "y", True),
    ("ai/hunyuan3d_oven.glb", "y", True),
    ("ai/trellis_tree.glb", "y", True),
    ("ai/trellis_tree2.glb", "y", True),
    ("ai/meshy_bear.glb", "y", True),
    ("ai/step1x3d_dragon.glb", "y", False),
    ("ai/holopart_helmet.glb", "y", False),
    ("ai/holopart_tophat.glb", "y", False),
    ("ai/holopart_cart.glb", "y", False),
    ("ai/trellis2_plant.glb", "y", True),
    ("ai/triposr_dolly.glb", "y", False),
)
QUICK = (
    "real/CesiumMilkTruck.glb",
    "real2/van_gogh_room.glb",
    "real2/ferrari348_lowpoly.glb",
    "real2/mannequiny.glb",
)
#: the AI-generated models whose hidden part is an inner shell or cavity joined to the
#: outer surface (../shared/models/ai/README.md): their hidden area is the inner shell's
INNER_SHELL = (
    "step1x3d_oven",
    "hunyuan3d_oven",
    "trellis_tree",
    "trellis_tree2",
    "meshy_bear",
    "step1x3d_dragon",
)
#: the folders ``--all`` reads every model of
FOLDERS = ("real", "real2", "ai")
AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
#: random sampling for the curve gets this many times the rays of guided sampling
CURVE_RANDOM_FACTOR = 4
#: shares of the default search's rays at which its error is read (error against run time)
RAY_SHARES = (0.125, 0.25, 0.5, 1.0)
#: the targets (docs/removal.md)
TARGET_MEAN, TARGET_WORST, TARGET_HIDDEN, TARGET_LAYER1_HIDDEN = 30.0, 300.0, 0.95, 0.05
#: layers peeled by sight in the benchmark (the rest is one bucket)
MAX_LAYERS = 4
DEFAULT_SEEDS = "0,1,2,3,4"
#: the long searches of the hidden estimate take the seeds after this one, apart from the
#: seeds of the removals they judge
HIDDEN_SEED = 1000


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
        help="model files or names (default: the real and AI-generated models with hidden geometry)",
    )
    add_models_argument(p)
    p.add_argument("--quick", action="store_true", help="four small models only")
    p.add_argument(
        "--all", action="store_true", help=f"every model in the shared folders {', '.join(FOLDERS)}"
    )
    p.add_argument(
        "--seeds",
        default=DEFAULT_SEEDS,
        metavar="S,S,...",
        help=f"seeds of the default removal (default {DEFAULT_SEEDS}); the other methods run at the first",
    )
    p.add_argument(
        "--hidden-searches",
        type=int,
        default=HIDDEN_SEARCHES,
        metavar="K",
        help=f"long searches that with the reference estimate the hidden faces (default {HIDDEN_SEARCHES})",
    )
    p.add_argument(
        "--hidden-rays",
        type=int,
        default=HIDDEN_MAX_RAYS,
        metavar="RAYS",
        help=f"at most this many rays per long search (default {HIDDEN_MAX_RAYS})",
    )
    p.add_argument(
        "--cache",
        default=os.path.join(os.path.expanduser("~"), ".cache", "meshvis"),
        help="folder of the cached references, hidden estimates and pixel tables (default ~/.cache/meshvis)",
    )
    p.add_argument(
        "--views", type=int, default=VIEWS, help=f"viewpoints of the false pixels (default {VIEWS})"
    )
    p.add_argument("--size", type=int, default=SIZE, help=f"image size of the false pixels (default {SIZE})")
    p.add_argument(
        "--others", action="store_true", help="also object, both, random, MeshLab AO and the cut's layers"
    )
    p.add_argument(
        "--default-only",
        action="store_true",
        help="only the default removal at the seeds (no layers, no cut, no time ratio): splits a long run",
    )
    p.add_argument("--curve", metavar="PNG", help="plot false pixels against rays, guided and random")
    p.add_argument(
        "--worst", metavar="FOLDER", help="pictures of the worst view of the default removal per model"
    )
    p.add_argument("--json", metavar="FILE", help="also write every number as JSON")


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
    seeds = [int(s) for s in str(args.seeds).split(",") if s.strip()]
    os.makedirs(args.cache, exist_ok=True)
    _warm_up()
    results = []
    for path, up, ground in todo:
        r = run_model(
            path,
            AXES[up],
            ground,
            seeds=seeds,
            searches=args.hidden_searches,
            hidden_rays=args.hidden_rays,
            cache=args.cache,
            worst=args.worst,
            views=args.views,
            size=args.size,
            others=args.others or bool(args.curve),
            default_only=args.default_only,
        )
        print(format_model(r), flush=True)
        results.append(r)
        if args.json:  # after every model: a long run stopped part-way keeps what it measured
            write_json(args.json, {"machine": _machine(), "results": results})
    print(format_summary(results))
    if args.curve:
        plot_curves(results, args.curve)
    return 0


def _selection(args) -> list[tuple[str, str, bool]]:
    folder = models_folder(args.models_dir).parent
    known = {name: (up, ground) for name, up, ground in MODELS}
    if args.only:
        out = []
        for m in args.only:
            name = next((k for k in known if k.endswith(os.path.basename(m))), None)
            up, ground = known.get(name, _guess_up(m))
            out.append((m if os.path.isfile(m) else str(folder / m), up, ground))
        return out
    if args.all:
        names = sorted(
            f"{sub}/{p.name}"
            for sub in FOLDERS
            if (folder / sub).is_dir()
            for p in (folder / sub).iterdir()
            if p.is_file() and p.suffix.lower() != ".md"
        )
        return [(str(folder / n), *known.get(n, _guess_up(n))) for n in names]
    names = QUICK if args.quick else [m[0] for m in MODELS]
    return [(str(folder / n), *known[n]) for n in names]


def _warm_up() -> None:
    """Compile the kernels of both removals on a small model, so that no timing pays for it."""
    import trimesh

    ball = trimesh.creation.icosphere(2)
    for mode in ("view", "object"):
        remove_interior(ball, visibility=mode, seed=0)


def _guess_up(path: str) -> tuple[str, bool]:
    """Up axis of a model not in :data:`MODELS`: y for glTF and OBJ, z otherwise; not on the ground."""
    return ("y" if Path(path).suffix.lower() in (".glb", ".gltf", ".obj") else "z"), False


def _machine() -> dict:
    import embreex

    return {
        "python": platform.python_version(),
        "machine": platform.machine(),
        "cores": os.cpu_count(),
        "load": list(os.getloadavg()),
        "numpy": np.__version__,
        "embreex": getattr(embreex, "__version__", "?"),
    }


def run_model(
    path: str,
    up,
    ground: bool,
    *,
    seeds=(0,),
    searches: int = HIDDEN_SEARCHES,
    hidden_rays: int = HIDDEN_MAX_RAYS,
    cache: str = ".",
    worst: str | None = None,
    views: int = VIEWS,
    size: int = SIZE,
    others: bool = False,
    default_only: bool = False,
) -> dict:
    """Every measure on one model; one dict as stored in the JSON output.

    Parameters
    ----------
    path : str
        The model file.
    up : (3,) float
        Up direction (for the views from above).
    ground : bool
        The scene stands on the ground: also judge the views from above.
    seeds : sequence of int
        Seeds of the default removal; the other methods run at the first.
    searches : int
        Long searches of the hidden estimate.
    hidden_rays : int
        At most this many rays per long search.
    cache : str
        Folder of the cached references, hidden estimates and pixel tables.
    worst : str, optional
        Folder for a picture of the worst view of the default removal.
    views, size : int
        Viewpoints and image size of the false pixels.
    others : bool
        Also the cut, both, random sampling, MeshLab AO and the cut's layers.
    default_only : bool
        Only the default removal at ``seeds`` and its error against its rays.

    Returns
    -------
    dict
    """
    soup = load(path)
    stem = Path(path).stem
    seeds = list(seeds) or [0]
    s0 = seeds[0]
    ref = reference(soup, seed=0, cache=os.path.join(cache, f"{stem}.seed0.npz"))
    suffix = "" if (views, size) == (VIEWS, SIZE) else f".{views}x{size}"
    table = face_pixels(soup, views=views, size=size, cache=os.path.join(cache, f"{stem}.pixels{suffix}.npz"))
    est = hidden(
        soup,
        ref,
        seed=HIDDEN_SEED,
        searches=searches,
        max_rays=hidden_rays,
        cache=os.path.join(cache, f"{stem}.hidden{searches}x{hidden_rays}.npz"),
    )
    up_views = up if ground else None

    def judge(name, keep, rays, seconds, **extra) -> dict:
        return {**_judge(name, soup.areas, keep, ~ref.seen, est, table, up_views, rays, seconds), **extra}

    default_rows, first = [], None
    keeps, seen_any = [], np.zeros(soup.n_faces, bool)
    for s in seeds:
        t = time.perf_counter()
        r = remove_interior(soup, seed=s)
        seconds = time.perf_counter() - t
        vis, check, rescue = r.visibility, r.check, r.rescue
        default_rows.append(
            judge(
                f"default (view), seed {s}",
                r.keep,
                vis.rays["total"] + rescue.rays + check.rays,
                seconds,
                seed=s,
                stopped=vis.stopped,
                rescued_faces=int(rescue.seen.sum()),
                check_faces_seen=int(check.seen.sum()),
                check_area=check.seen_area_fraction,
                check_share_of_time=check.seconds / max(seconds, 1e-9),
                rescue_share_of_time=rescue.seconds / max(seconds, 1e-9),
            )
        )
        keeps.append(r.keep)
        seen_any |= vis.seen | rescue.seen
        if first is None:
            first = (r, seconds)
    r0, t_default = first
    # a face a judged search saw is visible too (a traced free line of sight): the hidden
    # estimate less every face seen by any seed's search
    hidden_all = est.hidden & ~seen_any
    for row, keep in zip(default_rows, keeps):
        row["hidden_removed_all_searches"] = _share_removed(soup.areas, hidden_all, keep)
    result: dict = {
        "model": stem,
        "faces": soup.n_faces,
        "ground": ground,
        "up": list(up),
        "inner_shell": stem in INNER_SHELL,
        "reference_hidden_area": float(soup.areas[~ref.seen].sum() / soup.total_area),
        "hidden_area": est.area_fraction,
        "hidden_searches": len(est.rays),
        "hidden_rays": est.rays.tolist(),
        "default": default_rows,
        "budget_sweep": _sweep(soup, r0.visibility, t_default, table, est),
    }
    if default_only:
        return result
    # layers by sight: layer 1 is the default removal's kept set at the same seed
    t = time.perf_counter()
    lay = layers(soup, seed=s0, max_layers=MAX_LAYERS)
    t_layers = time.perf_counter() - t
    result["layers"] = {
        "layers": lay.n_layers,
        "faces_per_layer": lay.report(per_face=False)["faces_per_layer"],
        "never_seen_faces": lay.unreached,
        "layer1": judge("layers by sight: layer 1 alone", lay.layer == 1, 0, t_layers),
        "layer1_hidden_share": 1.0 - est.removed_share(lay.layer == 1),
        "layer1_hidden_share_all_searches": 1.0 - _share_removed(soup.areas, hidden_all, lay.layer == 1),
        "layer1_is_default": bool(np.array_equal(lay.layer == 1, r0.keep)),
    }
    t = time.perf_counter()
    obj = remove_interior(soup, visibility="object", seed=s0)  # with its self-check, as the command runs it
    t_obj = time.perf_counter() - t
    c = obj.classification
    assert c is not None  # the cut's mode always classifies
    result["object_seconds"] = t_obj
    result["default_over_object_time"] = t_default / max(t_obj, 1e-9)
    rows = [judge("object (graph cut)", obj.keep, int(c.report(per_face=False)["rays"]), t_obj)]
    if others:
        rows += _others(soup, s0, r0, judge)
        t = time.perf_counter()
        cut_layers = layers(soup, visibility="object", classification=c, max_layers=MAX_LAYERS)
        result["cut_layers"] = {
            "layers": cut_layers.n_layers,
            "layer1": judge(
                "layers by the cut: layer 1 alone", cut_layers.layer == 1, 0, time.perf_counter() - t
            ),
            "layer1_hidden_share": 1.0 - est.removed_share(cut_layers.layer == 1),
        }
        result["curves"] = _curves(soup, r0.visibility, table, s0)
    result["rows"] = rows
    if worst:
        os.makedirs(worst, exist_ok=True)
        result["worst_picture"] = worst_view_picture(
            soup, {"default": ~r0.keep}, table, os.path.join(worst, f"{stem}.png")
        )
    return result


def _others(soup, seed: int, default, judge) -> list[dict]:
    """``both``, random sampling with the default search's rays and MeshLab AO, judged."""
    t = time.perf_counter()
    both = remove_interior(soup, visibility="both", seed=seed, check_rays=0)
    t_both = time.perf_counter() - t
    cb = both.classification
    assert cb is not None and both.visibility is not None
    rows = [
        judge(
            "both", both.keep, both.visibility.rays["total"] + int(cb.report(per_face=False)["rays"]), t_both
        )
    ]
    t = time.perf_counter()
    rand = visible_from(soup, budget=default.visibility.rays["total"], seed=seed, method="random")
    rows.append(judge("random, rays of the default", rand.seen, rand.rays["total"], time.perf_counter() - t))
    ao = pymeshlab_ao(soup, both_sides=True)
    if ao.ok:
        rows.append(judge("MeshLab AO both sides", ao.values, 64 * 2 * soup.n_faces, ao.seconds))
    return rows


def _share_removed(areas, hidden, keep) -> float:
    """Share of the area of ``hidden`` that a removal keeping ``keep`` removes (1.0 when none)."""
    total = float(areas[hidden].sum())
    return float(areas[hidden & ~np.asarray(keep, bool)].sum()) / total if total > 0 else 1.0


def _judge(name, areas, keep, ref_hidden, est, table, up, rays, seconds) -> dict:
    removed = ~np.asarray(keep, bool)
    total = max(float(areas.sum()), 1e-300)
    ref_area = float(areas[ref_hidden].sum())
    fp = false_pixels(table, removed)
    row = {
        "method": name,
        "removed_area": float(areas[removed].sum()) / total,
        "hidden_removed": est.removed_share(keep),
        "reference_hidden_removed": float(areas[removed & ref_hidden].sum()) / ref_area if ref_area else 1.0,
        "false_pixels_mean": fp["mean"],
        "false_pixels_worst": fp["worst"],
        "rays": int(rays),
        "seconds": float(seconds),
    }
    if up is not None:
        fu = false_pixels(table, removed, up=up)
        row["false_pixels_up_mean"], row["false_pixels_up_worst"] = fu["mean"], fu["worst"]
    return row


def _sweep(soup, vis, seconds: float, table, est) -> list[dict]:
    """The default search stopped after shares of its rays: false pixels and hidden area removed.

    From the ray count at which each face was first seen and the time after every batch
    (one run gives the whole curve: the search records both).
    """
    h = vis.history
    out = []
    for share in RAY_SHARES:
        r = share * vis.rays["total"]
        keep = (vis.first_seen >= 0) & (vis.first_seen <= r)
        k = int(np.searchsorted(h["rays"], r, side="right")) - 1
        t = h["seconds"][k] if k >= 0 else 0.0
        fp = false_pixels(table, ~keep)
        out.append(
            {
                "share_of_rays": share,
                "rays": int(r),
                "search_seconds": float(t),
                "false_pixels_mean": fp["mean"],
                "false_pixels_worst": fp["worst"],
                "hidden_removed": est.removed_share(keep),
            }
        )
    out[-1]["removal_seconds"] = seconds
    return out


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

    results = [r for r in results if "curves" in r]
    n = max(len(results), 1)
    cols = min(n, 3)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    for ax, r in zip(axes.ravel(), results):
        for name, style in (("guided", "-"), ("random", "--")):
            cv = r["curves"][name]
            ax.loglog(cv["rays"], np.maximum(cv["false_pixels_mean"], 0.1), style, label=name)
        ax.set_title(f"{r['model']} ({r['faces']} faces)", fontsize=9)
        ax.set_xlabel("rays")
        ax.set_ylabel("false pixels per million (mean)")
        ax.legend(fontsize=7)
    for ax in axes.ravel()[len(results) :]:
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


def _row(x: dict, label: str) -> str:
    up = (
        f" {x['false_pixels_up_mean']:8.1f} {x['false_pixels_up_worst']:8.0f}"
        if "false_pixels_up_mean" in x
        else f" {'-':>8s} {'-':>8s}"
    )
    return (
        f"  {label:36s} {100 * x['removed_area']:7.2f}% {100 * x['hidden_removed']:7.1f}%"
        f" {x['false_pixels_mean']:8.1f} {x['false_pixels_worst']:8.0f}{up} {x['rays'] / 1e6:8.1f} {x['seconds']:7.1f}"
    )


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
        f"{r['model']}: {r['faces']} faces; hidden {100 * r['hidden_area']:.2f} % of the area (reference and "
        f"{r['hidden_searches']} searches of {max(r['hidden_rays']) / 1e6:.0f} M rays; the reference alone "
        f"{100 * r['reference_hidden_area']:.2f} %)"
        + (
            f"; default/object time {r['default_over_object_time']:.2f}"
            if "default_over_object_time" in r
            else ""
        ),
        f"  {'method':36s} {'removed':>8s} {'hid.rem':>8s} {'fp mean':>8s} {'fp worst':>8s} {'up mean':>8s}"
        f" {'up worst':>8s} {'M rays':>8s} {'s':>7s}",
    ]
    for x in r["default"]:
        lines.append(
            _row(x, x["method"])
            + f"  {x['stopped']}; {100 * x.get('hidden_removed_all_searches', np.nan):.1f} % against every seed's"
            f" search; rescue kept {x.get('rescued_faces', 0)} faces ({100 * x.get('rescue_share_of_time', 0):.0f} %"
            f" of the time); check saw {x['check_faces_seen']} faces ({100 * x['check_area']:.2g} %),"
            f" {100 * x['check_share_of_time']:.0f} % of the time"
        )
    if "layers" in r:
        lay = r["layers"]
        lines.append(
            _row(lay["layer1"], lay["layer1"]["method"])
            + f"  layer 1 holds {100 * lay['layer1_hidden_share']:.2f} % of the hidden area"
        )
        lines.append(
            f"  layers by sight: {lay['layers']} (at most {MAX_LAYERS}), faces per layer {lay['faces_per_layer']}"
            f"; layer 1 is the default removal's kept faces: {lay['layer1_is_default']}"
        )
    for x in r.get("rows", []):
        lines.append(_row(x, x["method"]))
    if "cut_layers" in r:
        cl = r["cut_layers"]
        lines.append(
            _row(cl["layer1"], cl["layer1"]["method"])
            + f"  layer 1 holds {100 * cl['layer1_hidden_share']:.2f} % of the hidden area"
        )
    lines.append(
        "  default search stopped at a share of its rays: "
        + "; ".join(
            f"{x['share_of_rays']:g}: {x['false_pixels_mean']:.1f} / {x['false_pixels_worst']:.0f}, "
            f"{100 * x['hidden_removed']:.1f} % hidden removed, {x['search_seconds']:.1f} s"
            for x in r["budget_sweep"]
        )
    )
    return "\n".join(lines)


def format_summary(results: list[dict]) -> str:
    """The targets on every model: the worst over the seeds, and the layers' layer 1.

    Parameters
    ----------
    results : list of dict
        The models' results.

    Returns
    -------
    str
        A table with one row per model and a last line counting the models that meet every target.
    """
    head = (
        f"{'model':28s} {'faces':>7s} {'hidden':>7s} {'fp mean':>8s} {'fp worst':>8s} {'hid.rem':>8s} {'rem.all':>8s}"
        f" {'L1 mean':>8s} {'L1 worst':>8s} {'L1 hid':>7s} {'t/object':>8s}  targets"
    )
    lines = [
        "summary (default removal: the worst over the seeds; layer 1 at the first seed; rem.all: the share"
        " of the hidden area removed once the faces any seed's search saw are taken out of it)",
        head,
    ]
    met = 0
    for r in results:
        d = r["default"]
        mean = max(x["false_pixels_mean"] for x in d)
        worst = max(x["false_pixels_worst"] for x in d)
        rem = min(x["hidden_removed"] for x in d)
        rem_all = min(x.get("hidden_removed_all_searches", np.nan) for x in d)
        ok = mean <= TARGET_MEAN and worst <= TARGET_WORST and rem >= TARGET_HIDDEN
        line = (
            f"{r['model'][:28]:28s} {r['faces']:7d} {100 * r['hidden_area']:6.2f}% {mean:8.1f} {worst:8.0f}"
            f" {100 * rem:7.1f}% {100 * rem_all:7.1f}%"
        )
        if "layers" in r:  # not with --default-only
            l1 = r["layers"]["layer1"]
            l1h = r["layers"]["layer1_hidden_share"]
            ok = (
                ok
                and l1["false_pixels_mean"] <= TARGET_MEAN
                and l1["false_pixels_worst"] <= TARGET_WORST
                and l1h <= TARGET_LAYER1_HIDDEN
            )
            line += (
                f" {l1['false_pixels_mean']:8.1f} {l1['false_pixels_worst']:8.0f} {100 * l1h:6.2f}%"
                f" {r['default_over_object_time']:8.2f}"
            )
        else:
            line += f" {'-':>8s} {'-':>8s} {'-':>7s} {'-':>8s}"
        met += ok
        lines.append(f"{line}  {'met' if ok else 'MISSED'}")
    lines.append(f"{met} of {len(results)} models meet every target")
    return "\n".join(lines)
