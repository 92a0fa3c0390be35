"""``meshvis visible``: which face sides a viewer in a region can see (a report, no output model)."""

from __future__ import annotations

import argparse

from .common import check_output, positive_int, say, write_json


def conservative_options(p) -> None:
    """The ``--conservative`` and ``--max-level`` options (defaults from :mod:`meshvis.visibility.conservative`)."""
    from meshvis.visibility.conservative import DEFAULT_MAX_LEVEL

    p.add_argument(
        "--conservative",
        action="store_true",
        help="also the faces that may be seen from points:... or path:CAMERAS.json (a set that surely "
        "holds every visible face; docs/conservative.md)",
    )
    p.add_argument(
        "--max-level",
        type=positive_int,
        default=DEFAULT_MAX_LEVEL,
        help=f"with --conservative: frusta are split down to 2**N a side of a cube-map face (default {DEFAULT_MAX_LEVEL})",
    )


def add_parser(sub) -> None:
    """Add the ``visible`` subcommand to the ``meshvis`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """
    p = sub.add_parser("visible", help="which faces can be seen from a region (GVS guided sampling)")
    p.add_argument("input", help="input model (OBJ, PLY, STL, OFF, glTF/GLB, 3MF)")
    p.add_argument(
        "--from",
        dest="from_region",
        default="outside",
        metavar="REGION",
        help="outside (default), upper-hemisphere[:ux,uy,uz], box:x0,y0,z0,x1,y1,z1, "
        "points:x,y,z;..., path:CAMERAS.json",
    )
    p.add_argument("--method", choices=("guided", "random"), default="guided")
    p.add_argument(
        "--budget",
        type=positive_int,
        help="stop after about this many rays (default: the stop rule ends the search, capped at 1024 rays per face, "
        "at least 2**22, at most meshvis.limits.MAX_RAYS)",
    )
    p.add_argument("--per-side", action="store_true", help="keep looking until both sides of a face are seen")
    conservative_options(p)
    p.add_argument(
        "--up", choices=("auto", "x", "y", "z"), default="auto", help="up axis of upper-hemisphere"
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--report", metavar="REPORT.json", help="write per-face results and the history")
    p.add_argument(
        "--preview", metavar="PICTURE.png", help="the model with unseen faces in red, and them alone"
    )
    p.add_argument("--force", action="store_true", help="overwrite existing outputs")
    p.add_argument("--quiet", "-q", action="store_true", help="print nothing but errors")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis visible``: search which faces can be seen from the region ``--from``.

    Prints one line unless ``--quiet`` (faces and share of the area seen, rays, why the
    search stopped, time), and with ``--conservative`` a second one (the faces that may be
    seen, the bracket between the two sets, frusta, time).
    No model is written; ``--report`` writes the JSON report with per-face results and
    ``--preview`` a picture with the unseen faces in red.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options: ``input``, ``from_region``, ``method``, ``budget``, ``per_side``,
        ``conservative``, ``max_level``, ``up``, ``seed``, ``report``, ``preview``, ``force``,
        ``quiet``.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    OutputError
        A ``--report`` or ``--preview`` path is refused (see :func:`meshvis.io.check_output`).
    ModelError
        The model cannot be read (see :func:`meshvis.load`).
    ParameterError
        Unknown region or method, or a bad budget (see :func:`meshvis.visible_from`).
    """
    from meshvis.io import load
    from meshvis.rays.camera import up_axis
    from meshvis.rays.render import save_png
    from meshvis.visibility import visible_from
    from meshvis.visibility.conservative import bracket
    from meshvis.visibility.preview import preview

    for path in (args.report, args.preview):
        if path:
            check_output(path, [args.input], args.force)
    soup = load(args.input)
    search = dict(
        budget=args.budget,
        seed=args.seed,
        method=args.method,
        up=up_axis(args.up, [args.input]),
        per_side=args.per_side,
    )
    if args.conservative:  # visible_from(..., conservative=True), with the subdivision limit
        vis = bracket(soup, args.from_region, search=visible_from, max_level=args.max_level, **search)
    else:
        vis = visible_from(soup, args.from_region, **search)
    r = vis.report(per_face=bool(args.report))
    say(
        args,
        f"{args.input}: {r['seen_faces']} of {r['faces']} faces seen ({100 * r['seen_area_fraction']:.1f} % of the area) "
        f"from {args.from_region}; {r['rays']['total']} rays, stopped: {r['stopped']}, {vis.seconds:.1f} s",
    )
    if args.conservative:
        c = r["conservative"]
        say(
            args,
            f"conservative: {c['conservative_faces']} faces may be seen ({c['conservative_area'] / max(c['sampled_area'], 1e-300):.2f} x the "
            f"sampled area); bracket {c['bracket_faces']} faces, {100 * c['bracket_area_fraction']:.1f} % of the area; "
            f"{c['frusta']} frusta, {c['seconds']:.1f} s",
        )
    if args.report:
        r["input"] = args.input
        write_json(args.report, r)
    if args.preview:
        save_png(preview(soup, vis), args.preview)
    return 0
