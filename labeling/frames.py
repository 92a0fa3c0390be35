"""Labels along a camera path, coherent from frame to frame (appendix I, Eq. 8-9).

Each frame is laid out with the previous frame's result, so the coherence terms
``f6`` (anchor) and ``f7`` (endpoint) pull the new leaders towards the old ones.  The
model is loaded and its ray caster built once for the whole path.  Every frame after the
first gets ``metrics["motion"]`` (:func:`meshvis.labeling.metrics.motion_metrics`) against its
predecessor.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from typing import Any

from meshvis.errors import ParameterError
from meshvis.rays.camera import Camera
from meshvis.rays.caster import RayCaster

from .inputs import load_models
from .metrics import motion_metrics
from .result import LayoutResult


def orbit(
    model: Any,
    n_frames: int,
    *,
    elevation: float = 20.0,
    start: float = 30.0,
    fov: float = 35.0,
    orthographic: bool = False,
    up: Sequence[float] = (0.0, 0.0, 1.0),
    fit_margin: float = 1.6,
    distance: float | None = None,
) -> list[Camera]:
    """``n_frames`` cameras turning once around the model, framed for labels (see ``fit_margin``)."""
    if int(n_frames) < 1:
        raise ParameterError(f"an orbit needs at least 1 frame, got {n_frames}")
    soup = load_models(model)
    return Camera.orbit(
        soup,
        int(n_frames),
        elevation=elevation,
        start=start,
        fov=fov,
        orthographic=orthographic,
        margin=fit_margin,
        up=up,
        distance=distance,
    )


def read_camera_path(path: str | os.PathLike) -> list[Camera]:
    """Cameras from a JSON file: a list of camera objects, or ``{"cameras": [...]}``.

    Each camera object has the keys of :meth:`Camera.to_json` (``position``, ``target``,
    optional ``up``, ``fov``, ``orthographic``, ``ortho_height``).
    """
    path = os.fspath(path)
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ParameterError(f"{path}: cannot read the camera path: {exc}") from None
    if isinstance(data, Mapping) and "cameras" in data:
        data = data["cameras"]
    if isinstance(data, Mapping):
        data = [data]
    if not isinstance(data, list) or not data:
        raise ParameterError(f"{path}: expected a list of cameras")
    cams = []
    for i, d in enumerate(data):
        if not isinstance(d, Mapping):
            raise ParameterError(f"{path}: camera {i} is not an object")
        try:
            cams.append(Camera.from_json(dict(d)))
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"{path}: camera {i}: {exc}") from None
    return cams


def layout_frames(
    model: Any,
    cameras: Sequence[Camera],
    *,
    coherence: bool = True,
    caster: RayCaster | None = None,
    **options: Any,
) -> list[LayoutResult]:
    """Lay out the labels of every frame of a camera path.

    Parameters
    ----------
    model : Soup, path, trimesh object, or a list of them
        As for :func:`meshvis.labeling.layout`.
    cameras : sequence of Camera
        The cameras, in order.
    coherence : bool
        Pass each frame the previous result (f6, f7); False lays frames out alone.
    caster : RayCaster, optional
        A ray caster of the model to reuse.
    **options
        Passed to :func:`meshvis.labeling.layout` (layout, size, texts, method, weights, ...).

    Returns
    -------
    list of LayoutResult
    """
    from .pipeline import layout

    soup = load_models(model)
    caster = caster or RayCaster(soup)
    results: list[LayoutResult] = []
    prev = None
    for cam in cameras:
        res = layout(soup, cam, caster=caster, previous=prev if coherence else None, **options)
        if results:
            res.metrics["motion"] = motion_metrics(results[-1], res)
        results.append(res)
        prev = res
    return results
