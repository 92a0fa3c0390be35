"""Live labeling: lay out the labels of views whose part-ID buffer comes from elsewhere.

The page of ``meshvis view`` renders the part-ID buffer on the GPU and sends it with its
camera; :class:`LiveLabeler` holds what does not change between those frames (the model,
its ray caster, the label texts and options) and, per viewer, the previous frame's
result, so that every layout is coherent with the one before it (appendix I, Eq. 8-9,
and the hysteresis of :mod:`meshvis.labeling.pipeline`).

The ID buffer arrives as RGBA bytes: part ``i`` is the colour ``i + 1`` written as a
24-bit number (red the low byte), background is black; WebGL reads rows bottom-up.  The
page packs it to two bytes a pixel (``i + 1``) when the model has fewer than 65535 parts.

>>> import trimesh
>>> from meshvis.soup import Soup
>>> a, b = trimesh.creation.box(), trimesh.creation.icosphere()
>>> b = b.apply_translation((1.5, 0, 0))
>>> soup = Soup.concatenate([Soup(a.vertices, a.faces, part_names=["box"]),
...                          Soup(b.vertices, b.faces, part_names=["ball"])])
>>> live = LiveLabeler(soup)
>>> cam = live.camera((96, 96))
>>> ids = id_buffer(soup, cam, (96, 96)).ids
>>> sorted(lab.text for lab in live.frame(ids, cam).labels)
['ball', 'box']
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from meshvis.errors import ParameterError
from meshvis.rays.camera import Camera
from meshvis.rays.caster import RayCaster

from .idbuffer import IdBuffer, id_buffer, projected_sphere
from .inputs import label_texts, load_models
from .pipeline import fit_camera, solve, warm_up
from .result import LayoutResult

#: viewers whose previous frame is kept (the least recently seen is forgotten first)
MAX_VIEWERS = 16
#: the largest ID buffer a frame may send (pixels per side)
MAX_SIDE = 2048

__all__ = ["LiveLabeler", "ids_from_rgba", "ids_from_u16", "MAX_SIDE", "id_buffer"]


def ids_from_rgba(data: bytes | bytearray | memoryview, width: int, height: int) -> np.ndarray:
    """Decode a WebGL read-out of the part-ID buffer into part ids.

    Parameters
    ----------
    data : bytes, ``width * height * 4`` of RGBA, rows bottom-up (as ``readPixels`` gives)
    width, height : int

    Returns
    -------
    (height, width) int64, part id per pixel (top row first), -1 for background

    Raises
    ------
    ParameterError
        The size is out of range or does not match the data.

    Examples
    --------
    >>> rgba = bytes([0, 0, 0, 255, 3, 0, 0, 255])  # background, then part 2
    >>> ids_from_rgba(rgba, 2, 1).tolist()
    [[-1, 2]]
    """
    width, height = int(width), int(height)
    if not (1 <= width <= MAX_SIDE and 1 <= height <= MAX_SIDE):
        raise ParameterError(f"ID buffer size must be 1..{MAX_SIDE} pixels a side, got {width} x {height}")
    rgba = np.frombuffer(data, np.uint8)
    if rgba.size != width * height * 4:
        raise ParameterError(
            f"ID buffer of {width} x {height} needs {width * height * 4} bytes, got {rgba.size}"
        )
    px = rgba.reshape(height, width, 4)[::-1].astype(np.int64)
    return px[..., 0] + (px[..., 1] << 8) + (px[..., 2] << 16) - 1


def ids_from_u16(data: bytes | bytearray | memoryview, width: int, height: int) -> np.ndarray:
    """Decode a part-ID buffer packed two bytes a pixel (part + 1, 0 = background), rows bottom-up.

    Parameters
    ----------
    data : bytes, ``width * height * 2``, little-endian
    width, height : int

    Returns
    -------
    (height, width) int64, part id per pixel (top row first), -1 for background

    Raises
    ------
    ParameterError
        The size is out of range or does not match the data.

    Examples
    --------
    >>> ids_from_u16(bytes([0, 0, 3, 0]), 2, 1).tolist()
    [[-1, 2]]
    """
    width, height = int(width), int(height)
    if not (1 <= width <= MAX_SIDE and 1 <= height <= MAX_SIDE):
        raise ParameterError(f"ID buffer size must be 1..{MAX_SIDE} pixels a side, got {width} x {height}")
    if len(data) != width * height * 2:
        raise ParameterError(
            f"ID buffer of {width} x {height} needs {width * height * 2} bytes, got {len(data)}"
        )
    v = np.frombuffer(data, "<u2")
    return v.reshape(height, width)[::-1].astype(np.int64) - 1


class LiveLabeler:
    """A model ready to be labelled view after view, coherently per viewer.

    Parameters
    ----------
    model : Soup, path, trimesh object or a list of them (see
        :func:`meshvis.labeling.inputs.load_models`)
    layout : a key of :data:`meshvis.labeling.LAYOUTS`
    texts : label texts, a mapping {part name or index: text} (default: the part names)
    up : the model's up direction (default: the model's own, see :meth:`Camera.fit`)
    fit_margin : room around the model of the first camera (:func:`fit_camera`)
    **options : passed to :func:`meshvis.labeling.solve` (area, margin, weights, d_a, d_e,
        method, font_size, min_pixels, spacing)
    """

    def __init__(
        self,
        model: Any,
        *,
        layout: str = "left-right",
        texts: Mapping[Any, str] | None = None,
        up: Sequence[float] | None = None,
        fit_margin: float = 1.6,
        **options: Any,
    ) -> None:
        warm_up()
        self.soup = load_models(model)
        self.caster = RayCaster(self.soup)
        self.texts = label_texts(self.soup.part_names, texts)
        self.layout = layout
        self.up = up
        self.fit_margin = fit_margin
        self.options = options
        self._previous: OrderedDict[str, LayoutResult] = OrderedDict()
        solve_check = id_buffer(self.soup, self.camera((16, 16)), (16, 16), caster=self.caster)
        solve(solve_check, self.texts, layout=layout, compute_metrics=False, **options)  # checks the options

    def camera(
        self, size: tuple[int, int] = (512, 512), azimuth: float = 30.0, elevation: float = 20.0
    ) -> Camera:
        """The first camera of a view of ``size`` = (width, height): :func:`fit_camera`."""
        return fit_camera(
            self.soup, azimuth=azimuth, elevation=elevation, up=self.up, margin=self.fit_margin, size=size
        )

    def frame(self, ids: np.ndarray, camera: Camera, viewer: str = "") -> LayoutResult:
        """Lay out the labels of one view, coherent with the viewer's previous frame.

        Parameters
        ----------
        ids : (h, w) int, part id per pixel (-1: background), e.g. from :func:`ids_from_rgba`
        camera : the camera that rendered ``ids``
        viewer : who is looking (each viewer has its own previous frame)

        Returns
        -------
        LayoutResult
            Without metrics (they are not part of a live frame); ``timings["layout_ms"]`` is
            the layout's time.

        Raises
        ------
        ParameterError
            ``ids`` names a part the model does not have.
        """
        idbuf = self._id_buffer(np.asarray(ids), camera)
        previous = self._previous.get(viewer)
        result = solve(
            idbuf, self.texts, layout=self.layout, previous=previous, compute_metrics=False, **self.options
        )
        self._set_anchor_points(result)
        self._previous[viewer] = result
        self._previous.move_to_end(viewer)
        while len(self._previous) > MAX_VIEWERS:
            self._previous.popitem(last=False)
        return result

    def forget(self, viewer: str = "") -> None:
        """Drop the viewer's previous frame (its next frame is laid out afresh)."""
        self._previous.pop(viewer, None)

    def _id_buffer(self, ids: np.ndarray, camera: Camera) -> IdBuffer:
        """An :class:`IdBuffer` around ids that came from elsewhere (no depth, no picture)."""
        if ids.ndim != 2:
            raise ParameterError(f"the ID buffer must be 2D, got shape {ids.shape}")
        n = self.soup.n_parts
        if ids.size and (ids.max() >= n or ids.min() < -1):
            raise ParameterError(f"the ID buffer names part {int(ids.max())}; the model has {n} parts")
        ids = ids.astype(np.int64, copy=False)
        h, w = ids.shape
        center, diameter = projected_sphere(self.soup, camera, w, h)
        return IdBuffer(
            ids=ids,
            # unknown here; read-only views, not buffers of the image's size
            face=np.broadcast_to(np.int64(-1), ids.shape),
            depth=np.broadcast_to(np.inf, ids.shape),
            image=np.zeros((1, 1, 3), np.uint8),
            camera=camera,
            areas=np.bincount(ids[ids >= 0], minlength=n).astype(np.int64),
            part_names=list(self.soup.part_names),
            sphere_center=center,
            sphere_diameter=max(diameter, 1.0),
        )

    def _set_anchor_points(self, result: LayoutResult) -> None:
        """The 3D point under every anchor, by one ray per anchor (the ID buffer has no depth)."""
        if not result.labels:
            return
        w, h = result.size
        xy = np.array([lab.anchor for lab in result.labels])
        origins, dirs = result.camera.pixel_rays(
            np.floor(xy[:, 0]).astype(np.int64), np.floor(xy[:, 1]).astype(np.int64), w, h
        )
        hits = self.caster.intersect(origins, dirs)
        points = hits.points(origins, dirs)
        for lab, p in zip(result.labels, points):
            lab.anchor_3d = p


def frame_json(result: LayoutResult, seq: int = 0) -> dict[str, Any]:
    """What the page needs of a live frame: the labels (pixels of the ID buffer) and the time.

    Examples
    --------
    >>> sorted(frame_json.__annotations__)
    ['result', 'return', 'seq']
    """

    def pts(a: np.ndarray) -> list:
        return np.round(np.asarray(a, np.float64), 2).tolist()

    return {
        "seq": int(seq),
        "width": result.size[0],
        "height": result.size[1],
        "fontSize": result.font_size,
        "boxHeight": round(result.box_height, 3),
        "layoutMs": round(result.timings.get("layout_ms", 0.0), 3),
        "labels": [
            {
                "part": lab.part,
                "text": lab.text,
                "anchor": pts(lab.anchor),
                "anchor3d": [float(x) if np.isfinite(x) else None for x in lab.anchor_3d],
                "leader": pts(lab.leader),
                "box": pts(lab.box),
                "side": lab.side,
            }
            for lab in result.labels
        ],
        "left_out": [name for _, name in result.unplaced],
    }
