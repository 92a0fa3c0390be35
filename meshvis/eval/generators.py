"""Ground-truth generators: models whose inside/outside answer is known by construction.

Every generator returns a :class:`GroundTruth`: a :class:`~meshvis.soup.Soup` plus, per face,

- ``outside`` (m, 2) bool: whether side 0 (the counter-clockwise front, DESIGN.md §5) and
  side 1 are *outside*: reachable from far away along a path that crosses no geometry,
  where hairline cracks and small holes (defects) do not count as paths but real openings
  do (DESIGN.md §4, "Semantics");
- ``layer`` (m,) int under *layer semantics*: 1 for every face with an outside side,
  2 for what becomes visible once layer 1 is removed, and so on (appendix H, §5);
- ``outward`` (m,) bool: True where the current front side is the side that faces outward
  with respect to the face's own layer (the orientation truth; for two-sided sheets the
  side facing the larger open region);
- ``two_sided`` (m,) bool: sheets whose both sides are meant to be seen (a cup wall, a cave);
- ``ambiguous`` (m,) bool: faces whose answer depends on a convention (faces lying on
  another solid's surface, faces straddling an intersection curve); evaluations should
  leave them out.

Truth arrays stay consistent through :func:`soupify`, which turns any truth into a messy
triangle soup (unwelded, randomly flipped, shuffled, duplicated, with small holes) and
records for every output face which input face it came from and whether it was flipped.

All geometry is float64 and deterministic for a given ``seed`` (randomness only from
``numpy.random.default_rng(seed)``).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from meshvis.errors import ModelError, ParameterError
from meshvis.geometry.adjacency import WELD_TOL, components, edges, face_adjacency, weld
from meshvis.soup import Soup

__all__ = [
    "GroundTruth",
    "nested_shells",
    "house",
    "cracked_box",
    "box_with_opening",
    "cup",
    "terrain",
    "overlapping_solids",
    "sphere_pair",
    "skin_and_ribcage",
    "assembly",
    "soupify",
    "from_closed_mesh",
    "is_closed",
    "signed_volume",
    "GENERATORS",
]


# ====================================================================== the truth container
@dataclass(eq=False)
class GroundTruth:
    """A model together with its known inside/outside, layer and orientation answer.

    Parameters
    ----------
    soup : Soup
        The geometry, with meaningful ``part_names`` / ``part_id``.
    outside : (m, 2) bool
        ``outside[f, s]``: side ``s`` of face ``f`` is outside (side 0 = front).
    layer : (m,) int
        Layer index under layer semantics (1 = outer shell).
    outward : (m,) bool
        The front side is the side facing outward with respect to the face's layer.
    two_sided : (m,) bool, optional
        Sheets meant to be seen from both sides; default all False.
    ambiguous : (m,) bool, optional
        Faces to leave out of error measures; default all False.
    hints : dict, optional
        ``inside_points`` / ``outside_points``: (k, 3) float64 user hints the model needs.
    name, notes : str
        What the model is and what it tests.
    origin_face : (m,) int, optional
        Index of the face in the generator's original model (changed by :func:`soupify`);
        default ``arange(m)``.
    flipped : (m,) bool, optional
        The face is turned over with respect to ``origin_face``; default all False.
    """

    soup: Soup
    outside: np.ndarray
    layer: np.ndarray
    outward: np.ndarray
    two_sided: np.ndarray | None = None
    ambiguous: np.ndarray | None = None
    hints: dict = field(default_factory=dict)
    name: str = ""
    notes: str = ""
    origin_face: np.ndarray | None = None
    flipped: np.ndarray | None = None

    def __post_init__(self) -> None:
        m = self.soup.n_faces
        self.outside = np.array(np.broadcast_to(np.asarray(self.outside, bool), (m, 2)))
        self.layer = np.array(np.broadcast_to(np.asarray(self.layer, np.int64), (m,)))
        self.outward = np.array(np.broadcast_to(np.asarray(self.outward, bool), (m,)))
        self.two_sided = (
            np.zeros(m, bool)
            if self.two_sided is None
            else np.array(np.broadcast_to(np.asarray(self.two_sided, bool), (m,)))
        )
        self.ambiguous = (
            np.zeros(m, bool)
            if self.ambiguous is None
            else np.array(np.broadcast_to(np.asarray(self.ambiguous, bool), (m,)))
        )
        self.origin_face = (
            np.arange(m, dtype=np.int64)
            if self.origin_face is None
            else np.asarray(self.origin_face, np.int64).reshape(m)
        )
        self.flipped = (
            np.zeros(m, bool) if self.flipped is None else np.asarray(self.flipped, bool).reshape(m)
        )
        self.hints = {k: np.asarray(v, np.float64).reshape(-1, 3) for k, v in self.hints.items()}

    # ------------------------------------------------------------------ views
    @property
    def n_faces(self) -> int:
        return self.soup.n_faces

    @property
    def hidden(self) -> np.ndarray:
        """(m,) bool: no side of the face is outside."""
        return ~self.outside.any(axis=1)

    @property
    def visible(self) -> np.ndarray:
        """(m,) bool: at least one side of the face is outside."""
        return self.outside.any(axis=1)

    @property
    def n_layers(self) -> int:
        return int(self.layer.max()) if self.n_faces else 0

    def check(self) -> list[str]:
        """The list of broken invariants (empty when the truth is self-consistent).

        Invariants: layers start at 1; layer 1 holds exactly the faces with an outside
        side; a visible one-sided face has exactly one outside side, the outward one; a
        visible two-sided face has both sides outside.
        """
        problems = []
        if self.n_faces and self.layer.min() < 1:
            problems.append("layer below 1")
        if np.any((self.layer == 1) != self.visible):
            problems.append("layer 1 is not the set of faces with an outside side")
        one = self.visible & ~self.two_sided
        if np.any(self.outside[one, 0] != self.outward[one]) or np.any(
            self.outside[one, 1] == self.outward[one]
        ):
            problems.append("a visible one-sided face's outside side is not its outward side")
        two = self.visible & self.two_sided
        if np.any(~self.outside[two].all(axis=1)):
            problems.append("a visible two-sided face has an inside side")
        return problems

    # ------------------------------------------------------------------ derived truths
    def subset(self, index: np.ndarray) -> GroundTruth:
        """The truth of the faces ``index`` (mask or integer array; repeats allowed)."""
        index = np.asarray(index)
        if index.dtype == bool:
            index = np.flatnonzero(index)
        return replace(
            self,
            soup=self.soup.subset(index),
            outside=self.outside[index],
            layer=self.layer[index],
            outward=self.outward[index],
            two_sided=self.two_sided[index],
            ambiguous=self.ambiguous[index],
            origin_face=self.origin_face[index],
            flipped=self.flipped[index],
            hints=dict(self.hints),
        )

    def flip_faces(self, flip: np.ndarray) -> GroundTruth:
        """The truth with the faces where ``flip`` is True turned over.

        Turning a face over swaps its sides, so the two ``outside`` columns swap and
        ``outward`` toggles.
        """
        flip = np.asarray(flip, bool).reshape(self.n_faces)
        return replace(
            self,
            soup=self.soup.flipped(flip),
            outside=np.where(flip[:, None], self.outside[:, ::-1], self.outside),
            outward=self.outward ^ flip,
            flipped=self.flipped ^ flip,
            two_sided=self.two_sided.copy(),
            ambiguous=self.ambiguous.copy(),
            layer=self.layer.copy(),
            origin_face=self.origin_face.copy(),
            hints=dict(self.hints),
        )

    def oriented(self) -> Soup:
        """The soup with every face turned so that its front faces outward (the ideal output
        of normal orientation)."""
        return self.soup.flipped(~self.outward)

    @classmethod
    def concatenate(cls, truths: Sequence[GroundTruth], name: str = "", notes: str = "") -> GroundTruth:
        """One truth from several (parts are kept apart, hints are merged)."""
        truths = list(truths)
        offsets = np.cumsum([0] + [t.n_faces for t in truths[:-1]])
        hints: dict[str, list] = {}
        for t in truths:
            for k, v in t.hints.items():
                hints.setdefault(k, []).append(v)
        return cls(
            soup=Soup.concatenate([t.soup for t in truths]),
            outside=np.concatenate([t.outside for t in truths]),
            layer=np.concatenate([t.layer for t in truths]),
            outward=np.concatenate([t.outward for t in truths]),
            two_sided=np.concatenate([t.two_sided for t in truths]),
            ambiguous=np.concatenate([t.ambiguous for t in truths]),
            hints={k: np.concatenate(v) for k, v in hints.items()},
            name=name or "+".join(t.name for t in truths),
            notes=notes,
            origin_face=np.concatenate([t.origin_face + o for t, o in zip(truths, offsets)]),
            flipped=np.concatenate([t.flipped for t in truths]),
        )

    # ------------------------------------------------------------------ files
    def save_arrays(self, path: str | os.PathLike) -> None:
        """Write the truth arrays (not the geometry) to a compressed ``.npz`` file.

        The arrays are indexed like the soup's faces; pair the file with the model file
        written from the same soup (faces in the same order).
        """
        arrays = dict(
            outside=self.outside,
            layer=self.layer,
            outward=self.outward,
            two_sided=self.two_sided,
            ambiguous=self.ambiguous,
            origin_face=self.origin_face,
            flipped=self.flipped,
            part_id=self.soup.part_id,
            part_names=np.array(self.soup.part_names),
            name=np.array(self.name),
            notes=np.array(self.notes),
        )
        for k, v in self.hints.items():
            arrays[f"hint_{k}"] = v
        _write_npz(os.fspath(path), arrays)

    @classmethod
    def load_arrays(cls, path: str | os.PathLike, soup: Soup) -> GroundTruth:
        """Pair truth arrays written by :meth:`save_arrays` with a soup loaded from the model file."""
        with np.load(os.fspath(path), allow_pickle=False) as z:
            if len(z["layer"]) != soup.n_faces:
                raise ModelError(
                    f"truth has {len(z['layer'])} faces but the model has {soup.n_faces}", os.fspath(path)
                )
            hints = {k[5:]: z[k] for k in z.files if k.startswith("hint_")}
            return cls(
                soup=soup,
                outside=z["outside"],
                layer=z["layer"],
                outward=z["outward"],
                two_sided=z["two_sided"],
                ambiguous=z["ambiguous"],
                hints=hints,
                name=str(z["name"]),
                notes=str(z["notes"]),
                origin_face=z["origin_face"],
                flipped=z["flipped"],
            )

    def __repr__(self) -> str:
        return (
            f"<GroundTruth {self.name!r}: {self.n_faces} faces, {int(self.visible.sum())} visible, "
            f"{self.n_layers} layers, {self.soup.n_parts} parts>"
        )


def _write_npz(path: str, arrays: dict[str, np.ndarray]) -> None:
    """A compressed ``.npz`` that is identical byte for byte for identical arrays.

    ``numpy.savez_compressed`` stamps every member with the current time; here every
    member gets a fixed date.  Written to a temporary file, then renamed.
    """
    import io
    import zipfile

    tmp = f"{path}.{os.getpid()}.tmp"
    try:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
            for key in sorted(arrays):
                buf = io.BytesIO()
                np.lib.format.write_array(buf, np.asarray(arrays[key]), allow_pickle=False)
                info = zipfile.ZipInfo(f"{key}.npy", date_time=(1980, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = 0o644 << 16
                zf.writestr(info, buf.getvalue())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


# ====================================================================== geometry helpers
@dataclass
class _Piece:
    """One building block of a generated model: geometry plus its (broadcastable) truth."""

    vertices: np.ndarray
    faces: np.ndarray
    part: str
    outside: Any = (True, False)
    layer: Any = 1
    outward: Any = True
    two_sided: Any = False
    ambiguous: Any = False


def _compose(pieces: Sequence[_Piece], name: str, notes: str, hints: dict | None = None) -> GroundTruth:
    """Concatenate pieces into one soup; parts named in order of first appearance."""
    names: list[str] = []
    for p in pieces:
        if p.part not in names:
            names.append(p.part)
    v_off = np.cumsum([0] + [len(p.vertices) for p in pieces[:-1]])
    faces = np.concatenate([np.asarray(p.faces, np.int64) + o for p, o in zip(pieces, v_off)])
    sizes = [len(p.faces) for p in pieces]

    def per_face(attr: str, width: int | None = None, dtype=bool) -> np.ndarray:
        out = []
        for p, m in zip(pieces, sizes):
            shape = (m,) if width is None else (m, width)
            out.append(np.broadcast_to(np.asarray(getattr(p, attr), dtype), shape))
        return np.concatenate(out)

    soup = Soup(
        vertices=np.concatenate([np.asarray(p.vertices, np.float64) for p in pieces]),
        faces=faces,
        part_id=np.repeat([names.index(p.part) for p in pieces], sizes),
        part_names=names,
    )
    return GroundTruth(
        soup=soup,
        outside=per_face("outside", 2),
        layer=per_face("layer", dtype=np.int64),
        outward=per_face("outward"),
        two_sided=per_face("two_sided"),
        ambiguous=per_face("ambiguous"),
        hints=hints or {},
        name=name,
        notes=notes,
    )


def _grid_tris(P: np.ndarray, keep: np.ndarray | None = None) -> np.ndarray:
    """Triangles of a (nu+1, nv+1, 3) point grid, two per cell; normals along du x dv.

    ``keep`` (nu, nv) bool drops cells (openings).
    """
    p00, p10, p11, p01 = P[:-1, :-1], P[1:, :-1], P[1:, 1:], P[:-1, 1:]
    t = np.stack([np.stack([p00, p10, p11], -2), np.stack([p00, p11, p01], -2)], 2)  # (nu, nv, 2, 3, 3)
    if keep is not None:
        t = t[keep]
    return t.reshape(-1, 3, 3)


def _weld(tris: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of triangles whose corners coincide exactly (bit-identical)."""
    tris = np.asarray(tris, np.float64).reshape(-1, 3, 3)
    V, inv = np.unique(tris.reshape(-1, 3), axis=0, return_inverse=True)
    return V, inv.reshape(-1, 3).astype(np.int64)


def _reverse(tris: np.ndarray) -> np.ndarray:
    return tris[:, [0, 2, 1]]


def _axis_patch(
    a: int, value: float, sign: int, ub: np.ndarray, vc: np.ndarray, keep: np.ndarray | None = None
) -> np.ndarray:
    """Triangles of an axis-aligned rectangle ``x_a = value`` over the coordinate arrays
    ``ub`` (along axis a+1) and ``vc`` (along axis a+2), normal ``sign * e_a``."""
    b, c = (a + 1) % 3, (a + 2) % 3
    P = np.empty((len(ub), len(vc), 3))
    P[..., a] = value
    P[..., b] = ub[:, None]
    P[..., c] = vc[None, :]
    t = _grid_tris(P, keep)  # e_b x e_c = e_a
    return t if sign > 0 else _reverse(t)


def _counts(lo: np.ndarray, hi: np.ndarray, cell: float) -> np.ndarray:
    return np.maximum(1, np.round((np.asarray(hi) - np.asarray(lo)) / cell)).astype(int)


def _box_tris(lo, hi, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """A closed, outward box ``[lo, hi]`` with cells of about ``cell``.

    Returns the triangles (k, 3, 3) and the box side of each, ``2 * axis + (0 for the low
    side, 1 for the high side)``.  Shared edges use the same coordinate arrays, so the
    corners of adjacent sides coincide exactly.
    """
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    n = _counts(lo, hi, cell)
    axes = [np.linspace(lo[a], hi[a], n[a] + 1) for a in range(3)]
    tris, side = [], []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        for s, value in ((0, lo[a]), (1, hi[a])):
            t = _axis_patch(a, value, 1 if s else -1, axes[b], axes[c])
            tris.append(t)
            side.append(np.full(len(t), 2 * a + s))
    return np.concatenate(tris), np.concatenate(side)


def _box(lo, hi, cell: float) -> tuple[np.ndarray, np.ndarray]:
    V, F = _weld(_box_tris(lo, hi, cell)[0])
    return V, F


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random rotation matrix (QR of a Gaussian matrix, sign-fixed)."""
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def _icosphere(
    subdivisions: int, radius: float = 1.0, center=(0.0, 0.0, 0.0), rotation: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=int(subdivisions), radius=1.0)
    V = np.asarray(m.vertices, np.float64)
    if rotation is not None:
        V = V @ rotation.T
    return V * radius + np.asarray(center, np.float64), np.asarray(m.faces, np.int64)


def _revolve(r: np.ndarray, z: np.ndarray, sections: int) -> np.ndarray:
    """Triangles of the surface swept by the profile ``(r, z)`` around the z axis.

    Profile points with ``r == 0`` collapse to one point on the axis; the degenerate
    triangles they create are dropped.  The seam closes exactly (angle 0 is reused).
    """
    phi = np.linspace(0, 2 * np.pi, sections + 1)
    cos, sin = np.cos(phi), np.sin(phi)
    cos[-1], sin[-1] = 1.0, 0.0
    P = np.stack(
        [r[:, None] * cos[None], r[:, None] * sin[None], np.broadcast_to(z[:, None], (len(r), len(phi)))], -1
    )
    P[r == 0, :, :2] = 0.0
    tris = _grid_tris(P)
    area = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
    return tris[area > 0]


def _cylinder(p0, p1, radius: float, sections: int, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """A closed, outward cylinder from ``p0`` to ``p1``, subdivided to about ``cell`` along
    its length and across its caps (so that few triangles straddle an intersection)."""
    p0, p1 = np.asarray(p0, np.float64), np.asarray(p1, np.float64)
    axis = p1 - p0
    length = float(np.linalg.norm(axis))
    nl = max(1, int(np.ceil(length / cell)))
    nr = max(1, int(np.ceil(radius / cell)))
    ring = np.linspace(0, radius, nr + 1)
    r = np.concatenate([ring, np.full(nl - 1, radius), ring[::-1]])
    z = np.concatenate([np.zeros(nr + 1), np.linspace(0, length, nl + 1)[1:-1], np.full(nr + 1, length)])
    V, F = _weld(_revolve(r, z, sections))
    F = _orient_from(V, F, (0.0, 0.0, 0.5 * length))
    # frame whose z is the axis
    w = axis / length
    u = np.cross(w, [1.0, 0.0, 0.0] if abs(w[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    return V @ np.stack([u, v, w]) + p0, F


def _face_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    t = V[F]
    return np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])


def _orient_from(V: np.ndarray, F: np.ndarray, center) -> np.ndarray:
    """Turn the faces of a shape that is star-shaped around ``center`` so they face away from it."""
    c = V[F].mean(axis=1)
    bad = np.einsum("ij,ij->i", _face_normals(V, F), c - np.asarray(center)) < 0
    F = F.copy()
    F[bad] = F[bad][:, [0, 2, 1]]
    return F


def signed_volume(V: np.ndarray, F: np.ndarray) -> float:
    """Signed volume enclosed by a closed triangle mesh (positive when it faces outward).

    Sum over faces of ``v0 . (v1 x v2) / 6`` after centring, which keeps the round-off
    independent of where the model sits.
    """
    V = np.asarray(V, np.float64)
    if len(F) == 0:
        return 0.0
    V = V - V[np.unique(F)].mean(axis=0)
    t = V[F]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)


# ====================================================================== closedness, components
def _welded(soup: Soup, tol: float = 0.0) -> np.ndarray:
    """(m, 3) welded corner ids (:func:`meshvis.geometry.adjacency.weld`; exact duplicates by default)."""
    return weld(soup.vertices, soup.faces, tol)[1]


def is_closed(soup: Soup, oriented: bool = True, tol: float = WELD_TOL) -> bool:
    """Whether the surface is closed once corners closer than ``tol`` x diagonal are merged.

    Closed means every edge is used an even number of times; *oriented* closed (the
    default) means every edge is crossed as often in one direction as in the other, i.e.
    the surface bounds a volume with consistent winding.  Non-manifold edges are allowed.
    """
    if soup.n_faces == 0:
        return False
    table = edges(_welded(soup, tol))
    if oriented:
        forward = np.bincount(table.half_edge, weights=table.half_forward, minlength=len(table.count))
        return bool(np.all(2 * forward == table.count))
    return bool(np.all(table.count % 2 == 0))


def _components(soup: Soup, tol: float = WELD_TOL) -> np.ndarray:
    """(m,) label of the edge-connected component (body) of every face."""
    pairs = face_adjacency(edges(_welded(soup, tol)), manifold_only=False)
    return components(soup.n_faces, pairs)[1]


def _outward_bodies(soup: Soup) -> tuple[np.ndarray, np.ndarray]:
    """Body (edge-connected component) of every face, and whether the face's front faces
    out of its body: the body's signed volume (sum of ``v0 . (v1 x v2)``) is not negative.
    Meaningful for closed, consistently wound bodies."""
    labels = _components(soup)
    t = soup.triangles - soup.bounds.mean(axis=0)
    vol = np.bincount(labels, np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])))
    return labels, (vol >= 0)[labels]


def _containment(
    pieces: Sequence[tuple[np.ndarray, np.ndarray]], eps: float, fast: bool = False
) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """How deep inside the closed pieces each face lies, and which faces are ambiguous.

    For every face of piece ``p`` the generalised winding number of all pieces (its own
    included) is evaluated at points pushed ``eps`` off the centroid to both sides and at
    the corners (pulled 2 % toward the centroid, pushed to the front).  The rounded front
    value is the depth: the number of pieces around the face, plus the folds of its own
    piece when that piece crosses itself (a face inside its own piece's volume cannot be
    seen).  The back value of a clean face is one more than the front.  A face is
    ambiguous when the two sides do not differ by one (it lies on another piece's surface)
    or a corner disagrees with the centroid (it straddles an intersection curve).
    """
    import igl

    wn = igl.fast_winding_number if fast else igl.winding_number
    # winding numbers add up over closed pieces: evaluate the whole model once
    offsets = np.cumsum([0] + [len(V) for V, _ in pieces[:-1]])
    Vall = np.ascontiguousarray(np.concatenate([V for V, _ in pieces]), np.float64)
    Fall = np.ascontiguousarray(
        np.concatenate([np.asarray(F, np.int64) + o for (_, F), o in zip(pieces, offsets)])
    )
    t = Vall[Fall]
    c = t.mean(axis=1)
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    corners = (c[:, None] + 0.98 * (t - c[:, None]) + eps * n[:, None]).reshape(-1, 3)
    w = np.asarray(wn(Vall, Fall, np.concatenate([c + eps * n, c - eps * n, corners])))
    m = len(Fall)
    front, back, corner = w[:m], w[m : 2 * m], w[2 * m :].reshape(m, 3)
    d = np.maximum(np.rint(front), 0).astype(np.int64)
    amb = (np.rint(back) - np.rint(front) != 1) | np.any(np.rint(corner) != np.rint(front)[:, None], axis=1)
    amb |= np.abs(front - np.rint(front)) > 0.25
    split = np.cumsum([len(F) for _, F in pieces])[:-1]
    depth, ambiguous = np.split(d, split), np.split(amb, split)
    return depth, ambiguous


def _closed_pieces_truth(
    pieces: Sequence[tuple[np.ndarray, np.ndarray]],
    parts: Sequence[str],
    name: str,
    notes: str,
    fast: bool = False,
) -> GroundTruth:
    """Truth of a set of closed, outward pieces that may overlap or nest.

    A face inside ``d`` other pieces is hidden when ``d > 0``; its layer is ``d + 1``
    (nesting depth; for overlapping pieces this is the depth of the overlap region).
    Visible faces are one-sided with the front outside.  Query points are pushed off
    the faces by 1e-6 of the bounding-box diagonal.
    """
    allv = np.concatenate([V[np.unique(F)] for V, F in pieces])
    eps = 1e-6 * float(np.linalg.norm(allv.max(axis=0) - allv.min(axis=0)))
    depth, amb = _containment(pieces, eps, fast)
    out = []
    for (V, F), part, d, a in zip(pieces, parts, depth, amb):
        vis = d == 0
        out.append(
            _Piece(
                V,
                F,
                part,
                outside=np.stack([vis, np.zeros_like(vis)], 1),
                layer=d + 1,
                outward=True,
                ambiguous=a,
            )
        )
    return _compose(out, name, notes)


# ====================================================================== 1. nested shells
def nested_shells(
    n: int = 3, kind: str = "sphere", subdivisions: int = 3, cell: float = 0.1, seed: int = 0
) -> GroundTruth:
    """Concentric closed shells that do not touch: the textbook layer test.

    Parameters
    ----------
    n : int
        Number of shells; radii (or half sizes) shrink linearly from 1 to 0.35.
    kind : {"sphere", "box", "mixed"}
        Icospheres, axis-aligned boxes of half size ``r * (1, 0.8, 0.6)``, or alternating
        spheres and cubes, each inscribed in the previous one, sizes halving per shell.
    subdivisions : int
        Icosphere subdivision level (20 * 4**subdivisions faces per sphere).
    cell : float
        Box cell size relative to the outer shell's half size.
    seed : int
        Seeds the random rotation of every sphere (so tessellations do not line up).

    Returns
    -------
    GroundTruth
        Shell ``i`` (1 = outermost) is layer ``i``; only shell 1 has an outside side (its
        front); every face is built facing away from the common centre, so ``outward`` is
        all True (layer semantics; the "cavity" reading would turn shells 2.. inward).
    """
    if n < 1:
        raise ParameterError(f"nested_shells needs n >= 1, got {n}")
    if kind not in ("sphere", "box", "mixed"):
        raise ParameterError(f"unknown shell kind {kind!r} (sphere, box, mixed)")
    rng = np.random.default_rng(seed)
    if kind == "mixed":
        # a cube inscribed (95 %) in a sphere, a sphere of half the radius inside the cube, ...
        scales = 0.5 ** np.arange(n)
        half = np.full(3, 0.95 / np.sqrt(3.0))
    else:
        scales = np.linspace(1.0, 0.35, n) if n > 1 else np.array([1.0])
        half = np.array([1.0, 0.8, 0.6])
    pieces = []
    for i, r in enumerate(scales):
        rot = _random_rotation(rng)
        use_box = kind == "box" or (kind == "mixed" and i % 2 == 1)
        if use_box:
            V, F = _box(-r * half, r * half, cell * r)
        else:
            V, F = _icosphere(subdivisions, r, rotation=rot)
        pieces.append(_Piece(V, F, f"shell_{i + 1}", outside=(i == 0, False), layer=i + 1))
    return _compose(
        pieces,
        "nested_shells",
        f"{n} concentric closed {kind} shells; layer i = shell i, all faces outward; "
        "tests layers and inside removal (everything but shell 1 is hidden)",
    )


# ====================================================================== 2. house
def house(
    rooms: tuple[int, int] = (3, 2),
    floors: int = 2,
    room_size: tuple[float, float, float] = (4.0, 3.5, 2.8),
    cell: float = 0.5,
    furniture: int = 2,
    roof: bool = True,
    partition: bool = True,
    seed: int = 0,
) -> GroundTruth:
    """A closed house of stacked room boxes with furniture: hidden interiors and coplanar walls.

    Every room is a closed box facing out of the room, with its own tessellation (cell size
    jittered per room), so neighbouring rooms share wall planes with coplanar, differently
    tessellated, oppositely facing duplicates.  A gable roof (a closed prism) sits on the
    top floor, its bottom coplanar with the top ceilings.  Each room holds up to four
    furniture boxes standing on its floor; the first room holds a cabinet with a safe
    floating inside it; one room has a free-standing single-sheet partition.

    Parameters
    ----------
    rooms : (int, int)
        Rooms along x and y; every room must touch the exterior (it lies on the grid's
        border or on the ground floor), else :class:`ParameterError`.
    floors : int
        Storeys.
    room_size : (float, float, float)
        Nominal room width, depth, height; widths and depths vary by +-20 % per column/row.
    cell : float
        Nominal triangle size.
    furniture : int
        Furniture boxes per room (0..4).
    roof, partition : bool
        Add the roof prism / the partition sheet.
    seed : int

    Returns
    -------
    GroundTruth
        What is outside: the side of a face reachable from far away without crossing
        geometry.  The house is closed, so only the exterior side of the hull faces (the
        room walls on the border, the ground floors, the roof slopes and gables) is
        outside: layer 1, front outside.  Everything else is hidden.  Layer 2 is what is
        seen once the hull is removed: walls and floors between rooms and the ceilings
        under the roof (their room side, the back, faces outward: ``outward`` False), the
        roof's bottom (its attic side, the back), furniture, the partition (two-sided) and
        the cabinet.  The safe is layer 3.  Faces lying on another solid (furniture
        bottoms, upper-floor triangles partly or wholly under furniture) are ``ambiguous``.
    """
    nx, ny = int(rooms[0]), int(rooms[1])
    floors = int(floors)
    if nx < 1 or ny < 1 or floors < 1:
        raise ParameterError(
            f"house needs at least one room and one floor, got rooms={rooms}, floors={floors}"
        )
    if nx > 2 and ny > 2 and floors > 1:
        raise ParameterError(
            f"rooms={rooms} with {floors} floors has rooms that do not touch the exterior "
            "(their layer would depend on coplanar duplicates); use at most 2 rooms along x or y"
        )
    if not 0 <= furniture <= 4:
        raise ParameterError(f"furniture must be 0..4 per room, got {furniture}")
    rng = np.random.default_rng(seed)
    W, D, H = (float(s) for s in room_size)
    xs = np.concatenate([[0.0], np.cumsum(W * rng.uniform(0.8, 1.2, nx))])
    ys = np.concatenate([[0.0], np.cumsum(D * rng.uniform(0.8, 1.2, ny))])
    zs = H * np.arange(floors + 1, dtype=np.float64)
    pieces: list[_Piece] = []
    furn_pieces: list[_Piece] = []
    for k in range(floors):
        for j in range(ny):
            for i in range(nx):
                lo = np.array([xs[i], ys[j], zs[k]])
                hi = np.array([xs[i + 1], ys[j + 1], zs[k + 1]])
                tris, side = _box_tris(lo, hi, cell * rng.uniform(0.8, 1.25))
                # which of the six box sides have a neighbour (room, or roof above)
                shared = np.array([i > 0, i < nx - 1, j > 0, j < ny - 1, k > 0, k < floors - 1 or roof])
                inner = shared[side]
                amb = np.zeros(len(tris), bool)
                # furniture: one box per chosen quadrant of the floor
                slots = rng.permutation(4)[:furniture]
                for s_i, slot in enumerate(slots):
                    qx, qy = slot % 2, slot // 2
                    s_lo = lo[:2] + np.array([qx, qy]) * (hi[:2] - lo[:2]) / 2
                    s_size = (hi[:2] - lo[:2]) / 2
                    margin = 0.08 * s_size
                    size = rng.uniform(0.35, 0.8, 2) * (s_size - 2 * margin)
                    pos = s_lo + margin + rng.uniform(0, 1, 2) * (s_size - 2 * margin - size)
                    f_lo = np.array([pos[0], pos[1], lo[2]])
                    f_hi = np.array([pos[0] + size[0], pos[1] + size[1], lo[2] + rng.uniform(0.25, 0.7) * H])
                    f_tris, f_side = _box_tris(f_lo, f_hi, 0.5 * cell)
                    first = (i, j, k) == (0, 0, 0) and s_i == 0
                    fname = "cabinet" if first else f"furniture_{i}{j}{k}_{s_i}"
                    fV, fF = _weld(f_tris)
                    # the bottom stands on the floor: coplanar contact, a matter of convention
                    f_amb = f_side == 4  # _weld keeps the triangle order
                    furn_pieces.append(
                        _Piece(fV, fF, fname, outside=(False, False), layer=2, ambiguous=f_amb)
                    )
                    if first:
                        c, e = (f_lo + f_hi) / 2, (f_hi - f_lo) / 2
                        sV, sF = _box(c - 0.45 * e, c + 0.45 * e, 0.25 * cell)
                        furn_pieces.append(_Piece(sV, sF, "safe", outside=(False, False), layer=3))
                    if k > 0:
                        # hidden floor triangles (partly) under the furniture are partly
                        # sandwiched: which side faces outward is a matter of convention
                        tmin, tmax = tris[..., :2].min(axis=1), tris[..., :2].max(axis=1)
                        under = np.all((tmax > f_lo[:2]) & (tmin < f_hi[:2]), axis=1)
                        amb |= under & (side == 4)
                V, F = _weld(tris)
                vis = ~inner
                pieces.append(
                    _Piece(
                        V,
                        F,
                        f"room_{i}{j}{k}",
                        outside=np.stack([vis, np.zeros_like(vis)], 1),
                        layer=np.where(inner, 2, 1),
                        outward=vis,
                        ambiguous=amb,
                    )
                )
                if partition and (i, j, k) == (nx - 1, ny - 1, floors - 1):
                    cy = 0.5 * (lo[1] + hi[1])
                    ub = np.linspace(lo[2], lo[2] + 0.6 * H, max(2, int(round(0.6 * H / cell)) + 1))
                    vc = np.linspace(
                        lo[0] + 0.2 * (hi[0] - lo[0]),
                        hi[0] - 0.2 * (hi[0] - lo[0]),
                        max(2, int(round(0.6 * (hi[0] - lo[0]) / cell)) + 1),
                    )
                    pV, pF = _weld(_axis_patch(1, cy, 1, ub, vc))
                    furn_pieces.append(
                        _Piece(pV, pF, "partition", outside=(False, False), layer=2, two_sided=True)
                    )
    if roof:
        Z0, Y, X = zs[-1], ys[-1], xs[-1]
        section = np.array([[0.0, Z0], [Y, Z0], [Y / 2, Z0 + 0.45 * Y]])
        rV, rF = _prism_x(xs[0], X, section, cell)
        bottom = np.all(rV[rF][..., 2] == Z0, axis=1)
        pieces.append(
            _Piece(
                rV,
                rF,
                "roof",
                outside=np.stack([~bottom, np.zeros_like(bottom)], 1),
                layer=np.where(bottom, 2, 1),
                outward=~bottom,
            )
        )
    return _compose(
        pieces + furn_pieces,
        "house",
        "closed house of room boxes with coplanar duplicate walls, roof, furniture, a cabinet "
        "with a safe inside (layer 3) and a two-sided partition; tests inside removal "
        "(only the hull is outside), coplanar handling and layers",
    )


def _prism_x(x0: float, x1: float, section: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """A closed, outward prism along x over the triangular cross-section ``section`` (3, 2) in (y, z).

    The cross-section is a barycentric lattice of order ``k``; its boundary points are reused
    by the side strips so that all corners coincide exactly.
    """
    A, B, C = (np.asarray(p, np.float64) for p in section)
    k = max(1, int(round(max(np.linalg.norm(B - A), np.linalg.norm(C - B), np.linalg.norm(A - C)) / cell)))
    i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
    L = A + (i[..., None] / k) * (B - A) + (j[..., None] / k) * (C - A)  # (k+1, k+1, 2), valid where i+j<=k
    loop = np.concatenate(
        [
            L[np.arange(k + 1), 0],  # A -> B
            L[k - np.arange(1, k + 1), np.arange(1, k + 1)],  # B -> C
            L[0, k - np.arange(1, k + 1)],  # C -> A (ends at A)
        ]
    )
    xs = np.linspace(x0, x1, max(1, int(round((x1 - x0) / cell))) + 1)
    P = np.empty((len(xs), len(loop), 3))
    P[..., 0] = xs[:, None]
    P[..., 1:] = loop[None]
    tris = [_grid_tris(P)]
    # end caps: lattice triangles at x0 and x1
    ii, jj = np.nonzero(i + j <= k - 1)
    up = np.stack([L[ii, jj], L[ii + 1, jj], L[ii, jj + 1]], 1)
    ii, jj = np.nonzero(i + j <= k - 2)
    down = np.stack([L[ii + 1, jj], L[ii + 1, jj + 1], L[ii, jj + 1]], 1)
    cap = np.concatenate([up, down])
    for x in (x0, x1):
        t = np.empty(cap.shape[:2] + (3,))
        t[..., 0] = x
        t[..., 1:] = cap
        tris.append(t)
    V, F = _weld(np.concatenate(tris))
    centre = np.array([(x0 + x1) / 2, *((A + B + C) / 3)])
    return V, _orient_from(V, F, centre)


# ====================================================================== 3./4. box sheets
_SIDES = ["-x", "+x", "-y", "+y", "-z", "+z"]


def _box_sheet(
    lo,
    hi,
    cell: float,
    gap: float = 0.0,
    splits: dict | None = None,
    opening: tuple[str, float] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A single-sheet box surface facing outward, optionally cracked or opened.

    Parameters
    ----------
    gap : float
        Every side is shrunk in its plane so that the edges of neighbouring sides are
        ``gap`` apart, leaving slits along the 12 box edges.
    splits : dict side -> (direction 0|1, fraction)
        The side is cut in two across the given in-plane direction, the halves ``gap`` apart.
    opening : (side, fraction)
        Cells of that side within a centred rectangle of ``fraction`` of its size are removed.

    Returns
    -------
    V, F, side : welded geometry and the box side (0..5, see ``_SIDES``) of every face
    """
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    splits = splits or {}
    n = _counts(lo, hi, cell)
    tris, side = [], []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        for s, value in ((0, lo[a]), (1, hi[a])):
            sid = 2 * a + s
            # in-plane ranges of the side's pieces, as (b-range, c-range) pairs
            # pulled back by gap / sqrt(2): the edges of two perpendicular sides are then
            # exactly ``gap`` apart
            d = gap / np.sqrt(2.0)
            rb = (lo[b] + d, hi[b] - d)
            rc = (lo[c] + d, hi[c] - d)
            parts = [(rb, rc)]
            if _SIDES[sid] in splits:
                d, frac = splits[_SIDES[sid]]
                r = rb if d == 0 else rc
                cut = r[0] + frac * (r[1] - r[0])
                halves = [(r[0], cut - gap / 2), (cut + gap / 2, r[1])]
                parts = [(h, rc) if d == 0 else (rb, h) for h in halves]
            for pb, pc in parts:
                if gap == 0 and len(parts) == 1:
                    ub, vc = np.linspace(lo[b], hi[b], n[b] + 1), np.linspace(lo[c], hi[c], n[c] + 1)
                else:
                    ub = np.linspace(pb[0], pb[1], max(1, int(round((pb[1] - pb[0]) / cell))) + 1)
                    vc = np.linspace(pc[0], pc[1], max(1, int(round((pc[1] - pc[0]) / cell))) + 1)
                keep = None
                if opening is not None and opening[0] == _SIDES[sid]:
                    f = opening[1]
                    mb, mc = 0.5 * (ub[:-1] + ub[1:]), 0.5 * (vc[:-1] + vc[1:])
                    cb, cc = 0.5 * (lo[b] + hi[b]), 0.5 * (lo[c] + hi[c])
                    in_b = np.abs(mb - cb) < 0.5 * f * (hi[b] - lo[b])
                    in_c = np.abs(mc - cc) < 0.5 * f * (hi[c] - lo[c])
                    keep = ~(in_b[:, None] & in_c[None, :])
                t = _axis_patch(a, value, 1 if s else -1, ub, vc, keep)
                tris.append(t)
                side.append(np.full(len(t), sid))
    V, F = _weld(np.concatenate(tris))
    return V, F, np.concatenate(side)


def cracked_box(
    size: tuple[float, float, float] = (2.0, 1.5, 1.0),
    cell: float = 0.05,
    crack_width: float = 1e-3,
    face_cracks: int = 3,
    inner: bool = True,
    seed: int = 0,
) -> GroundTruth:
    """A single-sheet closed box with hairline cracks, and a small box inside it.

    The six sides are separate sheets pulled back from the box edges, leaving slits of
    about ``crack_width`` along all 12 edges; ``face_cracks`` randomly chosen sides are
    also cut in two across a random line, the halves ``crack_width`` apart.  No edge of a
    side meets an edge of another.

    Parameters
    ----------
    size : (float, float, float)
        Box extents, centred on the origin.
    cell : float
        Triangle size.
    crack_width : float
        Width of the slits as a fraction of the box diagonal.
    face_cracks : int
        Sides (0..6) with an extra crack across them.
    inner : bool
        Put a closed box (30 % of the size) at the centre.
    seed : int

    Returns
    -------
    GroundTruth
        Cracks are defects: the interior stays inside.  Box sheet: layer 1, front outside.
        Inner box: hidden, layer 2, outward.
    """
    rng = np.random.default_rng(seed)
    half = 0.5 * np.asarray(size, np.float64)
    gap = float(crack_width) * float(np.linalg.norm(2 * half))
    chosen = rng.permutation(6)[: int(np.clip(face_cracks, 0, 6))]
    splits = {_SIDES[s]: (int(rng.integers(2)), float(rng.uniform(0.3, 0.7))) for s in chosen}
    V, F, _ = _box_sheet(-half, half, cell, gap=gap, splits=splits)
    pieces = [_Piece(V, F, "box", outside=(True, False), layer=1)]
    if inner:
        iV, iF = _box(-0.3 * half, 0.3 * half, cell)
        pieces.append(_Piece(iV, iF, "inner_box", outside=(False, False), layer=2))
    return _compose(
        pieces,
        "cracked_box",
        f"single-sheet box with slits of {crack_width:g} x diagonal along all edges and across "
        f"{len(chosen)} sides, a closed box inside; cracks must not let the outside in",
    )


def box_with_opening(
    size: tuple[float, float, float] = (2.0, 1.5, 1.0),
    cell: float = 0.05,
    opening: float = 0.6,
    side: str = "-y",
    crack_width: float = 0.0,
    inner: bool = True,
    seed: int = 0,
) -> GroundTruth:
    """A single-sheet box with a large opening in one side: a cave (appendix H, Fig. 7).

    Parameters
    ----------
    size, cell : as :func:`cracked_box`.
    opening : float
        The opening is a centred rectangle of ``opening`` times the side's width and height
        (cells whose centre lies in it are removed).
    side : {"-x", "+x", "-y", "+y", "-z", "+z"}
        The side with the opening.
    crack_width : float
        Optional slits along the edges as well (fraction of the diagonal).
    inner : bool
        Put a closed box (30 % of the size) at the centre, seen through the opening.
    seed : int
        Unused (the model is fully determined); kept for a uniform signature.

    Returns
    -------
    GroundTruth
        Everything inside is reachable through the opening: both sides of every sheet face
        are outside (``two_sided``, layer 1, front facing away from the box centre), and
        the inner box is visible (layer 1, front outside).  For small openings the truth
        stays "reachable"; where a method puts the line between crack and opening is its
        own parameter.
    """
    if side not in _SIDES:
        raise ParameterError(f"side must be one of {_SIDES}, got {side!r}")
    if not 0 < opening < 1:
        raise ParameterError(f"opening must be in (0, 1), got {opening}")
    half = 0.5 * np.asarray(size, np.float64)
    gap = float(crack_width) * float(np.linalg.norm(2 * half))
    V, F, _ = _box_sheet(-half, half, cell, gap=gap, opening=(side, float(opening)))
    pieces = [_Piece(V, F, "cave", outside=(True, True), layer=1, two_sided=True)]
    if inner:
        iV, iF = _box(-0.3 * half, 0.3 * half, cell)
        pieces.append(_Piece(iV, iF, "inner_box", outside=(True, False), layer=1))
    return _compose(
        pieces,
        "box_with_opening",
        f"single-sheet box with a {opening:g} x {opening:g} opening in side {side}; the inside is "
        "reachable, so both sides of the walls and the inner box are outside",
    )


# ====================================================================== 5. cup
def cup(
    radius: float = 1.0,
    height: float = 1.2,
    flare: float = 0.15,
    sections: int = 64,
    bottom_rings: int = 8,
    wall_rings: int = 16,
) -> GroundTruth:
    """A cup modelled as a single sheet (open top): every face is two-sided.

    A surface of revolution about z: a flat bottom disc of ``bottom_rings`` rings and a
    wall flaring from ``radius`` to ``radius * (1 + flare)`` over ``height``.

    Returns
    -------
    GroundTruth
        Both sides of every face are outside, layer 1, ``two_sided``; the front faces the
        larger open region (away from the axis and downward), so ``outward`` is True.
    """
    r = np.concatenate(
        [
            np.linspace(0, radius, bottom_rings + 1),
            radius * (1 + flare * np.linspace(0, 1, wall_rings + 1)[1:]),
        ]
    )
    z = np.concatenate([np.zeros(bottom_rings + 1), height * np.linspace(0, 1, wall_rings + 1)[1:]])
    V, F = _weld(_revolve(r, z, sections))
    F = _orient_from(V, F, (0.0, 0.0, 0.5 * height))
    return _compose(
        [_Piece(V, F, "cup", outside=(True, True), layer=1, two_sided=True)],
        "cup",
        "single-sheet cup with an open top: both sides of every face are outside",
    )


# ====================================================================== 6. terrain
def terrain(
    n: int = 64, size: float = 1.0, amplitude: float = 0.15, bumps: int = 12, seed: int = 0
) -> GroundTruth:
    """A heightfield sheet: open, with no inherent inside; the user names the sides.

    Heights are a sum of ``bumps`` random Gaussian hills and pits plus a gentle slope.

    Parameters
    ----------
    n : int
        Grid cells per side (``2 n**2`` faces).
    size, amplitude : float
        Extent in x and y; height scale.
    bumps : int
    seed : int

    Returns
    -------
    GroundTruth
        Hints: one inside point below the terrain's centre, one outside point above it.
        Given them, the top side (the front) is outside and the bottom inside; layer 1.
    """
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, size, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    c = rng.uniform(0, size, (bumps, 2))
    s = rng.uniform(0.05, 0.25, bumps) * size
    a = rng.uniform(-1, 1, bumps) * amplitude
    d2 = (X[..., None] - c[:, 0]) ** 2 + (Y[..., None] - c[:, 1]) ** 2
    Z = (a * np.exp(-d2 / (2 * s**2))).sum(-1) + 0.2 * amplitude * (X + 0.5 * Y) / size
    P = np.stack([X, Y, Z], -1)
    V, F = _weld(_grid_tris(P))  # normal e_x x e_y = +z: front up
    mid = np.array([size / 2, size / 2])
    hints = {
        "inside_points": [[*mid, Z.min() - 0.25 * size]],
        "outside_points": [[*mid, Z.max() + 0.25 * size]],
    }
    return _compose(
        [_Piece(V, F, "terrain", outside=(True, False), layer=1)],
        "terrain",
        "open heightfield; with the hints the top side is outside, the bottom inside",
        hints,
    )


# ====================================================================== 7. overlapping solids
def overlapping_solids(subdivisions: int = 4, cell: float = 0.1, seed: int = 0) -> GroundTruth:
    """Two closed solids that interpenetrate: a sphere and a box pushed half into it.

    Parameters
    ----------
    subdivisions : int
        Icosphere level of the unit sphere.
    cell : float
        Box triangle size.
    seed : int
        Jitters the box position and rotates the sphere's tessellation.

    Returns
    -------
    GroundTruth
        Truth from the generalised winding number (libigl) of the *other* solid at points
        just off each face: faces inside the other solid are hidden (layer 2), the rest are
        one-sided with the front outside (layer 1).  Faces that straddle the intersection
        curve are ``ambiguous``.
    """
    rng = np.random.default_rng(seed)
    sV, sF = _icosphere(subdivisions, 1.0, rotation=_random_rotation(rng))
    shift = rng.uniform(-0.05, 0.05, 3)
    bV, bF = _box(np.array([0.25, -0.7, -0.6]) + shift, np.array([2.0, 0.7, 0.6]) + shift, cell)
    return _closed_pieces_truth(
        [(sV, sF), (bV, bF)],
        ["sphere", "box"],
        "overlapping_solids",
        "a sphere and a box that interpenetrate; faces inside the other solid (winding number 1) are hidden",
    )


# ====================================================================== 8. sphere pair
def sphere_pair(
    subdivisions: int = 4, crack: int = 6, inner_radius: float = 0.5, seed: int = 0
) -> GroundTruth:
    """An outer sphere with a small hole of ``crack`` missing faces, and an inner sphere.

    The hole is the ``crack`` faces nearest to a random vertex (its one-ring for 6 on a
    regular vertex).

    Returns
    -------
    GroundTruth
        The hole is a defect (DESIGN.md §4: small cracks must not let the outside in):
        outer sphere layer 1, front outside; inner sphere hidden, layer 2, outward.
    """
    rng = np.random.default_rng(seed)
    V, F = _icosphere(subdivisions, 1.0, rotation=_random_rotation(rng))
    v = V[rng.integers(len(V))]
    dist = np.linalg.norm(V[F].mean(axis=1) - v, axis=1)
    keep = np.ones(len(F), bool)
    keep[np.argsort(dist, kind="stable")[: int(crack)]] = False
    iV, iF = _icosphere(max(subdivisions - 1, 1), inner_radius, rotation=_random_rotation(rng))
    pieces = [
        _Piece(V, F[keep], "outer_sphere", outside=(True, False), layer=1),
        _Piece(iV, iF, "inner_sphere", outside=(False, False), layer=2),
    ]
    return _compose(
        pieces,
        "sphere_pair",
        f"outer sphere missing {int(crack)} faces around one vertex, inner sphere hidden; "
        "tests that a small hole does not let the outside in",
    )


# ====================================================================== 9. skin and ribcage
def _load_mesh(path: Path) -> Soup:
    if not path.exists():
        raise FileNotFoundError(f"{path}: real test model not found")
    import trimesh

    try:
        from meshvis.io import load  # the project's reader
    except ImportError:  # pragma: no cover - io is part of the package
        load = None
    if load is not None:
        try:
            return load(path)
        except ModelError as exc:
            first: Exception = exc
    else:
        first = None
    try:  # plain trimesh read, vertex order and count untouched
        m = trimesh.load(os.fspath(path), process=False, force="mesh")
    except Exception:
        if first is not None:
            raise first from None
        raise
    return Soup(np.asarray(m.vertices, np.float64), np.asarray(m.faces, np.int64), path=os.fspath(path))


def skin_and_ribcage(folder: str | os.PathLike) -> GroundTruth:
    """The dm_control dog skin with its rib cage inside: real hidden geometry.

    Parameters
    ----------
    folder : str or os.PathLike
        Where ``dm_control__SKINbody.stl`` and ``dm_control__BONERibcage.stl`` are.

    Returns
    -------
    GroundTruth
        The truth of :func:`from_closed_mesh` for skin and bones together: the skin is
        layer 1, a bone inside the skin is layer 2, and the parts of a bone that sink into
        another bone lie one layer deeper (the rib cage's bones interpenetrate).  Where two
        bones touch, the file holds the same triangle twice, once per bone: such coincident
        copies are ``ambiguous`` — an STL has no connectivity, so which bone owns which
        copy (and so which way it faces) cannot be observed from the geometry; so are faces
        that cross another face.

    Raises
    ------
    FileNotFoundError
        When either file is missing.
    """
    from meshvis.geometry.adjacency import duplicate_faces, weld

    folder = Path(folder)
    skin = _load_mesh(folder / "dm_control__SKINbody.stl")
    ribs = _load_mesh(folder / "dm_control__BONERibcage.stl")
    both = Soup.concatenate([skin, ribs])
    both = Soup(both.vertices, both.faces, part_id=both.part_id, part_names=["skin", "ribcage"])
    t = from_closed_mesh(both, name="skin_and_ribcage")
    first = duplicate_faces(weld(both.vertices, both.faces)[1])
    t.ambiguous |= np.bincount(first, minlength=len(first))[first] > 1  # every member of a copy group
    t.notes = "real closed skin with the rib cage inside: inside removal and layers on real data"
    return t


# ====================================================================== 11. assembly
def assembly(sections: int = 24, cell: float = 0.2) -> GroundTruth:
    """An engine-like assembly of about 30 named closed parts of very different sizes.

    Block, head, valve cover and oil pan (large boxes); pistons inside the block (fully
    hidden); spark plugs and bolts half sunk into the valve cover; pulleys, alternator,
    water pump and a six-bladed fan in front (the fan partly hides the pulleys from the
    front); flywheel and starter at the back; exhaust and intake manifolds of pipes;
    air filter, dipstick and engine mounts.  Every part is made of closed, outward pieces
    that may interpenetrate or touch.

    Parameters
    ----------
    sections : int
        Segments around every cylinder.
    cell : float
        Triangle size of the large boxes.

    Returns
    -------
    GroundTruth
        Per face, from the winding number of all other pieces: inside ``d`` other pieces
        -> hidden, layer ``d + 1``; otherwise one-sided with the front outside.  Faces on
        another piece's surface (touching parts) or straddling an intersection are
        ``ambiguous``.  ``soup.part_names`` holds the part names.
    """
    import trimesh

    pieces: list[tuple[np.ndarray, np.ndarray]] = []
    parts: list[str] = []

    def add(mesh_or_vf, part: str) -> None:
        if isinstance(mesh_or_vf, tuple):
            V, F = mesh_or_vf
        else:
            V, F = np.asarray(mesh_or_vf.vertices, np.float64), np.asarray(mesh_or_vf.faces, np.int64)
        pieces.append((V, F))
        parts.append(part)

    def box(lo, hi, part, c=None):
        add(_box(lo, hi, c or cell), part)

    def cyl(p0, p1, r, part, sec=None):
        add(_cylinder(p0, p1, r, sec or sections, min(cell, max(2 * r, 0.1))), part)

    # large structure (x along the crankshaft, z up).  Parts that meet sink 0.02 into each
    # other instead of touching, so that few faces lie exactly on another part's surface.
    box((-2.0, -1.1, 0.0), (2.0, 1.1, 2.0), "engine_block")
    box((-1.95, -1.0, 1.98), (1.95, 1.0, 2.6), "cylinder_head")
    box((-1.8, -0.7, 2.58), (1.8, 0.7, 3.0), "valve_cover")
    box((-1.8, -0.9, -0.6), (1.8, 0.9, 0.02), "oil_pan")
    xs = np.array([-1.35, -0.45, 0.45, 1.35])
    for n, x in enumerate(xs, 1):
        cyl((x, 0, 0.9), (x, 0, 1.5), 0.36, f"piston_{n}")  # inside the block
        cyl((x, 0.35, 2.85), (x, 0.35, 3.35), 0.07, f"spark_plug_{n}")  # sunk into the cover
    bolt_x = np.array([-1.6, -0.55, 0.55, 1.6])
    for n, (x, y) in enumerate([(x, y) for y in (-0.55, 0.55) for x in bolt_x], 1):
        cyl((x, y, 2.9), (x, y, 3.12), 0.06, f"bolt_{n}", sec=6)  # hexagonal heads
    # front accessories (front = -x)
    box((-2.1, -0.9, 0.2), (-1.98, 0.9, 1.9), "timing_cover", c=0.2)
    cyl((-2.05, 0.0, 0.5), (-2.35, 0.0, 0.5), 0.55, "crankshaft_pulley")
    cyl((-1.3, 1.45, 1.7), (0.2, 1.45, 1.7), 0.38, "alternator")
    cyl((-1.2, 1.45, 1.7), (-2.35, 1.45, 1.7), 0.2, "alternator_pulley")
    box((-2.2, -0.75, 1.25), (-2.05, -0.25, 1.75), "water_pump", c=0.1)
    cyl((-2.15, -0.5, 1.5), (-2.4, -0.5, 1.5), 0.3, "water_pump_pulley")
    # fan on the water pump axis: hub plus six blades whose roots sink into the hub
    fan_x = -2.75
    cyl((-2.35, -0.5, 1.5), (fan_x - 0.1, -0.5, 1.5), 0.15, "fan")
    for b in range(6):
        T = trimesh.transformations.rotation_matrix(2 * np.pi * b / 6 + 0.3, [1, 0, 0])
        T[:3, 3] = [fan_x, -0.5, 1.5]
        T = T @ trimesh.transformations.translation_matrix((0, 0, 0.47))
        bV, bF = _box((-0.02, -0.1, -0.375), (0.02, 0.1, 0.375), 0.075)
        add((bV @ T[:3, :3].T + T[:3, 3], bF), "fan")
    # back
    cyl((1.98, 0.0, 0.5), (2.15, 0.0, 0.5), 1.05, "flywheel", sec=2 * sections)
    cyl((1.3, -1.3, 0.3), (2.3, -1.3, 0.3), 0.25, "starter_motor")
    # exhaust manifold (-y side): four runners into a collector, then the exhaust pipe
    for x in xs:
        cyl((x, -0.95, 2.3), (x, -1.6, 2.3), 0.12, "exhaust_manifold")
    cyl((-1.6, -1.6, 2.3), (1.7, -1.6, 2.3), 0.16, "exhaust_manifold")
    cyl((1.6, -1.6, 2.3), (1.6, -1.6, -0.9), 0.14, "exhaust_pipe")
    # intake (+y side): runners into a plenum box, air filter on top
    for x in xs:
        cyl((x, 0.95, 2.3), (x, 1.6, 2.3), 0.1, "intake_manifold")
    box((-1.7, 1.55, 2.1), (1.7, 2.0, 2.9), "intake_manifold", c=0.2)
    cyl((0.0, 1.8, 2.85), (0.0, 1.8, 3.25), 0.45, "air_filter")
    cyl((1.0, 1.0, 0.5), (1.0, 1.5, 3.1), 0.03, "dipstick", sec=8)
    box((-0.8, 1.08, 0.4), (0.8, 1.4, 0.8), "engine_mount_left", c=0.2)
    box((-0.8, -1.4, 0.4), (0.8, -1.08, 0.8), "engine_mount_right", c=0.2)
    return _closed_pieces_truth(
        pieces,
        parts,
        "assembly",
        "engine-like assembly of named closed parts of very different sizes; pistons "
        "hidden in the block, bolts and plugs half sunk; for labeling and inside removal",
    )


# ====================================================================== 10. soupify, closed meshes
def soupify(
    truth: GroundTruth,
    flip: float = 0.3,
    unweld: bool = True,
    shuffle: bool = True,
    duplicate: float = 0.0,
    holes: int = 0,
    seed: int = 0,
) -> GroundTruth:
    """Turn a truth into a messy triangle soup whose truth is still known.

    Steps, in this order: punch ``holes`` small holes (a random face and every face sharing
    a corner position with it is deleted); duplicate a fraction ``duplicate`` of the faces
    (exact copies, coplanar with their original); turn over ``round(flip * m)`` random
    faces; shuffle the face order and rotate every face's corners cyclically; give every
    face its own three vertices.

    Truth bookkeeping: a turned face swaps its ``outside`` columns and toggles
    ``outward`` and ``flipped``; ``origin_face`` maps every output face to the input
    face it copies.  Small holes are defects and change no truth; duplicates share their
    original's truth.

    Parameters
    ----------
    truth : GroundTruth
    flip, duplicate : float in [0, 1]
    unweld, shuffle : bool
    holes : int
    seed : int

    Returns
    -------
    GroundTruth
    """
    for nm, v in (("flip", flip), ("duplicate", duplicate)):
        if not 0.0 <= v <= 1.0:
            raise ParameterError(f"{nm} must be in [0, 1], got {v}")
    if holes < 0:
        raise ParameterError(f"holes must be >= 0, got {holes}")
    rng = np.random.default_rng(seed)
    t = truth
    m = t.n_faces
    if holes and m:
        keys = _welded(t.soup)
        seeds = rng.choice(m, size=min(int(holes), m), replace=False)
        marked = np.zeros(int(keys.max()) + 1, bool)
        marked[keys[seeds].ravel()] = True
        t = t.subset(~marked[keys].any(axis=1))
    if duplicate:
        k = int(round(duplicate * t.n_faces))
        extra = rng.choice(t.n_faces, size=k, replace=False)
        t = t.subset(np.concatenate([np.arange(t.n_faces), np.sort(extra)]))
    if flip:
        k = int(round(flip * t.n_faces))
        mask = np.zeros(t.n_faces, bool)
        mask[rng.choice(t.n_faces, size=k, replace=False)] = True
        t = t.flip_faces(mask)
    if shuffle:
        t = t.subset(rng.permutation(t.n_faces))
        shift = rng.integers(0, 3, t.n_faces)
        order = (np.arange(3)[None, :] + shift[:, None]) % 3  # cyclic: keeps the winding
        rows = np.arange(t.n_faces)[:, None]
        s = t.soup
        t = replace(
            t,
            soup=replace(
                s,
                faces=s.faces[rows, order],
                uv=None if s.uv is None else s.uv[rows, order],
                colors=None if s.colors is None else s.colors[rows, order],
            ),
        )
    if unweld:
        s = t.soup
        t = replace(
            t,
            soup=replace(
                s,
                vertices=s.triangles.reshape(-1, 3).copy(),
                faces=np.arange(3 * s.n_faces, dtype=np.int64).reshape(-1, 3),
            ),
        )
    bits = (
        [f"flip={flip:g}"]
        + (["unwelded"] if unweld else [])
        + (["shuffled"] if shuffle else [])
        + ([f"duplicate={duplicate:g}"] if duplicate else [])
        + ([f"holes={holes}"] if holes else [])
    )
    return replace(t, name=f"{truth.name}_soup", notes=f"{truth.notes} | soupified: {', '.join(bits)}")


#: fold-overs sharper than this (degrees) count as one surface stored twice
FOLD_DEGREES = 2.0


def _folded_onto_neighbour(soup: Soup, degrees: float = FOLD_DEGREES, max_fan: int = 8) -> np.ndarray:
    """(m,) bool: faces folded onto a neighbour across a shared edge.

    Two triangles ``(a, b, c)`` and ``(a, b, d)`` on one welded edge lie on each other when
    their planes agree within ``degrees`` and ``c``, ``d`` lie on the same side of the line
    ``ab``: the surface is there twice, as where a (slightly skew) quad is stored once per
    triangulation, or a triangle once per touching body.  Which copy faces which way is then
    not observable.  Every pair of faces on an edge is tested (edges with more than
    ``max_fan`` faces are skipped).  On the rib cage this finds 6,840 of the 6,872 faces
    of its coincident copies and 32 faces of slightly skew quads stored with both diagonals
    (planes 0.8-1.3 degrees apart); on cow, spot and the dog skin, nothing.
    """
    from meshvis.geometry.adjacency import edges

    tol = 1.0 - np.cos(np.radians(degrees))
    welded = _welded(soup, 0.0)
    table = edges(welded)
    start = np.searchsorted(table.half_edge, np.arange(len(table.count)))
    pairs = [
        np.stack([start[e] + i, start[e] + j], axis=1)
        for i in range(max_fan)
        for j in range(i + 1, max_fan)
        for e in [np.flatnonzero((table.count > j) & (table.count <= max_fan))]
    ]
    h = np.concatenate(pairs) if pairs else np.zeros((0, 2), np.int64)
    f, g = table.half_face[h[:, 0]], table.half_face[h[:, 1]]
    n = soup.normals
    keep = np.abs(np.einsum("ij,ij->i", n[f], n[g])) > 1 - tol
    f, g, ends = f[keep], g[keep], table.vertices[table.half_edge[h[keep, 0]]]

    def corner(face: np.ndarray, which: np.ndarray) -> np.ndarray:
        return soup.triangles[face, which.argmax(axis=1)]

    kf, kg = welded[f], welded[g]
    pa = corner(f, kf == ends[:, :1])
    pb = corner(f, kf == ends[:, 1:])
    cf = corner(f, (kf != ends[:, :1]) & (kf != ends[:, 1:]))  # the corners off the edge
    cg = corner(g, (kg != ends[:, :1]) & (kg != ends[:, 1:]))
    side_f = np.einsum("ij,ij->i", np.cross(pb - pa, cf - pa), n[f])
    side_g = np.einsum("ij,ij->i", np.cross(pb - pa, cg - pa), n[f])
    overlap = side_f * side_g > 0
    out = np.zeros(soup.n_faces, bool)
    out[f[overlap]] = True
    out[g[overlap]] = True
    return out


def from_closed_mesh(model: Any, name: str | None = None) -> GroundTruth:
    """The truth of a closed real model: every body outward and outside, nested ones hidden.

    The model must be closed with consistent winding (every directed edge matched by its
    reverse once coincident corners are merged), else :class:`ModelError`.  Bodies are
    the edge-connected components; each is outward where its signed volume is positive.
    A face whose outward side has winding number ``d`` (of all bodies, its own included)
    is hidden with layer ``d + 1`` when ``d > 0``: it lies inside another body, or inside
    a fold of its own body when the surface crosses itself (``cow.obj`` does).  Faces that
    cross another face, straddle an intersection curve or touch another body's surface
    are ambiguous (see :func:`_containment`).  For a clean single body this is simply:
    all faces layer 1, outside on the outward side.

    Parameters
    ----------
    model : Soup, trimesh, (V, F) or path
    name : str, optional

    Returns
    -------
    GroundTruth
    """
    from meshvis.io import as_soup

    soup = as_soup(model)
    if not is_closed(soup, oriented=True):
        raise ModelError("the model is not closed with consistent winding; its truth is not known", soup.path)
    labels, outward = _outward_bodies(soup)
    flip = ~outward
    # make every body outward, find nesting, then restore the input winding
    fixed = soup.flipped(flip)
    order = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[order], np.arange(labels.max() + 2))
    bodies = []
    for b in range(labels.max() + 1):
        used, f = np.unique(fixed.faces[order[bounds[b] : bounds[b + 1]]], return_inverse=True)
        bodies.append((fixed.vertices[used], f.reshape(-1, 3)))
    depth, amb = _containment(bodies, 1e-6 * soup.diagonal, fast=True)
    d = np.empty(soup.n_faces, np.int64)
    a = np.empty(soup.n_faces, bool)
    d[order] = np.concatenate(depth)
    a[order] = np.concatenate(amb)
    # a face that crosses another is partly in front of and partly behind it: no single answer
    from meshvis.geometry.intersect import intersection_flags

    a |= intersection_flags(soup.vertices, soup.faces)["intersects"]
    a |= _folded_onto_neighbour(soup)
    vis = d == 0
    outside = np.stack([vis & outward, vis & ~outward], 1)
    nm = name or (os.path.splitext(os.path.basename(soup.path))[0] if soup.path else "closed_mesh")
    return GroundTruth(
        soup=soup,
        outside=outside,
        layer=d + 1,
        outward=outward,
        ambiguous=a,
        name=nm,
        notes="closed model: every body outward, nested bodies hidden",
    )


#: name -> generator, for benchmarks and the models script
GENERATORS = {
    "nested_shells": nested_shells,
    "house": house,
    "cracked_box": cracked_box,
    "box_with_opening": box_with_opening,
    "cup": cup,
    "terrain": terrain,
    "overlapping_solids": overlapping_solids,
    "sphere_pair": sphere_pair,
    "assembly": assembly,
}
