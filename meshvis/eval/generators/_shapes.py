"""Geometry the generators are built from, and the composition of pieces into one truth.

Grids, boxes, spheres, solids of revolution and cylinders; :func:`_compose` joins closed
pieces into one :class:`GroundTruth`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis.soup import Soup

from .truth import GroundTruth


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
    """Build the triangles of an axis-aligned rectangle ``x_a = value``, normal ``sign * e_a``.

    The grid runs over the coordinate arrays ``ub`` (along axis a+1) and ``vc`` (along axis
    a+2).
    """
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
    """Build a closed, outward box ``[lo, hi]`` with cells of about ``cell``.

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
    """Draw a uniformly random rotation matrix (QR of a Gaussian matrix, sign-fixed)."""
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
    """Build a closed, outward cylinder from ``p0`` to ``p1``.

    It is subdivided to about ``cell`` along its length and across its caps (so that few
    triangles straddle an intersection).
    """
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
    """Compute the signed volume enclosed by a closed triangle mesh (positive when it faces outward).

    Sum over faces of ``v0 . (v1 x v2) / 6`` after centring, which keeps the round-off
    independent of where the model sits.

    Parameters
    ----------
    V : (n, 3) float
        Vertex coordinates.
    F : (m, 3) int
        Vertex indices of every triangle.

    Returns
    -------
    float
        The volume; 0.0 without faces.  Meaningful for a closed, consistently wound mesh.

    Examples
    --------
    >>> import trimesh
    >>> cube = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    >>> round(signed_volume(cube.vertices, cube.faces), 9), round(signed_volume(cube.vertices, cube.faces[:, ::-1]), 9)
    (6.0, -6.0)
    """
    V = np.asarray(V, np.float64)
    if len(F) == 0:
        return 0.0
    V = V - V[np.unique(F)].mean(axis=0)
    t = V[F]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)
