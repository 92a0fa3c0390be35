"""One repair operation on one loaded model, with its outputs.

The unit of work shared by the single-file commands and ``meshvis batch``.

Options are a plain mapping (an ``argparse.Namespace`` works too) whose keys and
defaults are :func:`default_options`; the command line takes its defaults from here, so a
batch file is processed exactly as the single-file command would process it.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from meshvis.errors import ParameterError
from meshvis.repair.remove_modes import cut_rays_per_point

#: operations that classify a model and write a result
OPERATIONS = ("classify", "orient", "remove-interior", "layers")

#: the library function each operation's options are the keywords of
CLASSIFY = "meshvis.graphcut.classify:classify"
ORIENT = "meshvis.repair.orient:orient"
ORIENT_FROM = "meshvis.repair.orient:orient_from"
#: orient's ``ground`` as the command line names it (``--ground auto|yes|no``)
GROUND_CHOICES: dict[str, bool | None] = {"auto": None, "yes": True, "no": False}
REMOVE = "meshvis.repair.remove:remove_interior"
LAYERS = "meshvis.repair.layers:layers"

#: options of the classification, shared by every operation: keywords of :func:`meshvis.classify`
CLASSIFY_OPTIONS = (
    "seed",
    "rays_per_node",
    "samples_per_face",
    "rays_per_point",
    "use_filter",
    "progressive",
    "solver",
)
#: options of each operation on top of the classification: option -> (function, its keyword)
OPERATION_OPTIONS: dict[str, dict[str, tuple[str, str]]] = {
    "classify": {},
    "orient": {
        "front": (ORIENT, "front"),
        "two_sided": (ORIENT, "two_sided"),
        "semantics": (ORIENT, "semantics"),
        "conflicts": (ORIENT, "conflicts"),
        "ground": (ORIENT, "ground"),
        "up": (ORIENT_FROM, "up"),
    },
    "remove-interior": {
        "visibility": (REMOVE, "visibility"),
        "from_region": (REMOVE, "region"),
        "level": (REMOVE, "level"),
        "keep_border": (REMOVE, "keep_border"),
        "budget": (REMOVE, "budget"),
        "up": (REMOVE, "up"),
        "transparent": (REMOVE, "transparent"),
        "check_rays": (REMOVE, "check_rays"),
        "rescue_rays": (REMOVE, "rescue_rays"),
        "conservative": (REMOVE, "conservative"),
    },
    "layers": {
        "max_layers": (LAYERS, "max_layers"),
        "visibility": (LAYERS, "visibility"),
        "from_region": (LAYERS, "region"),
        "budget": (LAYERS, "budget"),
        "up": (LAYERS, "up"),
        "transparent": (LAYERS, "transparent"),
        "rescue_rays": (LAYERS, "rescue_rays"),
    },
}
#: options that are no keyword of a library function: the hints (lists of points and boxes,
#: :class:`meshvis.Hints`) and orient's region (given: orient toward what its viewers see)
OTHER_DEFAULTS: dict[str, dict[str, Any]] = {
    "classify": {"inside_points": [], "outside_points": [], "inside_boxes": [], "outside_boxes": []},
    "orient": {"from_region": None},
}
#: where results go (None: not written)
OUTPUT_KEYS = ("output", "report", "preview", "removed", "graphml")


def library_default(function: str, keyword: str) -> Any:
    """The default of ``keyword`` in the signature of ``function`` (``"module:name"``).

    Every default of the command line and of ``meshvis batch`` is read here, from the
    function the option is passed to, so it is written once, in the library.

    Examples
    --------
    >>> library_default(CLASSIFY, "rays_per_node")
    32
    """
    from meshvis._defaults import signature_default

    return signature_default(function, keyword)


@functools.cache
def _defaults(op: str) -> dict[str, Any]:
    d = {k: library_default(CLASSIFY, k) for k in CLASSIFY_OPTIONS}
    d.update(OTHER_DEFAULTS["classify"])
    d.update({k: library_default(fn, kw) for k, (fn, kw) in OPERATION_OPTIONS[op].items()})
    d.update(OTHER_DEFAULTS.get(op, {}))
    return d


def default_options(op: str) -> dict[str, Any]:
    """Every option of ``op`` with its default value, read from the library's signatures.

    Parameters
    ----------
    op : str
        One of :data:`OPERATIONS`.

    Returns
    -------
    dict
        The classification's options (:data:`CLASSIFY_OPTIONS` and the hints) and the
        options of ``op`` (:data:`OPERATION_OPTIONS`), each with the default of the library
        function it is passed to.

    Raises
    ------
    ParameterError
        When ``op`` is not an operation.

    Examples
    --------
    >>> default_options("layers")["max_layers"] is None
    True
    """
    if op not in OPERATIONS:
        raise ParameterError(f"unknown operation {op!r}; choose one of {', '.join(OPERATIONS)}")
    return {k: list(v) if isinstance(v, list) else v for k, v in _defaults(op).items()}


def __getattr__(name: str) -> Any:
    # the two tables of defaults, built on first use (reading them imports the library)
    if name == "CLASSIFY_DEFAULTS":
        return default_options("classify")
    if name == "OPERATION_DEFAULTS":
        shared = default_options("classify")
        return {op: {k: v for k, v in default_options(op).items() if k not in shared} for op in OPERATIONS}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _up(value: Any) -> Any:
    """The library's ``up`` for an option value: ``auto`` (the command line's word) is None."""
    return None if value is None or (isinstance(value, str) and value == "auto") else value


def _options(options: Mapping[str, Any] | Any) -> dict[str, Any]:
    return dict(options) if isinstance(options, Mapping) else dict(vars(options))


def classify_kwargs(options: Mapping[str, Any] | Any) -> dict[str, Any]:
    """Keyword arguments of :func:`meshvis.classify` from operation options."""
    from meshvis.graphcut.hints import Hints

    o = {**default_options("classify"), **_options(options)}
    hints = None
    if o["inside_points"] or o["outside_points"] or o["inside_boxes"] or o["outside_boxes"]:
        hints = Hints(
            inside_points=np.array(o["inside_points"], np.float64).reshape(-1, 3),
            outside_points=np.array(o["outside_points"], np.float64).reshape(-1, 3),
            inside_boxes=np.array(o["inside_boxes"], np.float64).reshape(-1, 2, 3),
            outside_boxes=np.array(o["outside_boxes"], np.float64).reshape(-1, 2, 3),
        )
    return dict(
        rays_per_node=int(o["rays_per_node"]),
        seed=int(o["seed"]),
        samples_per_face=int(o["samples_per_face"]),
        rays_per_point=None if o["rays_per_point"] is None else int(o["rays_per_point"]),
        use_filter=bool(o["use_filter"]),
        progressive=bool(o["progressive"]),
        solver=o["solver"],
        hints=hints,
    )


def check_options(op: str, options: Mapping[str, Any] | Any) -> None:
    """Refuse, before any work, the options and output paths that ``op`` would refuse later.

    Checks the numbers of the classification, the regions (``from_region``), the up axis,
    the formats of the outputs (a model output the writers know, one that can hold layers
    for ``layers``, a picture format for ``preview``) and the extra that ``graphml`` needs.
    The file system is not touched except to read a camera path file.

    Parameters
    ----------
    op : str
        One of :data:`OPERATIONS`.
    options : mapping or argparse.Namespace
        The options and output paths, as for :func:`run_operation`.

    Raises
    ------
    ParameterError
        A bad number, region or up axis.
    OutputError
        An output whose extension names no format that can hold the result.
    MissingExtraError
        ``graphml`` without networkx installed.
    """
    from meshvis import _validate
    from meshvis.io.up_axis import up_vector
    from meshvis.io.writing import check_format
    from meshvis.rays.render import check_image_format
    from meshvis.visibility.regions import parse_region

    o = {**default_options(op), **dict.fromkeys(OUTPUT_KEYS), **_options(options)}
    _validate.operation_options(o)
    if _up(o.get("up")) is not None:
        up_vector(_up(o["up"]))
    by_region = (op == "orient" and o["from_region"]) or (
        op in ("remove-interior", "layers") and o["visibility"] != "object"
    )
    if by_region and op == "remove-interior":  # its region may name a PVS file of meshvis pvs
        from meshvis.viewcells.removal import cells_path, is_cells_region

        if is_cells_region(o["from_region"]):
            cells_path(o["from_region"])
        else:
            parse_region(o["from_region"])
    elif by_region:
        parse_region(o["from_region"])
    if op == "remove-interior" and o["conservative"]:
        from meshvis.visibility.viewpoints import parse_viewpoints

        parse_viewpoints(o["from_region"])  # viewpoints, not a region: fails before any work
    if o["output"] and op != "classify":
        check_format(o["output"], layers=op == "layers")
    if o["removed"]:
        check_format(o["removed"])
    if o["preview"]:
        check_image_format(o["preview"])
    if op == "classify" and o["graphml"]:  # GraphML needs an extra: missing, it fails here
        from meshvis._extras import import_extra

        import_extra("networkx", "GraphML export (--graphml)")


def _classify_outputs(soup, c, o: dict, tell: Callable[[str], None], up) -> tuple[dict, str]:
    """``classify``: the report, the visibility graph (GraphML) and a preview of the sides."""
    from meshvis._extras import import_extra
    from meshvis.io import atomic_write
    from meshvis.rays.render import render, save_image

    report = c.report()
    wrote = []
    if o["graphml"]:
        nx = import_extra("networkx", "GraphML export (--graphml)")
        with atomic_write(o["graphml"], "wb") as fh:
            nx.write_graphml(c.graph.to_networkx({"area": c.nodes.area}), fh)
        wrote.append(o["graphml"])
    if o["preview"]:
        save_image(render(soup, color_by="side", up=up).image, o["preview"])
        wrote.append(o["preview"])
    hidden, two = int(c.hidden.sum()), int(c.two_sided.sum())
    line = f"{hidden} of {soup.n_faces} faces hidden (no side seen from outside), {two} seen from both sides"
    return report, line + (f"; wrote {' and '.join(wrote)}" if wrote else "")


def _orient_outputs(soup, c, o: dict, tell: Callable[[str], None], up) -> tuple[dict, str]:
    """``orient``: the oriented model and its preview."""
    from meshvis.rays.render import render, save_image
    from meshvis.repair.orient import orient, orient_from

    if o["from_region"]:
        r = orient_from(soup, o["from_region"], front=o["front"], seed=int(o["seed"]), up=_up(o["up"]))
    else:
        r = orient(
            soup,
            classification=c,
            front=o["front"],
            two_sided=o["two_sided"],
            semantics=o["semantics"],
            conflicts=o["conflicts"],
            ground=GROUND_CHOICES.get(o["ground"], o["ground"]),
            up=_up(o["up"]),
        )
    _save(r.soup, o["output"], tell)
    report = r.report()
    wrote = [o["output"]]
    if o["preview"]:
        save_image(render(r.soup, color_by="side", up=up).image, o["preview"])
        wrote.append(o["preview"])
    added = r.soup.n_faces - report["input_faces"]
    line = f"turned {report['flipped']} of {report['input_faces']} faces" + (
        f", added {added} copies facing the other way" if added > 0 else ""
    )
    return report, f"{line}; wrote {' and '.join(wrote)}"


def _remove_outputs(soup, c, o: dict, tell: Callable[[str], None], up) -> tuple[dict, str]:
    """``remove-interior``: the kept faces, optionally the removed ones, and a preview."""
    from meshvis.rays.render import render, save_image
    from meshvis.repair.remove import remove_interior

    with warnings.catch_warnings():  # the cut was made for this removal, with the budget asked for
        warnings.filterwarnings("ignore", message="the classification given gave its sample points")
        r = remove_interior(soup, classification=c, progress=o["progress"], **removal_kwargs(o, soup))
    for text in r.summary()[1:]:  # a search ended by its budget; the self-check
        tell(text)
    _save(r.kept, o["output"], tell)
    wrote = [o["output"]]
    if o["removed"] and r.removed.n_faces > 0:
        _save(r.removed, o["removed"], tell)
        wrote.append(o["removed"])
    elif o["removed"]:  # an empty model is no model: say so, write nothing
        tell(f"nothing was removed: {o['removed']} not written")
    report = r.report()
    if o["preview"]:
        save_image(render(r.kept, color_by="side", up=up).image, o["preview"])
        wrote.append(o["preview"])
    line = (
        f"removed {report['removed_faces']} of {report['input_faces']} faces "
        f"({100 * report['removed_area_fraction']:.1f} % of the area), kept {report['kept_faces']}"
    )
    if r.see_through:
        line += f"; {r.see_through} faces of see-through materials let sight through"
    return report, f"{line}; wrote {' and '.join(wrote)}"


def _save(soup, path: str, tell: Callable[[str], None], why: str | None = None, **groups) -> bool:
    """:func:`meshvis.io.writing.write`, with a one-line note when the output is rebuilt, not edited."""
    from meshvis.io.writing import rebuild_note, write

    edited = write(soup, path, **groups)
    note = None if edited else rebuild_note(soup, path, why)
    if note:
        tell(note)
    return edited


def layer_paths(path: str, n: int) -> list[str]:
    """The per-layer files of a ``layers`` output: ``name.layer1.ext`` ... ``name.layer<n>.ext``."""
    import os

    stem, ext = os.path.splitext(path)
    return [f"{stem}.layer{k}{ext}" for k in range(1, n + 1)]


def _layers_outputs(soup, c, o: dict, tell: Callable[[str], None], up) -> tuple[dict, str]:
    """``layers``: the model with one face group per layer, and a preview coloured by layer.

    An edited glTF output gives each node a child node per deeper layer; a PLY output gets
    a ``layer`` face property.  An OBJ output of an OBJ input is rebuilt with one group per
    layer, so every layer is also written as the input edited to that layer's faces
    (:func:`layer_paths`), each keeping everything the input had.
    """
    from meshvis.io import check_output
    from meshvis.io.writing import rebuilds_groups
    from meshvis.rays.render import render_layers, save_image
    from meshvis.repair.layers import layers

    r = layers(soup, classification=c, **layer_kwargs(o))
    n = int(r.layer.max())
    if rebuilds_groups(o["output"]) and _same_format(soup, o["output"]):
        _check_layer_paths(layer_paths(o["output"], n), o)
    names = [f"layer{k}" for k in range(1, n + 1)]
    groups = dict(face_groups=r.layer - 1, group_names=names, face_values={"layer": r.layer})
    edited = _save(soup, o["output"], tell, "one node or group per layer", **groups)
    report = r.report()
    wrote = [o["output"]]
    if not edited and rebuilds_groups(o["output"]) and _same_format(soup, o["output"]):
        for k, path in enumerate(layer_paths(o["output"], n), start=1):
            check_output(path, [soup.path] if soup.path else [], bool(o.get("force", True)))
            _save(soup.subset(r.layer == k), path, tell)
            wrote.append(path)
        report["layer_files"] = wrote[1:]
    if o["preview"]:
        save_image(render_layers(soup, r.layer, up=up), o["preview"])
        wrote.append(o["preview"])
    per_layer = ", ".join(map(str, report["faces_per_layer"][: r.n_layers]))
    last = "never seen" if r.mode == "view" else "no view reaches"
    unreached = f", {r.unreached} faces {last}" if r.unreached else ""
    clear = f"; {r.see_through} faces of see-through materials let sight through" if r.see_through else ""
    line = f"{r.n_layers} layers by {'sight' if r.mode == 'view' else 'the cut'} ({per_layer} faces{unreached}){clear}"
    return report, f"{line}; wrote {', '.join(wrote)}"


def _check_layer_paths(paths: list[str], o: dict) -> None:
    """Refuse per-layer files that would be another output of the command, or its MTL.

    The other outputs are ``--preview``, ``--report`` and so on; checked before anything is
    written.
    """
    import os

    from meshvis.errors import OutputError
    from meshvis.io._common import companions

    others = [p for k in (*OUTPUT_KEYS, "per_face") if k != "output" and (p := o.get(k)) and p != "-"]
    taken = {os.path.realpath(q) for p in others for q in [p, *companions(p)]}
    for path in paths:
        for q in [path, *companions(path)]:
            if os.path.realpath(q) in taken:
                raise OutputError(
                    "a file of one layer would be another output of the command; choose another path", q
                )


def _same_format(soup, path: str) -> bool:
    """Whether ``soup`` was read from a file that ``path`` can be an edit of."""
    import os

    from meshvis.io import WRITE_FORMATS

    out = WRITE_FORMATS.get(os.path.splitext(path)[1].lower())
    rec = soup.source
    return rec is not None and (out == rec.format or {out, rec.format} == {"glb", "gltf"})


#: operation -> the step that applies it to a classified model and writes its outputs
_OUTPUTS = {
    "classify": _classify_outputs,
    "orient": _orient_outputs,
    "remove-interior": _remove_outputs,
    "layers": _layers_outputs,
}


def removal_kwargs(options: Mapping[str, Any] | Any, soup) -> dict[str, Any]:
    """Keyword arguments of :func:`meshvis.remove_interior` from operation options."""
    o = {**default_options("remove-interior"), **_options(options)}
    return dict(
        visibility=o["visibility"],
        region=o["from_region"],
        level=o["level"],
        keep_border=int(o["keep_border"]),
        budget=None if o["budget"] is None else int(o["budget"]),
        up=_up(o["up"]),
        seed=int(o["seed"]),
        transparent=o["transparent"],
        check_rays=int(o["check_rays"]),
        rescue_rays=int(o["rescue_rays"]),
        conservative=bool(o["conservative"]),
    )


def layer_kwargs(options: Mapping[str, Any] | Any) -> dict[str, Any]:
    """Keyword arguments of :func:`meshvis.layers` from operation options (the cut's come apart)."""
    o = {**default_options("layers"), **_options(options)}
    kw: dict[str, Any] = dict(max_layers=o["max_layers"], visibility=o["visibility"])
    if o["visibility"] == "view":
        kw.update(
            region=o["from_region"],
            budget=None if o["budget"] is None else int(o["budget"]),
            up=_up(o["up"]),
            seed=int(o["seed"]),
            transparent=o["transparent"],
            rescue_rays=int(o["rescue_rays"]),
        )
    return kw


#: what the face statuses of ``orient`` mean, for ``--verbose``
ORIENT_STATUS_NOTES = {
    "one-sided": "seen from outside through one side",
    "two-sided": "seen through both sides",
    "hidden": "seen through neither side",
    "conflict": "intersected faces whose sample points disagree about the outside side",
    "degenerate": "zero area",
}


def _details(op: str, report: dict) -> list[str]:
    """The ``--verbose`` lines of an operation's report beyond the classification summary."""
    if op == "orient" and "status_counts" in report:
        return [
            f"  {name:<11} {n:>9}  {ORIENT_STATUS_NOTES.get(name, '')}"
            for name, n in report["status_counts"].items()
        ]
    if op == "remove-interior":
        return [f"  {n:>9}  {reason}" for reason, n in report.get("reasons", {}).items()]
    return []


def run_operation(
    op: str,
    soup,
    options: Mapping[str, Any] | Any,
    progress: Callable | None = None,
    say: Callable[[str], None] | None = None,
    detail: Callable[[str], None] | None = None,
) -> dict:
    """Classify ``soup``, apply ``op``, write the outputs named in ``options``, return the report.

    Parameters
    ----------
    op : str
        One of :data:`OPERATIONS`.
    soup : Soup
        The loaded model.
    options : mapping or argparse.Namespace
        Operation options (keys and defaults of :func:`default_options`) plus the output
        paths ``output``, ``preview``, ``removed``, ``graphml`` (the report is the caller's).
    progress : callable, optional
        ``progress(stage, fraction)`` callback of :func:`meshvis.classify`.
    say : callable, optional
        Where the one-line summary goes (what changed, how much, where it was written,
        time), and the notes about outputs written anew (default: nowhere).
    detail : callable, optional
        Where the internals go: the classification's stages, graph and rays, the faces
        per status or reason (``--verbose``; default: nowhere).

    Returns
    -------
    dict
        The JSON report (per-face arrays, counts, stages, rays, nodes, edges, timings, seed).

    Raises
    ------
    ParameterError, OutputError
        An option or output refused by :func:`check_options`, before any work.
    """
    import time

    from meshvis.graphcut.classify import classify
    from meshvis.io.report import with_schema
    from meshvis.io.up_axis import up_vector
    from meshvis.repair.orient import classify_for_orient

    t0 = time.perf_counter()
    o = {**default_options(op), **dict.fromkeys(OUTPUT_KEYS), **_options(options)}
    check_options(op, o)
    tell = say or (lambda text: None)
    more = detail or (lambda text: None)
    up = up_vector(_up(o.get("up")), soup)  # of the preview
    c = None
    by_sight = (
        (op in ("remove-interior", "layers") and o["visibility"] == "view")
        or (op == "remove-interior" and o["conservative"])
        or (op == "orient" and o["from_region"])
    )
    if not by_sight:  # sight alone needs no cut
        kw = classify_kwargs(o)
        if op == "remove-interior":  # both gives the sample points less (remove_modes)
            kw["rays_per_point"] = cut_rays_per_point(
                o["visibility"], kw["rays_per_node"], kw["samples_per_face"], kw["rays_per_point"]
            )
        # orient classifies the faces wound canonically (the cut orient makes itself)
        c = (classify_for_orient if op == "orient" else classify)(soup, progress=progress, **kw)
        more(c.summary())
    report, line = _OUTPUTS[op](soup, c, {**o, "progress": progress}, tell, up)
    for text in _details(op, report):
        more(text)
    tell(f"{op}: {line}; {time.perf_counter() - t0:.1f} s")
    report["operation"] = op
    report["seed"] = o["seed"]
    return with_schema(report)
