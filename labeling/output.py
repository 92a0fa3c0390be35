"""Writing labelled views: SVG, PNG, animated GIF and JSON, each written atomically.

* **SVG**: the shaded render embedded as a PNG data URI; leaders, anchors, boxes and texts
  as vector elements.  Each text is pinned to the width it was measured at
  (``textLength``), so it fits its box in any viewer.  The canvas is the image grown to
  hold every box (:attr:`LayoutResult.canvas`).
* **PNG**: the same drawing rasterised with Pillow (drawn at twice the size, then reduced,
  for smooth lines and text).
* **GIF**: the PNG frames of a sequence on a common canvas.
* **JSON**: :meth:`LayoutResult.to_json` per frame (labels, metrics, timings).
"""

from __future__ import annotations

import base64
import io
import os
from collections.abc import Sequence
from typing import Any
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from meshvis.errors import OutputError

from .result import LayoutResult
from .text import FONT_FAMILY, TextStyle, font

LEADER = (30, 30, 30)
ANCHOR = (200, 30, 30)
BOX_FILL = (255, 255, 255)
BOX_EDGE = (110, 110, 110)
TEXT = (20, 20, 20)
AREA = (200, 200, 200)


def _atomic(path: str, mode: str):
    from meshvis.io import atomic_write

    return atomic_write(path, mode)


def _png_bytes(image: np.ndarray) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.asarray(image, np.uint8)).save(buf, format="PNG", optimize=True)
    return buf.getvalue()


def _rgb(c: tuple[int, int, int]) -> str:
    return "#%02x%02x%02x" % c


def to_svg(result: LayoutResult, *, show_area: bool = False, canvas: Sequence[float] | None = None) -> str:
    """The SVG document of a labelled view.

    Parameters
    ----------
    result : LayoutResult
        The layout to draw.
    show_area : bool
        Also draw the boundary of the internal area ``A_I`` (dashed).
    canvas : (4,) float, optional
        ``(x0, y0, x1, y1)`` to use instead of ``result.canvas``.
    """
    x0, y0, x1, y1 = canvas if canvas is not None else result.canvas
    w, h = result.size
    style = TextStyle(result.font_size)
    uri = "data:image/png;base64," + base64.b64encode(_png_bytes(result.image)).decode("ascii")
    out = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
        f'width="{x1 - x0:g}" height="{y1 - y0:g}" viewBox="{x0:g} {y0:g} {x1 - x0:g} {y1 - y0:g}">',
        f"<title>{escape(result.layout)} labels ({escape(result.method)})</title>",
        f'<rect x="{x0:g}" y="{y0:g}" width="{x1 - x0:g}" height="{y1 - y0:g}" fill="#ffffff"/>',
        f'<image x="0" y="0" width="{w}" height="{h}" preserveAspectRatio="none" href="{uri}" xlink:href="{uri}"/>',
    ]
    if show_area and len(result.area_polygon):
        pts = " ".join(f"{x:.2f},{y:.2f}" for x, y in result.area_polygon)
        out.append(f'<polygon points="{pts}" fill="none" stroke="{_rgb(AREA)}" stroke-dasharray="4 3"/>')
    out.append(f'<g fill="none" stroke="{_rgb(LEADER)}" stroke-width="1" stroke-linejoin="round">')
    for lab in result.labels:
        pts = " ".join(f"{x:.2f},{y:.2f}" for x, y in lab.leader)
        out.append(f'<polyline points="{pts}"/>')
    out.append("</g>")
    out.append(f'<g fill="{_rgb(ANCHOR)}" stroke="#ffffff" stroke-width="0.8">')
    for lab in result.labels:
        out.append(f'<circle cx="{lab.anchor[0]:.2f}" cy="{lab.anchor[1]:.2f}" r="2.2"/>')
    out.append("</g>")
    out.append(f'<g font-family={quoteattr(FONT_FAMILY)} font-size="{result.font_size}" fill="{_rgb(TEXT)}">')
    for lab in result.labels:
        bx0, by0, bx1, by1 = (float(v) for v in lab.box)
        tw = style.text_width(lab.text)
        baseline = by0 + style.pad_y + style.ascent
        out.append(
            f'<g><rect x="{bx0:.2f}" y="{by0:.2f}" width="{bx1 - bx0:.2f}" height="{by1 - by0:.2f}" '
            f'fill="{_rgb(BOX_FILL)}" fill-opacity="0.9" stroke="{_rgb(BOX_EDGE)}" stroke-width="0.6"/>'
            f'<text x="{bx0 + style.pad_x:.2f}" y="{baseline:.2f}" textLength="{tw:.2f}" '
            f'lengthAdjust="spacingAndGlyphs">{escape(lab.text)}</text></g>'
        )
    out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"


def to_image(
    result: LayoutResult,
    *,
    canvas: Sequence[float] | None = None,
    supersample: int = 2,
    show_area: bool = False,
):
    """Rasterise a labelled view to a ``PIL.Image`` (RGB) of the canvas size."""
    from PIL import Image, ImageDraw

    x0, y0, x1, y1 = canvas if canvas is not None else result.canvas
    s = max(1, int(supersample))
    W, H = int(round(x1 - x0)), int(round(y1 - y0))
    img = Image.new("RGB", (W * s, H * s), (255, 255, 255))
    w, h = result.size
    base = Image.fromarray(np.asarray(result.image, np.uint8)).resize(
        (w * s, h * s), Image.Resampling.NEAREST
    )
    img.paste(base, (int(round(-x0)) * s, int(round(-y0)) * s))
    draw = ImageDraw.Draw(img)

    def P(x: float, y: float) -> tuple[float, float]:
        return ((x - x0) * s, (y - y0) * s)

    if show_area and len(result.area_polygon):
        pts = [P(x, y) for x, y in result.area_polygon]
        draw.line(pts + pts[:1], fill=AREA, width=s)
    for lab in result.labels:
        draw.line([P(x, y) for x, y in lab.leader], fill=LEADER, width=s, joint="curve")
    r = 2.2 * s
    for lab in result.labels:
        cx, cy = P(*lab.anchor)
        draw.ellipse([cx - r, cy - r, cx + r, cy + r], fill=ANCHOR, outline=(255, 255, 255))
    style = TextStyle(result.font_size)
    f = font(result.font_size * s)
    for lab in result.labels:
        bx0, by0 = P(lab.box[0], lab.box[1])
        bx1, by1 = P(lab.box[2], lab.box[3])
        draw.rectangle([bx0, by0, bx1, by1], fill=BOX_FILL, outline=BOX_EDGE, width=max(1, s // 2))
        draw.text((bx0 + style.pad_x * s, by0 + style.pad_y * s), lab.text, font=f, fill=TEXT)
    if s > 1:
        img = img.resize((W, H), Image.Resampling.LANCZOS)
    return img


def _check_path(path: str) -> str:
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise OutputError("output folder does not exist", path)
    return path


def write_svg(result: LayoutResult, path: str, **kw: Any) -> None:
    """Write the SVG of a labelled view (atomically)."""
    with _atomic(_check_path(path), "w") as fh:
        fh.write(to_svg(result, **kw))


def write_png(result: LayoutResult, path: str, **kw: Any) -> None:
    """Write the PNG of a labelled view (atomically)."""
    img = to_image(result, **kw)
    with _atomic(_check_path(path), "wb") as fh:
        img.save(fh, format="PNG", optimize=True)


def union_canvas(results: Sequence[LayoutResult]) -> tuple[float, float, float, float]:
    """The canvas that holds every frame's canvas."""
    c = np.array([r.canvas for r in results])
    return float(c[:, 0].min()), float(c[:, 1].min()), float(c[:, 2].max()), float(c[:, 3].max())


def write_gif(results: Sequence[LayoutResult], path: str, *, duration_ms: int = 120, loop: int = 0) -> None:
    """Write an animated GIF of a sequence of labelled frames on a common canvas."""
    if not results:
        raise OutputError("no frames to write", path)
    canvas = union_canvas(results)
    frames = [to_image(r, canvas=canvas).convert("P", palette=1, colors=255) for r in results]
    with _atomic(_check_path(path), "wb") as fh:
        frames[0].save(
            fh,
            format="GIF",
            save_all=True,
            append_images=frames[1:],
            duration=int(duration_ms),
            loop=int(loop),
            optimize=False,
            disposal=1,
        )


def write_json(data: Any, path: str) -> None:
    """Write JSON atomically (NaN written as null)."""
    from meshvis.io.jsonfile import write_json as _write

    _write(_check_path(path), data)


def write(result: LayoutResult | Sequence[LayoutResult], path: str, **kw: Any) -> list[str]:
    """Write one frame or a sequence, the format chosen by the extension of ``path``.

    ``.svg`` / ``.png``: one file per frame (``name_000.svg`` ... for a sequence);
    ``.gif``: one animation; ``.json``: the frames' JSON.  Returns the paths written.
    """
    frames = [result] if isinstance(result, LayoutResult) else list(result)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".gif":
        write_gif(frames, path, **kw)
        return [path]
    if ext == ".json":
        write_json({"frames": [f.to_json() for f in frames]}, path)
        return [path]
    if ext not in (".svg", ".png"):
        raise OutputError("unknown output format (use .svg, .png, .gif or .json)", path)
    writer = write_svg if ext == ".svg" else write_png
    if len(frames) == 1:
        writer(frames[0], path, **kw)
        return [path]
    stem = path[: -len(ext)]
    canvas = union_canvas(frames)
    paths = []
    for i, f in enumerate(frames):
        p = f"{stem}_{i:03d}{ext}"
        writer(f, p, canvas=canvas, **kw)
        paths.append(p)
    return paths
