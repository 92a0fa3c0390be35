"""One repair operation on one loaded model, with its outputs.

The unit of work shared by the single-file commands and ``meshvis batch``.

Options are a plain mapping (an ``argparse.Namespace`` works too) whose keys and
defaults are :func:`default_options`; the command line takes its defaults from here, so a
batch file is processed exactly as the single-file command would process it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from meshvis.errors import ParameterError
from meshvis.graphcut.solvers import DEFAULT_SOLVER
from meshvis.repair.remove_modes import DEFAULT_VISIBILITY, cut_rays_per_point

#: operations that classify a model and write a result
OPERATIONS = ("classify", "orient", "remove-interior", "layers")

#: options of the classification, shared by every operation: keyword arguments of
#: :func:`meshvis.classify` under their own names, and the hints as lists
CLASSIFY_DEFAULTS: dict[str, Any] = {
    "seed": 0,
    "rays_per_node": 32,
    "samples_per_face": 4,
    "rays_per_point": None,  # None: rays_per_node
    "use_filter": True,
    "progressive": True,
    "solver": DEFAULT_SOLVER,
    "inside_points": [],
    "outside_points": [],
    "inside_boxes": [],
    "outside_boxes": [],
}
#: options of each operation on top of the classification
OPERATION_DEFAULTS: dict[str, dict[str, Any]] = {
    "classify": {},
    "orient": {
        "front": "ccw",
        "two_sided": "keep",
        "semantics": "layer",
        "conflicts": "majority",
        "from_region": None,  # a region: orient toward what its viewers see (no cut)
        "up": "auto",
    },
    "remove-interior": {
        "visibility": DEFAULT_VISIBILITY,
        "from_region": "outside",
        "level": "face",
        "keep_border": 0,
        "budget": None,  # rays of the from-region search (None: its stop rule ends it)
        "up": "auto",
    },
    "layers": {"max_layers": None},
}
#: where results go (None: not written)
OUTPUT_KEYS = ("output", "report", "preview", "removed", "graphml")


def default_options(op: str) -> dict[str, Any]:
    """Every option of ``op`` with its default value.

    Parameters
    ----------
    op : str
        One of :data:`OPERATIONS`.

    Returns
    -------
    dict
        :data:`CLASSIFY_DEFAULTS` and the options of ``op``.

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
    return {**CLASSIFY_DEFAULTS, **OPERATION_DEFAULTS[op]}


def _options(options: Mapping[str, Any] | Any) -> dict[str, Any]:
    return dict(options) if isinstance(options, Mapping) else dict(vars(options))


def classify_kwargs(options: Mapping[str, Any] | Any) -> dict[str, Any]:
    """Keyword arguments of :func:`meshvis.classify` from operation options."""
    from meshvis.graphcut.hints import Hints

    o = {**CLASSIFY_DEFAULTS, **_options(options)}
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


def _classify_outputs(soup, c, o: dict, tell: Callable[[str], None], up) -> dict:
    """``classify``: the report, the visibility graph (GraphML) and a preview of the sides."""
    from meshvis._extras import import_extra
    from meshvis.io import atomic_write
    from meshvis.rays.render import render, save_png

    report = c.report()
    if o["graphml"]:
        nx = import_extra("networkx", "GraphML export (--graphml)")
        with atomic_write(o["graphml"], "wb") as fh:
            nx.write_graphml(c.graph.to_networkx({"area": c.nodes.area}), fh)
    if o["preview"]:
        save_png(render(soup, color_by="side", up=up).image, o["preview"])
    return report


def _orient_outputs(soup, c, o: dict, tell: Callable[[str], None], up) -> dict:
    """``orient``: the oriented model and its preview."""
    from meshvis.rays.render import render, save_png
    from meshvis.repair.orient import orient, orient_from

    if o["from_region"]:
        r = orient_from(soup, o["from_region"], front=o["front"], seed=int(o["seed"]), up=up)
    else:
        r = orient(
            soup,
            classification=c,
            front=o["front"],
            two_sided=o["two_sided"],
            semantics=o["semantics"],
            conflicts=o["conflicts"],
        )
    _save(r.soup, o["output"], tell)
    report = r.report()
    tell(
        f"flipped {report['flipped']} of {report['input_faces']} faces; "
        f"{report['status_counts']}; wrote {o['output']} ({r.soup.n_faces} faces)"
    )
    if o["preview"]:
        save_png(render(r.soup, color_by="side", up=up).image, o["preview"])
    return report


def _remove_outputs(soup, c, o: dict, tell: Callable[[str], None], up) -> dict:
    """``remove-interior``: the kept faces, optionally the removed ones, and a preview."""
    from meshvis.rays.render import render, save_png
    from meshvis.repair.remove import remove_interior

    r = remove_interior(soup, classification=c, **removal_kwargs(o, soup))
    _save(r.kept, o["output"], tell)
    wrote_removed = bool(o["removed"]) and r.removed.n_faces > 0
    if wrote_removed:
        _save(r.removed, o["removed"], tell)
    report = r.report()
    tell(
        f"kept {report['kept_faces']}, removed {report['removed_faces']} of {report['input_faces']} faces; "
        f"wrote {o['output']}" + (f" and {o['removed']}" if wrote_removed else "")
    )
    if o["removed"] and not wrote_removed:  # an empty model is no model: say so, write nothing
        tell(f"nothing was removed: {o['removed']} not written")
    if o["preview"]:
        save_png(render(r.kept, color_by="side", up=up).image, o["preview"])
    return report


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


def _layers_outputs(soup, c, o: dict, tell: Callable[[str], None], up) -> dict:
    """``layers``: the model with one face group per layer, and a preview coloured by layer.

    An edited glTF output gives each node a child node per deeper layer; a PLY output gets
    a ``layer`` face property.  An OBJ output of an OBJ input is rebuilt with one group per
    layer, so every layer is also written as the input edited to that layer's faces
    (:func:`layer_paths`), each keeping everything the input had.
    """
    from meshvis.io import check_output
    from meshvis.io.writing import rebuilds_groups
    from meshvis.rays.render import render_layers, save_png
    from meshvis.repair.layers import layers

    r = layers(soup, classification=c, max_layers=o["max_layers"])
    n = int(r.layer.max())
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
    tell(f"{r.n_layers} layers, faces per layer {report['faces_per_layer']}; wrote {', '.join(wrote)}")
    if o["preview"]:
        save_png(render_layers(soup, r.layer, up=up), o["preview"])
    return report


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
    from meshvis.rays.camera import up_axis

    o = {**default_options("remove-interior"), **_options(options)}
    return dict(
        visibility=o["visibility"],
        region=o["from_region"],
        level=o["level"],
        keep_border=int(o["keep_border"]),
        budget=None if o["budget"] is None else int(o["budget"]),
        up=up_axis(o["up"], [soup.path] if soup.path else []),
        seed=int(o["seed"]),
    )


def run_operation(
    op: str,
    soup,
    options: Mapping[str, Any] | Any,
    progress: Callable | None = None,
    say: Callable[[str], None] | None = None,
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
        Where to print one-line summaries (default: nowhere).

    Returns
    -------
    dict
        The JSON report (per-face arrays, counts, stages, rays, nodes, edges, timings, seed).
    """
    from meshvis.graphcut.classify import classify
    from meshvis.io.report import with_schema
    from meshvis.rays.camera import up_axis
    from meshvis.repair.orient import classify_for_orient

    o = {**default_options(op), **dict.fromkeys(OUTPUT_KEYS), **_options(options)}
    if op == "classify" and o["graphml"]:  # fail before the classification, not after
        from meshvis._extras import import_extra

        import_extra("networkx", "GraphML export (--graphml)")
    tell = say or (lambda text: None)
    up = up_axis(o.get("up") or "auto", [soup.path] if soup.path else [])  # of the preview
    c = None
    by_sight = (op == "remove-interior" and o["visibility"] == "view") or (
        op == "orient" and o["from_region"]
    )
    if not by_sight:  # sight alone needs no cut
        kw = classify_kwargs(o)
        if op == "remove-interior":  # both gives the sample points less (remove_modes)
            kw["rays_per_point"] = cut_rays_per_point(
                o["visibility"], kw["rays_per_node"], kw["samples_per_face"], kw["rays_per_point"]
            )
        # orient classifies the faces wound canonically (the cut orient makes itself)
        c = (classify_for_orient if op == "orient" else classify)(soup, progress=progress, **kw)
        tell(c.summary())
    report = _OUTPUTS[op](soup, c, o, tell, up)
    report["operation"] = op
    report["seed"] = o["seed"]
    return with_schema(report)
