"""A picture of a from-region visibility result: the model, and what nobody saw."""

from __future__ import annotations

import numpy as np

from meshvis.rays.camera import Camera
from meshvis.rays.render import BACKGROUND, render
from meshvis.soup import Soup
from meshvis.visibility.visible import Visibility

#: colours of seen and unseen faces (RGB)
SEEN = np.array([170, 190, 215], np.float64)
UNSEEN = np.array([220, 60, 50], np.float64)


def preview(soup: Soup, vis: Visibility, *, size: int = 512, azimuth: float = 30.0, elevation: float = 20.0):
    """Two panels side by side: the model with unseen faces in red, and the unseen faces alone.

    Parameters
    ----------
    soup : Soup
        The model ``vis`` was computed on.
    vis : Visibility
        The result of :func:`meshvis.visible_from` on ``soup``.
    size : int
        Height of the picture (each panel is square).
    azimuth, elevation : float
        Camera angles in degrees (one camera for both panels).

    Returns
    -------
    (size, 2 * size, 3) uint8 array
        The two panels.

    Examples
    --------
    >>> import trimesh
    >>> from meshvis.io import as_soup
    >>> from meshvis.visibility import visible_from
    >>> s = as_soup(trimesh.creation.box())
    >>> preview(s, visible_from(s), size=32).shape
    (32, 64, 3)
    """
    camera = Camera.fit(soup, azimuth=azimuth, elevation=elevation)
    left = render(soup, camera, size=(size, size), color_by=None)
    hit = left.face >= 0
    img = left.image.astype(np.float64)
    shade = img[hit] / 200.0
    colour = np.where(vis.seen[left.face[hit]][:, None], SEEN, UNSEEN)
    img[hit] = np.clip(colour * shade, 0, 255)
    hidden = ~vis.seen
    if hidden.any():
        right = render(soup.subset(hidden), camera, size=(size, size), color_by=None).image
    else:
        right = np.broadcast_to(BACKGROUND, (size, size, 3))
    return np.concatenate([img.astype(np.uint8), right], axis=1)
