"""``meshvis demo``: orient, remove-interior and layers on a bundled model, with previews."""

from __future__ import annotations

import argparse
import os

from meshvis.errors import OutputError

from .common import detail, say, verbosity_options


def add_parser(sub) -> None:
    """Add the ``demo`` subcommand to the ``meshvis`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """
    p = sub.add_parser("demo", help="run all three repairs on a bundled model and write results + previews")
    p.add_argument("--out", default="meshvis-demo", help="folder to write into (default ./meshvis-demo)")
    p.add_argument("--seed", type=int, default=0, help="seed of the soup and of the classification")
    p.add_argument("--size", type=int, default=512, help="preview size in pixels (default 512)")
    p.add_argument("--force", action="store_true", help="write into a folder that already has demo files")
    verbosity_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis demo``: orient, remove-interior and layers on the bundled model.

    The folder ``--out`` (created when missing) receives the models, their PNG previews and
    ``report.json`` (:data:`meshvis.eval.demo.DEMO_FILES`); a line per step is printed unless
    ``--quiet``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options: ``out``, ``seed``, ``size`` (preview pixels), ``force``, ``quiet``.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    OutputError
        ``--out`` exists and is not a folder, or it already holds one of the demo files and
        ``--force`` is not given.
    """
    from meshvis.eval.demo import DEMO_FILES, run_demo

    if os.path.exists(args.out) and not os.path.isdir(args.out):
        raise OutputError("exists and is not a folder", args.out)
    if not args.force and any(os.path.exists(os.path.join(args.out, f)) for f in DEMO_FILES):
        raise OutputError("already holds demo results; use --force to overwrite", args.out)
    run_demo(
        args.out,
        seed=args.seed,
        size=args.size,
        say=lambda text: say(args, text),
        detail=lambda text: detail(args, text),
    )
    return 0
