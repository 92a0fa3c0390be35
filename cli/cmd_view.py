"""``meshvis view MODEL...``: a local page that shows the model and labels that follow it."""

from __future__ import annotations

import argparse

from .common import positive_int, say, verbosity_options


def add_parser(sub) -> None:
    """Add the ``view`` subcommand to the ``meshvis`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """
    from meshvis.labeling.candidates import LAYOUTS
    from meshvis.labeling.pipeline import MIN_PIXELS
    from meshvis.labeling.server import PORT

    p = sub.add_parser(
        "view",
        help="a local page showing the model with labels that follow it as you turn it",
        description="Serve a page on 127.0.0.1 that shows the model (glTF as it is, other formats "
        "converted) with orbit controls and external labels for its visible parts. The page renders "
        "the part-ID buffer on the GPU; the server lays the labels out, coherently from frame to frame. "
        "Nothing is fetched from the internet. Stop with Ctrl-C.",
    )
    p.add_argument("inputs", nargs="+", metavar="MODEL", help="model file(s); parts become labels")
    p.add_argument(
        "--layout", choices=tuple(LAYOUTS), default="left-right", help="label layout (default left-right)"
    )
    p.add_argument("--port", type=int, default=PORT, help=f"port on 127.0.0.1 (default {PORT}; 0: any free)")
    p.add_argument(
        "--texts", metavar="FILE", help="JSON object or 2-column CSV mapping part names to label texts"
    )
    p.add_argument(
        "--up",
        choices=("auto", "x", "y", "z"),
        default="auto",
        help="the model's up axis (default auto: y for glTF/GLB and OBJ, z otherwise)",
    )
    p.add_argument(
        "--min-pixels",
        type=positive_int,
        default=MIN_PIXELS,
        help=f"parts with fewer visible pixels are not labelled (default {MIN_PIXELS})",
    )
    p.add_argument("--no-browser", action="store_true", help="do not open the page in a browser")
    verbosity_options(p)  # --verbose prints every request
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis view``: load the model, serve the page until Ctrl-C.

    Prints one line with the page's address (unless ``--quiet``) and opens it in the
    default browser (unless ``--no-browser``).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``meshvis view``.

    Returns
    -------
    int
        Exit status 0 after Ctrl-C.

    Raises
    ------
    ModelError
        A model cannot be read.
    ParameterError
        A ``--texts`` entry names no part, or ``--port`` is out of range.
    OSError
        The port is taken.
    """
    import sys
    import webbrowser

    from meshvis.errors import ParameterError
    from meshvis.labeling.inputs import read_texts
    from meshvis.labeling.live import LiveLabeler
    from meshvis.labeling.server import ViewServer
    from meshvis.rays.camera import up_axis

    if not 0 <= args.port <= 65535:
        raise ParameterError(f"--port must be 0..65535, got {args.port}")
    texts = read_texts(args.texts) if args.texts else None
    model = args.inputs if len(args.inputs) > 1 else args.inputs[0]
    live = LiveLabeler(
        model, layout=args.layout, texts=texts, up=up_axis(args.up, args.inputs), min_pixels=args.min_pixels
    )
    path = args.inputs[0] if len(args.inputs) == 1 else None
    server = ViewServer(live, path, port=args.port, verbose=args.verbose)
    say(args, f"meshvis view: {server.url} ({live.soup.n_parts} parts, {args.layout}; Ctrl-C to stop)")
    sys.stdout.flush()  # the address is what a script waiting on the pipe reads
    if not args.no_browser:
        webbrowser.open(server.url)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.shutdown()
    return 0
