"""``meshvis info MODEL [--json]``: what is wrong with a model (counts and timings)."""

from __future__ import annotations

import argparse
import json

from meshvis.errors import ParameterError

from .common import library_default


def add_parser(sub) -> None:
    """Add the ``info`` subcommand to the ``meshvis`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """
    p = sub.add_parser(
        "info",
        help="diagnose a model: components, holes, non-manifold edges, winding, "
        "degenerate / duplicate / intersecting / coplanar faces",
    )
    p.add_argument("model", help="input model")
    p.add_argument("--json", action="store_true", help="print the numbers as JSON")
    p.add_argument(
        "--eps",
        type=float,
        default=library_default("meshvis.geometry.diagnostics:diagnose", "eps"),
        help="distance tolerance of the intersection tests, fraction of the diagonal",
    )
    p.add_argument(
        "--no-intersections",
        action="store_true",
        help="skip the intersection / coplanarity tests (the slowest stage)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis info``: diagnose a model and print the counts and timings.

    Prints the text report, or the same numbers as JSON with ``--json``; on a terminal a
    progress bar on standard error follows the stages.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options: ``model``, ``json``, ``eps`` (tolerance of the intersection tests,
        a fraction of the diagonal), ``no_intersections``.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    ParameterError
        ``--eps`` outside [1e-9, 1).
    ModelError
        The model cannot be read (see :func:`meshvis.load`).
    """
    from meshvis.geometry.diagnostics import diagnose, format_report
    from meshvis.io import load

    if not (1e-9 <= args.eps < 1):
        raise ParameterError(f"--eps must lie in [1e-9, 1), got {args.eps}")
    from .progress import stage_progress

    soup = load(args.model)
    with stage_progress(args) as progress:
        report = diagnose(soup, eps=args.eps, intersections=not args.no_intersections, progress=progress)
    print(json.dumps(report, indent=1) if args.json else format_report(report))
    return 0
