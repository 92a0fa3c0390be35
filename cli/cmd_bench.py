"""``meshvis bench rays|classify|accuracy|stability|compare|orientation|orient-twice|real|scale|labeling|labeling-sweep|startup|conservative|pvs``: reproducible measurements."""

from __future__ import annotations

import argparse

from meshvis.eval.bench.real_models import add_models_argument

from .common import positive_int, write_json


def add_parser(sub) -> None:
    """Add the ``bench`` subcommand and its benchmarks to the ``meshvis`` parser.

    ``rays`` and ``classify`` are set up here; every other benchmark is a module of
    :mod:`meshvis.eval.bench` with ``add_arguments(parser)`` and ``main(args)``, whose help is
    the first line of its module docstring (a module that is not there is left out).
    A benchmark name is required: ``meshvis bench`` alone is a usage error (status 2).

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser.
    """
    p = sub.add_parser("bench", help="benchmarks (speed as ratios measured in one run)")
    bs = p.add_subparsers(dest="bench", metavar="BENCH", required=True)

    r = bs.add_parser("rays", help="ray backend throughput next to raw embreex, threads vs processes")
    r.add_argument("model")
    r.add_argument("--rays", type=positive_int, default=1_000_000)
    r.add_argument("--repeat", type=positive_int, default=3)
    r.add_argument("--json", metavar="FILE", help="also write the numbers as JSON")
    r.set_defaults(func=run_rays)

    c = bs.add_parser("classify", help="per-stage times of the classification on large models")
    c.add_argument("models", nargs="*", help="models (default: the monastery and the skin + ribcage)")
    c.add_argument("--rays-per-node", type=positive_int, default=32)
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--json", metavar="FILE")
    add_models_argument(c)
    c.set_defaults(func=run_classify)

    for name in (
        "accuracy",
        "stability",
        "labeling",
        "labeling-sweep",
        "labeling-orbit",
        "labeling-page",
        "compare",
        "scale",
        "orientation",
        "orient-twice",
        "indoor",
        "real",
        "startup",
        "conservative",
        "pvs",
    ):
        try:
            mod = __import__(f"meshvis.eval.bench.{name.replace('-', '_')}", fromlist=["add_arguments"])
        except ModuleNotFoundError:
            continue
        if hasattr(mod, "add_arguments"):
            q = bs.add_parser(name, help=(mod.__doc__ or "").strip().splitlines()[0])
            mod.add_arguments(q)
            q.set_defaults(func=lambda a, m=mod: m.main(a))
    p.set_defaults(func=lambda a: (p.print_help(), 2)[1])


def run_rays(args: argparse.Namespace) -> int:
    """Run ``meshvis bench rays``: ray throughput of the backend next to raw embreex.

    Prints the table of :func:`meshvis.eval.bench.rays.format`.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options: ``model``, ``rays`` (rays per measurement), ``repeat`` (the best
        of this many runs counts), ``json`` (optional file for the numbers).

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    ModelError
        The model cannot be read (see :func:`meshvis.load`).
    """
    from meshvis.eval.bench import rays
    from meshvis.io import load

    r = rays.run(load(args.model), n_rays=args.rays, repeat=args.repeat)
    print(rays.format(r))
    if args.json:
        write_json(args.json, r)
    return 0


def run_classify(args: argparse.Namespace) -> int:
    """Run ``meshvis bench classify``: per-stage times of the classification of large models.

    Prints the summary of every model (:func:`meshvis.eval.bench.classify.format`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options: ``models`` (files; default the monastery and the skin + rib cage
        of ``models_dir``), ``rays_per_node``, ``seed``, ``json`` (optional file for the
        numbers), ``models_dir``.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    ParameterError
        Without model files, when ``--models`` is not a folder.
    ModelError
        A model cannot be read.
    """
    from meshvis.eval.bench import classify as bc

    results = bc.run(
        args.models or None, rays_per_node=args.rays_per_node, seed=args.seed, models_dir=args.models_dir
    )
    print(bc.format(results))
    if args.json:
        write_json(args.json, results)
    return 0
