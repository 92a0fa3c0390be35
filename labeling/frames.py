"""Labels along a camera path, coherent from frame to frame (appendix I, Eq. 8-9).

Each frame is laid out with the previous frame's result, so the coherence terms
``f6`` (anchor) and ``f7`` (endpoint) pull the new leaders towards the old ones.  The
model is loaded and its ray caster built once for the whole path.  Every frame after the
first gets ``metrics["motion"]`` (:func:`meshvis.labeling.metrics.motion_metrics`) against its
predecessor.
"""

from __future__ import annotations

import inspect
from collections.abc import Sequence
from typing import Any

from meshvis import _validate
from meshvis.rays.camera import Camera
from meshvis.rays.caster import RayCaster

from .inputs import load_models, read_camera_path  # noqa: F401  (read_camera_path: re-exported)
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
    size: tuple[int, int] | None = None,
) -> list[Camera]:
    """``n_frames`` cameras turning once around the model, framed for labels.

    Each is :func:`meshvis.labeling.pipeline.fit_camera` at an azimuth ``start + 360 k / n``
    (``fit_margin`` is its margin; ``size`` makes a portrait image fit its width too).  At
    most ``MAX_FRAMES`` of :mod:`meshvis.limits`.
    """
    from .pipeline import fit_camera

    n_frames = _validate.frames(n_frames)
    soup = load_models(model)
    return [
        fit_camera(
            soup,
            azimuth=start + 360.0 * k / int(n_frames),
            elevation=elevation,
            distance=distance,
            fov=fov,
            orthographic=orthographic,
            up=up,
            margin=fit_margin,
            size=size,
        )
        for k in range(int(n_frames))
    ]


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

    _validate.frames(len(cameras), options.get("size", inspect.signature(layout).parameters["size"].default))
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
