"""Start-up cost of the command: ``meshvis info`` and others on a tiny model next to ``python -c pass``.

Each command runs in a fresh process, the commands taking turns so that a change of the
machine's load touches them alike; the table gives the median and the best of
``--repeat`` runs of each, the median's excess over bare ``python -c pass``, and the
median CPU time (user + system), which a busy machine inflates less than wall time.
Then the steps of the start are timed one by one (CPU seconds) in fresh processes.  The
default model (100 triangles) makes the work itself negligible: what is left is the
fixed cost of starting the interpreter and importing what the command needs
(``remove-interior`` adds a classification with rays and numba's compiled kernels, small
on this model but not nothing).
"""

from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import time

from meshvis.eval.bench.real_models import add_models_argument

#: the default model, in the folder of --models: 100 triangles
DEFAULT_MODEL = "soup.stl"
#: the start-up cost the command is held to (seconds over ``python -c pass``)
TARGET_SECONDS = 0.5


def add_arguments(p) -> None:
    """Add the options of ``meshvis bench startup`` to ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The benchmark's sub-parser.
    """
    p.add_argument("model", nargs="?", help=f"model for meshvis info (default: <models>/{DEFAULT_MODEL})")
    p.add_argument("--repeat", type=int, default=5, help="runs of each command; the median counts")
    add_models_argument(p)
    p.add_argument("--json", metavar="FILE", help="also write the numbers as JSON")
    p.add_argument(
        "--kernels",
        nargs="+",
        metavar="MODEL",
        help="instead: meshvis info on each model with numba's kernels and with their numpy "
        "versions, in fresh processes taking turns (median of --repeat)",
    )


def commands(model: str, out_dir: str) -> dict[str, list[str]]:
    """The measured commands, by name.

    Bare Python, ``meshvis --version``, ``meshvis info``, a parser alone (``orient --help``)
    and a whole repair (``remove-interior``, writing into ``out_dir``).
    """
    me = [sys.executable, "-m", "meshvis"]
    out = os.path.join(out_dir, "out" + os.path.splitext(model)[1])
    return {
        "python -c pass": [sys.executable, "-c", "pass"],
        "meshvis --version": [*me, "--version"],
        "meshvis info MODEL": [*me, "info", model],
        "meshvis orient --help": [*me, "orient", "--help"],
        "meshvis remove-interior": [*me, "remove-interior", model, "-o", out, "--force", "--quiet"],
    }


#: the steps of a computing command's start, timed in CPU seconds inside one fresh process:
#: ``meshvis info`` on the model, then what a model above
#: :data:`meshvis.geometry._vectorised.SMALL_MODEL_FACES` faces adds (the compiled kernels)
STEPS_CODE = """
import json, sys, time
steps, t = {}, time.process_time()
def mark(name):
    global t
    now = time.process_time(); steps[name] = now - t; t = now
import numpy; mark("numpy")
import meshvis.cli.main, meshvis.geometry.diagnostics, meshvis.io; mark("meshvis modules")
from meshvis.geometry.diagnostics import diagnose
diagnose(meshvis.io.load(sys.argv[1])); mark("the work of meshvis info")
import numba; mark("larger models: numba, imported")
import scipy.linalg.cython_blas; mark("larger models: scipy's BLAS (numba's set-up)")
from meshvis.geometry._kernels import exact_groups
exact_groups(numpy.zeros((1, 3), numpy.uint64), numpy.zeros(1, numpy.uint64))
mark("larger models: numba, first compiled kernel called")
print(json.dumps(steps))
"""


def steps(model: str, repeat: int = 3) -> dict[str, float]:
    """Median CPU seconds of each step of :data:`STEPS_CODE` over ``repeat`` fresh processes."""
    import json

    runs = [
        json.loads(
            subprocess.run(
                [sys.executable, "-c", STEPS_CODE, model], capture_output=True, text=True, check=True
            ).stdout
        )
        for _ in range(repeat)
    ]
    return {k: statistics.median(r[k] for r in runs) for k in runs[0]}


def run(model: str, repeat: int = 5) -> dict:
    """Time every command of :func:`commands` ``repeat`` times, taking turns.

    Parameters
    ----------
    model : str
        The model given to ``meshvis info``.
    repeat : int
        Runs of each command.

    Returns
    -------
    dict
        ``seconds`` (name -> list of wall times), ``median``, ``best``, ``over_python``
        (median minus the median of ``python -c pass``), ``model``, ``load`` (the load
        average before the runs), ``target``.
    """
    import tempfile

    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "0"}
    with tempfile.TemporaryDirectory(prefix="meshvis-startup-") as out_dir:
        cmds = commands(model, out_dir)
        for cmd in cmds.values():  # one untimed run each: byte code and kernel caches in place
            subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, check=True)
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
        seconds: dict[str, list[float]] = {name: [] for name in cmds}
        cpu: dict[str, list[float]] = {name: [] for name in cmds}
        for _ in range(repeat):
            for name, cmd in cmds.items():
                before = _children_cpu()
                t0 = time.perf_counter()
                subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, check=True)
                seconds[name].append(time.perf_counter() - t0)
                cpu[name].append(_children_cpu() - before)
    median = {k: statistics.median(v) for k, v in seconds.items()}
    base = median["python -c pass"]
    return {
        "model": model,
        "load": load,
        "repeat": repeat,
        "seconds": seconds,
        "median": median,
        "best": {k: min(v) for k, v in seconds.items()},
        "over_python": {k: v - base for k, v in median.items()},
        "cpu_median": {k: statistics.median(v) for k, v in cpu.items()},
        "steps_cpu": steps(model),
        "target": TARGET_SECONDS,
    }


def _children_cpu() -> float:
    """User + system CPU seconds of the finished child processes (less sensitive to load than wall time)."""
    use = resource.getrusage(resource.RUSAGE_CHILDREN)
    return use.ru_utime + use.ru_stime


def format(r: dict) -> str:
    """The table of :func:`run`'s result."""
    load = "" if r["load"] is None else f", load average {r['load']:.2f}"
    lines = [
        f"start-up: {r['model']}, median of {r['repeat']} runs each{load}",
        f"{'command':<24} {'median s':>9} {'best s':>8} {'over python s':>14} {'CPU s':>7}",
    ]
    for name in r["median"]:
        lines.append(
            f"{name:<24} {r['median'][name]:9.3f} {r['best'][name]:8.3f} {r['over_python'][name]:14.3f}"
            f" {r['cpu_median'][name]:7.3f}"
        )
    over = r["over_python"]["meshvis info MODEL"]
    verdict = "met" if over <= r["target"] else "missed"
    lines.append(f"meshvis info over python -c pass: {over:.3f} s (target <= {r['target']} s: {verdict})")
    lines.append(
        "steps of meshvis info's start, then what a larger model adds (CPU s, median of 3 fresh processes):"
    )
    width = max(len(name) for name in r["steps_cpu"])
    lines += [f"  {name:<{width}} {sec:6.3f}" for name, sec in r["steps_cpu"].items()]
    return "\n".join(lines)


#: ``meshvis info`` with the small-model threshold set (argv: model, threshold)
INFO_CODE = """
import contextlib, io, sys
import meshvis.geometry._vectorised as v
v.SMALL_MODEL_FACES = int(sys.argv[2])
from meshvis.cli.main import main
with contextlib.redirect_stdout(io.StringIO()):
    main(["info", sys.argv[1]])
"""
#: the thresholds that force each way: every model compiled, every model by numpy
WAYS = {"numba": -1, "numpy": 2**62}


def kernels(models: list[str], repeat: int = 3) -> dict:
    """``meshvis info`` on each model with numba's kernels and with their numpy versions.

    Every run is a fresh process; the models and the two ways take turns (after one
    untimed run of each).

    Returns
    -------
    dict
        ``load`` (before the runs), ``repeat``, and ``rows``: per model its ``faces`` and
        the median ``wall`` and ``cpu`` seconds of each way (``numba``, ``numpy``).
    """
    from meshvis.io import load

    def once(model: str, way: str) -> tuple[float, float]:
        before, t0 = _children_cpu(), time.perf_counter()
        cmd = [sys.executable, "-c", INFO_CODE, model, str(WAYS[way])]
        subprocess.run(cmd, stdout=subprocess.DEVNULL, check=True)
        return time.perf_counter() - t0, _children_cpu() - before

    for model in models:
        for way in WAYS:
            once(model, way)
    load_avg = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    times: dict[tuple[str, str], list[tuple[float, float]]] = {}
    for _ in range(repeat):
        for model in models:
            for way in WAYS:
                times.setdefault((model, way), []).append(once(model, way))
    rows = []
    for model in models:
        row: dict = {"model": model, "faces": load(model).n_faces}
        for way in WAYS:
            row[way] = {
                "wall": statistics.median(w for w, _ in times[(model, way)]),
                "cpu": statistics.median(c for _, c in times[(model, way)]),
            }
        rows.append(row)
    return {"load": load_avg, "repeat": repeat, "rows": rows}


def format_kernels(r: dict) -> str:
    """The table of :func:`kernels`' result."""
    load = "" if r["load"] is None else f", load average {r['load']:.2f}"
    lines = [
        f"meshvis info, numba's kernels against their numpy versions, median of {r['repeat']} runs{load}",
        f"{'model':<32} {'faces':>8} {'numba wall s':>13} {'numpy wall s':>13} {'numba CPU s':>12} {'numpy CPU s':>12}",
    ]
    for row in r["rows"]:
        a, b = row["numba"], row["numpy"]
        lines.append(
            f"{os.path.basename(row['model']):<32} {row['faces']:>8} {a['wall']:13.3f} {b['wall']:13.3f}"
            f" {a['cpu']:12.3f} {b['cpu']:12.3f}"
        )
    return "\n".join(lines)


def main(args) -> int:
    """Run ``meshvis bench startup`` and print its table."""
    from meshvis.errors import ModelError

    if args.kernels:
        for model in args.kernels:
            if not os.path.isfile(model):
                raise ModelError("file not found", model)
        k = kernels(args.kernels, max(1, int(args.repeat)))
        print(format_kernels(k))
        if args.json:
            from meshvis.io.jsonfile import write_json

            write_json(args.json, k)
        return 0
    model = args.model or os.path.join(args.models_dir, DEFAULT_MODEL)
    if not os.path.isfile(model):
        raise ModelError("file not found", model)
    r = run(model, max(1, int(args.repeat)))
    print(format(r))
    if args.json:
        from meshvis.io.jsonfile import write_json

        write_json(args.json, r)
    return 0
