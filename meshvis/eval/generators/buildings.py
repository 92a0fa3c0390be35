"""A house: rooms with shared coplanar walls, floors, a roof and furniture inside."""

from __future__ import annotations

import numpy as np

from meshvis.errors import ParameterError

from ._shapes import _axis_patch, _box, _box_tris, _compose, _grid_tris, _orient_from, _Piece, _weld
from .truth import GroundTruth


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
    """Build a closed house of stacked room boxes with furniture: hidden interiors and coplanar walls.

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
        border or on the ground floor).
    floors : int
        Storeys.
    room_size : (3,) float
        Nominal room width, depth, height; widths and depths vary by +-20 % per column/row.
    cell : float
        Nominal triangle size.
    furniture : int
        Furniture boxes per room (0..4).
    roof : bool
        Add the roof prism.
    partition : bool
        Add the partition sheet (in the last room of the top floor).
    seed : int
        Jitters the room widths, depths and cell sizes and places the furniture.

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

    Raises
    ------
    ParameterError
        No room or no floor, a room that does not touch the exterior (more than two rooms
        along both x and y with several floors), or ``furniture`` outside 0..4.

    Examples
    --------
    >>> t = house(rooms=(1, 1), floors=1, furniture=0)
    >>> t.soup.part_names, t.n_layers, t.check()
    (['room_000', 'roof', 'partition'], 2, [])
    """
    nx, ny, floors = int(rooms[0]), int(rooms[1]), int(floors)
    _check_house(rooms, floors, furniture)
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
                furn, amb = _furniture(rng, lo, hi, (i, j, k), furniture, cell, H, tris, side)
                furn_pieces += furn
                pieces.append(_room(tris, shared[side], amb, f"room_{i}{j}{k}"))
                if partition and (i, j, k) == (nx - 1, ny - 1, floors - 1):
                    furn_pieces.append(_partition(lo, hi, H, cell))
    if roof:
        pieces.append(_roof(xs, ys, zs, cell))
    return _compose(
        pieces + furn_pieces,
        "house",
        "closed house of room boxes with coplanar duplicate walls, roof, furniture, a cabinet "
        "with a safe inside (layer 3) and a two-sided partition; tests inside removal "
        "(only the hull is outside), coplanar handling and layers",
    )


def _check_house(rooms: tuple[int, int], floors: int, furniture: int) -> None:
    """Raise ParameterError unless every room of the house touches the exterior."""
    nx, ny = int(rooms[0]), int(rooms[1])
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


def _furniture(
    rng: np.random.Generator,
    lo: np.ndarray,
    hi: np.ndarray,
    room: tuple[int, int, int],
    n: int,
    cell: float,
    height: float,
    tris: np.ndarray,
    side: np.ndarray,
) -> tuple[list[_Piece], np.ndarray]:
    """Furnish one room: one box per chosen quadrant of its floor.

    The first room's first box is a cabinet with a safe floating inside.  Also returns which
    of the room's triangles are ambiguous (floor triangles of an upper storey partly under
    furniture).
    """
    i, j, k = room
    pieces = []
    amb = np.zeros(len(tris), bool)
    slots = rng.permutation(4)[:n]
    for s_i, slot in enumerate(slots):
        qx, qy = slot % 2, slot // 2
        s_lo = lo[:2] + np.array([qx, qy]) * (hi[:2] - lo[:2]) / 2
        s_size = (hi[:2] - lo[:2]) / 2
        margin = 0.08 * s_size
        size = rng.uniform(0.35, 0.8, 2) * (s_size - 2 * margin)
        pos = s_lo + margin + rng.uniform(0, 1, 2) * (s_size - 2 * margin - size)
        f_lo = np.array([pos[0], pos[1], lo[2]])
        f_hi = np.array([pos[0] + size[0], pos[1] + size[1], lo[2] + rng.uniform(0.25, 0.7) * height])
        f_tris, f_side = _box_tris(f_lo, f_hi, 0.5 * cell)
        first = (i, j, k) == (0, 0, 0) and s_i == 0
        fname = "cabinet" if first else f"furniture_{i}{j}{k}_{s_i}"
        fV, fF = _weld(f_tris)
        # the bottom stands on the floor: coplanar contact, a matter of convention
        f_amb = f_side == 4  # _weld keeps the triangle order
        pieces.append(_Piece(fV, fF, fname, outside=(False, False), layer=2, ambiguous=f_amb))
        if first:
            c, e = (f_lo + f_hi) / 2, (f_hi - f_lo) / 2
            sV, sF = _box(c - 0.45 * e, c + 0.45 * e, 0.25 * cell)
            pieces.append(_Piece(sV, sF, "safe", outside=(False, False), layer=3))
        if k > 0:
            # hidden floor triangles (partly) under the furniture are partly
            # sandwiched: which side faces outward is a matter of convention
            tmin, tmax = tris[..., :2].min(axis=1), tris[..., :2].max(axis=1)
            under = np.all((tmax > f_lo[:2]) & (tmin < f_hi[:2]), axis=1)
            amb |= under & (side == 4)
    return pieces, amb


def _room(tris: np.ndarray, inner: np.ndarray, amb: np.ndarray, name: str) -> _Piece:
    """Make a room box a piece: its sides toward the exterior outside, the shared ones hidden.

    Sides toward the exterior are layer 1 with the front outward; sides shared with a
    neighbour are layer 2 with the back outward.
    """
    V, F = _weld(tris)
    vis = ~inner
    return _Piece(
        V,
        F,
        name,
        outside=np.stack([vis, np.zeros_like(vis)], 1),
        layer=np.where(inner, 2, 1),
        outward=vis,
        ambiguous=amb,
    )


def _partition(lo: np.ndarray, hi: np.ndarray, height: float, cell: float) -> _Piece:
    """Build a free-standing single sheet across the middle of a room: hidden, two-sided."""
    cy = 0.5 * (lo[1] + hi[1])
    ub = np.linspace(lo[2], lo[2] + 0.6 * height, max(2, int(round(0.6 * height / cell)) + 1))
    vc = np.linspace(
        lo[0] + 0.2 * (hi[0] - lo[0]),
        hi[0] - 0.2 * (hi[0] - lo[0]),
        max(2, int(round(0.6 * (hi[0] - lo[0]) / cell)) + 1),
    )
    pV, pF = _weld(_axis_patch(1, cy, 1, ub, vc))
    return _Piece(pV, pF, "partition", outside=(False, False), layer=2, two_sided=True)


def _roof(xs: np.ndarray, ys: np.ndarray, zs: np.ndarray, cell: float) -> _Piece:
    """Build the gable roof: a closed prism on the top ceilings; its bottom (coplanar with them) is hidden."""
    Z0, Y, X = zs[-1], ys[-1], xs[-1]
    section = np.array([[0.0, Z0], [Y, Z0], [Y / 2, Z0 + 0.45 * Y]])
    rV, rF = _prism_x(xs[0], X, section, cell)
    bottom = np.all(rV[rF][..., 2] == Z0, axis=1)
    return _Piece(
        rV,
        rF,
        "roof",
        outside=np.stack([~bottom, np.zeros_like(bottom)], 1),
        layer=np.where(bottom, 2, 1),
        outward=~bottom,
    )


def _prism_x(x0: float, x1: float, section: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Build a closed, outward prism along x over the triangular cross-section ``section`` (3, 2) in (y, z).

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
