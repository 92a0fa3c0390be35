"""``meshvis render MODEL -o PICTURE.png``: a shaded preview through the ray backend."""

from __future__ import annotations

import argparse
import time

from .common import check_output, library_default, positive_int, say, up_option, verbosity_options

#: the library function whose keywords the options are, and whose defaults they take
RENDER = "meshvis.rays.render:render"


def add_parser(sub) -> None:
    """Add the ``render`` subcommand to the ``meshvis`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """

    def d(keyword):
        return library_default(RENDER, keyword)

    p = sub.add_parser("render", help="render a shaded preview image (front sides blue, back sides orange)")
    p.add_argument("input", help="input model")
    p.add_argument(
        "-o", "--output", required=True, help="picture to write, PNG or JPEG (format from the extension)"
    )
    p.add_argument(
        "--color-by",
        choices=("side", "part", "layer", "none"),
        default=d("color_by") or "none",
        help="side: front blue / back orange; part: a colour per part; layer: runs the layer peeling, "
        "outer layers translucent over the inner ones; none: grey",
    )
    p.add_argument("--azimuth", type=float, default=d("azimuth"), help="degrees around the up axis")
    p.add_argument("--elevation", type=float, default=d("elevation"), help="degrees above the horizon")
    up_option(p, "the camera")
    p.add_argument("--size", type=positive_int, nargs=2, default=d("size"), metavar=("W", "H"), help="pixels")
    p.add_argument(
        "--seed",
        type=int,
        default=library_default("meshvis.graphcut.classify:classify", "seed"),
        help="seed of the layer peeling (--color-by layer)",
    )
    p.add_argument("--force", action="store_true", help="overwrite an existing output")
    verbosity_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis render``: write a shaded preview picture of a model.

    The picture's format (PNG or JPEG) comes from the output's extension, checked before
    the model is read.  The camera is fitted to the model from ``--azimuth`` and
    ``--elevation`` about the up axis.  With ``--color-by layer`` the layer peeling runs
    first (seeded by ``--seed``) and every layer shows: the outer ones translucent, the
    innermost opaque (:func:`meshvis.rays.render.render_layers`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options: ``input``, ``output``, ``color_by``, ``azimuth``, ``elevation``,
        ``up``, ``size`` (width, height), ``seed``, ``force``, ``quiet``, ``verbose``.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    OutputError
        The output path or its format is refused (see :func:`meshvis.io.check_output`).
    ModelError
        The model cannot be read (see :func:`meshvis.load`).
    """
    from meshvis.io import load
    from meshvis.io.up_axis import up_vector
    from meshvis.io.writing import check_not_read
    from meshvis.rays.camera import Camera
    from meshvis.rays.render import check_image_format, render, render_layers, save_image

    t0 = time.perf_counter()
    check_image_format(args.output)
    up = None if args.up == "auto" else up_vector(args.up)
    check_output(args.output, [args.input], args.force)
    soup = load(args.input)
    check_not_read(args.output, soup)  # not over a texture of the model
    camera = Camera.fit(soup, azimuth=args.azimuth, elevation=args.elevation, up=up)
    size = tuple(args.size)
    if args.color_by == "layer":
        from meshvis.repair.layers import layers

        peeled = layers(soup, seed=args.seed)
        image = render_layers(soup, peeled.layer, camera, size=size)
        what = f"{peeled.n_layers} layers"
    else:
        r = render(soup, camera, size=size, color_by=None if args.color_by == "none" else args.color_by)
        image = r.image
        what = f"{int((r.face >= 0).sum())} model pixels"
    save_image(image, args.output)
    say(
        args,
        f"{args.input}: render: wrote {args.output} ({size[0]}x{size[1]}, {what}); "
        f"{time.perf_counter() - t0:.1f} s",
    )
    return 0
