"""``meshvis classify | orient | remove-interior | layers``: the graph-cut commands."""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

from cli.common import check_output, point, positive_int, say, write_json
from meshvis.errors import ParameterError


def _common(p: argparse.ArgumentParser, needs_output: bool = True) -> None:
    p.add_argument("input", help="input model (OBJ, PLY, STL, OFF, glTF/GLB, 3MF)")
    if needs_output:
        p.add_argument("-o", "--output", required=True, help="output model; format from the extension")
    p.add_argument("--report", metavar="REPORT.json", help="write a JSON report with per-face results")
    p.add_argument("--preview", metavar="PICTURE.png", help="write a ray-cast preview image")
    algorithm_options(p)
    p.add_argument("--inside-point", type=point, action="append", default=[], metavar="X,Y,Z",
                   help="a point known to be inside (repeatable)")
    p.add_argument("--outside-point", type=point, action="append", default=[], metavar="X,Y,Z",
                   help="a point known to be outside (repeatable)")
    p.add_argument("--inside-box", type=box, action="append", default=[], metavar="X0,Y0,Z0,X1,Y1,Z1",
                   help="an axis-aligned box known to be inside (repeatable)")
    p.add_argument("--outside-box", type=box, action="append", default=[], metavar="X0,Y0,Z0,X1,Y1,Z1",
                   help="an axis-aligned box known to be outside (repeatable)")
    p.add_argument("--force", action="store_true", help="overwrite existing outputs")
    p.add_argument("--quiet", "-q", action="store_true", help="print nothing but errors")


def box(text: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Parse ``x0,y0,z0,x1,y1,z1`` (min corner, max corner)."""
    try:
        v = [float(t) for t in text.split(",")]
    except ValueError:
        v = []
    if len(v) != 6 or any(a > b for a, b in zip(v[:3], v[3:])):
        raise argparse.ArgumentTypeError(f"expected x0,y0,z0,x1,y1,z1 with min <= max, got {text!r}")
    return tuple(v[:3]), tuple(v[3:])


def algorithm_options(p: argparse.ArgumentParser) -> None:
    """Add the graph-cut options that apply to any model (shared with ``meshvis batch``)."""
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--rays-per-node", type=positive_int, default=32, help="ray budget per node (default 32)")
    p.add_argument("--samples-per-face", type=positive_int, default=4,
                   help="sample points per intersecting/coplanar face (default 4)")
    p.add_argument("--no-filter", action="store_true", help="switch off the cosine filter (Eq. 8-9)")
    p.add_argument("--no-progressive", action="store_true", help="cast the whole ray budget in one round")
    p.add_argument("--solver", choices=("pymaxflow", "scipy"), default="pymaxflow")


def add_parser(sub) -> None:
    p = sub.add_parser("classify", help="classify every triangle side inside/outside (report only)")
    _common(p, needs_output=False)
    p.add_argument("--graphml", metavar="GRAPH.graphml", help="export the visibility graph")
    p.set_defaults(func=run, op="classify")

    p = sub.add_parser("orient", help="orient every face so its front faces the outside")
    _common(p)
    p.add_argument("--front", choices=("ccw", "cw"), default="ccw", help="winding of the front side")
    p.add_argument("--two-sided", choices=("keep", "duplicate", "strongest"), default="keep",
                   help="what to do with faces whose both sides are outside (default keep)")
    p.add_argument("--semantics", choices=("layer", "cavity"), default="layer",
                   help="hidden shells face outward per layer (default) or inward as cavities")
    p.add_argument("--conflicts", choices=("majority", "duplicate"), default="majority",
                   help="intersected faces whose samples disagree: area majority or both orientations")
    p.set_defaults(func=run, op="orient")

    p = sub.add_parser("remove-interior", help="remove the faces that cannot be seen from outside")
    _common(p)
    p.add_argument("--removed", metavar="FILE", help="also write the removed faces")
    p.set_defaults(func=run, op="remove-interior")

    p = sub.add_parser("layers", help="peel the model into nested layers")
    _common(p)
    p.add_argument("--max-layers", type=positive_int, help="stop after K layers")
    p.set_defaults(func=run, op="layers")


def classify_kwargs(args: argparse.Namespace) -> dict:
    from meshvis.hints import Hints

    given = {k: getattr(args, k, None) or [] for k in ("inside_point", "outside_point", "inside_box", "outside_box")}
    hints = None
    if any(given.values()):
        hints = Hints(inside_points=np.array(given["inside_point"]).reshape(-1, 3),
                      outside_points=np.array(given["outside_point"]).reshape(-1, 3),
                      inside_boxes=np.array(given["inside_box"]).reshape(-1, 2, 3),
                      outside_boxes=np.array(given["outside_box"]).reshape(-1, 2, 3))
    return dict(rays_per_node=args.rays_per_node, seed=args.seed, samples_per_face=args.samples_per_face,
                use_filter=not args.no_filter, progressive=not args.no_progressive, solver=args.solver,
                hints=hints)


def run(args: argparse.Namespace) -> int:
    from meshvis.io import load
    from cli.progress import stage_progress

    outputs = [x for x in (getattr(args, "output", None), args.report, args.preview,
                           getattr(args, "removed", None), getattr(args, "graphml", None)) if x]
    if len(set(map(os.path.abspath, outputs))) != len(outputs):
        raise ParameterError("two outputs share one path")
    for path in outputs:
        check_output(path, [args.input], args.force)
    t0 = time.perf_counter()
    soup = load(args.input)
    say(args, f"{args.input}: {soup.n_faces} faces, {soup.n_parts} parts")
    with stage_progress(args) as progress:
        report = run_op(args.op, soup, args, progress)
    report["input"] = args.input
    report["seconds_total"] = time.perf_counter() - t0
    if args.report:
        write_json(args.report, report)
    return 0


def run_op(op: str, soup, args: argparse.Namespace, progress=None) -> dict:
    """Run one operation on a loaded soup, write its outputs, return the report."""
    from meshvis.classification import classify
    from meshvis.io import save
    from meshvis.layering import layers
    from meshvis.orientation import orient
    from meshvis.removal import remove_interior
    from meshvis.render import render, render_layers, save_png

    c = classify(soup, progress=progress, **classify_kwargs(args))
    say(args, c.summary())
    if op == "classify":
        report = c.report()
        if getattr(args, "graphml", None):
            import networkx as nx

            from meshvis.io import atomic_write

            g = c.graph.to_networkx({"area": c.nodes.area})
            with atomic_write(args.graphml, "wb") as fh:
                nx.write_graphml(g, fh)
        if args.preview:
            save_png(render(soup, color_by="side").image, args.preview)
    elif op == "orient":
        r = orient(soup, classification=c, front=args.front, two_sided=args.two_sided,
                   semantics=args.semantics, conflicts=args.conflicts)
        save(r.soup, args.output)
        report = r.report()
        say(args, f"flipped {report['flipped']} of {report['input_faces']} faces; "
                  f"{report['status_counts']}; wrote {args.output} ({r.soup.n_faces} faces)")
        if args.preview:
            save_png(render(r.soup, color_by="side").image, args.preview)
    elif op == "remove-interior":
        r = remove_interior(soup, classification=c)
        save(r.kept, args.output)
        if args.removed:
            save(r.removed, args.removed)
        report = r.report()
        say(args, f"kept {report['kept_faces']}, removed {report['removed_faces']} of {report['input_faces']} faces; "
                  f"wrote {args.output}" + (f" and {args.removed}" if args.removed else ""))
        if args.preview:
            save_png(render(r.kept, color_by="side").image, args.preview)
    elif op == "layers":
        r = layers(soup, classification=c, max_layers=args.max_layers)
        names = [f"layer{k}" for k in range(1, int(r.layer.max()) + 1)]
        save(soup, args.output, face_groups=r.layer - 1, group_names=names, face_values={"layer": r.layer})
        report = r.report()
        say(args, f"{r.n_layers} layers, faces per layer {report['faces_per_layer']}; wrote {args.output}")
        if args.preview:
            save_png(render_layers(soup, r.layer), args.preview)
    else:  # pragma: no cover - argparse restricts op
        raise ParameterError(f"unknown operation {op}")
    report["operation"] = op
    report["seed"] = args.seed
    return report
