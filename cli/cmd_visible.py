"""``meshvis visible``: which face sides a viewer in a region can see (a report, no output model)."""

from __future__ import annotations

import argparse

from .common import (
    check_outputs,
    detail,
    library_default,
    positive_int,
    say,
    staged_outputs,
    up_option,
    verbosity_options,
    write_json,
)

#: the library function whose keywords the options are, and whose defaults they take
VISIBLE_FROM = "meshvis.visibility.visible:visible_from"
#: ... and the one ``--conservative`` calls (visible_from with conservative=True)
BRACKET = "meshvis.visibility.conservative:bracket"


def add_parser(sub) -> None:
    """Add the ``visible`` subcommand to the ``meshvis`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """
    from meshvis._defaults import module_constant

    methods = module_constant("meshvis.visibility.visible:METHODS")

    def d(keyword):
        return library_default(VISIBLE_FROM, keyword)

    p = sub.add_parser("visible", help="which faces can be seen from a region (GVS guided sampling)")
    p.add_argument("input", help="input model (OBJ, PLY, STL, OFF, glTF/GLB, 3MF)")
    p.add_argument(
        "--from",
        dest="from_region",
        default=d("region"),
        metavar="REGION",
        help="where the viewers are: outside, upper-hemisphere[:ux,uy,uz], box:x0,y0,z0,x1,y1,z1, "
        "points:x,y,z;..., path:CAMERAS.json",
    )
    p.add_argument("--method", choices=methods, default=d("method"), help="guided sampling, or random rays")
    p.add_argument(
        "--budget",
        type=positive_int,
        default=d("budget"),
        help="stop after about this many rays (default: the stop rule ends the search, capped at 1024 rays per face, "
        "at least 2**22, at most meshvis.limits.MAX_RAYS)",
    )
    p.add_argument("--per-side", action="store_true", help="keep looking until both sides of a face are seen")
    p.add_argument(
        "--conservative",
        action="store_true",
        help="also the faces that may be seen from points:... or path:CAMERAS.json (a set that surely "
        "holds every visible face; docs/conservative.md)",
    )
    p.add_argument(
        "--max-level",
        type=positive_int,
        default=library_default(BRACKET, "max_level"),
        help="with --conservative: frusta are split down to 2**N a side of a cube-map face "
        f"(default {library_default(BRACKET, 'max_level')})",
    )
    up_option(p, "the upper-hemisphere region")
    p.add_argument("--seed", type=int, default=d("seed"), help="random seed")
    p.add_argument(
        "--report",
        metavar="REPORT.json",
        help="write per-face results and the history ('-': standard output)",
    )
    p.add_argument(
        "--preview",
        metavar="PICTURE.png",
        help="the model with unseen faces in red, and them alone (PNG or JPEG)",
    )
    p.add_argument("--force", action="store_true", help="overwrite existing outputs")
    verbosity_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis visible``: search which faces can be seen from the region ``--from``.

    The region, the up axis and the outputs are checked before the model is read.  Prints
    one line unless ``--quiet`` (faces and share of the area seen, rays, why the search
    stopped, time), and with ``--conservative`` a second one (the faces that may be seen,
    the bracket between the two sets, frusta, time); ``--verbose`` adds the region and the
    rays of each kind.  No model is written; ``--report`` writes the JSON report with
    per-face results and ``--preview`` a picture with the unseen faces in red.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options: ``input``, ``from_region``, ``method``, ``budget``, ``per_side``,
        ``conservative``, ``max_level``, ``up``, ``seed``, ``report``, ``preview``, ``force``,
        ``quiet``, ``verbose``.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    OutputError
        A ``--report`` or ``--preview`` path is refused (see :func:`meshvis.io.check_outputs`).
    ModelError
        The model cannot be read (see :func:`meshvis.load`).
    ParameterError
        Unknown region or method, or a bad budget (see :func:`meshvis.visible_from`).
    """
    from meshvis.io import load
    from meshvis.io.jsonfile import STDOUT
    from meshvis.io.up_axis import up_vector
    from meshvis.io.writing import check_not_read
    from meshvis.rays.render import check_image_format, save_image
    from meshvis.visibility import visible_from
    from meshvis.visibility.conservative import bracket
    from meshvis.visibility.preview import preview
    from meshvis.visibility.regions import parse_region

    up = None if args.up == "auto" else args.up
    parse_region(args.from_region, up=up)  # a malformed region fails before any work
    if up is not None:
        up_vector(up)
    if args.preview:
        check_image_format(args.preview)
    outputs = [p for p in (args.report, args.preview) if p and p != STDOUT]
    check_outputs(outputs, [args.input], args.force)
    if args.report == STDOUT:
        args.quiet = True  # standard output carries the report alone
    soup = load(args.input)
    for path in outputs:  # not over a texture of the model
        check_not_read(path, soup)
    search = dict(budget=args.budget, seed=args.seed, method=args.method, up=up, per_side=args.per_side)
    if args.conservative:  # visible_from(..., conservative=True), with the subdivision limit
        vis = bracket(soup, args.from_region, search=visible_from, max_level=args.max_level, **search)
    else:
        vis = visible_from(soup, args.from_region, **search)
    r = vis.report(per_face=bool(args.report))
    detail(args, f"region: {r.get('region', args.from_region)}")
    detail(args, f"rays: {r['rays']}")
    wrote = outputs
    say(
        args,
        f"{args.input}: visible: {r['seen_faces']} of {r['faces']} faces seen "
        f"({100 * r['seen_area_fraction']:.1f} % of the area) from {args.from_region}; "
        f"{r['rays']['total']} rays, stopped: {r['stopped']}"
        + (f"; wrote {' and '.join(wrote)}" if wrote else "")
        + f"; {vis.seconds:.1f} s",
    )
    if args.conservative:
        c = r["conservative"]
        say(
            args,
            f"conservative: {c['conservative_faces']} faces may be seen ({c['area_ratio'] or 0:.2f} x the sampled "
            f"area); bracket {c['bracket_faces']} faces, {100 * c['bracket_area_fraction']:.1f} % of the area; "
            f"{c['frusta']} frusta, {c['seconds']:.1f} s",
        )
    with staged_outputs():  # the report and the preview appear together or not at all
        if args.preview:
            save_image(preview(soup, vis), args.preview)
        if args.report:
            r["input"] = args.input
            write_json(args.report, r)
    return 0
