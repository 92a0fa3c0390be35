"""Stressed models of the stability benchmark: transformed, degenerate and tiny geometry.

Similarity transforms, slivers, zero-area, duplicate and near-coplanar faces, perturbed
corners, and tiny pieces beside huge ones.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from meshvis.soup import Soup

#: edge lengths of the tiny cubes of the weights case, fractions of the model's diagonal
TINY_SIZES = (1e-6, 1e-5, 1e-4, 1e-3, 1e-2)


def _with(soup: Soup, vertices: np.ndarray, faces: np.ndarray, parent: np.ndarray) -> Soup:
    """Make a soup of new geometry whose faces inherit the attributes of their ``parent`` faces."""
    return Soup(
        vertices,
        faces,
        part_id=soup.part_id[parent],
        part_names=list(soup.part_names),
        source_face=soup.source_face[parent],
        material_id=soup.material_id[parent],
        materials=list(soup.materials),
        path=soup.path,
    )


def similarity(soup: Soup, kind: str, amount: float = 1.0, seed: int = 0) -> Soup:
    """Apply a similarity transform to the soup.

    Parameters
    ----------
    soup : Soup
        The model.
    kind : {"scale", "translate", "rotate"}
        Uniform scale about the origin by the factor ``amount``; translation by ``amount`` ×
        diagonal along (1, 2, 3)/|(1, 2, 3)|; or a random rotation drawn from ``seed``.
    amount : float
        The scale factor, or the translation in diagonals (unused by "rotate").
    seed : int
        Seed of the rotation.

    Returns
    -------
    Soup
        The transformed soup, faces and attributes unchanged.

    Raises
    ------
    ValueError
        An unknown ``kind``.
    """
    m = np.eye(4)
    if kind == "scale":
        m[:3, :3] *= amount
    elif kind == "translate":
        d = np.array([1.0, 2.0, 3.0])
        m[:3, 3] = amount * soup.diagonal * d / np.linalg.norm(d)
    elif kind == "rotate":
        q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
        q = q * np.sign(np.diag(r))
        if np.linalg.det(q) < 0:
            q[:, 0] = -q[:, 0]
        m[:3, :3] = q
    else:
        raise ValueError(f"unknown similarity {kind!r}")
    return soup.transformed(m)


def split_into_slivers(
    soup: Soup, fraction: float = 0.25, t_min: float = 1e-6, t_max: float = 1e-2, seed: int = 0
) -> tuple[Soup, np.ndarray]:
    """Split a ``fraction`` of the faces in two at a point very close to a corner.

    Face (a, b, c) becomes (a, p, c) and (p, b, c) with ``p = a + t (b − a)``, ``t``
    log-uniform in ``[t_min, t_max]`` (the first split uses ``t_min`` exactly): the first
    piece is a sliver of aspect ratio about ``1/t``.  Both pieces keep the winding.  The
    split point also leaves a T-junction on the neighbour across edge ab.

    Parameters
    ----------
    soup : Soup
        The model.
    fraction : float
        Probability of every face to be split (at least one face is).
    t_min : float
        Smallest split position along ab, a fraction of the edge.
    t_max : float
        Largest split position along ab.
    seed : int
        Seeds the choice of faces and the positions.

    Returns
    -------
    soup : Soup
        The new soup: the unsplit faces first, then the slivers, then their partners.
    parent : (k,) int64
        Per new face, the index of the face it came from.
    """
    rng = np.random.default_rng(seed)
    m = soup.n_faces
    idx = np.flatnonzero(rng.random(m) < fraction)
    if len(idx) == 0:
        idx = np.array([0])
    t = 10.0 ** rng.uniform(np.log10(t_min), np.log10(t_max), len(idx))
    t[0] = t_min
    a, b = soup.triangles[idx, 0], soup.triangles[idx, 1]
    fa, fb, fc = soup.faces[idx].T
    fp = soup.n_vertices + np.arange(len(idx))
    keep = np.setdiff1d(np.arange(m), idx)
    faces = np.concatenate([soup.faces[keep], np.stack([fa, fp, fc], 1), np.stack([fp, fb, fc], 1)])
    parent = np.concatenate([keep, idx, idx])
    vertices = np.concatenate([soup.vertices, a + t[:, None] * (b - a)])
    return _with(soup, vertices, faces, parent), parent


def add_zero_area(soup: Soup, fraction: float = 0.1, seed: int = 0) -> Soup:
    """Append zero-area faces: half collapsed to a corner (a, a, a), half collinear (a, mid(ab), b).

    The original faces keep their indices ``0 .. m-1``.

    Parameters
    ----------
    soup : Soup
        The model.
    fraction : float
        Zero-area faces to add, a fraction of the face count (at least 2).
    seed : int
        Seeds which faces the new ones are made from.

    Returns
    -------
    Soup
        The soup with the zero-area faces appended (attributes from their source faces).
    """
    rng = np.random.default_rng(seed)
    k = max(2, int(fraction * soup.n_faces))
    src = rng.choice(soup.n_faces, k, replace=False)
    f = soup.faces[src]
    half = k // 2
    point = np.repeat(f[:half, :1], 3, axis=1)
    mid = soup.n_vertices + np.arange(k - half)
    line = np.stack([f[half:, 0], mid, f[half:, 1]], 1)
    mids = 0.5 * (soup.vertices[f[half:, 0]] + soup.vertices[f[half:, 1]])
    parent = np.concatenate([np.arange(soup.n_faces), src])
    return _with(
        soup, np.concatenate([soup.vertices, mids]), np.concatenate([soup.faces, point, line]), parent
    )


def add_duplicates(soup: Soup, fraction: float = 0.1, seed: int = 0) -> Soup:
    """Append exact duplicates of a ``fraction`` of the faces, and reversed duplicates of as many others.

    Parameters
    ----------
    soup : Soup
        The model.
    fraction : float
        Faces to duplicate each way, a fraction of the face count (at least 1).
    seed : int
        Seeds which faces are duplicated.

    Returns
    -------
    Soup
        The soup with the copies appended (the original faces keep their indices).
    """
    rng = np.random.default_rng(seed)
    k = max(1, int(fraction * soup.n_faces))
    src = rng.permutation(soup.n_faces)[: 2 * k]
    same, rev = src[:k], src[k:]
    faces = np.concatenate([soup.faces, soup.faces[same], soup.faces[rev][:, ::-1]])
    return _with(soup, soup.vertices, faces, np.concatenate([np.arange(soup.n_faces), same, rev]))


def add_near_coplanar(soup: Soup, offset: float = 1e-7, fraction: float = 0.1, seed: int = 0) -> Soup:
    """Append copies of a ``fraction`` of the faces moved ``offset`` × diagonal along their normal.

    Parameters
    ----------
    soup : Soup
        The model.
    offset : float
        Distance of the copies from their originals, a fraction of the diagonal.
    fraction : float
        Faces to copy, a fraction of the face count (at least 1).
    seed : int
        Seeds which faces are copied.

    Returns
    -------
    Soup
        The soup with the moved copies appended (the original faces keep their indices).
    """
    rng = np.random.default_rng(seed)
    k = max(1, int(fraction * soup.n_faces))
    src = rng.choice(soup.n_faces, k, replace=False)
    moved = soup.triangles[src] + (offset * soup.diagonal) * soup.normals[src][:, None, :]
    faces = np.concatenate([soup.faces, soup.n_vertices + np.arange(3 * k).reshape(k, 3)])
    return _with(
        soup,
        np.concatenate([soup.vertices, moved.reshape(-1, 3)]),
        faces,
        np.concatenate([np.arange(soup.n_faces), src]),
    )


def perturb_corners(soup: Soup, amount: float = 1e-9, seed: int = 0) -> Soup:
    """Unweld every corner and move it by a uniform random vector of at most ``amount`` × diagonal per axis.

    Neighbouring faces then no longer share corners exactly: hairline cracks and overlaps
    of about ``amount`` appear along every edge (the faces keep their order).

    Parameters
    ----------
    soup : Soup
        The model.
    amount : float
        Largest move per axis, a fraction of the diagonal.
    seed : int
        Seeds the moves.

    Returns
    -------
    Soup
        The perturbed soup, three vertices per face.
    """
    rng = np.random.default_rng(seed)
    v = soup.triangles.reshape(-1, 3)
    v = v + rng.uniform(-1.0, 1.0, v.shape) * amount * soup.diagonal
    return _with(soup, v, np.arange(3 * soup.n_faces).reshape(-1, 3), np.arange(soup.n_faces))


def _cube(center: np.ndarray, size: float) -> tuple[np.ndarray, np.ndarray]:
    """Build a closed axis-aligned cube of edge ``size`` (12 outward triangles)."""
    import trimesh

    b = trimesh.creation.box(extents=(size, size, size))
    return np.asarray(b.vertices) + center, np.asarray(b.faces)


def _triangle(center: np.ndarray, size: float, normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One equilateral triangle of edge ``size`` centred at ``center``, facing ``normal``."""
    n = normal / np.linalg.norm(normal)
    u = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    ang = 2 * np.pi * np.arange(3) / 3
    r = size / np.sqrt(3.0)
    return center + r * (np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * v), np.array([[0, 1, 2]])


def tiny_beside_huge(sizes: Iterable[float] = TINY_SIZES, subdivisions: int = 2, hole: bool = True) -> Soup:
    """Build large nested spheres with tiny lone triangles and tiny closed cubes beside them.

    The outer sphere (radius 1, one face removed when ``hole``: a small crack, so that the
    min cut is not trivially zero) encloses a sphere of radius 0.5.  For every ``size`` (a
    fraction of ``D`` = 2√3, about the diagonal) a lone triangle and a closed cube of edge
    ``size × D`` float outside the outer sphere (radius 1.15) and between the spheres
    (radius 0.75).  Node areas then range from about 12 (the outer sphere) down to
    ``(√3/4)(1e-6 D)²`` ≈ 5e-12, and the edge weights (Eq. 5) over 12 orders of magnitude.

    Parameters
    ----------
    sizes : iterable of float
        Edge lengths of the tiny pieces, fractions of ``D``.
    subdivisions : int
        Icosphere level of both spheres.
    hole : bool
        Remove one face of the outer sphere.

    Returns
    -------
    Soup
        One part per piece: ``outer``, ``inner``, ``{out,in}_{tri,cube}_<size>``.
    """
    import trimesh

    sizes = list(sizes)
    outer = trimesh.creation.icosphere(subdivisions, radius=1.0)
    of = np.asarray(outer.faces)[1:] if hole else np.asarray(outer.faces)
    inner = trimesh.creation.icosphere(subdivisions, radius=0.5)
    pieces: list[tuple[np.ndarray, np.ndarray, str]] = [
        (np.asarray(outer.vertices), of, "outer"),
        (np.asarray(inner.vertices), np.asarray(inner.faces), "inner"),
    ]
    D = 2.0 * np.sqrt(3.0)
    for k, s in enumerate(sizes):
        ang = 2 * np.pi * k / len(sizes)
        d = np.array([np.cos(ang), np.sin(ang), 0.3])
        d /= np.linalg.norm(d)
        e = np.array([-d[1], d[0], 0.0]) * 0.08  # cube and triangle side by side
        for where, radius in (("out", 1.15), ("in", 0.75)):
            pieces.append((*_triangle(radius * d - e, s * D, d), f"{where}_tri_{s:g}"))
            pieces.append((*_cube(radius * d + e, s * D), f"{where}_cube_{s:g}"))
    v, f, pid, off = [], [], [], 0
    for i, (pv, pf, _) in enumerate(pieces):
        v.append(pv)
        f.append(pf + off)
        pid.append(np.full(len(pf), i))
        off += len(pv)
    return Soup(
        np.concatenate(v), np.concatenate(f), part_id=np.concatenate(pid), part_names=[p[2] for p in pieces]
    )
