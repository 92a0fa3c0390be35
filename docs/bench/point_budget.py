"""Error against time over the rays per sample point and the sample points per face.

`rays_per_point` and `samples_per_face` of `meshvis.classify`, on real scenes.

Usage (from the repository root):
    python docs/bench/point_budget.py remove [MODEL ...] [--points 32,16,8] [--samples 4] [--seeds 0,1,2]
    python docs/bench/point_budget.py orient [MODEL ...] [--points 32,8] [--seeds 0,1] [--libigl]

``remove``: `remove_interior(visibility="object")` (or ``--visibility both``) judged as `meshvis bench real` judges it
(DESIGN.md §10): false pixels per million over 128 views (mean and worst view), the share of
the reference-hidden area removed, the removed area; the time is classification and removal (and the from-outside search of ``both``).
``orient``: `orient` on the model as it is and as a soup with 30 % of its faces turned over
(as `meshvis bench orientation` makes it), judged by the side reference: the decisive area
whose front is not the side that escapes (double-sided pairs left out, as there).  Both read the references and pixel tables from
``--cache`` (the caches of `meshvis bench real --cache` and `meshvis bench orientation`) and
compute the missing ones.  One process; the kernels are warmed first; default model: the
samurai monastery.
"""

import argparse
import itertools
import os
import time
import warnings
from pathlib import Path

import numpy as np

from meshvis.eval.bench.orientation import BASELINES, soup_of
from meshvis.eval.bench.real import _judge as judge
from meshvis.eval.false_pixels import face_pixels
from meshvis.eval.reference import reference
from meshvis.geometry.adjacency import weld
from meshvis.geometry.duplicates import opposite_copies
from meshvis.graphcut.classify import classify
from meshvis.io import load
from meshvis.repair.orient import orient
from meshvis.repair.remove import remove_interior

warnings.simplefilter("ignore")
LIBIGL = BASELINES["libigl_reorient"]
parser = argparse.ArgumentParser()
parser.add_argument("task", choices=("remove", "orient"))
parser.add_argument("models", nargs="*", default=["../shared/models/real/pybullet__samurai_monastry.obj"])
parser.add_argument("--cache", default="/tmp/meshvis-refcache")
parser.add_argument("--points", default="32,8", help="rays_per_point values (32 is the default budget)")
parser.add_argument("--samples", default="4", help="samples_per_face values")
parser.add_argument(
    "--rays", default="32", help="remove: rays_per_node values (rays_per_point at most these)"
)
parser.add_argument("--curve", metavar="PNG", help="remove: plot mean false pixels against time")
parser.add_argument(
    "--replot", metavar="TXT", help="remove: only draw --curve from the saved output of a run"
)
parser.add_argument("--seeds", default="0,1")
parser.add_argument("--libigl", action="store_true", help="orient: also time libigl's default")
parser.add_argument(
    "--visibility", default="object", choices=("object", "both"), help="remove: the mode judged"
)
args = parser.parse_args()


def ints(text):
    """A comma-separated list of integers."""
    return [int(x) for x in text.split(",")]


def remove_rows(model, stem):
    """One table row per setting and seed: inside removal judged by false pixels.

    Returns ``{(samples_per_face, rays_per_node, rays_per_point): [(seconds, mean false px), ...]}``.
    """
    ref = reference(model, seed=0, cache=os.path.join(args.cache, f"{stem}.seed0.npz"))
    table = face_pixels(model, cache=os.path.join(args.cache, f"{stem}.pixels.npz"))
    area, total, hidden = model.areas, model.areas.sum(), ~ref.seen
    print(
        f"\n{stem}: {model.n_faces} faces, reference-hidden area {100 * area[hidden].sum() / total:.2f} %\n"
    )
    print(
        "| samples_per_face | rays_per_node | rays_per_point | seed | classify + removal | rays | rounds "
        "| removed area | hidden removed | false px mean | false px worst |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    points = {}
    # a rays_per_point above rays_per_node is taken as rays_per_node (the default budget)
    settings = dict.fromkeys(
        (s, n, min(p, n)) for s in ints(args.samples) for n in ints(args.rays) for p in ints(args.points)
    )
    for (spf, rpn, rpp), seed in itertools.product(settings, ints(args.seeds)):
        t = time.perf_counter()
        c = classify(model, seed=seed, rays_per_node=rpn, samples_per_face=spf, rays_per_point=rpp)
        keep = remove_interior(model, classification=c, visibility=args.visibility, seed=seed).keep
        seconds = time.perf_counter() - t
        # judged by `meshvis bench real`'s own function (the "unseen" column is not printed)
        row = judge(args.visibility, area, keep, hidden, hidden, table, None, c.n_rays, seconds)
        points.setdefault((spf, rpn, rpp), []).append((seconds, row["false_pixels_mean"]))
        print(
            f"| {spf} | {rpn} | {rpp} | {seed} | {seconds:.2f} s | {c.n_rays / 1e6:.2f} M | {len(c.rounds)} "
            f"| {100 * row['removed_area']:.2f} % | {100 * row['reference_hidden_removed']:.1f} % "
            f"| {row['false_pixels_mean']:.0f} | {row['false_pixels_worst']:.0f} |",
            flush=True,
        )
    return points


def plot(curves, path):
    """Mean false pixels against time, one panel per model; a line per rays_per_node."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(curves), figsize=(5.5 * len(curves), 4.2), squeeze=False)
    for ax, (stem, points) in zip(axes[0], curves.items()):
        for rpn in sorted({k[1] for k in points}, reverse=True):
            keys = sorted((k for k in points if k[1] == rpn), key=lambda k: -k[2])
            t = [np.mean([a for a, _ in points[k]]) for k in keys]
            e = [np.mean([b for _, b in points[k]]) for k in keys]
            ax.plot(t, e, "o-", label=f"rays_per_node {rpn}")
            for k, x, y in zip(keys, t, e):
                ax.annotate(f"{k[2]}", (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
        ax.set_title(f"{stem}, visibility {args.visibility}", fontsize=10)
        ax.set_xlabel("classify + removal, mean over seeds (s)")
        ax.set_ylabel("false pixels per million (mean)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, title="point labels: rays_per_point", title_fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def orient_rows(model, stem):
    """One table row per input, setting and seed: orientation judged by the side reference."""
    ref = reference(model, seed=0, cache=os.path.join(args.cache, f"{stem}.seed0.npz"))
    m = model.n_faces
    judged = ref.decisive.copy()
    judged[opposite_copies(weld(model.vertices, model.faces)[1]).ravel()] = False  # as the bench judges
    total = ref.area[judged].sum()
    print(f"\n{stem}: {m} faces\n")
    print("| input | rays_per_point | seed | orient | error |")
    print("|---|---:|---:|---:|---:|")
    for kind, (s, turned) in [("as is", (model, np.zeros(m, bool))), ("soup", soup_of(model, 0))]:
        if args.libigl:  # libigl's default on the same input, before the meshvis runs
            for seed in ints(args.seeds):
                res = LIBIGL.run(s, **LIBIGL.fixed)
                print(f"| {kind} | libigl_reorient | {seed} | {res.seconds:.2f} s | |", flush=True)
        for rpp in ints(args.points):
            for seed in ints(args.seeds):
                t = time.perf_counter()
                r = orient(s, seed=seed, rays_per_point=rpp)
                seconds = time.perf_counter() - t
                wrong = judged & ((np.asarray(r.flipped, bool) ^ turned) != ref.outside_side.astype(bool))
                print(
                    f"| {kind} | {rpp} | {seed} | {seconds:.2f} s | {100 * ref.area[wrong].sum() / total:.3f} % |",
                    flush=True,
                )


def read_rows(path):
    """The curves of a saved ``remove`` output (the tables printed by :func:`remove_rows`)."""
    curves, stem = {}, None
    for line in open(path):
        if line.endswith(" %\n") and " faces, " in line:
            stem = line.split(":")[0]
        elif line.startswith("| 4") or line[:3].strip("| ").isdigit():
            c = [x.strip() for x in line.strip().strip("|").split("|")]
            key = (int(c[0]), int(c[1]), int(c[2]))
            curves.setdefault(stem, {}).setdefault(key, []).append((float(c[4].split()[0]), float(c[9])))
    return curves


if args.replot:
    plot(read_rows(args.replot), args.curve)
    raise SystemExit(0)
classify(load("models/assembly.obj"), seed=0)  # load the compiled kernels
curves = {}
for path in args.models:
    stem = Path(path).stem
    if args.task == "remove":
        curves[stem] = remove_rows(load(path), stem)
    else:
        orient_rows(load(path), stem)
if args.curve and curves:
    plot(curves, args.curve)
