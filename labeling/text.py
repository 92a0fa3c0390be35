"""Label text metrics: the size of every label box, measured with the font used to draw it.

Boxes are measured with DejaVu Sans (shipped with matplotlib, so always present) through
Pillow; the PNG writer draws with the same font and the SVG writer pins each text to the
measured width (``textLength``), so a text always fits its box whatever font the SVG
viewer substitutes.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

#: the label font family written into SVG files
FONT_FAMILY = "DejaVu Sans, Verdana, Arial, sans-serif"


@lru_cache(maxsize=1)
def font_file() -> str:
    """Path of DejaVuSans.ttf (from matplotlib's data folder)."""
    import matplotlib

    return os.path.join(matplotlib.get_data_path(), "fonts", "ttf", "DejaVuSans.ttf")


@lru_cache(maxsize=32)
def font(size: int):
    """A Pillow font of ``size`` pixels."""
    from PIL import ImageFont

    return ImageFont.truetype(font_file(), int(size))


#: texts whose measured widths are kept: a live view measures the same few dozen texts
#: at a few font sizes every frame
LENGTH_CACHE = 8192


@lru_cache(maxsize=LENGTH_CACHE)
def _length(size: int, text: str) -> float:
    """Width of ``text`` at ``size`` pixels, without padding (Pillow's advance width)."""
    return float(font(size).getlength(text))


def default_font_size(height: int) -> int:
    """Font size in pixels for an image ``height`` pixels high (11 px at 512)."""
    return int(max(7, round(0.0215 * height)))


@dataclass(frozen=True)
class TextStyle:
    """Font size and the padding between text and box edge, in pixels."""

    font_size: int
    pad_x: float = 3.0
    pad_y: float = 1.5

    @property
    def ascent(self) -> float:
        """Font ascent in pixels."""
        return float(font(self.font_size).getmetrics()[0])

    @property
    def descent(self) -> float:
        """Font descent in pixels."""
        return float(font(self.font_size).getmetrics()[1])

    @property
    def box_height(self) -> float:
        """Height of every label box."""
        return self.ascent + self.descent + 2 * self.pad_y

    def box_widths(self, texts: Sequence[str]) -> np.ndarray:
        """Width of the box of each text."""
        return np.array([_length(self.font_size, t) + 2 * self.pad_x for t in texts], np.float64)

    def text_width(self, text: str) -> float:
        """Width of ``text`` in pixels, without padding."""
        return _length(self.font_size, text)
