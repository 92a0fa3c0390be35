"""Inputs, runners and scoring shared by ``meshvis bench compare`` and ``meshvis bench accuracy``.

A *case* is a ground-truth model (:mod:`meshvis.eval.generators`) turned into a triangle soup
with half of its faces turned over (``soupify(truth, flip=0.5)``: unwelded, shuffled,
randomly flipped), so that orientation has something to repair.  Real models come from
the shared model folder; a missing file skips its case with a note instead of failing.

A *point* is one run of one method at one budget on one case and one task, scored
against the truth (:mod:`meshvis.eval.metrics`) and stamped with the machine's load average,
because the machine these numbers come from is shared.
"""

from __future__ import annotations

import os
import platform
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from meshvis.eval import generators as gen
from meshvis.eval.baselines import BASELINES, Baseline, BaselineResult
from meshvis.eval.bench.real_models import DEFAULT_MODELS, models_folder
from meshvis.eval.generators import GroundTruth
from meshvis.eval.metrics import layer_error, orientation_error, removal_scores

__all__ = [
    "Case",
    "Point",
    "CASES",
    "QUICK",
    "HIDDEN_SHELL_CASES",
    "select_cases",
    "load_case",
    "meshvis_run",
    "baseline_point",
    "score",
    "machine",
    "machine_lines",
    "load1",
    "warm_up",
    "fmt_err",
    "fmt_time",
]

TASK_TITLES = {"orient": "normal orientation", "remove": "inside removal", "layers": "layers"}


@dataclass(frozen=True)
class Case:
    """A named input: how to build its truth, and what it tests."""

    name: str
    #: called with no argument, or for a real case with the folder of the real models
    build: Callable[..., GroundTruth]
    note: str
    real: bool = False


def _soup(make: Callable[..., GroundTruth], seed: int = 0) -> Callable[..., GroundTruth]:
    return lambda *folder: gen.soupify(make(*folder), flip=0.5, seed=seed)


def _real(file: str) -> Callable[[Path], GroundTruth]:
    return lambda folder: gen.from_closed_mesh(os.fspath(folder / file))


#: every case, in report order
CASES: dict[str, Case] = {
    c.name: c
    for c in [
        Case(
            "sphere_pair",
            _soup(gen.sphere_pair),
            "outer sphere with a 6-face crack around a hidden inner sphere",
        ),
        Case("nested_shells", _soup(gen.nested_shells), "three concentric closed spheres"),
        Case(
            "cracked_box", _soup(gen.cracked_box), "single-sheet box with hairline cracks, small box inside"
        ),
        Case("box_with_opening", _soup(gen.box_with_opening), "cave: a large opening, two-sided interior"),
        Case("cup", _soup(gen.cup), "open cup modelled as one sheet (every face two-sided)"),
        Case(
            "terrain",
            _soup(gen.terrain),
            "open heightfield; meshvis gets the generator's side hints, the baselines cannot take any",
        ),
        Case("house", _soup(gen.house), "rooms with shared coplanar walls and furniture inside"),
        Case("overlapping_solids", _soup(gen.overlapping_solids), "a sphere and a box that interpenetrate"),
        Case("assembly", _soup(gen.assembly), "engine-like assembly of 36 parts, pistons hidden"),
        Case(
            "skin_ribcage", _soup(gen.skin_and_ribcage), "dm_control dog skin with the rib cage inside", True
        ),
        Case("cow", _soup(_real("cow.obj")), "cow.obj, closed", True),
        Case("spot", _soup(_real("spot.obj")), "spot.obj, closed", True),
        Case("dog_skin", _soup(_real("dm_control__SKINbody.stl")), "dm_control skin alone, closed", True),
    ]
}

#: the cases of ``--quick`` runs (small, crack and hidden shells, one real model)
QUICK = ("sphere_pair", "nested_shells", "cracked_box", "cow")
#: cases with a crack or a hidden shell: where the orientation curves are compared
HIDDEN_SHELL_CASES = ("sphere_pair", "nested_shells", "cracked_box", "skin_ribcage")


def select_cases(names: str | None, default: tuple[str, ...]) -> list[Case]:
    """Look up the cases named in a comma-separated list.

    Parameters
    ----------
    names : str or None
        Comma-separated case names (blanks around names ignored); None or empty for
        ``default``.
    default : tuple of str
        The names used when ``names`` gives none.

    Returns
    -------
    list of Case
        The cases, in the order named.

    Raises
    ------
    ParameterError
        A name that is not a key of :data:`CASES`.
    """
    from meshvis.errors import ParameterError

    wanted = [n.strip() for n in names.split(",") if n.strip()] if names else list(default)
    bad = [n for n in wanted if n not in CASES]
    if bad:
        raise ParameterError(f"unknown case(s) {', '.join(bad)}; choose from {', '.join(CASES)}")
    return [CASES[n] for n in wanted]


def built_cases(cases, skipped: list[str], log, models_dir: str | os.PathLike = DEFAULT_MODELS):
    """Build the cases one by one, yielding those that can be built.

    A case that cannot be built (a missing real model) is logged and listed in ``skipped``:
    it is not an error of the benchmark.  A missing folder of real models is, as soon as
    any case is real, before the first case is built.

    Parameters
    ----------
    cases : iterable of Case
        The cases, in order.
    skipped : list of str
        Receives one line per case that was skipped, with the reason.
    log : callable
        Receives one line per case (its face count, or why it was skipped).
    models_dir : str or os.PathLike
        The folder of the real models.

    Yields
    ------
    tuple of (Case, GroundTruth)
        Every case that was built, with its truth.

    Raises
    ------
    ParameterError
        Some case is real and ``models_dir`` is not a folder.
    """
    cases = list(cases)
    if any(case.real for case in cases):
        models_folder(models_dir)
    for case in cases:
        truth, why = load_case(case, models_dir)
        if truth is None:
            skipped.append(f"{case.name}: {why}")
            log(f"{case.name}: {why}")
            continue
        log(f"{case.name}: {truth.n_faces} faces")
        yield case, truth


def load_case(case: Case, models_dir: str | os.PathLike = DEFAULT_MODELS) -> tuple[GroundTruth | None, str]:
    """Build a case's truth (a real one from ``models_dir``).

    Parameters
    ----------
    case : Case
        The case.
    models_dir : str or os.PathLike
        The folder of the real models (read for real cases only).

    Returns
    -------
    truth : GroundTruth or None
        The truth; None when a real model is missing or its truth cannot be built.
    reason : str
        Why the case was skipped; empty when it was built.

    Raises
    ------
    ParameterError
        The case is real and ``models_dir`` is not a folder.
    Exception
        Whatever a generated (not real) case's builder raises.
    """
    try:
        return (case.build(models_folder(models_dir)) if case.real else case.build()), ""
    except FileNotFoundError as exc:
        return None, f"skipped: {exc}"
    except Exception as exc:  # a real model whose truth cannot be built
        if not case.real:
            raise
        return None, f"skipped: {type(exc).__name__}: {exc}"


# ====================================================================== points
@dataclass
class Point:
    """One (time, error) measurement; ``error`` is NaN when the run failed."""

    case: str
    faces: int
    task: str
    method: str
    label: str
    knob: str
    value: float
    seconds: float
    error: float
    error_hidden: float = float("nan")
    precision: float = float("nan")
    recall: float = float("nan")
    ok: bool = True
    message: str = ""
    load1: float = 0.0
    default: bool = False
    extra: dict = field(default_factory=dict)

    def row(self) -> dict:
        """Give the point as a flat dictionary (a CSV row): every field but ``extra``.

        Returns
        -------
        dict
            Field name -> value.
        """
        d = asdict(self)
        d.pop("extra")
        return d


def load1() -> float:
    """Read the 1-minute load average.

    Returns
    -------
    float
        The load average; 0.0 where the OS does not report it.
    """
    try:
        return float(os.getloadavg()[0])
    except (OSError, AttributeError):
        return 0.0


def score(truth: GroundTruth, task: str, values: np.ndarray | None) -> dict:
    """Score a per-face result against the truth: ``error`` (the charted number) and the task's extras.

    orient: ``error`` = area-weighted misoriented fraction, ``error_hidden`` = the same on
    faces of layer 2 and deeper (NaN when there are none); remove: ``error`` = area
    decided wrongly, plus ``precision`` and ``recall``; layers: ``error`` = area in the
    wrong layer.

    Parameters
    ----------
    truth : GroundTruth
        The case's truth.
    task : {"orient", "remove", "layers"}
        What ``values`` answers.
    values : (m,) ndarray or None
        ``flipped`` (bool), ``keep`` (bool) or ``layer`` (int) per face; None for a failed
        run.

    Returns
    -------
    dict
        The fields of :class:`Point` to set: ``error`` (NaN for a failed run) and the
        task's extras.

    Raises
    ------
    ValueError
        An unknown ``task``.
    """
    nan = float("nan")
    if values is None:
        return {"error": nan}
    if task == "orient":
        hidden = truth.layer >= 2
        return {
            "error": orientation_error(truth, values),
            "error_hidden": orientation_error(truth, values, where=hidden) if hidden.any() else nan,
        }
    if task == "remove":
        s = removal_scores(truth, values)
        return {"error": s.error, "precision": s.precision, "recall": s.recall}
    if task == "layers":
        return {"error": layer_error(truth, values)}
    raise ValueError(task)


def meshvis_run(
    truth: GroundTruth, tasks: tuple[str, ...], *, seed: int = 0, share: bool = True, **classify_kw
) -> dict[str, tuple[float, np.ndarray, dict]]:
    """Run meshvis' applications on a case and time each.

    With ``share`` the classification is computed once and its time is added to every
    task's own time (what a user pays for each command alone, without paying the
    classification three times in the benchmark); without, every task runs end to end
    (``orient(soup)``, ``remove_interior(soup)``, ``layers(soup)``), as the commands do.
    The generator's side hints, if any, are passed on.

    Parameters
    ----------
    truth : GroundTruth
        The case; its soup is the input and its hints are used.
    tasks : tuple of str
        Among "orient", "remove" and "layers" (any other name runs the layers).
    seed : int
        Seed of the classification.
    share : bool
        Classify once for all tasks.
    **classify_kw
        Passed to :func:`meshvis.classify` (``rays_per_node``, ``progressive``, ...).

    Returns
    -------
    dict
        Task -> ``(seconds, values, info)``: the time including the classification, the
        per-face answer (``flipped``, ``keep`` or ``layer``) and ``{"rays", "rounds"}`` of the
        classification used.
    """
    from meshvis.graphcut.classify import classify
    from meshvis.repair.layers import layers
    from meshvis.repair.orient import orient
    from meshvis.repair.remove import remove_interior

    kw = dict(classify_kw, seed=seed)
    if truth.hints:
        kw["hints"] = {k: v for k, v in truth.hints.items()}
    soup = truth.soup
    out: dict[str, tuple[float, np.ndarray, dict]] = {}
    t_c, c = 0.0, None
    if share:
        t = time.perf_counter()
        c = classify(soup, **kw)
        t_c = time.perf_counter() - t
    for task in tasks:
        t = time.perf_counter()
        if task == "orient":
            r = orient(soup, classification=c, **({} if share else kw))
            values, cl = r.flipped, r.classification
        elif task == "remove":
            # the cut itself is what the accuracy benchmarks judge
            r = remove_interior(soup, classification=c, visibility="object", **({} if share else kw))
            values, cl = r.keep, r.classification
        else:
            r = layers(soup, classification=c, visibility="object", **({} if share else kw))
            values, cl = r.layer, r.classification
        dt = time.perf_counter() - t
        out[task] = (t_c + dt, values, {"rays": cl.n_rays, "rounds": len(cl.rounds)})
    return out


def baseline_point(
    truth: GroundTruth, case: str, name: str, value: float | None, *, timeout: float = 300.0
) -> Point:
    """Run baseline ``name`` with its knob at sweep ``value`` and score it.

    Parameters
    ----------
    truth : GroundTruth
        The case; the baseline runs on its soup.
    case : str
        The case's name, recorded in the point.
    name : str
        A key of :data:`meshvis.eval.baselines.BASELINES`.
    value : float or None
        The sweep value of the baseline's knob (see :meth:`Baseline.knob_value`); None for
        the library's default.
    timeout : float
        Time limit in seconds of the CGAL peel's worker (``libigl_peel`` only).

    Returns
    -------
    Point
        The scored run; ``ok=False`` with the library's message (and NaN errors) when it
        failed.

    Raises
    ------
    KeyError
        ``name`` is not a baseline.
    MissingExtraError
        A MeshLab baseline without pymeshlab installed.
    """
    b: Baseline = BASELINES[name]
    kw = dict(b.fixed)
    if b.knob is not None and value is not None:
        kw[b.knob] = b.knob_value(value, truth.n_faces)
    if name == "libigl_peel":
        kw["timeout"] = timeout
    r: BaselineResult = b.run(truth.soup, **kw)
    s = score(truth, b.task, r.values if r.ok else None)
    shown = b.default if value is None else value
    return Point(
        case=case,
        faces=truth.n_faces,
        task=b.task,
        method=name,
        label=b.label,
        knob=(b.knob + (" per face" if b.per_face else "")) if b.knob else "",
        value=float("nan") if shown is None else float(shown),
        seconds=r.seconds,
        ok=r.ok,
        message=r.message,
        load1=load1(),
        default=value is None or value == b.default,
        **s,
    )


def warm_up() -> None:
    """Run every method once on a tiny model, so that start-up is not charged to a measured run.

    Library start-up (Embree devices, imports, loading compiled kernels) then happens here:
    meshvis orients two spheres that cut into each other and removes their inside, which
    reaches the kernels of the intersection tests, the sample points, the per-face evidence
    and the from-region search.  The CGAL peel, which runs in its own process anyway, is
    left out.
    """
    import trimesh

    from meshvis.repair.orient import orient
    from meshvis.repair.remove import remove_interior

    m = trimesh.creation.icosphere(1)
    tiny = (np.asarray(m.vertices, np.float64), np.asarray(m.faces, np.int64))
    pair = (np.vstack([tiny[0], tiny[0] + [0.5, 0.0, 0.0]]), np.vstack([tiny[1], tiny[1] + len(tiny[0])]))
    orient(pair, rays_per_node=1, seed=0)
    remove_interior(pair, rays_per_node=1, seed=0)
    for name, b in BASELINES.items():
        if name != "libigl_peel":
            b.run(tiny, **b.fixed)


# ====================================================================== machine
def machine() -> dict:
    """Describe where the numbers come from: CPU, cores, OS, Python and library versions, load.

    Returns
    -------
    dict
        ``cpu``, ``cores``, ``os``, ``python``, ``meshvis``, ``versions`` (library ->
        version, or "missing") and ``load_average`` (1, 5 and 15 minutes).
    """
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    versions = {}
    for mod in ("numpy", "embreex", "trimesh", "pymeshlab", "igl", "maxflow"):
        try:
            m = __import__(mod)
            versions[mod] = str(getattr(m, "__version__", "") or _dist_version(mod))
        except Exception:
            versions[mod] = "missing"
    from meshvis._version import __version__

    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "os": platform.platform(),
        "python": sys.version.split()[0],
        "meshvis": __version__,
        "versions": versions,
        "load_average": [round(x, 2) for x in os.getloadavg()],
    }


def _dist_version(mod: str) -> str:
    from importlib import metadata

    for dist in {"igl": "libigl", "maxflow": "PyMaxflow"}.get(mod, mod), mod:
        try:
            return metadata.version(dist)
        except metadata.PackageNotFoundError:
            continue
    return ""


def machine_lines(m: dict) -> list[str]:
    """Describe a :func:`machine` result as Markdown bullet lines.

    Parameters
    ----------
    m : dict
        A result of :func:`machine`.

    Returns
    -------
    list of str
        Three bullet lines: CPU and OS, versions, load average at the start.
    """
    v = ", ".join(f"{k} {x}" for k, x in m["versions"].items())
    return [
        f"- CPU: {m['cpu']}, {m['cores']} logical cores; {m['os']}",
        f"- Python {m['python']}, meshvis {m['meshvis']}; {v}",
        f"- load average at the start (1, 5, 15 min): {', '.join(str(x) for x in m['load_average'])} "
        "(the machine is shared with other jobs; every row also records the 1-minute load)",
    ]


def shared_legend(fig, axes, fontsize: int, ncol: int | None = None) -> None:
    """Draw one legend below the panels of ``fig``: every labelled line of ``axes`` once, in order.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    axes : ndarray of matplotlib.axes.Axes
        Its panels.
    fontsize : int
        Font size of the legend.
    ncol : int, optional
        Columns of the legend; default one per entry, at most 4.
    """
    handles, names = [], []
    for ax in axes.ravel():
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in names:
                handles.append(h)
                names.append(lab)
    ncol = min(4, max(len(names), 1)) if ncol is None else ncol
    fig.legend(handles, names, loc="lower center", ncol=ncol, fontsize=fontsize, frameon=False)


def report_head(title: str, command: str, seconds: float, machine: dict, skipped: list[str]) -> list[str]:
    """Write the first lines of a benchmark's Markdown report: title, command, machine, skipped cases.

    Parameters
    ----------
    title : str
        The report's title.
    command : str
        The command that produced the numbers.
    seconds : float
        Wall time of the whole run.
    machine : dict
        A result of :func:`machine` (taken at the start).
    skipped : list of str
        One line per skipped case.

    Returns
    -------
    list of str
        The lines, the load average at the end included.
    """
    lines = [f"# {title}", "", f"Command: `{command}` — {seconds:.0f} s in all.", ""]
    lines += machine_lines(machine) + [
        f"- load average at the end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}",
        "",
    ]
    if skipped:
        lines += ["Skipped cases:", ""] + [f"- {s}" for s in skipped] + [""]
    return lines


def fmt_err(x: float) -> str:
    """Format an error for a table: '–' when the run failed, '0' when exact.

    Parameters
    ----------
    x : float or None
        The error; None or NaN for a failed run.

    Returns
    -------
    str
        Four decimals, or scientific notation below 1e-3.
    """
    if x is None or np.isnan(x):
        return "–"
    if x == 0:
        return "0"
    return f"{x:.1e}" if x < 1e-3 else f"{x:.4f}"


def fmt_time(x: float) -> str:
    """Format seconds for a table.

    Parameters
    ----------
    x : float or None
        The time; None or NaN for a failed run ('–').

    Returns
    -------
    str
        Three decimals below 10 s, one above.
    """
    return "–" if x is None or np.isnan(x) else (f"{x:.3f}" if x < 10 else f"{x:.1f}")
