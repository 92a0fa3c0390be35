"""``meshvis pvs``: the potentially visible set of every view cell (AGVS on a view-cell hierarchy)."""

from __future__ import annotations

import argparse

from .common import (
    check_output,
    detail,
    library_default,
    non_negative_float,
    positive_int,
    positive_seconds,
    say,
    up_option,
    verbosity_options,
    write_json,
)

#: the library function whose keywords the options are, and whose defaults they take
PVS = "meshvis.viewcells.agvs:pvs"


def add_parser(sub) -> None:
    """Add the ``pvs`` subcommand to the ``meshvis`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """

    def d(keyword):
        return library_default(PVS, keyword)

    p = sub.add_parser("pvs", help="the potentially visible set of every view cell (AGVS)")
    p.add_argument("input", help="input model (OBJ, PLY, STL, OFF, glTF/GLB, 3MF)")
    p.add_argument("-o", "--output", required=True, metavar="PVS.npz", help="the PVS file to write")
    p.add_argument(
        "--cells",
        default=d("cells"),
        help="view cells: auto[:N] (N cells by render cost, N = 64 without it), grid:NX,NY,NZ, or CELLS.json "
        "(a list of boxes [x0, y0, z0, x1, y1, z1])",
    )
    p.add_argument(
        "--view-space",
        default=d("view_space"),
        metavar="REGION",
        help="where viewers stand: auto (the bounding box, above the ground for scenes standing on one), "
        "box (the bounding box) or box:x0,y0,z0,x1,y1,z1",
    )
    stop = p.add_mutually_exclusive_group()
    stop.add_argument(
        "--time", type=positive_seconds, default=d("seconds"), metavar="SECONDS", help="stop after this time"
    )
    stop.add_argument(
        "--rays",
        type=positive_int,
        default=d("budget"),
        help="stop after about this many rays (default: a cap of 2**30)",
    )
    p.add_argument(
        "--target",
        type=non_negative_float,
        default=d("target_error"),
        help="stop when the estimated error is at most this many wrong pixels per million (0: never)",
    )
    p.add_argument("--filter", action="store_true", help="extend each PVS by the visibility filter (AGVS §5)")
    up_option(p, "the ground")
    p.add_argument("--seed", type=int, default=d("seed"), help="random seed")
    p.add_argument(
        "--report", metavar="REPORT.json", help="write the run's report (cells, PVS sizes, history)"
    )
    p.add_argument(
        "--top-view", metavar="PICTURE.png", help="the level from above, the cells coloured by PVS size"
    )
    p.add_argument(
        "--height", type=float, help="height of the top view's slice (default: a quarter up the view space)"
    )
    p.add_argument(
        "--cell-view", metavar="PICTURE.png", help="the scene with the PVS of one cell (--cell) highlighted"
    )
    p.add_argument("--cell", type=int, help="the cell of --cell-view (default: the one with the largest PVS)")
    p.add_argument("--force", action="store_true", help="overwrite existing outputs")
    verbosity_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis pvs``: compute the PVS of every view cell and write it.

    The cells, the view space, the up axis and the outputs are checked before the model is
    read.  Prints one line unless ``--quiet`` (cells, mean PVS size, estimated error, rays,
    why it stopped, time); ``--verbose`` adds the view space, the rays and new entries of
    each distribution and what was left out.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    OutputError
        An output path is refused (see :func:`meshvis.io.check_output`).
    ModelError
        The model cannot be read (see :func:`meshvis.load`).
    ParameterError
        Malformed cells, view space or up axis.
    """
    from meshvis.errors import ParameterError
    from meshvis.io import load
    from meshvis.io.up_axis import up_vector
    from meshvis.rays.render import check_image_format, save_image
    from meshvis.viewcells.agvs import check_arguments, pvs

    from .progress import stage_progress

    up = None if args.up == "auto" else args.up
    if up is not None:
        up_vector(up)
    check_arguments(args.cells, args.view_space, args.seed)
    if args.cell is not None and args.cell < 0:
        raise ParameterError(f"--cell must be at least 0, got {args.cell}")
    for picture in (args.top_view, args.cell_view):
        if picture:
            check_image_format(picture)
    for path in (args.output, args.report, args.top_view, args.cell_view):
        if path:
            check_output(path, [args.input], args.force)
    soup = load(args.input)
    with stage_progress(args) as progress:
        result = pvs(
            soup,
            args.cells,
            view_space=args.view_space,
            budget=args.rays,
            seconds=args.time,
            target_error=args.target,
            visibility_filter=args.filter,
            seed=args.seed,
            up=up,
            progress=progress,
        )
    result.save(args.output)
    report = result.report()
    wrote = [args.output]
    if args.report:
        write_json(args.report, {"input": args.input, **report})
        wrote.append(args.report)
    if args.top_view:
        from meshvis.viewcells.pictures import top_view

        save_image(top_view(result, soup, height=args.height), args.top_view)
        wrote.append(args.top_view)
    if args.cell_view:
        from meshvis.viewcells.pictures import cell_view

        cell = int(result.sizes().argmax()) if args.cell is None else args.cell
        save_image(cell_view(result, soup, cell), args.cell_view)
        wrote.append(args.cell_view)
    est = report["estimate"]
    detail(args, f"view space: {report['view_space']}")
    for name, st in report["strategies"].items():
        detail(
            args,
            f"  {name:<11} {st['rays']:>12} rays {st['contribution']:>10} new entries {st['seconds']:7.1f} s",
        )
    for what, n in report["left_out"].items():
        detail(args, f"  left out: {what.replace('_', ' ')}: {n}")
    say(
        args,
        f"{args.input}: pvs: {report['cells']['cells']} cells, mean PVS {report['pvs_size']['mean']:.0f} of "
        f"{report['faces']} faces, estimated error {est['per_million']:.3g} per million; "
        f"{report['rays']['total']} rays, stopped: {report['stopped']}; wrote {' and '.join(wrote)}; "
        f"{report['seconds']:.1f} s",
    )
    return 0
