"""``meshvis label MODEL... -o OUT.svg``: external labels for the visible parts of a model."""

from __future__ import annotations

import argparse
import os

from .common import check_outputs, positive_int, say, staged_outputs, verbosity_options

UP_AXES = ("auto", "x", "y", "z")


def add_parser(sub) -> None:
    """Add the ``label`` subcommand to the ``meshvis`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """
    from meshvis.labeling.candidates import LAYOUTS
    from meshvis.labeling.internal_area import SHAPES

    p = sub.add_parser(
        "label",
        help="lay out external labels (leader lines + text boxes) for the named parts of a model",
        description="Label every visible part of a model with a text box outside the model, joined to "
        "an anchor on the part by a leader line (fuzzy-greedy layout, thesis appendix I). Several "
        "input files are combined; a single-part file is named after its file.",
    )
    p.add_argument("inputs", nargs="+", metavar="MODEL", help="model file(s); parts become labels")
    p.add_argument(
        "-o",
        "--output",
        required=True,
        help="SVG, PNG or GIF to write (with several frames: NAME_000.svg ... or one GIF)",
    )
    p.add_argument(
        "--layout", choices=tuple(LAYOUTS), default="left-right", help="label layout (default left-right)"
    )
    p.add_argument("--area", choices=SHAPES, default="hull", help="internal area shape (default hull)")
    p.add_argument("--margin", type=float, help="internal area margin in pixels (default 2%% of the image)")
    p.add_argument(
        "--method",
        choices=("fuzzy", "two-step"),
        default="fuzzy",
        help="fuzzy-greedy layout (default) or the classic two-step baseline",
    )
    p.add_argument(
        "--json", metavar="FILE", help="also write labels, metrics and timings as JSON ('-': standard output)"
    )
    p.add_argument("--png", metavar="FILE", help="also write a PNG of the (first) frame")
    p.add_argument(
        "--texts", metavar="FILE", help="JSON object or 2-column CSV mapping part names to label texts"
    )
    p.add_argument(
        "--size",
        type=positive_int,
        nargs=2,
        default=(512, 512),
        metavar=("W", "H"),
        help="image size in pixels (default 512 512)",
    )
    _camera_arguments(p.add_argument_group("camera"))
    _optimisation_arguments(p.add_argument_group("optimisation (appendix I)"))
    p.add_argument("--show-area", action="store_true", help="draw the internal area's boundary")
    p.add_argument("--duration", type=positive_int, default=120, help="GIF frame time in ms (default 120)")
    p.add_argument("--force", action="store_true", help="overwrite existing outputs")
    verbosity_options(p)
    p.set_defaults(func=run)


def _camera_arguments(cam: argparse._ArgumentGroup) -> None:
    """Where the views come from: one fitted camera, an orbit, a camera file or a path."""
    src = cam.add_mutually_exclusive_group()
    src.add_argument("--orbit", type=positive_int, metavar="N", help="N frames turning once around the model")
    src.add_argument(
        "--camera-path", metavar="FILE", help="JSON list of cameras (position, target, up, fov, ...)"
    )
    src.add_argument("--camera", metavar="FILE", help="JSON of one camera")
    cam.add_argument("--azimuth", type=float, default=30.0, help="degrees around the up axis (default 30)")
    cam.add_argument("--elevation", type=float, default=20.0, help="degrees above the horizon (default 20)")
    cam.add_argument("--distance", type=float, help="camera distance (default: fit the model)")
    cam.add_argument("--fov", type=float, default=35.0, help="vertical field of view in degrees (default 35)")
    cam.add_argument("--orthographic", action="store_true", help="orthographic projection")
    cam.add_argument(
        "--up",
        choices=UP_AXES,
        default="auto",
        help="the model's up axis (default auto: y for glTF/GLB and OBJ, z otherwise)",
    )
    cam.add_argument(
        "--fit-margin",
        type=float,
        default=1.6,
        help="room around the model when fitting the camera (default 1.6)",
    )


def _optimisation_arguments(opt: argparse._ArgumentGroup) -> None:
    """Add the thresholds and weights of the fuzzy-greedy optimisation, font and visibility."""
    opt.add_argument(
        "--d-a", type=float, default=0.05, help="anchor distance threshold, fraction of d_S (default 0.05)"
    )
    opt.add_argument(
        "--d-e", type=float, help="endpoint distance threshold, fraction of d_S (default: box size)"
    )
    opt.add_argument(
        "--weights", metavar="W2,W3,W4,W5,W6,W7", help="weights of f2..f7 (default 0.2,1,1,1,0.7,0.7)"
    )
    opt.add_argument("--no-coherence", action="store_true", help="lay frames out independently (no f6, f7)")
    opt.add_argument(
        "--font-size", type=positive_int, help="label font size in pixels (default: from the image size)"
    )
    from meshvis.labeling.pipeline import MIN_PIXELS

    opt.add_argument(
        "--min-pixels",
        type=positive_int,
        default=MIN_PIXELS,
        help=f"parts with fewer visible pixels are not labelled (default {MIN_PIXELS})",
    )


def _up(args: argparse.Namespace) -> tuple[float, float, float]:
    from meshvis.rays.camera import up_axis

    return up_axis(args.up, args.inputs)


def _weights(text: str | None):
    from meshvis.errors import ParameterError
    from meshvis.labeling.membership import Weights

    if not text:
        return Weights()
    try:
        vals = [float(t) for t in text.split(",")]
    except ValueError:
        raise ParameterError(f"--weights: expected 6 numbers, got {text!r}") from None
    if len(vals) != 6:
        raise ParameterError(f"--weights: expected 6 numbers (w2..w7), got {len(vals)}")
    return Weights(**dict(zip(("w2", "w3", "w4", "w5", "w6", "w7"), vals)))


def _frame_paths(output: str, n: int) -> list[str]:
    stem, ext = os.path.splitext(output)
    if n == 1 or ext.lower() in (".gif", ".json"):
        return [output]
    return [f"{stem}_{i:03d}{ext}" for i in range(n)]


def _cameras(args: argparse.Namespace, soup) -> list:
    """Build the cameras of the frames: an orbit, a camera path, one camera file or one fitted view."""
    from meshvis.labeling import frames as fr
    from meshvis.labeling.inputs import read_camera
    from meshvis.labeling.pipeline import fit_camera

    up = _up(args)
    if args.orbit:
        return fr.orbit(
            soup,
            args.orbit,
            elevation=args.elevation,
            start=args.azimuth,
            fov=args.fov,
            orthographic=args.orthographic,
            up=up,
            fit_margin=args.fit_margin,
            distance=args.distance,
            size=tuple(args.size),
        )
    if args.camera_path:
        return fr.read_camera_path(args.camera_path)
    if args.camera:
        return [read_camera(args.camera)]
    return [
        fit_camera(
            soup,
            azimuth=args.azimuth,
            elevation=args.elevation,
            distance=args.distance,
            fov=args.fov,
            orthographic=args.orthographic,
            margin=args.fit_margin,
            up=up,
            size=tuple(args.size),
        )
    ]


def _write_outputs(args: argparse.Namespace, results: list, ext: str) -> None:
    """Write the picture(s) or GIF, the optional PNG of the first frame and the JSON."""
    from meshvis.labeling import output as out
    from meshvis.labeling.metrics import sequence_metrics

    with staged_outputs():  # the pictures and the JSON appear together or not at all
        if ext == ".gif":
            out.write_gif(results, args.output, duration_ms=args.duration)
        else:
            out.write(results if len(results) > 1 else results[0], args.output, show_area=args.show_area)
        if args.png:
            out.write_png(results[0], args.png, show_area=args.show_area)
        if args.json:
            data = {"inputs": list(args.inputs), "frames": [r.to_json() for r in results]}
            if len(results) > 1:
                data["sequence"] = sequence_metrics(results)
            out.write_json(data, args.json)


def _report(args: argparse.Namespace, results: list, paths: list[str]) -> None:
    """One summary line (labels placed, what was written); the quality figures with ``--verbose``."""
    from meshvis.labeling.metrics import sequence_metrics

    from .common import detail

    first = results[0]
    m = first.metrics
    shown = ", ".join(paths if len(paths) <= 3 else paths[:2] + ["...", paths[-1]])
    left = len(first.invisible) + len(first.unplaced)
    frames = f" in each of {len(results)} frames" if len(results) > 1 else ""
    say(
        args,
        f"label: {len(first.labels)} labels{frames} ({args.layout}, {args.method})"
        + (f", {left} parts not labelled (--verbose names them)" if left else "")
        + f"; wrote {shown}",
    )
    detail(
        args,
        f"overlaps {m['overlaps']}, crossings {m['crossings']}, label over model {m['label_over_model']} px; "
        f"layout {first.timings['layout_ms']:.1f} ms",
    )
    if first.invisible:
        detail(args, f"not visible, not labelled: {', '.join(n for _, n in first.invisible)}")
    outside = set(first.params.get("outside_image", []))
    if outside:
        detail(
            args,
            f"left out, no room inside the image even at {first.font_size} px: {', '.join(sorted(outside))}",
        )
    rest = [n for _, n in first.unplaced if n not in outside]
    if rest:
        detail(args, f"no room found for: {', '.join(rest)}")
    if len(results) > 1:
        s = sequence_metrics(results)
        detail(
            args,
            f"{len(results)} frames; mean label motion {s['label_motion_mean']:.1f} px, "
            f"side flips {s['side_flips']}, order swaps {s['order_swaps']}",
        )


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis label``: lay out external labels for the visible parts and write the pictures.

    The input files are combined into one model (a single-part file is named after its
    file).  There is a frame per camera (``--orbit``, ``--camera-path``, ``--camera``, or one
    view fitted to the model); several frames are written as ``NAME_000.svg``, ... or as one
    GIF.  The pictures, the PNG of ``--png`` and the JSON of ``--json`` appear together or
    not at all.  Prints what was written and the first frame's quality (and the motion of a
    sequence) unless ``--quiet``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``meshvis label`` (inputs, output, layout, camera and
        optimisation options).

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    OutputError
        The output is not ``.svg``, ``.png`` or ``.gif``, or an output path is refused (see
        :func:`meshvis.io.check_output`).
    ParameterError
        ``--weights`` is not six numbers, the ``--camera`` file cannot be read, or a
        ``--texts`` entry names no part.
    ModelError
        A model cannot be read (see :func:`meshvis.load`).
    """
    from meshvis.errors import OutputError
    from meshvis.io.jsonfile import STDOUT
    from meshvis.io.writing import check_not_read
    from meshvis.labeling import frames as fr
    from meshvis.labeling.inputs import load_models, read_texts

    ext = os.path.splitext(args.output)[1].lower()
    if ext not in (".svg", ".png", ".gif"):
        raise OutputError("unknown output format (use .svg, .png or .gif)", args.output)
    soup = load_models(args.inputs if len(args.inputs) > 1 else args.inputs[0])
    cameras = _cameras(args, soup)
    paths = _frame_paths(args.output, len(cameras))
    outputs = paths + [p for p in (args.json, args.png) if p and p != STDOUT]
    check_outputs(outputs, args.inputs, args.force)
    for path in outputs:  # not over a texture of a model
        check_not_read(path, soup)
    if args.json == STDOUT:
        args.quiet = True  # standard output carries the JSON alone
    texts = read_texts(args.texts, soup.part_names) if args.texts else None
    options = dict(
        layout=args.layout,
        area=args.area,
        margin=args.margin,
        method=args.method,
        size=tuple(args.size),
        texts=texts,
        weights=_weights(args.weights),
        d_a=args.d_a,
        d_e=args.d_e,
        font_size=args.font_size,
        min_pixels=args.min_pixels,
    )
    results = fr.layout_frames(soup, cameras, coherence=not args.no_coherence, **options)
    _write_outputs(args, results, ext)
    _report(args, results, paths)
    return 0
