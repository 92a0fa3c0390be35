"""Orientation on real scenes, judged by the dense random reference (DESIGN.md §10).

``meshvis bench orientation --out DIR [--quick] [--models A,B]`` runs, in one process and
on every real model of the shared model folders (``real/`` and ``real2/``):

* two inputs per model: the file **as it is**, and a **soup** of it: every face given its
  own three corners and ``round(0.3 m)`` random faces turned over (seeded).  The
  reference of the file (:func:`meshvis.eval.reference.reference`, cached under
  ``--cache``) judges both: a face turned over in the soup swaps which of its sides
  escapes, so no second reference is needed;
* meshvis ``orient`` at its defaults, libigl ``reorient_facets_raycast``, MeshLab's
  re-orientation by geometry and trimesh ``fix_normals`` at theirs, each timed end to end;
* the error of the input itself (nothing turned);
* meshvis again with ``rays_per_node`` swept (the error-against-time curve).

The error is the decisive area whose front is not the side that escapes more, over the
decisive area (:meth:`meshvis.eval.reference.Reference.orientation_error`).  Faces stored
twice with opposite winding (:mod:`meshvis.geometry.duplicates`) are judged as pairs
instead: they are left out of the error, and the pairs a method writes with one winding
(losing a side) are counted.

Output under ``DIR``: ``orientation.csv`` (one row per run), ``orientation.md`` (the
machine, a table per input kind, the orientation targets checked on the numbers) and
``orientation.png`` (error against time, one panel per model).

``meshvis bench orientation --out DIR --elevations 20 60 [--only A,B]`` measures what a
viewer above a scene sees instead (no reference, no baselines): each model as it is,
``orient``'s output at its defaults and with ``--ground auto``, rendered from each
elevation above the model's up axis (azimuth 30, 512 x 512), and the share of the
model's pixels that show a back side (``meshvis render --color-by side`` draws them
orange).  Output: ``from_above.csv`` and ``from_above.md``.
"""

from __future__ import annotations

import argparse
import csv
import io
import os
import sys
import time
from dataclasses import asdict, dataclass

import numpy as np

from meshvis.eval.baselines import BASELINES
from meshvis.eval.bench import cases as C
from meshvis.eval.bench.accuracy import prepare_out
from meshvis.eval.bench.real_models import DEFAULT_MODELS, add_models_argument, models_folder

#: share of the faces turned over in the soup inputs
FLIP = 0.3
#: the orientation baselines, in table order
METHODS = ("meshvis", "libigl_reorient", "pymeshlab_reorient", "trimesh_fix_normals")
#: meshvis ray budgets of the sweep (rays per node)
SWEEP_FULL = (2, 8, 64)
SWEEP_QUICK = (4,)
#: the inputs of ``--quick``
QUICK = ("cow.obj", "ferrari348_lowpoly.glb", "mannequiny.glb", "suzanne.obj")
#: the orientation targets (error at most the best baseline's and this share, time at most 1/5 of libigl's)
ERROR_TARGET = 1e-3
SPEED_TARGET = 5.0
#: errors below this are drawn on the floor of the log axis
FLOOR = 1e-6
OUTPUTS = ("orientation.csv", "orientation.md", "orientation.png")
FROM_ABOVE_OUTPUTS = ("from_above.csv", "from_above.md")
DEFAULT_CACHE = "/tmp/meshvis-refcache"


@dataclass
class Run:
    """One method on one input: error against the reference and wall time."""

    model: str
    kind: str  # "as is" or "soup"
    faces: int
    method: str
    rays_per_node: int  # meshvis' budget (0 for the defaults and for the baselines)
    seconds: float
    error: float
    ok: bool = True
    message: str = ""
    load1: float = 0.0
    pairs: int = 0  # double-sided pairs in the input (faces stored twice, opposite winding)
    pairs_broken: int = 0  # of them, written with the same winding (one side lost)
    error_confirmed: float = float("nan")  # on the faces a recount confirms (``--confirm``)


def model_paths(names: str | None, quick: bool, models_dir: str | os.PathLike = DEFAULT_MODELS) -> list[str]:
    """The real model files of ``models_dir`` and its sibling ``real2``, smallest first.

    ``names`` (comma-separated file names or stems) selects some of them.
    """
    root = models_folder(models_dir)
    paths = []
    for sub in (root, root.parent / "real2"):
        if sub.is_dir():
            paths += [
                os.fspath(p) for p in sorted(sub.iterdir()) if p.suffix.lower() != ".md" and p.is_file()
            ]
    paths.sort(key=os.path.getsize)
    wanted = names.split(",") if names else (QUICK if quick else None)
    if wanted is None:
        return paths
    by_name = {}
    for p in paths:
        by_name[os.path.basename(p)] = p
        by_name[os.path.splitext(os.path.basename(p))[0]] = p
    missing = [w for w in wanted if w not in by_name]
    if missing:
        from meshvis.errors import ParameterError

        raise ParameterError(
            f"unknown model(s) {', '.join(missing)}; choose from {', '.join(sorted(by_name))}"
        )
    return [by_name[w] for w in wanted]


def soup_of(soup, seed: int = 0):
    """The soup input: unwelded, ``round(FLIP m)`` random faces turned over, the model's up axis kept.

    Returns
    -------
    soup : Soup
    turned : (m,) bool
        The faces turned over
    """
    from meshvis.soup import Soup

    m = soup.n_faces
    rng = np.random.default_rng(seed)
    turned = np.zeros(m, bool)
    turned[rng.choice(m, int(round(FLIP * m)), replace=False)] = True
    corners = soup.vertices[soup.faces].reshape(-1, 3)
    faces = np.arange(3 * m, dtype=np.int64).reshape(m, 3)
    return Soup(corners, faces, up=soup.up).flipped(turned), turned


def _meshvis(soup, rays_per_node: int | None, seed: int):
    from meshvis.repair.orient import orient

    kw = {} if rays_per_node is None else {"rays_per_node": rays_per_node, "progressive": False}
    t = time.perf_counter()
    r = orient(soup, seed=seed, **kw)
    return time.perf_counter() - t, r.flipped


def run_input(name: str, kind: str, soup, turned, ref, *, sweep, seed: int, log, confirmed=None) -> list[Run]:
    """Run every method on one input and judge it by the reference.

    ``turned`` says which faces the input turned over relative to the file the reference
    was computed on; ``confirmed``, the ``(decisive, outside_side)`` of
    :meth:`meshvis.eval.reference.Confirmation.judged`, judges every run a second time.
    """
    from meshvis.geometry.adjacency import weld
    from meshvis.geometry.duplicates import opposite_copies

    m = soup.n_faces
    pairs = opposite_copies(weld(soup.vertices, soup.faces)[1])
    judged = ref.decisive.copy()
    judged[pairs.ravel()] = False  # a double-sided pair is judged as a pair: kept opposite

    def error(flipped, decisive=ref.decisive, side=ref.outside_side):
        decisive = decisive & judged
        total = ref.area[decisive].sum()
        wrong = decisive & ((np.asarray(flipped, bool) ^ turned) != side.astype(bool))
        return float(ref.area[wrong].sum() / total) if total > 0 else 0.0

    def error_confirmed(flipped):
        return float("nan") if confirmed is None else error(flipped, *confirmed)

    def broken(flipped):
        flipped = np.asarray(flipped, bool)
        return int((flipped[pairs[:, 0]] != flipped[pairs[:, 1]]).sum())

    runs = [Run(name, kind, m, "input", 0, 0.0, error(np.zeros(m, bool)), pairs=len(pairs))]
    runs[-1].error_confirmed = error_confirmed(np.zeros(m, bool))
    sec, flipped = _meshvis(soup, None, seed)
    runs.append(Run(name, kind, m, "meshvis", 0, sec, error(flipped), load1=C.load1(), pairs=len(pairs)))
    runs[-1].pairs_broken = broken(flipped)
    runs[-1].error_confirmed = error_confirmed(flipped)
    for method in METHODS[1:]:
        b = BASELINES[method]
        res = b.run(soup, **b.fixed)
        err = error(res.values) if res.ok else float("nan")
        runs.append(
            Run(name, kind, m, method, 0, res.seconds, err, res.ok, res.message, C.load1(), len(pairs))
        )
        runs[-1].pairs_broken = broken(res.values) if res.ok else 0
        runs[-1].error_confirmed = error_confirmed(res.values) if res.ok else float("nan")
    for rays in sweep:
        sec, flipped = _meshvis(soup, rays, seed)
        runs.append(
            Run(name, kind, m, "meshvis", rays, sec, error(flipped), load1=C.load1(), pairs=len(pairs))
        )
    for r in runs:
        if r.method != "input" and r.rays_per_node == 0:
            log(f"  {kind:6} {r.method:20} {C.fmt_time(r.seconds):>8} s  error {C.fmt_err(r.error)}")
    return runs


def run(
    paths: list[str], *, quick: bool, seed: int, cache: str, log=print, recount: bool = False
) -> list[Run]:
    """Both inputs of every model in ``paths``; ``recount`` also judges on the faces a recount confirms."""
    from meshvis.eval.reference import CONFIRM_RAYS, confirm, reference
    from meshvis.io import ensure_folder, load

    ensure_folder(cache)
    sweep = SWEEP_QUICK if quick else SWEEP_FULL
    runs: list[Run] = []
    for path in paths:
        name = os.path.basename(path)
        soup = load(path)
        stem = os.path.splitext(name)[0]
        t = time.perf_counter()
        ref = reference(soup, seed=seed, cache=os.path.join(cache, f"{stem}.seed{seed}.npz"))
        log(f"{name}: {soup.n_faces} faces, reference {time.perf_counter() - t:.1f} s")
        confirmed = None
        if recount:
            t = time.perf_counter()
            rec = confirm(soup, ref, cache=os.path.join(cache, f"{stem}.confirm{CONFIRM_RAYS}.npz"))
            confirmed = rec.judged(soup.n_faces)
            log(f"{name}: recount of {len(rec.faces)} decisive faces {time.perf_counter() - t:.1f} s")
        m = soup.n_faces
        kw = {"sweep": sweep, "seed": seed, "log": log, "confirmed": confirmed}
        runs += run_input(name, "as is", soup, np.zeros(m, bool), ref, **kw)
        s, turned = soup_of(soup, seed)
        runs += run_input(name, "soup", s, turned, ref, **kw)
    return runs


@dataclass
class FromAbove:
    """Back-facing pixels of one model seen from one elevation: the input and ``orient``'s outputs."""

    model: str
    faces: int
    elevation: float
    input: float  # share of the model's pixels showing a back side
    default: float  # after ``orient`` at its defaults
    ground_auto: float  # after ``orient(ground=None)``
    ground_found: bool
    seconds_default: float
    seconds_auto: float
    load1: float = 0.0


def from_above(paths: list[str], elevations: list[float], *, seed: int, log=print) -> list[FromAbove]:
    """Back-facing pixels seen from ``elevations`` before and after ``orient`` (default and ``ground=None``).

    Parameters
    ----------
    paths : list of str
        Model files.
    elevations : list of float
        Degrees above the horizon of the model's up axis (azimuth 30).
    seed : int
        Seed of ``orient``.
    log : callable
        Progress lines.

    Returns
    -------
    list of FromAbove
        One row per model and elevation.
    """
    from meshvis.eval.bench.orient_twice import back_facing
    from meshvis.io import load
    from meshvis.repair.orient import orient

    rows = []
    for path in paths:
        soup = load(path)
        t = time.perf_counter()
        default = orient(soup, seed=seed)
        t_default = time.perf_counter() - t
        t = time.perf_counter()
        auto = orient(soup, seed=seed, ground=None)
        t_auto = time.perf_counter() - t
        found = bool(auto.visibility and auto.visibility["ground"])
        for e in elevations:
            shares = [back_facing(s, e, soup.up) for s in (soup, default.soup, auto.soup)]
            rows.append(
                FromAbove(
                    os.path.basename(path), soup.n_faces, e, *shares, found, t_default, t_auto, C.load1()
                )
            )
            log(f"{rows[-1].model}: {e:g} degrees, back-facing " + ", ".join(f"{x:.3%}" for x in shares))
    return rows


def from_above_markdown(rows: list[FromAbove], command: str) -> str:
    """The table of :func:`from_above`: one row per model and elevation."""
    lines = [
        "Back-facing pixels: the share of the model's pixels that show a back side, seen from the "
        "elevation above its up axis (azimuth 30, 512 x 512), as it comes and after `orient`.",
        "",
        f"Command: `{command}`",
        "",
        "| model | faces | elevation | input | `orient` | `orient --ground auto` (ground found) | `orient` time, default / auto |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r.model} | {r.faces} | {r.elevation:g}° | {r.input:.3%} | {r.default:.3%} | "
            f"{r.ground_auto:.3%} ({'yes' if r.ground_found else 'no'}) | "
            f"{r.seconds_default:.1f} s / {r.seconds_auto:.1f} s (load {r.load1:.1f}) |"
        )
    return "\n".join(lines)


# ====================================================================== reporting
def write_csv(path: str, runs: list) -> None:
    """Write one CSV row per run to ``path`` (atomically).

    Parameters
    ----------
    path : str
        The CSV file.
    runs : list of Run or FromAbove
        The runs, in order.
    """
    from meshvis.io import atomic_write

    buf = io.StringIO()
    fields = list(asdict(runs[0]).keys()) if runs else list(Run.__dataclass_fields__)
    w = csv.DictWriter(buf, fieldnames=fields)
    w.writeheader()
    for r in runs:
        w.writerow(asdict(r))
    with atomic_write(path, "w") as fh:
        fh.write(buf.getvalue())


def _get(runs, model, kind, method, rays=0):
    return next(
        (r for r in runs if (r.model, r.kind, r.method, r.rays_per_node) == (model, kind, method, rays)), None
    )


def checks(runs: list[Run], model: str, kind: str) -> list[str]:
    """The orientation targets on one input: which of them fail ('' when all hold)."""
    mv = _get(runs, model, kind, "meshvis")
    inp = _get(runs, model, kind, "input")
    base = [r for r in (_get(runs, model, kind, b) for b in METHODS[1:]) if r is not None and r.ok]
    fails = []
    if base and mv.error > min(r.error for r in base):
        fails.append("worse than a baseline")
    if mv.error > ERROR_TARGET:
        fails.append(f"error > {100 * ERROR_TARGET:g} %")
    if mv.error > inp.error:
        fails.append("worse than the input")
    ig = _get(runs, model, kind, "libigl_reorient")
    if ig is not None and ig.ok and mv.seconds * SPEED_TARGET > ig.seconds:
        fails.append(f"slower than 1/{SPEED_TARGET:g} of libigl")
    return fails


def _pct(x: float) -> str:
    if x is None or np.isnan(x):
        return "failed"
    return "0" if x == 0 else f"{100 * x:.3f} %"


def _errors(r: Run, recounted: bool) -> str:
    """A run's error, and with ``--confirm`` its error on the confirmed faces after a slash."""
    return f"{_pct(r.error)} / {_pct(r.error_confirmed)}" if recounted else _pct(r.error)


def markdown(runs: list[Run], machine: dict, command: str, seconds: float) -> str:
    """Format the runs as the Markdown report: a table per input kind and the targets.

    Parameters
    ----------
    runs : list of Run
        The runs of :func:`run`.
    machine : dict
        The machine description of ``cases.machine``.
    command : str
        The command line that made the runs.
    seconds : float
        Wall time of the whole benchmark.

    Returns
    -------
    str
        The report.
    """
    lines = [
        "Orientation on real scenes: error = decisive area whose front is not the side that escapes "
        "more, over the decisive area (dense random reference, DESIGN.md §10); time = wall time of the "
        "call, end to end.",
        "",
        f"Command: `{command}` ({seconds:.0f} s)",
        "",
        *C.machine_lines(machine),
        "",
    ]
    recounted = any(not np.isnan(r.error_confirmed) for r in runs)
    if recounted:
        lines += [
            "Errors read *by the reference / on the faces a recount confirms* (`--confirm`: the "
            "reference's decisive faces recounted with 2,048 rays from as many points, and up to "
            "32,768 where the count is near the 4x line, "
            "`meshvis.eval.reference.confirm`); the targets are checked on the first.",
            "",
        ]
    models = list(dict.fromkeys(r.model for r in runs))
    for kind in ("as is", "soup"):
        lines += [
            f"### {'files as they are' if kind == 'as is' else f'soups: unwelded, {100 * FLIP:g} % of faces turned'}",
            "",
            "| model | faces | input | meshvis | libigl | MeshLab | trimesh | libigl / meshvis time "
            "| double-sided pairs broken (meshvis, libigl, MeshLab, trimesh) | targets |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---|---|",
        ]
        for model in models:
            row = {mth: _get(runs, model, kind, mth) for mth in ("input",) + METHODS}
            if row["meshvis"] is None:
                continue

            cells = [_errors(row["input"], recounted)]
            for mth in METHODS:
                r = row[mth]
                cells.append("–" if r is None else f"{_errors(r, recounted)} ({C.fmt_time(r.seconds)} s)")
            ig = row["libigl_reorient"]
            ratio = f"{ig.seconds / row['meshvis'].seconds:.1f}" if ig is not None and ig.ok else "–"
            fails = checks(runs, model, kind)
            n_pairs = row["input"].pairs
            pairs = (
                "–"
                if not n_pairs
                else f"of {n_pairs}: "
                + ", ".join(str(row[mth].pairs_broken) if row[mth] is not None else "–" for mth in METHODS)
            )
            lines.append(
                f"| {model} | {row['meshvis'].faces} | "
                + " | ".join(cells)
                + f" | {ratio} | {pairs} | {'all met' if not fails else '; '.join(fails)} |"
            )
        lines.append("")
    return "\n".join(lines)


def plot(path: str, runs: list[Run]) -> None:
    """One PNG: a panel per model and input kind, error (log) against time (log)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from meshvis.io import atomic_write

    panels = list(dict.fromkeys((r.model, r.kind) for r in runs))
    cols = min(4, max(len(panels), 1))
    rows = (len(panels) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows + 0.6), squeeze=False)
    style = {
        "libigl_reorient": ("C0", "s", "libigl (default)"),
        "pymeshlab_reorient": ("C1", "^", "MeshLab (default)"),
        "trimesh_fix_normals": ("C2", "D", "trimesh"),
    }
    for ax, (model, kind) in zip(axes.ravel(), panels):
        pr = [r for r in runs if r.model == model and r.kind == kind and r.ok]
        ax.set_xscale("log")
        ax.set_yscale("log")
        sw = sorted(
            (r for r in pr if r.method == "meshvis" and r.rays_per_node), key=lambda r: r.rays_per_node
        )
        if sw:
            ax.plot(
                [r.seconds for r in sw],
                [max(r.error, FLOOR) for r in sw],
                "o-",
                color="C3",
                label="meshvis, rays per node swept",
            )
        d = _get(runs, model, kind, "meshvis")
        if d is not None:
            ax.plot([d.seconds], [max(d.error, FLOOR)], "*", color="C3", ms=13, label="meshvis (defaults)")
        for mth, (col, mk, lab) in style.items():
            r = _get(runs, model, kind, mth)
            if r is not None and r.ok:
                ax.plot([r.seconds], [max(r.error, FLOOR)], mk, color=col, label=lab)
        inp = _get(runs, model, kind, "input")
        if inp is not None:
            ax.axhline(max(inp.error, FLOOR), color="0.5", ls="--", lw=1, label="input")
        ax.axhline(ERROR_TARGET, color="C3", ls=":", lw=1, label="0.1 % target")
        ax.set_ylim(FLOOR / 2, 1.5)
        ax.set_title(f"{model} ({kind})", fontsize=9)
        ax.set_xlabel("wall time (s)", fontsize=8)
        ax.set_ylabel("error", fontsize=8)
        ax.grid(True, which="both", alpha=0.25)
    for ax in axes.ravel()[len(panels) :]:
        ax.axis("off")
    C.shared_legend(fig, axes, ncol=4, fontsize=8)
    fig.tight_layout(rect=(0, 0.6 / (3.4 * rows + 0.6), 1, 1))
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    plt.close(fig)
    with atomic_write(path, "wb") as fh:
        fh.write(buf.getvalue())


# ====================================================================== command
def add_arguments(p: argparse.ArgumentParser) -> None:
    """Orientation on the real scenes against libigl, MeshLab and trimesh, judged by the dense reference."""
    p.add_argument(
        "--out", required=True, metavar="DIR", help="folder for the CSV, chart and table (created)"
    )
    p.add_argument("--quick", action="store_true", help=f"only {', '.join(QUICK)} and a one-point sweep")
    p.add_argument("--only", metavar="A,B,...", help="model files (names or stems) to run; default: all")
    add_models_argument(p)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--cache", default=DEFAULT_CACHE, metavar="DIR", help="folder of the cached references (created)"
    )
    p.add_argument("--force", action="store_true", help="overwrite earlier results in DIR")
    p.add_argument("--quiet", action="store_true")
    p.add_argument(
        "--elevations",
        nargs="+",
        type=float,
        metavar="DEG",
        help="instead of the errors: back-facing pixels seen from these elevations above the up axis, "
        "before and after orient (default and --ground auto)",
    )
    p.add_argument(
        "--confirm",
        action="store_true",
        help="also judge on the faces a recount of the reference confirms (2,048 rays per face, up to "
        "32,768 near the 4x line; cached; about a minute per 50,000 decisive faces)",
    )


def main(args: argparse.Namespace) -> int:
    """Run ``meshvis bench orientation`` and write its CSV, table and chart.

    Parameters
    ----------
    args : argparse.Namespace
        The options of :func:`add_arguments`.

    Returns
    -------
    int
        Exit status 0.
    """
    paths = model_paths(args.only, args.quick, args.models_dir)
    log = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr, flush=True))
    command = "meshvis bench orientation " + " ".join(sys.argv[3:]) if len(sys.argv) > 2 else ""
    if args.elevations:
        from meshvis.io import atomic_write

        prepare_out(args.out, FROM_ABOVE_OUTPUTS, args.force)
        rows = from_above(paths, args.elevations, seed=args.seed, log=log)
        write_csv(os.path.join(args.out, "from_above.csv"), rows)
        md = from_above_markdown(rows, command.strip())
        with atomic_write(os.path.join(args.out, "from_above.md"), "w") as fh:
            fh.write(md + "\n")
        print(md)
        return 0
    prepare_out(args.out, OUTPUTS, args.force)
    machine = C.machine()
    C.warm_up()
    t0 = time.perf_counter()
    runs = run(paths, quick=args.quick, seed=args.seed, cache=args.cache, log=log, recount=args.confirm)
    seconds = time.perf_counter() - t0
    write_csv(os.path.join(args.out, "orientation.csv"), runs)
    md = markdown(runs, machine, command.strip(), seconds)
    from meshvis.io import atomic_write

    with atomic_write(os.path.join(args.out, "orientation.md"), "w") as fh:
        fh.write(md + "\n")
    plot(os.path.join(args.out, "orientation.png"), runs)
    print(md)
    return 0
