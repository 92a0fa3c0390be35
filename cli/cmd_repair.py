"""``meshvis classify | orient | remove-interior | layers``: the graph-cut commands.

Every default is read from the library function the option is passed to
(:func:`meshvis.repair.operation.default_options`), so a command gives the faces the same
call gives from Python.
"""

from __future__ import annotations

import argparse
import os
import time

from meshvis.errors import ParameterError
from meshvis.graphcut.solvers import SOLVERS
from meshvis.io.report import write_report
from meshvis.repair.remove_modes import LAYER_MODES, LEVELS, TRANSPARENT_MODES, VISIBILITY_MODES

from .common import check_outputs, point, positive_int, say, staged_outputs, up_option, verbosity_options


def _defaults(op: str) -> dict:
    from meshvis.repair.operation import default_options

    return default_options(op)


def _common(p: argparse.ArgumentParser, needs_output: bool = True, layers: bool = False) -> None:
    p.add_argument("input", help="input model (OBJ, PLY, STL, OFF, glTF/GLB, 3MF)")
    if needs_output:
        formats = "OBJ, PLY, glTF/GLB" if layers else "OBJ, PLY, STL, OFF, glTF/GLB"
        p.add_argument(
            "-o", "--output", required=True, help=f"output model ({formats}); format from the extension"
        )
    p.add_argument(
        "--report",
        metavar="REPORT.json",
        help="write a JSON report with per-face results ('-': standard output; default: none)",
    )
    p.add_argument(
        "--per-face",
        metavar="FILE.npz",
        help="write the report's per-face arrays to a .npz file instead (default: in the report)",
    )
    p.add_argument(
        "--preview",
        metavar="PICTURE.png",
        help="write a ray-cast preview picture, PNG or JPEG (default: none)",
    )
    up_option(p, "the preview and the upper-hemisphere region")
    algorithm_options(p)
    p.add_argument(
        "--inside-point",
        dest="inside_points",
        type=point,
        action="append",
        default=[],
        metavar="X,Y,Z",
        help="a point known to be inside (repeatable; default: none)",
    )
    p.add_argument(
        "--outside-point",
        dest="outside_points",
        type=point,
        action="append",
        default=[],
        metavar="X,Y,Z",
        help="a point known to be outside (repeatable; default: none)",
    )
    p.add_argument(
        "--inside-box",
        dest="inside_boxes",
        type=box,
        action="append",
        default=[],
        metavar="X0,Y0,Z0,X1,Y1,Z1",
        help="an axis-aligned box known to be inside (repeatable; default: none)",
    )
    p.add_argument(
        "--outside-box",
        dest="outside_boxes",
        type=box,
        action="append",
        default=[],
        metavar="X0,Y0,Z0,X1,Y1,Z1",
        help="an axis-aligned box known to be outside (repeatable; default: none)",
    )
    p.add_argument("--force", action="store_true", help="overwrite existing outputs")
    verbosity_options(p)


def box(text: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Parse ``x0,y0,z0,x1,y1,z1`` into the min and max corners of a box (an argparse ``type``).

    Parameters
    ----------
    text : str
        Six comma-separated numbers: the min corner, then the max corner.

    Returns
    -------
    tuple of two tuple of 3 float
        The min corner and the max corner.

    Raises
    ------
    argparse.ArgumentTypeError
        Not six numbers, or a min coordinate above its max.
    """
    try:
        v = [float(t) for t in text.split(",")]
    except ValueError:
        v = []
    if len(v) != 6 or any(a > b for a, b in zip(v[:3], v[3:])):
        raise argparse.ArgumentTypeError(f"expected x0,y0,z0,x1,y1,z1 with min <= max, got {text!r}")
    return tuple(v[:3]), tuple(v[3:])


def algorithm_options(p: argparse.ArgumentParser) -> None:
    """Add the graph-cut options that apply to any model (shared with ``meshvis batch``).

    The options are ``--seed``, ``--rays-per-node``, ``--rays-per-point``,
    ``--samples-per-face``, ``--no-filter``, ``--no-progressive`` and ``--solver``; their
    ``dest`` names are the keywords of :func:`meshvis.classify` and their defaults those of
    its signature.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The parser to add them to.
    """
    d = _defaults("classify")
    p.add_argument("--seed", type=int, default=d["seed"], help="random seed")
    p.add_argument(
        "--rays-per-node", type=positive_int, default=d["rays_per_node"], help="ray budget per node"
    )
    p.add_argument(
        "--rays-per-point",
        type=positive_int,
        default=d["rays_per_point"],
        help="ray budget per sample point of an intersecting/coplanar face (default: --rays-per-node; "
        "in remove-interior --visibility both, --rays-per-node divided by --samples-per-face)",
    )
    p.add_argument(
        "--samples-per-face",
        type=positive_int,
        default=d["samples_per_face"],
        help="sample points per intersecting/coplanar face",
    )
    # the flags switch off what the library's keywords (use_filter, progressive) switch on
    p.add_argument(
        "--no-filter",
        dest="use_filter",
        action="store_false",
        default=d["use_filter"],
        help="switch off the cosine filter (Eq. 8-9; on by default)",
    )
    p.add_argument(
        "--no-progressive",
        dest="progressive",
        action="store_false",
        default=d["progressive"],
        help="cast the whole ray budget in one round (by default rounds stop when the cut settles)",
    )
    p.add_argument("--solver", choices=SOLVERS, default=d["solver"], help="the min-cut solver")


def region_option(p: argparse.ArgumentParser, default: str | None, what: str) -> None:
    """Add the ``--from REGION`` option: where the viewers are.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The parser to add it to.
    default : str or None
        The region when the option is not given (None: no region).
    what : str
        The start of the help text, before the list of region forms.
    """
    p.add_argument(
        "--from",
        dest="from_region",
        default=default,
        metavar="REGION",
        help=f"{what}; regions: outside, upper-hemisphere[:ux,uy,uz], box:x0,y0,z0,x1,y1,z1, "
        "points:x,y,z;..., path:CAMERAS.json, cells:PVS.npz (remove-interior: the view cells of meshvis pvs)",
    )


def removal_options(p: argparse.ArgumentParser) -> None:
    """Add the options of inside removal by sight to the ``remove-interior`` parser.

    The options are ``--visibility``, ``--from``, ``--budget``, ``--transparent``,
    ``--check-rays``, ``--rescue-rays``, ``--level``, ``--keep-border`` and ``--conservative``, with the defaults of
    :func:`meshvis.remove_interior`.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The parser to add them to.
    """
    d = _defaults("remove-interior")
    p.add_argument(
        "--visibility",
        choices=VISIBILITY_MODES,
        default=d["visibility"],
        help="remove what no view from --from reaches (view), what the cut calls hidden (object), "
        "or only what both call hidden",
    )
    region_option(p, d["from_region"], "where viewers are")
    _budget_option(p, d["budget"], "stop the search for views (view and both)")
    _transparent_option(p, d["transparent"])
    p.add_argument(
        "--check-rays",
        type=int,
        default=d["check_rays"],
        metavar="N",
        help="self-check: fresh random rays from every removed face, reported (0: no check)",
    )
    _rescue_option(p, d["rescue_rays"], "view and both")
    p.add_argument(
        "--level",
        choices=LEVELS,
        default=d["level"],
        help="remove single faces, or whole patches / parts whose faces are all hidden",
    )
    p.add_argument(
        "--keep-border",
        type=int,
        default=d["keep_border"],
        metavar="N",
        help="keep N rings of hidden faces next to kept ones",
    )
    p.add_argument(
        "--conservative",
        action="store_true",
        default=d["conservative"],
        help="remove only faces surely hidden from --from points:... or path:CAMERAS.json (outside the "
        "conservative set: nothing visible from there is removed; no cut, --visibility is not used)",
    )


def _budget_option(p: argparse.ArgumentParser, default, what: str) -> None:
    p.add_argument(
        "--budget",
        type=positive_int,
        default=default,
        metavar="RAYS",
        help=f"{what} after about this many rays (default: its stop rule ends it); fewer rays are faster "
        "and delete more visible faces",
    )


def _rescue_option(p: argparse.ArgumentParser, default: int, what: str) -> None:
    p.add_argument(
        "--rescue-rays",
        type=int,
        default=default,
        metavar="N",
        help=f"rescue pass ({what}): random rays from every face the search did not see next to a seen one "
        "(fewer from the others); a face one of them sees from is kept (0: no rescue)",
    )


def _transparent_option(p: argparse.ArgumentParser, default: str) -> None:
    p.add_argument(
        "--transparent",
        choices=TRANSPARENT_MODES,
        default=default,
        help="faces of see-through materials (glTF BLEND, MASK below its cutoff, transmission; MTL d < 1, "
        "Tr > 0) let sight through, or are walls",
    )


def layer_options(p: argparse.ArgumentParser) -> None:
    """Add the options of ``layers``, with the defaults of :func:`meshvis.layers`.

    The options are ``--max-layers``, ``--visibility``, ``--from``, ``--budget``,
    ``--transparent`` and ``--rescue-rays``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The parser to add them to.
    """
    d = _defaults("layers")
    p.add_argument(
        "--max-layers",
        type=positive_int,
        default=d["max_layers"],
        help="stop after K layers (default: peel until no face is added)",
    )
    p.add_argument(
        "--visibility",
        choices=LAYER_MODES,
        default=d["visibility"],
        help="peel by sight from --from: layer k is what is seen once layers 1..k-1 are gone (view), or by "
        "the graph cut (object)",
    )
    region_option(p, d["from_region"], "where viewers are, for --visibility view")
    _budget_option(p, d["budget"], "stop each layer's search for views")
    _transparent_option(p, d["transparent"])
    _rescue_option(p, d["rescue_rays"], "--visibility view, every layer")


def add_parser(sub) -> None:
    """Add the ``classify``, ``orient``, ``remove-interior`` and ``layers`` subcommands.

    All four share the input, report, preview, graph-cut and hint options; each adds its
    own, and sets ``func`` to :func:`run` and ``op`` to its name.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser.
    """
    p = sub.add_parser("classify", help="classify every triangle side inside/outside (report only)")
    _common(p, needs_output=False)
    p.add_argument("--graphml", metavar="GRAPH.graphml", help="export the visibility graph (default: none)")
    p.set_defaults(func=run, op="classify")

    p = sub.add_parser("orient", help="orient every face so its front faces the outside")
    _common(p)
    od = _defaults("orient")
    p.add_argument("--front", choices=("ccw", "cw"), default=od["front"], help="winding of the front side")
    p.add_argument(
        "--two-sided",
        choices=("keep", "duplicate", "strongest"),
        default=od["two_sided"],
        help="what to do with faces whose both sides are outside",
    )
    p.add_argument(
        "--semantics",
        choices=("layer", "cavity"),
        default=od["semantics"],
        help="hidden shells face outward per layer, or inward as cavities",
    )
    p.add_argument(
        "--conflicts",
        choices=("majority", "duplicate"),
        default=od["conflicts"],
        help="intersected faces whose samples disagree: area majority or both orientations",
    )
    from meshvis.repair.operation import GROUND_CHOICES

    ground_name = {v: k for k, v in GROUND_CHOICES.items()}[od["ground"]]
    p.add_argument(
        "--ground",
        choices=tuple(GROUND_CHOICES),
        default=ground_name,
        help="a scene standing on a ground is seen from above it only: yes, no, or auto (where one is found)",
    )
    region_option(
        p,
        od["from_region"],
        "orient every face toward the side seen from REGION instead of the outside (default: the outside "
        "of the graph cut)",
    )
    p.set_defaults(func=run, op="orient")

    p = sub.add_parser("remove-interior", help="remove the faces that cannot be seen from outside")
    _common(p)
    p.add_argument("--removed", metavar="FILE", help="also write the removed faces (default: not written)")
    removal_options(p)
    p.set_defaults(func=run, op="remove-interior")

    p = sub.add_parser("layers", help="peel the model into nested layers")
    _common(p, layers=True)
    layer_options(p)
    p.set_defaults(func=run, op="layers")


def run(args: argparse.Namespace) -> int:
    """Run one graph-cut command (``args.op``) on one model and write its outputs.

    Every option and output path is checked before the model is read
    (:func:`meshvis.repair.operation.check_options`).  The outputs appear together at
    the end, or none of them does (an error, Ctrl-C, SIGTERM).  Prints one summary line
    (and a note for an output written anew); ``--verbose`` adds the internals, ``--quiet``
    prints nothing.  ``--report -`` writes the report to standard output and silences the
    other messages.  When ``--removed`` is given and no face was removed, an existing file
    of that name is deleted, so that it does not pass for this run's result.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of the subcommand, with ``op`` naming it.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    ParameterError
        ``--per-face`` without ``--report``, or an option out of its range (a malformed
        ``--from`` region, ...).
    OutputError
        An output path or format is refused (see :func:`meshvis.io.check_outputs`): two
        outputs share one path, or one would replace the input, its MTL or a texture.
    ModelError
        The model cannot be read (see :func:`meshvis.load`).
    """
    from meshvis.io import load
    from meshvis.io.writing import check_not_read
    from meshvis.repair.operation import check_options

    from .common import detail
    from .progress import stage_progress

    t0 = time.perf_counter()
    outputs = [
        x
        for x in (
            getattr(args, "output", None),
            args.report if args.report != "-" else None,
            args.per_face,
            args.preview,
            getattr(args, "removed", None),
            getattr(args, "graphml", None),
        )
        if x
    ]
    if args.per_face and not args.report:
        raise ParameterError("--per-face needs --report")
    check_options(args.op, args)
    check_outputs(outputs, [args.input], args.force)
    if args.report == "-":
        args.quiet = True  # standard output carries the report alone
    soup = load(args.input)
    for path in outputs:  # nor over the MTL or a texture the model reads
        check_not_read(path, soup)
    detail(args, f"{args.input}: {soup.n_faces} faces, {soup.n_parts} parts")
    removed = getattr(args, "removed", None)
    # every output appears at the end, together, or none does (an error, Ctrl-C, SIGTERM)
    with staged_outputs(), stage_progress(args) as progress:
        report = run_op(args.op, soup, args, progress)
        report["input"] = args.input
        report["seconds_total"] = time.perf_counter() - t0
        if args.report:
            write_report(report, args.report, args.per_face)
    if removed and not report["removed_faces"] and os.path.exists(removed):
        os.remove(removed)  # an older result there would pass for this run's (--force was given)
    return 0


def run_op(op: str, soup, args: argparse.Namespace, progress=None) -> dict:
    """Run one operation on a loaded soup through the library and write its outputs.

    Parameters
    ----------
    op : {"classify", "orient", "remove-interior", "layers"}
        The operation.
    soup : Soup
        The loaded model.
    args : argparse.Namespace
        The operation's options and output paths (see
        :func:`meshvis.repair.operation.run_operation`); ``quiet`` silences the summary,
        ``verbose`` adds the internals.
    progress : callable, optional
        ``progress(stage, fraction)`` callback of the classification.

    Returns
    -------
    dict
        The JSON-ready report of the operation.
    """
    from meshvis.repair.operation import run_operation

    from .common import detail

    return run_operation(
        op,
        soup,
        args,
        progress,
        say=lambda text: say(args, f"{args.input}: {text}" if text.startswith(f"{op}:") else text),
        detail=lambda text: detail(args, text),
    )
