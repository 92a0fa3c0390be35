"""View cells: a partition of the view space into boxes, kept as a kD-tree (DESIGN.md §11).

Every set of view cells is the leaves of one kD-tree over the view space's box: a uniform
grid (:meth:`ViewCells.grid`), boxes read from a JSON file (:meth:`ViewCells.from_boxes`,
split apart by axis-aligned planes that cut none of them) or the tree built by render cost
(:func:`meshvis.viewcells.hierarchy.auto_cells`).  A leaf with no part of the view space in it
(under the ground, or between the boxes of a file) has no cell: it is left out.  The
compiled walk of :mod:`._kernels` follows a segment through the tree; the PVS compression
stores what two siblings share at their parent (:meth:`ViewCells.compress`).

>>> from meshvis.viewcells.viewspace import ViewSpace
>>> vc = ViewCells.grid(ViewSpace(np.zeros(3), np.ones(3)), (2, 2, 1))
>>> vc.n_cells, vc.locate(np.array([[0.25, 0.75, 0.5]])).tolist()
(4, [1])
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field

import numpy as np

from meshvis.errors import ParameterError
from meshvis.viewcells import _kernels
from meshvis.viewcells.viewspace import ViewSpace

#: cells of ``auto`` without a count
DEFAULT_AUTO_CELLS = 64
#: most view cells of one set (memory: the PVS bit set takes cells x faces / 8 bytes)
MAX_CELLS = 1 << 16
#: bytes of a view cells file (a box is about 100 bytes of JSON)
MAX_CELLS_FILE = 200 * MAX_CELLS
#: a cell whose share of its box above the ground is below this has no cell (left out)
MIN_VOLUME_SHARE = 1e-9


@dataclass
class ViewCells:
    """View cells as the leaves of a kD-tree over the view space.

    Parameters
    ----------
    view_space : ViewSpace
        The space the cells partition; the tree's root is its box.
    axis : (n,) int8
        Split axis of each node, -1 for a leaf.
    split : (n,) float64
        Split position (a coordinate along ``axis``); the left child is below it.
    left, right : (n,) int32
        Children of each node (-1 for a leaf).
    cell : (n,) int32
        The cell of each leaf (-1: a leaf outside the view space, or an inner node).
    kind : str
        How the cells were made (``grid:4,4,4``, ``auto:64``, ``file``).

    Attributes
    ----------
    n_cells : int
        Number of cells ``k``.
    cell_lo, cell_hi : (k, 3) float64
        The cells' boxes.
    volume : (k,) float64
        Each cell's share of the view space's volume (P(cell) of 002 §3.3).
    parent : (n,) int32
        Each node's parent (-1 for the root).
    """

    view_space: ViewSpace
    axis: np.ndarray
    split: np.ndarray
    left: np.ndarray
    right: np.ndarray
    cell: np.ndarray
    kind: str = "grid"
    node_lo: np.ndarray = field(init=False, repr=False)
    node_hi: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.axis = np.ascontiguousarray(self.axis, np.int8)
        self.split = np.ascontiguousarray(self.split, np.float64)
        self.left = np.ascontiguousarray(self.left, np.int32)
        self.right = np.ascontiguousarray(self.right, np.int32)
        self.cell = np.ascontiguousarray(self.cell, np.int32)
        n = len(self.axis)
        if not (len(self.split) == len(self.left) == len(self.right) == len(self.cell) == n) or n == 0:
            raise ParameterError("view cells: the tree's arrays must have one entry per node")
        self._check_tree()
        self.node_lo, self.node_hi = self._boxes()
        cells = self.cell[self.cell >= 0]
        self.n_cells = int(cells.max()) + 1 if len(cells) else 0
        if self.n_cells > MAX_CELLS:
            raise ParameterError(f"{self.n_cells} view cells, more than the cap of {MAX_CELLS}")
        if len(np.unique(cells)) != len(cells) or len(cells) != self.n_cells:
            raise ParameterError("view cells: every cell must be exactly one leaf")
        self.cell_node = np.empty(self.n_cells, np.int64)
        self.cell_node[cells] = np.flatnonzero(self.cell >= 0)
        self.cell_lo = self.node_lo[self.cell_node]
        self.cell_hi = self.node_hi[self.cell_node]
        share = self.view_space.volume_share(self.cell_lo, self.cell_hi)
        vol = share * np.prod(self.cell_hi - self.cell_lo, axis=1)
        self.volume = vol / max(float(vol.sum()), 1e-300)

    def _check_tree(self) -> None:
        n = len(self.axis)
        inner = self.axis >= 0
        kids = np.concatenate([self.left[inner], self.right[inner]])
        if (
            (self.axis > 2).any()
            or (kids <= 0).any()
            or (kids >= n).any()
            or len(np.unique(kids)) != len(kids)
        ):
            raise ParameterError("view cells: not a tree (bad axis or child index)")
        if len(kids) != n - 1 or (self.cell[inner] >= 0).any():
            raise ParameterError(
                "view cells: not a tree (nodes without a parent, or inner nodes with a cell)"
            )
        parent = np.full(n, -1, np.int32)
        parent[self.left[inner]] = np.flatnonzero(inner)
        parent[self.right[inner]] = np.flatnonzero(inner)
        # children come after their parents, so every node hangs from the root
        if (parent[1:] >= np.arange(1, n)).any():
            raise ParameterError("view cells: children must come after their parent")
        self.parent = parent

    def _boxes(self) -> tuple[np.ndarray, np.ndarray]:
        n = len(self.axis)
        lo = np.empty((n, 3))
        hi = np.empty((n, 3))
        lo[0], hi[0] = self.view_space.lo, self.view_space.hi
        for node in range(n):  # parents come first
            a = int(self.axis[node])
            if a < 0:
                continue
            s = self.split[node]
            if not lo[node, a] < s < hi[node, a]:
                raise ParameterError(f"view cells: node {node} splits at {s}, outside its box")
            left, right = self.left[node], self.right[node]
            lo[left], hi[left] = lo[node], hi[node]
            lo[right], hi[right] = lo[node], hi[node]
            hi[left, a] = s
            lo[right, a] = s
        return lo, hi

    # ------------------------------------------------------------------ builders
    @classmethod
    def grid(cls, view_space: ViewSpace, shape) -> ViewCells:
        """A uniform grid of ``nx x ny x nz`` cells (those without view space left out).

        Parameters
        ----------
        view_space : ViewSpace
            The space the grid covers (its box).
        shape : 3 ints
            Cells along x, y and z.

        Returns
        -------
        ViewCells
        """
        shape = tuple(int(s) for s in shape)
        if len(shape) != 3 or min(shape) < 1:
            raise ParameterError(f"a grid needs three cell counts of at least 1, got {shape}")
        if int(np.prod(shape)) > MAX_CELLS:
            raise ParameterError(f"a grid of {int(np.prod(shape))} cells is more than the cap of {MAX_CELLS}")
        lo, hi = view_space.lo, view_space.hi
        edges = [lo[a] + (hi[a] - lo[a]) * np.arange(shape[a] + 1) / shape[a] for a in range(3)]
        tree = _TreeBuilder()

        def build(node: int, box: tuple) -> None:
            # split the axis with the most cells left at its middle index
            counts = [box[a][1] - box[a][0] for a in range(3)]
            a = int(np.argmax(counts))
            if counts[a] == 1:
                tree.leaf(node, (box[0][0], box[1][0], box[2][0]))
                return
            mid = (box[a][0] + box[a][1]) // 2
            left, right = tree.inner(node, a, float(edges[a][mid]))
            lbox, rbox = list(box), list(box)
            lbox[a], rbox[a] = (box[a][0], mid), (mid, box[a][1])
            build(left, tuple(lbox))
            build(right, tuple(rbox))

        build(tree.root(), tuple((0, s) for s in shape))
        return tree.cells(view_space, "grid:" + ",".join(map(str, shape)))

    @classmethod
    def from_boxes(cls, view_space: ViewSpace, boxes, kind: str = "file") -> ViewCells:
        """Cells from boxes that axis-aligned planes can split apart (a kD partition).

        Parameters
        ----------
        view_space : ViewSpace
            The space the boxes partition.
        boxes : (k, 6) float
            ``x0, y0, z0, x1, y1, z1`` of each cell; clipped to the view space's box (a box
            outside it is left out).  Boxes must not overlap.

        Returns
        -------
        ViewCells
            Cell ``i`` is the ``i``-th box that is left after clipping, in the given order.

        Raises
        ------
        ParameterError
            Not (k, 6) finite numbers with min < max, overlapping boxes, or boxes that no
            sequence of axis-aligned cuts separates.
        """
        try:
            b = np.asarray(boxes, np.float64).reshape(-1, 6)
        except (TypeError, ValueError):
            raise ParameterError("view cell boxes must be lists of six numbers x0,y0,z0,x1,y1,z1") from None
        if len(b) == 0 or not np.isfinite(b).all() or (b[:, 3:] <= b[:, :3]).any():
            raise ParameterError(
                "view cell boxes must be finite with x0 < x1, y0 < y1, z0 < z1 (and at least one)"
            )
        if len(b) > MAX_CELLS:
            raise ParameterError(f"{len(b)} view cells, more than the cap of {MAX_CELLS}")
        lo = np.maximum(b[:, :3], view_space.lo)
        hi = np.minimum(b[:, 3:], view_space.hi)
        keep = (hi > lo).all(axis=1)
        lo, hi = lo[keep], hi[keep]
        if len(lo) == 0:
            raise ParameterError("no view cell box meets the view space")
        tree = _TreeBuilder()

        def build(node: int, nlo, nhi, idx) -> None:
            if len(idx) == 0:
                tree.leaf(node, None)
                return
            if len(idx) == 1:
                i = idx[0]
                for a in range(3):  # carve the box out of the node, one face at a time
                    for s, keep_left in ((lo[i, a], False), (hi[i, a], True)):
                        if nlo[a] < s < nhi[a]:
                            left, right = tree.inner(node, a, float(s))
                            inner, outer = (left, right) if keep_left else (right, left)
                            tree.leaf(outer, None)
                            clo, chi = nlo.copy(), nhi.copy()
                            (chi if keep_left else clo)[a] = s
                            build(inner, clo, chi, idx)
                            return
                tree.leaf(node, int(i))
                return
            a, s = _free_cut(lo[idx], hi[idx], nlo, nhi)
            if a < 0:
                raise ParameterError(
                    "view cell boxes overlap, or no axis-aligned cut separates them (they must form a kD partition)"
                )
            left, right = tree.inner(node, a, s)
            go_left = hi[idx, a] <= s
            build(left, nlo, np.where(np.arange(3) == a, s, nhi), idx[go_left])
            build(right, np.where(np.arange(3) == a, s, nlo), nhi, idx[~go_left])

        build(tree.root(), view_space.lo.copy(), view_space.hi.copy(), np.arange(len(lo)))
        return tree.cells(view_space, kind, numbered=True)

    @classmethod
    def from_json(cls, path: str, view_space: ViewSpace) -> ViewCells:
        """Cells from a JSON file: a list of boxes, or ``{"cells": [...]}`` (see :meth:`from_boxes`)."""
        boxes = read_boxes(path)
        try:
            return cls.from_boxes(view_space, boxes, kind="file")
        except ParameterError as exc:
            raise ParameterError(f"{path}: {exc}") from None

    # ------------------------------------------------------------------ queries
    def tree_arrays(
        self,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The arguments of the kernels that walk the tree."""
        return self.axis, self.split, self.left, self.right, self.cell, self.view_space.lo, self.view_space.hi

    def locate(self, points: np.ndarray) -> np.ndarray:
        """(n,) int32 cell of each point (-1 outside every cell)."""
        pts = np.ascontiguousarray(np.asarray(points, np.float64).reshape(-1, 3))
        return _kernels.locate(self.tree_arrays(), pts)

    def radius(self) -> np.ndarray:
        """(k,) half the diagonal of each cell's box."""
        return 0.5 * np.linalg.norm(self.cell_hi - self.cell_lo, axis=1)

    def adjacent(self) -> tuple[np.ndarray, np.ndarray]:
        """CSR ``(ptr, nbr)`` of the cells whose box shares a piece of wall with each cell's box.

        Cell ``c``'s neighbours are ``nbr[ptr[c]:ptr[c + 1]]``: boxes that touch along one
        axis (within a relative 1e-9 of the view space's diagonal) and overlap, with a
        positive extent, along the other two.
        """
        lo, hi = self.cell_lo, self.cell_hi
        eps = 1e-9 * self.view_space.diagonal
        overlap = np.minimum(hi[:, None], hi[None]) - np.maximum(lo[:, None], lo[None])  # (k, k, 3)
        touch = (np.abs(hi[:, None] - lo[None]) <= eps) | (np.abs(lo[:, None] - hi[None]) <= eps)
        wide = overlap > eps
        # touching along one axis, overlapping along both others
        pair = (touch & (wide.sum(axis=2, keepdims=True) - wide == 2)).any(axis=2)
        np.fill_diagonal(pair, False)
        rows, nbr = np.nonzero(pair)
        ptr = np.zeros(self.n_cells + 1, np.int64)
        np.add.at(ptr, rows + 1, 1)
        return np.cumsum(ptr), nbr.astype(np.int64)

    def describe(self) -> dict:
        """The cells as a JSON-ready dict (the boxes of every cell)."""
        return {
            "kind": self.kind,
            "cells": self.n_cells,
            "tree_nodes": int(len(self.axis)),
            "leaves_without_view_space": int(((self.axis < 0) & (self.cell < 0)).sum()),
            "boxes": np.concatenate([self.cell_lo, self.cell_hi], axis=1).tolist(),
        }

    def arrays(self) -> dict[str, np.ndarray]:
        """The cells as named arrays (for the PVS file)."""
        return {
            "tree_axis": self.axis,
            "tree_split": self.split,
            "tree_left": self.left,
            "tree_right": self.right,
            "tree_cell": self.cell,
            "tree_kind": np.array(self.kind),
            **self.view_space.arrays(),
        }

    @classmethod
    def from_arrays(cls, data) -> ViewCells:
        """The cells that :meth:`arrays` wrote."""
        return cls(
            ViewSpace.from_arrays(data),
            data["tree_axis"],
            data["tree_split"],
            data["tree_left"],
            data["tree_right"],
            data["tree_cell"],
            kind=str(data["tree_kind"]),
        )

    # ------------------------------------------------------------------ compression (002 §5.2)
    def compress(self, bits: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each node's stored share of the cells' PVS: what all cells below it see, less its parent's.

        Parameters
        ----------
        bits : (k, w) uint64
            The PVS of each cell as a bit set.

        Returns
        -------
        stored : (n, w) uint64
            The faces stored at each node; the PVS of a cell is the union of what is stored
            on its path from the root (:meth:`expand`).
        """
        n, w = len(self.axis), bits.shape[1]
        full = np.zeros((n, w), np.uint64)
        void = np.ones(n, bool)  # no cell below
        leaves = np.flatnonzero(self.cell >= 0)
        full[leaves] = bits[self.cell[leaves]]
        void[leaves] = False
        for node in range(n - 1, -1, -1):  # children after parents: backwards is bottom-up
            if self.axis[node] < 0:
                continue
            a, b = self.left[node], self.right[node]
            if void[a] and void[b]:
                continue
            void[node] = False
            full[node] = full[b] if void[a] else full[a] if void[b] else full[a] & full[b]
        stored = full.copy()
        inner_kids = self.parent >= 0
        stored[inner_kids] &= ~full[self.parent[inner_kids]]
        stored[void] = 0
        return stored

    def expand(self, stored: np.ndarray) -> np.ndarray:
        """(k, w) uint64: the cells' PVS from :meth:`compress`'s stored sets."""
        n = len(self.axis)
        full = stored.copy()
        for node in range(1, n):  # parents first
            full[node] |= full[self.parent[node]]
        return full[self.cell_node]


class _TreeBuilder:
    """Nodes of a kD-tree added parent first; leaves numbered as cells in the order they come."""

    def __init__(self) -> None:
        self.axis: list[int] = []
        self.split: list[float] = []
        self.left: list[int] = []
        self.right: list[int] = []
        self.leaf_key: list = []

    def root(self) -> int:
        return self._new()

    def _new(self) -> int:
        self.axis.append(-1)
        self.split.append(0.0)
        self.left.append(-1)
        self.right.append(-1)
        self.leaf_key.append(None)
        return len(self.axis) - 1

    def inner(self, node: int, axis: int, at: float) -> tuple[int, int]:
        a, b = self._new(), self._new()
        self.axis[node], self.split[node], self.left[node], self.right[node] = axis, at, a, b
        return a, b

    def leaf(self, node: int, key) -> None:
        self.leaf_key[node] = key

    def cells(self, view_space: ViewSpace, kind: str, numbered: bool = False) -> ViewCells:
        n = len(self.axis)
        cell = np.full(n, -1, np.int32)
        axis = np.array(self.axis, np.int8)
        lo = np.empty((n, 3))
        hi = np.empty((n, 3))
        lo[0], hi[0] = view_space.lo, view_space.hi
        for node in range(n):
            a = axis[node]
            if a >= 0:
                for child, side in ((self.left[node], 1), (self.right[node], 0)):
                    lo[child], hi[child] = lo[node], hi[node]
                    (hi if side else lo)[child, a] = self.split[node]
        leaves = [i for i in range(n) if axis[i] < 0 and self.leaf_key[i] is not None]
        share = view_space.volume_share(lo[leaves], hi[leaves]) if leaves else np.zeros(0)
        alive = [node for node, s in zip(leaves, share) if s > MIN_VOLUME_SHARE]
        if numbered:  # a file's cells keep the order of its boxes
            alive.sort(key=lambda node: self.leaf_key[node])
        cell[alive] = np.arange(len(alive), dtype=np.int32)
        if not alive:
            raise ParameterError("no view cell has any view space in it")
        return ViewCells(
            view_space, axis, np.array(self.split), np.array(self.left), np.array(self.right), cell, kind=kind
        )


def grid_shape(view_space: ViewSpace, n: int) -> tuple[int, int, int]:
    """The grid of exactly ``n`` cells whose cells are closest to cubes over the view space's box.

    Examples
    --------
    >>> grid_shape(ViewSpace(np.zeros(3), np.array([4.0, 1.0, 2.0])), 8)
    (4, 1, 2)
    """
    size = view_space.hi - view_space.lo
    best, shape = np.inf, (n, 1, 1)
    for nx in range(1, n + 1):
        if n % nx:
            continue
        for ny in range(1, n // nx + 1):
            if (n // nx) % ny:
                continue
            nz = n // nx // ny
            side = size / np.array([nx, ny, nz])
            spread = float(np.log(side.max() / side.min()))
            if spread < best - 1e-12:
                best, shape = spread, (nx, ny, nz)
    return shape


def _free_cut(lo: np.ndarray, hi: np.ndarray, nlo: np.ndarray, nhi: np.ndarray) -> tuple[int, float]:
    """An axis-aligned plane inside the node that cuts no box, splitting the boxes; ``(-1, 0)`` if none.

    Of the planes through the boxes' faces, the one with the most even split.
    """
    best = (-1, 0.0, -1)
    for a in range(3):
        for s in np.unique(np.concatenate([lo[:, a], hi[:, a]])):
            if not nlo[a] < s < nhi[a]:
                continue
            cut = (lo[:, a] < s) & (hi[:, a] > s)
            if cut.any():
                continue
            below = int((hi[:, a] <= s).sum())
            even = min(below, len(lo) - below)
            if even > 0 and even > best[2]:
                best = (a, float(s), even)
    return best[0], best[1]


def read_boxes(path: str) -> np.ndarray:
    """(k, 6) the boxes of a JSON file of view cells: a list of ``[x0, y0, z0, x1, y1, z1]``, or ``{"cells": [...]}``.

    Raises
    ------
    ParameterError
        A missing or unreadable file, or not such boxes (the message names the file).
    """
    if not os.path.isfile(path):
        raise ParameterError(f"{path}: view cells file not found")
    if os.path.getsize(path) > MAX_CELLS_FILE:
        raise ParameterError(f"{path}: a view cells file of more than {MAX_CELLS_FILE} bytes")
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError) as exc:
        raise ParameterError(f"{path}: not a JSON file of view cells ({exc})") from None
    if isinstance(data, dict):
        data = data.get("cells", data.get("boxes"))
    try:
        b = np.asarray(data, np.float64)
    except (TypeError, ValueError):
        b = np.zeros((0, 0))
    if b.ndim != 2 or b.shape[1] != 6 or len(b) == 0:
        raise ParameterError(
            f"{path}: expected a list of boxes [x0, y0, z0, x1, y1, z1] or {{'cells': [...]}}"
        )
    if len(b) > MAX_CELLS:
        raise ParameterError(f"{path}: {len(b)} view cells, more than the cap of {MAX_CELLS}")
    if not np.isfinite(b).all() or (b[:, 3:] <= b[:, :3]).any():
        raise ParameterError(f"{path}: every box needs finite corners with x0 < x1, y0 < y1, z0 < z1")
    return b


def parse_cells(text, view_space: ViewSpace) -> ViewCells | tuple[str, int]:
    """The cells that the ``cells`` argument of :func:`meshvis.viewcells.pvs` names.

    Parameters
    ----------
    text : str or ViewCells
        ``grid:NX,NY,NZ``; ``auto`` or ``auto:N`` (built by render cost, returned as
        ``("auto", N)`` for the caller to build); a path to a JSON file of boxes.
    view_space : ViewSpace
        The space the cells partition.

    Returns
    -------
    ViewCells or ("auto", int)

    Raises
    ------
    ParameterError
        A malformed text or file.
    """
    if isinstance(text, ViewCells):
        return text
    s = str(text).strip()
    kind, _, rest = s.partition(":")
    if kind.lower() == "grid":
        try:
            shape = [int(t) for t in rest.split(",")]
        except ValueError:
            shape = []
        if len(shape) != 3:
            raise ParameterError(f"cells {text!r}: expected grid:NX,NY,NZ (three integers)")
        return ViewCells.grid(view_space, shape)
    if kind.lower() == "auto":
        try:
            n = int(rest) if rest else DEFAULT_AUTO_CELLS
        except ValueError:
            raise ParameterError(f"cells {text!r}: expected auto or auto:N (an integer)") from None
        if not 1 <= n <= MAX_CELLS:
            raise ParameterError(f"cells {text!r}: the cell count must be in 1..{MAX_CELLS}")
        return ("auto", n)
    if s.lower().endswith(".json"):
        return ViewCells.from_json(s, view_space)
    raise ParameterError(f"unknown cells {text!r}; use grid:NX,NY,NZ, auto[:N] or a CELLS.json file")
