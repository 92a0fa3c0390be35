"""The state the placement of one frame shares: labels, sides, ``A_I``, what is placed."""

from __future__ import annotations

import numpy as np

from ..candidates import EAST, NORTH, SOUTH, WEST
from ..internal_area import resample_boundary
from .spacing import BoxStats, Placement

#: spacing (pixels) of the points along the boundary of ``A_I`` that the silhouette layout
#: moves endpoints between and takes its push-out normals from
BOUNDARY_STEP = 2.0
#: the farthest push-out the searches consider: 1.2 image sizes, or the height of a stack of
#: three boxes per label when there are many labels
REACH_IMAGE = 1.2
REACH_STACK = 3.0
#: the nearer search before the farthest one, as a fraction of the image size: most labels
#: find their place there, and its candidate lists are much shorter
NEAR_REACH = 0.4
#: length of a push-out ray in the tests against boxes, in reaches (plus the widest box):
#: beyond any push-out a search may choose
RAY_REACHES = 2.0
#: floor of a tangent length (pixels) where boundary points coincide
_TINY = 1e-12
#: hysteresis of the columns and rows along a camera path: a column (row) stays where it
#: was last frame while it is still clear of ``A_I`` and at most this fraction of the
#: image's smaller side farther out than needed
LINE_SLACK = 0.06


def _sticky(needed: float, before: float, outward: float, slack: float) -> float:
    """The column (row) coordinate: ``before`` while valid and within ``slack``, else ``needed``.

    ``outward`` is -1 for west/north (smaller coordinates are farther out), +1 otherwise.
    """
    if not np.isfinite(before):
        return needed
    extra = (before - needed) * outward
    return float(before) if 0.0 <= extra <= slack else needed


class Context:
    """Everything the placement of one frame shares."""

    def __init__(
        self,
        anchors,
        endpoints,
        sides,
        widths,
        height,
        area,
        image_size,
        spacing,
        rank,
        previous=None,
        directions=None,
        centres=None,
        lines=None,
        leaders=None,
        motion=None,
        left_out=None,
    ):
        self.anchors = np.asarray(anchors, np.float64).reshape(-1, 2)
        # per label: its box centre along each side in the previous frame (NaN: elsewhere)
        self.previous = (
            np.full((len(self.anchors), 4), np.nan) if previous is None else np.asarray(previous, np.float64)
        )
        self.endpoints = np.array(endpoints, np.float64).reshape(-1, 2)  # a copy: parting moves them
        self.sides = np.array(sides, np.int64)  # a copy: a label may change side
        # the layout's principal directions (a label may move to another one of them)
        self.directions = tuple(sorted(set(self.sides.tolist()))) if directions is None else tuple(directions)
        self.widths = np.asarray(widths, np.float64)
        self.height = float(height)
        self.area = area
        self.W, self.H = (float(s) for s in image_size)
        self.sp = spacing
        self.rank = np.asarray(rank, np.int64)
        self.placed: list[Placement | None] = [None] * len(self.anchors)
        x0, y0, x1, y1 = area.bbox
        # per label: where its box centre would be had it followed its anchor since the
        # previous frame (NaN: no previous frame), for the silhouette layout's search
        self.centres = (
            np.full((len(self.anchors), 2), np.nan) if centres is None else np.asarray(centres, np.float64)
        )
        before = np.full(4, np.nan) if lines is None else np.asarray(lines, np.float64)
        slack = LINE_SLACK * min(self.W, self.H)
        self.col_x = {
            WEST: _sticky(float(np.nanmin(area.left)) - spacing.clearance, before[WEST], -1.0, slack),
            EAST: _sticky(float(np.nanmax(area.right)) + spacing.clearance, before[EAST], 1.0, slack),
        }
        self.row_y = {
            NORTH: _sticky(float(np.nanmin(area.top)) - spacing.clearance, before[NORTH], -1.0, slack),
            SOUTH: _sticky(float(np.nanmax(area.bottom)) + spacing.clearance, before[SOUTH], 1.0, slack),
        }
        self.center = area.centroid
        # per label: the previous frame's leader moved with its anchor (None: none), and
        # the direction of its flag box in a row (1 left of the port, -1 right, 0: by the
        # side of the centre the port is on), set by the row stacking
        self.leaders = [None] * len(self.anchors) if leaders is None else leaders
        self.flags = np.zeros(len(self.anchors), np.int8)
        # per label: how far (pixels) the surface under its anchor moved since the previous
        # frame (0: no previous frame)
        self.motion = (
            np.zeros(len(self.anchors)) if motion is None else np.nan_to_num(np.asarray(motion, np.float64))
        )
        # per label: left out for lack of room in the previous frame
        self.left_out = np.zeros(len(self.anchors), bool) if left_out is None else np.asarray(left_out, bool)
        self.stats = BoxStats()
        self._boundary = None
        self._rays = None
        self._cache = None

    # geometry of one label in a column / row
    def column_box(self, k: int, side: int, y: np.ndarray) -> np.ndarray:
        """Column box (x0, y0, x1, y1) of label k on ``side`` centred at height ``y``."""
        x = self.col_x[side]
        w, h = self.widths[k], self.height
        y = np.asarray(y, np.float64)
        x0 = np.full_like(y, x - w if side == WEST else x)
        return np.stack([x0, y - h / 2, x0 + w, y + h / 2], axis=-1)

    def row_box(self, k: int, side: int, x: np.ndarray, tier: np.ndarray) -> np.ndarray:
        """Flag box of label k whose leader port is at ``x``, in ``tier``."""
        w, h, sp = self.widths[k], self.height, self.sp
        if np.ndim(x) == 0 and np.ndim(tier) == 0:  # one box: plain floats cost far less than arrays
            return np.array(self._one_row_box(float(w), side, float(x), float(tier), int(self.flags[k])))
        x = np.asarray(x, np.float64)
        tier = np.asarray(tier, np.float64)
        left_flag = x < self.center[0] if self.flags[k] == 0 else np.full(x.shape, self.flags[k] > 0)
        x0 = np.where(left_flag, x + sp.inset - w, x - sp.inset)
        step = h + sp.gap
        if side == NORTH:
            y1 = self.row_y[NORTH] - tier * step
            y0 = y1 - h
        else:
            y0 = self.row_y[SOUTH] + tier * step
            y1 = y0 + h
        x0, y0, y1 = np.broadcast_arrays(x0, y0, y1)
        return np.stack([x0, y0, x0 + w, y1], axis=-1)

    def _one_row_box(
        self, w: float, side: int, x: float, tier: float, flag: int = 0
    ) -> tuple[float, float, float, float]:
        """:meth:`row_box` of one label of width ``w`` (the same arithmetic on floats)."""
        h, sp = self.height, self.sp
        left = x < self.center[0] if flag == 0 else flag > 0
        x0 = x + sp.inset - w if left else x - sp.inset
        step = h + sp.gap
        if side == NORTH:
            y1 = self.row_y[NORTH] - tier * step
            y0 = y1 - h
        else:
            y0 = self.row_y[SOUTH] + tier * step
            y1 = y0 + h
        return x0, y0, x0 + w, y1

    def row_leader(self, k: int, side: int, x: float, tier: int) -> np.ndarray:
        """Leader polyline of label k in a row: anchor, port at ``x`` and, beyond tier 0, the box edge."""
        box = self.row_box(k, side, np.array(x), np.array(tier))
        port = (x, self.row_y[side])
        pts = [self.anchors[k], port]
        if tier > 0:
            pts.append((x, box[3] if side == NORTH else box[1]))
        return np.array(pts, np.float64)

    boundary_step = BOUNDARY_STEP
    future: tuple = ()

    def ray_direction(self, k: int) -> np.ndarray:
        """Outward unit normal of ``A_I`` at label k's endpoint: the direction of its push-out.

        Normals of a convex boundary turn monotonically, so these rays never meet.
        """
        if self._rays is None:
            pts, normals = self.boundary
            d2 = ((self.endpoints[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2)
            self._nearest = np.argmin(d2, axis=1)
            self._rays = normals[self._nearest]
        return self._rays[k]

    def boundary_index(self, k: int) -> int:
        """Index of the boundary point (:attr:`boundary`) nearest to label k's endpoint."""
        self.ray_direction(k)
        return int(self._nearest[k])

    def future_rays(self, k: int) -> np.ndarray:
        """Rays (m, 2, 2) of the radial labels not placed yet (other than k)."""
        js = np.fromiter((j for j in self.future if j != k), np.int64)
        if len(js) == 0:
            return np.zeros((0, 2, 2))
        self.ray_direction(0)
        e = self.endpoints[js]
        out = np.empty((len(js), 2, 2))
        out[:, 0] = e
        out[:, 1] = e + self.ray_length * self._rays[js]
        return out

    @property
    def reach(self) -> float:
        """Farthest push-out of a box (pixels) the candidate searches consider."""
        size = max(self.W, self.H)
        return max(REACH_IMAGE * size, REACH_STACK * len(self.anchors) * (self.height + self.sp.gap))

    @property
    def ray_length(self) -> float:
        """Length of a label's push-out ray in the tests against boxes.

        It is longer than any push-out the search may choose plus the widest box, since a
        box beyond a ray's end would count as leaving the ray free.
        """
        return RAY_REACHES * self.reach + float(self.widths.max()) + self.height

    def future_insides(self, k: int) -> np.ndarray:
        """Inside parts (m, 2, 2), anchor to endpoint, of the radial labels not placed yet (other than k)."""
        js = np.fromiter((j for j in self.future if j != k), np.int64)
        out = np.empty((len(js), 2, 2))
        out[:, 0] = self.anchors[js]
        out[:, 1] = self.endpoints[js]
        return out

    @property
    def boundary(self) -> tuple[np.ndarray, np.ndarray]:
        """Points every :data:`BOUNDARY_STEP` px along the boundary of ``A_I`` and their outward unit normals."""
        if self._boundary is None:
            pts, arc = resample_boundary(self.area.polygon, BOUNDARY_STEP)
            self.boundary_step = float(arc[1] - arc[0])
            tangent = np.roll(pts, -1, axis=0) - np.roll(pts, 1, axis=0)
            normal = np.column_stack([tangent[:, 1], -tangent[:, 0]])
            normal /= np.maximum(np.hypot(normal[:, 0], normal[:, 1]), _TINY)[:, None]
            outward = np.einsum("ij,ij->i", normal, pts - self.center) >= 0
            normal[~outward] *= -1  # convex area: outward = away from the centre
            self._boundary = (pts, normal)
        return self._boundary
