"""``meshvis render MODEL -o PICTURE.png``: a shaded preview through the ray backend."""

from __future__ import annotations

import argparse

from .common import check_output, positive_int, say


def add_parser(sub) -> None:
    """Add the ``render`` subcommand to the ``meshvis`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """
    p = sub.add_parser("render", help="render a shaded preview image (front sides blue, back sides orange)")
    p.add_argument("input", help="input model")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument(
        "--color-by",
        choices=("side", "part", "layer", "none"),
        default="side",
        help="side: front blue / back orange (default); part; layer (runs the layer peeling)",
    )
    p.add_argument("--azimuth", type=float, default=30.0, help="degrees around the up axis (default 30)")
    p.add_argument("--elevation", type=float, default=20.0, help="degrees above the horizon (default 20)")
    p.add_argument(
        "--up",
        choices=("auto", "x", "y", "z"),
        default="auto",
        help="the model's up axis (default auto: y for glTF/GLB and OBJ, z otherwise)",
    )
    p.add_argument("--size", type=positive_int, nargs=2, default=(512, 512), metavar=("W", "H"))
    p.add_argument("--seed", type=int, default=0, help="seed of the layer peeling (--color-by layer)")
    p.add_argument("--force", action="store_true", help="overwrite an existing output")
    p.add_argument("--quiet", "-q", action="store_true")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis render``: write a shaded PNG preview of a model.

    The camera is fitted to the model from ``--azimuth`` and ``--elevation`` about the up
    axis.  With ``--color-by layer`` the layer peeling runs first (seeded by ``--seed``) and
    each face is coloured by its layer.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options: ``input``, ``output``, ``color_by``, ``azimuth``, ``elevation``,
        ``up``, ``size`` (width, height), ``seed``, ``force``, ``quiet``.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    OutputError
        The output path is refused (see :func:`meshvis.io.check_output`).
    ModelError
        The model cannot be read (see :func:`meshvis.load`).
    """
    from meshvis.io import load
    from meshvis.io.writing import check_not_read
    from meshvis.rays.camera import Camera, up_axis
    from meshvis.rays.render import render, save_png

    check_output(args.output, [args.input], args.force)
    soup = load(args.input)
    check_not_read(args.output, soup)  # not over a texture of the model
    values = None
    color_by = None if args.color_by == "none" else args.color_by
    if color_by == "layer":
        from meshvis.repair.layers import layers

        values = layers(soup, seed=args.seed).layer
    camera = Camera.fit(
        soup, azimuth=args.azimuth, elevation=args.elevation, up=up_axis(args.up, [args.input])
    )
    r = render(soup, camera, size=tuple(args.size), color_by=color_by, face_values=values)
    save_png(r.image, args.output)
    say(args, f"wrote {args.output} ({args.size[0]}x{args.size[1]}, {int((r.face >= 0).sum())} model pixels)")
    return 0
