"""Error against run time: sweep the ray budget of meshvis and the baselines' own knobs.

``meshvis bench accuracy [--quick] --out DIR`` runs, in one process and on the same inputs
(:mod:`meshvis.eval.bench.cases`), for normal orientation, inside removal and layers:

* meshvis with ``rays_per_node`` = 1, 2, 4, …, 64 and ``progressive=False`` (so that the
  budget is exactly what is asked), plus meshvis' default settings (progressive
  sampling, up to 32 rays per node) as a single point;
* every baseline of :data:`meshvis.eval.baselines.BASELINES` on the same task, with its own
  budget knob swept (libigl ``rays_total``, MeshLab ``rays``; trimesh and the CGAL peel
  have no knob and give one point).

Every point records (wall time, error) and the 1-minute load average.  Meshvis' three
applications share one classification per budget; each task's time is the
classification time plus the task's own time.

Output under ``DIR``: ``accuracy.csv`` (one row per point), ``accuracy_<task>.png`` (error
against time, both logarithmic, one panel per input and one curve per method; exact
answers, error 0, are drawn on the floor line), and ``accuracy.md`` (the machine, a
table per task, and a check of where meshvis' curve is not at or below a baseline's).
"""

from __future__ import annotations

import argparse
import csv
import io
import os
import sys
import time
from collections.abc import Iterable

import numpy as np

from meshvis.errors import OutputError
from meshvis.eval.baselines import BASELINES, require_baselines
from meshvis.eval.bench import cases as C
from meshvis.eval.bench.real_models import DEFAULT_MODELS, add_models_argument

#: meshvis sweeps (rays per node)
RAYS_FULL = (1, 2, 4, 8, 16, 32, 64)
RAYS_QUICK = (1, 4, 16)
#: baseline sweeps in ``--quick`` runs (full runs use each baseline's own ``sweep``)
QUICK_SWEEPS = {
    "libigl_reorient": (1, 10),
    "pymeshlab_reorient": (4, 16),
    "pymeshlab_ao": (4, 16),
    "pymeshlab_ao_2sided": (4, 16),
}
TASKS = ("orient", "remove", "layers")
#: errors below this are drawn on the floor of the log axis
FLOOR = 1e-5
OUTPUTS = ("accuracy.csv", "accuracy.md") + tuple(f"accuracy_{t}.png" for t in TASKS)


# ====================================================================== the sweep
def sweep(
    cases: Iterable[C.Case],
    *,
    quick: bool = False,
    seed: int = 0,
    peel_timeout: float = 300.0,
    log=print,
    models_dir: str | os.PathLike = DEFAULT_MODELS,
) -> tuple[list[C.Point], list[str]]:
    """Measure every method at every budget on every case (real ones read from ``models_dir``).

    Parameters
    ----------
    cases : iterable of Case
        The inputs (:mod:`meshvis.eval.bench.cases`).
    quick : bool
        Use the short sweeps (:data:`RAYS_QUICK`, :data:`QUICK_SWEEPS`).
    seed : int
        Seed of meshvis' classification.
    peel_timeout : float
        Time limit in seconds of one CGAL peel.
    log : callable
        Receives a progress line per case and per run.
    models_dir : str or os.PathLike
        The folder of the real models.

    Returns
    -------
    points : list of Point
        One scored run per method, budget, case and task.
    skipped : list of str
        One line per case that could not be built (missing real model).

    Raises
    ------
    ParameterError
        A real case is asked for and ``models_dir`` is not a folder.
    """
    points: list[C.Point] = []
    skipped: list[str] = []
    C.warm_up()
    for case, truth in C.built_cases(cases, skipped, log, models_dir):
        settings = [
            (r, dict(rays_per_node=r, progressive=False), False) for r in (RAYS_QUICK if quick else RAYS_FULL)
        ]
        settings.append((32, {}, True))  # the defaults: progressive, up to 32 rays per node
        for r, kw, default in settings:
            res = C.meshvis_run(truth, TASKS, seed=seed, **kw)
            for task, (sec, values, info) in res.items():
                p = C.Point(
                    case=case.name,
                    faces=truth.n_faces,
                    task=task,
                    method="meshvis_default" if default else "meshvis",
                    label="meshvis default (progressive)" if default else "meshvis",
                    knob="rays_per_node",
                    value=r,
                    seconds=sec,
                    load1=C.load1(),
                    default=default,
                    extra=info,
                    **C.score(truth, task, values),
                )
                points.append(p)
            log(
                f"  meshvis {'default' if default else f'rays_per_node={r}'}: "
                + ", ".join(
                    f"{t} {res[t][0]:.3f} s err {points[-3 + i].error:.2e}" for i, t in enumerate(TASKS)
                )
            )
        for name, b in BASELINES.items():
            values = QUICK_SWEEPS.get(name, b.sweep) if quick else b.sweep
            for v in values or (None,):
                p = C.baseline_point(truth, case.name, name, v, timeout=peel_timeout)
                points.append(p)
                state = f"err {p.error:.2e}" if p.ok else f"FAILED: {p.message}"
                log(f"  {name} {'' if v is None else f'{b.knob}={v}'}: {p.seconds:.3f} s {state}")
    return points, skipped


# ====================================================================== outputs
def write_csv(path: str, points: list[C.Point]) -> None:
    """Write the points to ``path`` as CSV, one row per point (floats to 6 significant digits).

    Parameters
    ----------
    path : str
        The CSV file, written atomically.
    points : list of Point
        The points.
    """
    from meshvis.io import atomic_write

    rows = [p.row() for p in points]
    cols = list(rows[0]) if rows else [f for f in C.Point.__dataclass_fields__ if f != "extra"]
    with atomic_write(path, "w") as fh:
        w = csv.DictWriter(fh, fieldnames=cols, lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})


def read_csv(path: str) -> list[C.Point]:
    """Read the points of an ``accuracy.csv`` written by :func:`write_csv` (to redraw charts).

    Parameters
    ----------
    path : str
        The CSV file.

    Returns
    -------
    list of Point
        The points, fields converted back to their types (``extra`` empty).
    """
    kinds = {f.name: f.type for f in C.Point.__dataclass_fields__.values()}
    points = []
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            kw = {}
            for k, v in row.items():
                t = kinds.get(k)
                kw[k] = (
                    (v == "True")
                    if t in ("bool", bool)
                    else int(v)
                    if t in ("int", int)
                    else float(v)
                    if t in ("float", float)
                    else v
                )
            points.append(C.Point(**kw))
    return points


def _methods(points: list[C.Point]) -> list[str]:
    seen: list[str] = []
    for p in points:
        if p.method not in seen:
            seen.append(p.method)
    return seen


STYLE = {
    "meshvis": dict(color="C3", marker="o", lw=2.2, zorder=5),
    "meshvis_default": dict(color="C3", marker="*", ms=14, lw=0, zorder=6),
    "libigl_reorient": dict(color="C0", marker="s"),
    "trimesh_fix_normals": dict(color="C2", marker="D"),
    "pymeshlab_reorient": dict(color="C1", marker="^"),
    "pymeshlab_ao": dict(color="C1", marker="v"),
    "pymeshlab_ao_2sided": dict(color="C4", marker="<"),
    "libigl_peel": dict(color="C0", marker="P"),
}


def plot_task(path: str, task: str, points: list[C.Point]) -> None:
    """Draw one PNG: a panel per case, error (log) against time (log), one curve per method.

    Exact answers (error 0) are drawn on the floor line :data:`FLOOR`.

    Parameters
    ----------
    path : str
        The PNG file, written atomically.
    task : {"orient", "remove", "layers"}
        The task to draw.
    points : list of Point
        All points; those of other tasks and failed runs are left out.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    from meshvis.io import atomic_write

    pts = [p for p in points if p.task == task]
    case_names = list(dict.fromkeys(p.case for p in pts))
    n = max(len(case_names), 1)
    cols = min(3, n)
    rows = (n + cols - 1) // cols
    legend_in = 0.9  # inches kept free under the panels for the legend
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 4.0 * rows + legend_in), squeeze=False)
    labels: dict[str, str] = {}
    for ax, case in zip(axes.ravel(), case_names):
        cp = [p for p in pts if p.case == case]
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(FLOOR / 2, 1.5)
        for method in _methods(cp):
            # connect the points in budget order: the curve is the sweep of the knob
            mp = sorted((p for p in cp if p.method == method and p.ok), key=lambda p: (p.value, p.seconds))
            if not mp:
                continue
            x = np.array([p.seconds for p in mp])
            y = np.maximum(np.array([p.error for p in mp]), FLOOR)
            st = dict(STYLE.get(method, {}))
            st.setdefault("lw", 1.4 if len(mp) > 1 else 0)
            ax.plot(x, y, label=mp[0].label, **st)
            labels[mp[0].label] = method
        ax.axhline(FLOOR, color="0.6", ls=":", lw=1)
        # ticks at 1, 2, 5 per decade, plain labels: readable on short and long ranges alike
        ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_ylim(FLOOR / 2, 1.5)
        ax.set_title(f"{case} ({cp[0].faces} faces)", fontsize=10)
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel("error (area fraction)")
        ax.grid(True, which="both", alpha=0.25)
    for ax in axes.ravel()[len(case_names) :]:
        ax.axis("off")
    C.shared_legend(fig, axes, fontsize=9)
    fig.suptitle(
        f"{C.TASK_TITLES[task]}: error against time (error 0 drawn at {FLOOR:g}, dotted line)", fontsize=11
    )
    height = 4.0 * rows + legend_in
    fig.tight_layout(rect=(0, legend_in / height, 1, 1 - 0.35 / height))
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    with atomic_write(path, "wb") as fh:
        fh.write(buf.getvalue())


def dominance(points: list[C.Point], task: str, case: str) -> tuple[list[str], list[str]]:
    """Compare meshvis' sweep with every baseline point of one task on one case.

    Parameters
    ----------
    points : list of Point
        All points.
    task : str
        The task.
    case : str
        The case's name.

    Returns
    -------
    beaten : list of str
        Baseline points with a lower error than any meshvis point at most as slow
        (meshvis' curve lies above them), one line each.
    earlier : list of str
        Baseline points faster than meshvis' fastest point where meshvis' fastest point is
        at least as accurate (the curves do not overlap in time; meshvis is not worse, only
        later), one line each.
    """
    mv = [p for p in points if p.case == case and p.task == task and p.method == "meshvis" and p.ok]
    beaten, earlier = [], []
    if not mv:
        return beaten, earlier
    first = min(mv, key=lambda m: m.seconds)
    for b in (p for p in points if p.case == case and p.task == task and not p.method.startswith("meshvis")):
        if not b.ok:
            continue
        knob = f" {b.knob}={b.value:g}" if b.knob else ""
        where = f"{b.method}{knob} ({C.fmt_time(b.seconds)} s, error {C.fmt_err(b.error)})"
        by_then = [m.error for m in mv if m.seconds <= b.seconds]
        if not by_then:
            if first.error > b.error:
                beaten.append(
                    f"{where}: faster than meshvis' fastest point ({C.fmt_time(first.seconds)} s, "
                    f"error {C.fmt_err(first.error)}) and more accurate"
                )
            else:
                earlier.append(where)
        elif min(by_then) > b.error:
            beaten.append(f"{where}: meshvis' best error by then is {C.fmt_err(min(by_then))}")
    return beaten, earlier


def markdown(points: list[C.Point], skipped: list[str], machine: dict, command: str, seconds: float) -> str:
    """Write the report: machine, command, one table per task, and the curve check.

    Parameters
    ----------
    points : list of Point
        All points.
    skipped : list of str
        One line per skipped case.
    machine : dict
        A result of :func:`~meshvis.eval.bench.cases.machine`.
    command : str
        The command that produced the numbers.
    seconds : float
        Wall time of the sweep.

    Returns
    -------
    str
        The Markdown text of ``accuracy.md``.
    """
    lines = C.report_head("meshvis bench accuracy", command, seconds, machine, skipped)
    for task in TASKS:
        pts = [p for p in points if p.task == task]
        if not pts:
            continue
        lines += [
            f"## {C.TASK_TITLES[task]}",
            "",
            "| case | method | points | fastest: s / error | default: s / error | best error (s) |",
            "|---|---|---:|---|---|---|",
        ]
        for case in dict.fromkeys(p.case for p in pts):
            for method in _methods([p for p in pts if p.case == case]):
                mp = [p for p in pts if p.case == case and p.method == method]
                ok = [p for p in mp if p.ok]
                if not ok:
                    lines.append(f"| {case} | {mp[0].label} | {len(mp)} | failed: {mp[0].message} | | |")
                    continue
                fast = min(ok, key=lambda p: p.seconds)
                best = min(ok, key=lambda p: (p.error, p.seconds))
                dflt = [p for p in ok if p.default]
                d_txt = f"{C.fmt_time(dflt[0].seconds)} / {C.fmt_err(dflt[0].error)}" if dflt else "–"
                n_txt = f"{len(ok)}" if len(ok) == len(mp) else f"{len(ok)} ({len(mp) - len(ok)} failed)"
                lines.append(
                    f"| {case} | {mp[0].label} | {n_txt} | "
                    f"{C.fmt_time(fast.seconds)} / {C.fmt_err(fast.error)} | {d_txt} | "
                    f"{C.fmt_err(best.error)} ({C.fmt_time(best.seconds)}) |"
                )
        lines += [""]
    lines += [
        "## Where meshvis' curve is not at or below a baseline's",
        "",
        "A baseline point is *above* meshvis' curve when some point of meshvis' sweep is at most as "
        "slow and at most as wrong.  Listed: points where meshvis' curve is above the baseline "
        "(**beaten**), and points faster than meshvis' fastest run where that run is nevertheless "
        "at least as accurate (**earlier**: the baseline finishes first, with an equal or larger error).",
        "",
    ]
    for task in TASKS:
        for case in dict.fromkeys(p.case for p in points if p.task == task):
            beaten, earlier = dominance(points, task, case)
            flag = " (crack / hidden shell)" if task == "orient" and case in C.HIDDEN_SHELL_CASES else ""
            head = f"- {C.TASK_TITLES[task]}, {case}{flag}: "
            if not beaten and not earlier:
                lines.append(head + "at or below every baseline point")
                continue
            lines.append(
                head
                + (f"**beaten** by {len(beaten)} point(s)" if beaten else "never beaten")
                + (f"; earlier: {'; '.join(earlier)}" if earlier else "")
            )
            lines += [f"  - beaten: {b}" for b in beaten]
    return "\n".join(lines) + "\n"


# ====================================================================== command
def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench accuracy`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The parser of the benchmark.
    """
    p.add_argument(
        "--out", required=True, metavar="DIR", help="folder for the CSV, charts and table (created)"
    )
    p.add_argument("--quick", action="store_true", help="small inputs and short sweeps (under two minutes)")
    p.add_argument(
        "--cases",
        metavar="A,B,...",
        help=f"inputs to run (default: all, or {','.join(C.QUICK)} "
        f"with --quick); choose from {','.join(C.CASES)}",
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--peel-timeout",
        type=float,
        default=300.0,
        metavar="S",
        help="time limit of one CGAL peel (it runs in a worker process)",
    )
    p.add_argument("--force", action="store_true", help="overwrite earlier results in DIR")
    p.add_argument("--quiet", action="store_true")
    add_models_argument(p)


def prepare_out(out: str, names: tuple[str, ...], force: bool) -> None:
    """Create ``out``; refuse to overwrite earlier results in it without ``force``.

    Parameters
    ----------
    out : str
        The output folder.
    names : tuple of str
        The files the benchmark writes there.
    force : bool
        Allow replacing them.

    Raises
    ------
    OutputError
        ``out`` cannot be created or written, or holds one of ``names`` while ``force`` is
        False.
    """
    from meshvis.io import ensure_folder

    ensure_folder(out)
    there = [n for n in names if os.path.exists(os.path.join(out, n))]
    if there and not force:
        raise OutputError(f"holds earlier results ({', '.join(there)}); use --force to overwrite", out)


def main(args: argparse.Namespace) -> int:
    """Run ``meshvis bench accuracy`` and write :data:`OUTPUTS` into ``--out``.

    Progress goes to standard error and the Markdown report to standard output, unless
    ``--quiet``.  ``--quick`` also caps the CGAL peel at 60 s.

    Parameters
    ----------
    args : argparse.Namespace
        The options of :func:`add_arguments`.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    MissingExtraError
        pymeshlab (the ``bench`` extra) is not installed.
    ParameterError
        An unknown case, or no folder of real models when a real case is asked for.
    OutputError
        ``--out`` cannot be written, or holds earlier results and ``--force`` is not given.
    """
    require_baselines()
    chosen = C.select_cases(args.cases, C.QUICK if args.quick else tuple(C.CASES))
    prepare_out(args.out, OUTPUTS, args.force)
    log = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr, flush=True))
    m = C.machine()
    t0 = time.perf_counter()
    points, skipped = sweep(
        chosen,
        quick=args.quick,
        seed=args.seed,
        peel_timeout=min(args.peel_timeout, 60.0) if args.quick else args.peel_timeout,
        log=log,
        models_dir=args.models_dir,
    )
    total = time.perf_counter() - t0
    write_csv(os.path.join(args.out, "accuracy.csv"), points)
    for task in TASKS:
        plot_task(os.path.join(args.out, f"accuracy_{task}.png"), task, points)
    command = "meshvis bench accuracy " + " ".join(
        x
        for x in [
            "--quick" if args.quick else "",
            f"--cases {args.cases}" if args.cases else "",
            f"--seed {args.seed}" if args.seed else "",
            f"--models {args.models_dir}" if args.models_dir != DEFAULT_MODELS else "",
            f"--out {args.out}",
        ]
        if x
    )
    text = markdown(points, skipped, m, command, total)
    from meshvis.io import atomic_write

    with atomic_write(os.path.join(args.out, "accuracy.md"), "w") as fh:
        fh.write(text)
    if not args.quiet:
        print(text)
    return 0
