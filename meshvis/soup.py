"""The in-memory model: a triangle soup with per-face attributes.

A :class:`Soup` is what every meshvis algorithm consumes.  It never assumes connectivity:
faces index a vertex array, but two faces that touch may well use different vertex
indices.  Attributes are stored per face (part, material, source polygon) or per face
corner (UVs, colours), so that flipping, subsetting or duplicating faces never needs a
re-weld.

Conventions (DESIGN.md §5): float64 vertices, int64 faces, side 0 of a face is the side its
counter-clockwise normal points to.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

import numpy as np

from meshvis.errors import ModelError


@dataclass(eq=False)
class Material:
    """A material as read from a file, kept opaque so that it can be written back.

    Parameters
    ----------
    name : str
        Material name (``usemtl`` name in OBJ, material name in glTF).
    source : object, optional
        What the reader produced (e.g. the MTL lines and folder, or a trimesh material);
        only the writers interpret it.
    """

    name: str
    source: Any = None


@dataclass(eq=False)
class SourceRecord:
    """What a reader keeps of its file so that the writer of the same format can edit it.

    A repair changes which faces exist and which way they wind; with this record a writer
    rewrites only the face data and copies everything else of the file (DESIGN §5: files
    come back as rich as they went in).

    Parameters
    ----------
    format : str
        The reader's format name (``"glb"``, ``"obj"``, ``"ply"``, ...).
    vertices : (n, 3) float64
        The soup's vertex array as read: a soup whose vertices moved is written anew.
    faces : (m0, 3) int64
        The faces as read, indexed by :attr:`Soup.origin`.
    data : object
        What the format's writer needs (the glTF document, the OBJ lines, the PLY elements).
    """

    format: str
    vertices: np.ndarray
    faces: np.ndarray
    data: Any = None


def _shaped(name: str, value: Any, dtype: type, shape: tuple[int, ...]) -> np.ndarray:
    """``value`` as a contiguous ``dtype`` array of ``shape`` (-1: any length).

    Anything else raises a :class:`ModelError` naming the attribute.
    """
    try:
        return np.ascontiguousarray(value, dtype=dtype).reshape(shape)
    except (TypeError, ValueError, OverflowError):
        shown = (
            "(" + ", ".join("k" if n < 0 else str(n) for n in shape) + ("," if len(shape) == 1 else "") + ")"
        )
        try:
            got = f"shape {np.shape(value)}"
        except ValueError:  # ragged
            got = f"a ragged {type(value).__name__}"
        raise ModelError(f"{name} must be numbers of shape {shown}, got {got}") from None


@dataclass(eq=False)
class Soup:
    """A triangle soup with per-face attributes.

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Vertex coordinates.
    faces : (m, 3) int64 array
        Indices into ``vertices``, counter-clockwise seen from side 0.
    part_id : (m,) int64 array, optional
        Index into ``part_names`` of each face; all 0 by default.
    part_names : list of str, optional
        Name of each part; ``part0``, ``part1``, ... by default.
    source_face : (m,) int64 array, optional
        Index of the polygon of the source file each triangle came from; ``arange(m)`` by
        default.
    material_id : (m,) int64 array, optional
        Index into ``materials`` of each face, or -1; all -1 by default.
    materials : list of Material, optional
        The materials the faces refer to.
    uv : (m, 3, 2) float64 array or None
        Per-corner texture coordinates.
    colors : (m, 3, 4) uint8 array or None
        Per-corner RGBA vertex colours.
    path : str or None
        The file the soup was read from (for messages).
    origin : (m,) int64 array, optional
        Index of each face in the soup as it was read (follows subsets and flips).
    source : SourceRecord or None
        What the reader kept of the file, so that a writer of the same format can edit the
        file instead of rebuilding it.
    up : (3,) float
        The model's up direction: the convention of the format it was read from, as
        :func:`meshvis.load` records it (y for glTF and OBJ, z for STL, PLY, OFF and 3MF);
        z for a model made in memory.  Functions that need an up direction take ``up=None``
        to mean this one.

    Examples
    --------
    >>> import numpy as np
    >>> s = Soup(np.eye(3), np.array([[0, 1, 2]]))
    >>> s.n_faces, round(float(s.areas[0]), 4)
    (1, 0.866)
    """

    vertices: np.ndarray
    faces: np.ndarray
    # None in the constructor means "the default"; __post_init__ always fills an array
    part_id: np.ndarray = None  # type: ignore[assignment]
    part_names: list[str] = field(default_factory=list)
    source_face: np.ndarray = None  # type: ignore[assignment]
    material_id: np.ndarray = None  # type: ignore[assignment]
    materials: list[Material] = field(default_factory=list)
    uv: np.ndarray | None = None
    colors: np.ndarray | None = None
    path: str | None = None
    origin: np.ndarray = None  # type: ignore[assignment]  # filled in __post_init__
    source: SourceRecord | None = None
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        self.vertices = _shaped("vertices", self.vertices, np.float64, (-1, 3))
        self.faces = _shaped("faces", self.faces, np.int64, (-1, 3))
        m = len(self.faces)
        if self.part_id is None:
            self.part_id = np.zeros(m, np.int64)
        self.part_id = _shaped("part_id", self.part_id, np.int64, (m,))
        if m and self.part_id.min() < 0:
            raise ModelError(f"part_id must be at least 0, got {int(self.part_id.min())}")
        if not self.part_names:
            n_parts = int(self.part_id.max()) + 1 if m else 1
            self.part_names = [f"part{i}" for i in range(n_parts)]
        if m and self.part_id.max() >= len(self.part_names):
            raise ModelError(
                f"part_id {int(self.part_id.max())} names no part (there are {len(self.part_names)} part names)"
            )
        if self.source_face is None:
            self.source_face = np.arange(m, dtype=np.int64)
        self.source_face = _shaped("source_face", self.source_face, np.int64, (m,))
        if self.material_id is None:
            self.material_id = np.full(m, -1, np.int64)
        self.material_id = _shaped("material_id", self.material_id, np.int64, (m,))
        if self.origin is None:
            self.origin = np.arange(m, dtype=np.int64)
        self.origin = _shaped("origin", self.origin, np.int64, (m,))
        if self.uv is not None:
            self.uv = _shaped("uv", self.uv, np.float64, (m, 3, 2))
        if self.colors is not None:
            self.colors = _shaped("colors", self.colors, np.uint8, (m, 3, 4))
        up = _shaped("up", self.up, np.float64, (3,))
        norm = float(np.linalg.norm(up))
        if not np.isfinite(norm) or norm == 0:
            raise ModelError(f"the up direction must be a finite non-zero vector, got {up.tolist()}")
        self.up = tuple((up / norm).tolist())

    # ------------------------------------------------------------------ basic sizes
    @property
    def n_faces(self) -> int:
        """Number of faces ``m``."""
        return len(self.faces)

    @property
    def n_vertices(self) -> int:
        """Number of stored vertices ``n`` (used or not)."""
        return len(self.vertices)

    @property
    def n_parts(self) -> int:
        """Number of parts (``len(part_names)``)."""
        return len(self.part_names)

    # ------------------------------------------------------------------ geometry (cached)
    @cached_property
    def triangles(self) -> np.ndarray:
        """(m, 3, 3) float64 corner coordinates."""
        return self.vertices[self.faces]

    @cached_property
    def _cross(self) -> np.ndarray:
        t = self.triangles
        return np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])

    @cached_property
    def areas(self) -> np.ndarray:
        """(m,) triangle areas."""
        return 0.5 * np.linalg.norm(self._cross, axis=1)

    @cached_property
    def normals(self) -> np.ndarray:
        """(m, 3) unit normals of side 0 (counter-clockwise); zero rows for degenerate faces."""
        c = self._cross
        length = np.linalg.norm(c, axis=1)
        out = np.zeros_like(c)
        ok = length > 0
        out[ok] = c[ok] / length[ok, None]
        return out

    @cached_property
    def bounds(self) -> np.ndarray:
        """(2, 3) min and max corner of the bounding box of the *used* vertices."""
        if self.n_faces == 0:
            return np.zeros((2, 3))
        mask = np.zeros(self.n_vertices, bool)
        mask[self.faces.ravel()] = True  # a mask, not np.unique: O(n + m) with no sort
        used = self.vertices[mask]
        return np.stack([used.min(axis=0), used.max(axis=0)])

    @cached_property
    def diagonal(self) -> float:
        """Length of the bounding-box diagonal: the unit of every size-relative epsilon."""
        return float(np.linalg.norm(self.bounds[1] - self.bounds[0]))

    @property
    def total_area(self) -> float:
        """Sum of the face areas."""
        return float(self.areas.sum())

    # ------------------------------------------------------------------ derived soups
    def subset(self, index: np.ndarray) -> Soup:
        """The soup made of the faces ``index``, attributes kept.

        Vertices are not compacted: the new soup shares the vertex array.

        Parameters
        ----------
        index : (m,) bool array or (k,) int array
            A face mask or face indices.

        Returns
        -------
        Soup
            The selected faces, in the order of ``index``.
        """
        index = np.asarray(index)
        if index.dtype == bool:
            index = np.flatnonzero(index)
        return replace(
            self,
            faces=self.faces[index],
            part_id=self.part_id[index],
            source_face=self.source_face[index],
            origin=self.origin[index],
            material_id=self.material_id[index],
            uv=None if self.uv is None else self.uv[index],
            colors=None if self.colors is None else self.colors[index],
        )

    def flipped(self, flip: np.ndarray) -> Soup:
        """The soup with the faces where ``flip`` is True turned over (corners 1 and 2 swapped).

        Parameters
        ----------
        flip : (m,) bool array
            Faces to turn over; per-corner UVs and colours follow their corners.

        Returns
        -------
        Soup
            The same faces in the same order.
        """
        flip = np.asarray(flip, bool).reshape(self.n_faces)
        order = np.where(flip[:, None], [0, 2, 1], [0, 1, 2])
        rows = np.arange(self.n_faces)[:, None]
        return replace(
            self,
            faces=self.faces[rows, order],
            uv=None if self.uv is None else self.uv[rows, order],
            colors=None if self.colors is None else self.colors[rows, order],
            part_id=self.part_id.copy(),
            source_face=self.source_face.copy(),
            origin=self.origin.copy(),
            material_id=self.material_id.copy(),
        )

    def transformed(self, matrix: np.ndarray) -> Soup:
        """The soup with its vertices mapped by a 4x4 homogeneous matrix (attributes kept).

        A transform with negative determinant would turn every face over, so the faces are
        flipped back to keep each side's meaning.

        Parameters
        ----------
        matrix : (4, 4) float array
            Homogeneous transform applied to column vectors.

        Returns
        -------
        Soup
            The transformed copy.
        """
        matrix = np.asarray(matrix, np.float64)
        v = self.vertices @ matrix[:3, :3].T + matrix[:3, 3]
        out = replace(self, vertices=v)
        if np.linalg.det(matrix[:3, :3]) < 0:
            out = out.flipped(np.ones(self.n_faces, bool))
        return out

    def copy(self) -> Soup:
        """A deep copy: every array and list is new."""
        return replace(
            self,
            vertices=self.vertices.copy(),
            faces=self.faces.copy(),
            part_id=self.part_id.copy(),
            source_face=self.source_face.copy(),
            origin=self.origin.copy(),
            material_id=self.material_id.copy(),
            uv=None if self.uv is None else self.uv.copy(),
            colors=None if self.colors is None else self.colors.copy(),
            part_names=list(self.part_names),
            materials=list(self.materials),
        )

    @classmethod
    def concatenate(cls, soups: Sequence[Soup]) -> Soup:
        """One soup from several; part and material indices are shifted, names kept.

        Parameters
        ----------
        soups : sequence of Soup
            At least one soup.

        Returns
        -------
        Soup
            The faces of every soup in order; UVs or colours missing in some of them are
            filled with zeros or opaque white.

        Raises
        ------
        ModelError
            ``soups`` is empty.
        """
        soups = list(soups)
        if not soups:
            raise ModelError("nothing to concatenate")
        v_off = np.cumsum([0] + [s.n_vertices for s in soups[:-1]])
        p_off = np.cumsum([0] + [s.n_parts for s in soups[:-1]])
        m_off = np.cumsum([0] + [len(s.materials) for s in soups[:-1]])
        s_off = np.cumsum([0] + [int(s.source_face.max()) + 1 if s.n_faces else 0 for s in soups[:-1]])
        has_uv = any(s.uv is not None for s in soups)
        has_col = any(s.colors is not None for s in soups)
        return cls(
            vertices=np.concatenate([s.vertices for s in soups]),
            faces=np.concatenate([s.faces + o for s, o in zip(soups, v_off)]),
            part_id=np.concatenate([s.part_id + o for s, o in zip(soups, p_off)]),
            part_names=[n for s in soups for n in s.part_names],
            source_face=np.concatenate([s.source_face + o for s, o in zip(soups, s_off)]),
            material_id=np.concatenate(
                [np.where(s.material_id >= 0, s.material_id + o, -1) for s, o in zip(soups, m_off)]
            ),
            materials=[m for s in soups for m in s.materials],
            uv=np.concatenate([s.uv if s.uv is not None else np.zeros((s.n_faces, 3, 2)) for s in soups])
            if has_uv
            else None,
            colors=np.concatenate(
                [
                    s.colors if s.colors is not None else np.full((s.n_faces, 3, 4), 255, np.uint8)
                    for s in soups
                ]
            )
            if has_col
            else None,
            path=soups[0].path,
            up=soups[0].up,
        )

    def to_trimesh(self):
        """The soup as a trimesh object of the kind it came from.

        A soup made from a ``trimesh.Trimesh`` (:func:`meshvis.as_soup`), or a repair of
        it (``meshvis.orient(mesh).soup``, ``meshvis.remove_interior(mesh).kept``), gives
        a ``Trimesh`` back with the input's visual (UVs, texture, colours, material) and
        vertex normals; one made from a ``trimesh.Scene`` gives a ``Scene`` with its graph,
        transforms and visuals.  Any other soup gives a ``Trimesh`` of the geometry only
        (no processing, no merging).

        Examples
        --------
        >>> import trimesh, meshvis
        >>> box = trimesh.creation.box()
        >>> type(meshvis.orient(box).soup.to_trimesh()).__name__
        'Trimesh'
        """
        rebuild = getattr(self.source.data, "to_trimesh", None) if self.source is not None else None
        if rebuild is not None:
            out = rebuild(self)
            if out is not None:
                return out
        import trimesh

        return trimesh.Trimesh(self.vertices, self.faces, process=False, validate=False)

    def __repr__(self) -> str:
        name = f" {os.path.basename(self.path)!r}" if self.path else ""
        return f"<Soup{name}: {self.n_faces} faces, {self.n_vertices} vertices, {self.n_parts} parts>"


def validate(vertices: np.ndarray, faces: np.ndarray, path: str | None = None) -> None:
    """Raise :class:`ModelError` unless (vertices, faces) is a usable triangle soup.

    Checks shape, emptiness, finite coordinates and index range.

    Parameters
    ----------
    vertices : (n, 3) float array
        Vertex coordinates.
    faces : (m, 3) int array
        Vertex indices of each triangle.
    path : str or None
        The file the arrays came from; it leads the error message.

    Raises
    ------
    ModelError
        The first problem found, in one line.
    """
    try:
        vertices, faces = np.asarray(vertices), np.asarray(faces)
    except (TypeError, ValueError) as exc:  # ragged lists, objects numpy cannot hold
        raise ModelError(f"vertices and faces must be numeric arrays ({exc})", path) from None
    if np.iscomplexobj(vertices):
        raise ModelError("vertex coordinates are complex numbers", path)
    if vertices.dtype.kind not in "iuf":
        raise ModelError(f"vertex coordinates must be numbers, got dtype {vertices.dtype}", path)
    if faces.dtype.kind not in "iuf" and not (faces.size == 0 and faces.dtype.kind == "O"):
        raise ModelError(f"face indices must be integers, got dtype {faces.dtype}", path)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise ModelError(f"vertices must have shape (n, 3), got {vertices.shape}", path)
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise ModelError(f"faces must have shape (m, 3), got {faces.shape}", path)
    if len(faces) == 0:
        raise ModelError("the model has no faces", path)
    if not np.issubdtype(faces.dtype, np.integer):
        if not np.all(np.isfinite(faces)) or np.any(faces != np.round(faces)):
            raise ModelError("face indices are not integers", path)
        if np.abs(faces).max() >= 2**62:
            raise ModelError("face indices are out of range", path)
        faces = faces.astype(np.int64)
    from meshvis import limits

    # one pass for the common case: every vertex finite and within the cap (NaN fails <=;
    # a Python float, so no float32 overflow)
    small = vertices.size == 0 or float(np.abs(vertices).max()) <= limits.MAX_COORDINATE
    bad = None if small else ~np.isfinite(vertices).all(axis=1)
    if bad is not None and bad.any():
        used_bad = np.intersect1d(np.flatnonzero(bad), faces.ravel())
        if len(used_bad):
            what = "vertex used by a face has" if len(used_bad) == 1 else "vertices used by faces have"
            raise ModelError(
                f"{len(used_bad)} {what} NaN or infinite coordinates (first: vertex {int(used_bad[0])})",
                path,
            )
    lo, hi = int(faces.min()), int(faces.max())
    if lo < 0:
        raise ModelError(f"negative vertex index {lo} in the faces", path)
    if hi >= len(vertices):
        raise ModelError(f"vertex index {hi} is out of range (the model has {len(vertices)} vertices)", path)
    if small:  # the used vertices are within the cap too
        return
    mask = np.zeros(len(vertices), bool)
    mask[faces.ravel().astype(np.intp, copy=False)] = True
    used = vertices[mask]
    if float(np.abs(used).max()) > limits.MAX_COORDINATE:  # a Python float: no float32 overflow
        raise ModelError(
            f"coordinates too large to compute with (above {limits.MAX_COORDINATE:g}, the cap of meshvis.limits)",
            path,
        )
