"""Pictures of a PVS: the cells coloured by PVS size (AGVS Fig. 2), and one cell's PVS in the scene.

* :func:`top_view` -- the level seen from above (orthographic, grey), with every cell that
  holds the chosen height drawn as a rectangle coloured by the size of its PVS;
* :func:`cell_view` -- the scene from outside, the faces in the PVS of one cell opaque and
  coloured, every other face a faint veil (depth peeling through
  :func:`meshvis.rays.render.render_layers`), the cell's box drawn in red.
"""

from __future__ import annotations

import io

import numpy as np

from meshvis.errors import ParameterError
from meshvis.io import as_soup
from meshvis.rays.camera import Camera
from meshvis.rays.render import render, render_layers

#: pixels along the longer side of the top view's scene picture
TOP_VIEW_PIXELS = 800
#: default height of the top view's slice, as a share of the view space's box above its bottom
SLICE_SHARE = 0.25
#: size of the cell view
CELL_VIEW_SIZE = (900, 700)


def slice_height(result, height: float | None = None) -> float:
    """The height of the top view's slice: ``height``, or :data:`SLICE_SHARE` up the view space."""
    vs = result.cells.view_space
    a = vs.up_axis
    if height is not None:
        return float(height)
    low, high = (vs.lo[a], vs.hi[a]) if vs.up_sign > 0 else (vs.hi[a], vs.lo[a])
    return float(low + SLICE_SHARE * (high - low))


def top_view(result, model, *, height: float | None = None) -> np.ndarray:
    """(h, w, 3) uint8: the level from above with the cells at ``height`` coloured by PVS size.

    Parameters
    ----------
    result : PVS
        The PVS of every cell.
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model the PVS was made for.
    height : float, optional
        The slice (a coordinate along the up axis); default :func:`slice_height`.

    Returns
    -------
    (h, w, 3) uint8 array
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle
    from PIL import Image

    soup = as_soup(model)
    vs = result.cells.view_space
    a, (u, v) = vs.up_axis, vs.horizontal
    h = slice_height(result, height)
    lo, hi = vs.lo, vs.hi
    extent = (lo[u], hi[u], lo[v], hi[v])
    width = TOP_VIEW_PIXELS
    px_h = max(1, int(round(width * (hi[v] - lo[v]) / max(hi[u] - lo[u], 1e-300))))
    # the scene from above, orthographic, framing the view space's footprint
    top = np.zeros(3)
    top[a] = vs.up_sign
    centre = 0.5 * (lo + hi)
    screen_up = np.zeros(3)
    screen_up[v] = 1.0
    span = max(hi[v] - lo[v], 1e-300)
    cam = Camera(centre + top * 2 * soup.diagonal, centre, screen_up, orthographic=True, ortho_height=span)
    picture = render(soup, cam, size=(width, px_h), color_by=None).image
    # the camera's right may run against the u axis: put u to the right, as the plot does
    right = cam.basis()[0]
    if right[u] < 0:
        picture = picture[:, ::-1]
    sizes = result.sizes()
    at = (result.cells.cell_lo[:, a] <= h) & (result.cells.cell_hi[:, a] > h)
    fig, ax = plt.subplots(figsize=(8, 8 * px_h / width + 0.8), dpi=110)
    ax.imshow(picture, extent=extent, origin="upper", alpha=0.6)
    norm = matplotlib.colors.Normalize(vmin=0, vmax=max(int(sizes.max()), 1))
    cmap = matplotlib.colormaps["inferno"]
    for c in np.flatnonzero(at):
        x0, y0 = result.cells.cell_lo[c, u], result.cells.cell_lo[c, v]
        w, d = result.cells.cell_hi[c, u] - x0, result.cells.cell_hi[c, v] - y0
        ax.add_patch(
            Rectangle((x0, y0), w, d, facecolor=cmap(norm(sizes[c])), edgecolor="white", lw=0.6, alpha=0.55)
        )
    ax.set_xlim(lo[u], hi[u])
    ax.set_ylim(lo[v], hi[v])
    ax.set_xlabel("xyz"[u])
    ax.set_ylabel("xyz"[v])
    ax.set_title(f"PVS size of the {int(at.sum())} cells at {'xyz'[a]} = {h:.4g}")
    fig.colorbar(
        matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, label="faces in the PVS", shrink=0.8
    )
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")
    plt.close(fig)
    buf.seek(0)
    return np.asarray(Image.open(buf).convert("RGB"))


def cell_view(
    result, model, cell: int, *, size=CELL_VIEW_SIZE, azimuth: float = 30.0, elevation: float = 35.0
) -> np.ndarray:
    """(h, w, 3) uint8: the scene with the PVS of ``cell`` opaque, the rest a veil, the cell's box in red.

    Parameters
    ----------
    result : PVS
        The PVS of every cell.
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model the PVS was made for.
    cell : int
        The cell whose PVS is drawn.
    size : (int, int)
        Width and height of the picture in pixels.
    azimuth, elevation : float
        Degrees of the fitted camera (:meth:`meshvis.rays.camera.Camera.fit`).

    Returns
    -------
    (h, w, 3) uint8 array
    """
    from PIL import Image, ImageDraw

    soup = as_soup(model)
    if not 0 <= int(cell) < result.cells.n_cells:
        raise ParameterError(f"cell must be in 0..{result.cells.n_cells - 1}, got {cell}")
    up = np.zeros(3)
    up[result.cells.view_space.up_axis] = result.cells.view_space.up_sign
    cam = Camera.fit(soup, azimuth=azimuth, elevation=elevation, up=up)
    layer = np.ones(soup.n_faces, np.int64)
    layer[result.faces(int(cell))] = 2
    image = render_layers(soup, layer, cam, size=size)
    lo, hi = result.cells.cell_lo[int(cell)], result.cells.cell_hi[int(cell)]
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    px, _ = cam.project(corners, size[0], size[1])
    picture = Image.fromarray(image)
    draw = ImageDraw.Draw(picture)
    for i in range(8):
        for j in range(i + 1, 8):
            if bin(i ^ j).count("1") == 1 and np.isfinite(px[[i, j]]).all():
                draw.line([tuple(px[i]), tuple(px[j])], fill=(220, 30, 30), width=2)
    return np.asarray(picture)
