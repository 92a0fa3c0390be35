"""An engine-like assembly of many named closed parts of very different sizes."""

from __future__ import annotations

import numpy as np

from ._shapes import _box, _cylinder
from .closed import _closed_pieces_truth
from .truth import GroundTruth


class _Parts:
    """The closed pieces of an assembly and the part each belongs to, in the order added."""

    def __init__(self, sections: int, cell: float) -> None:
        self.sections, self.cell = sections, cell
        self.pieces: list[tuple[np.ndarray, np.ndarray]] = []
        self.parts: list[str] = []

    def add(self, mesh_or_vf, part: str) -> None:
        """Add a piece given as ``(V, F)`` or as a mesh with ``vertices`` and ``faces``."""
        if isinstance(mesh_or_vf, tuple):
            V, F = mesh_or_vf
        else:
            V, F = np.asarray(mesh_or_vf.vertices, np.float64), np.asarray(mesh_or_vf.faces, np.int64)
        self.pieces.append((V, F))
        self.parts.append(part)

    def box(self, lo, hi, part, c=None) -> None:
        self.add(_box(lo, hi, c or self.cell), part)

    def cyl(self, p0, p1, r, part, sec=None) -> None:
        self.add(_cylinder(p0, p1, r, sec or self.sections, min(self.cell, max(2 * r, 0.1))), part)


def _block_and_head(b: _Parts) -> np.ndarray:
    """Block, head, valve cover and oil pan; pistons, spark plugs, bolts; the cylinders' x."""
    # large structure (x along the crankshaft, z up).  Parts that meet sink 0.02 into each
    # other instead of touching, so that few faces lie exactly on another part's surface.
    b.box((-2.0, -1.1, 0.0), (2.0, 1.1, 2.0), "engine_block")
    b.box((-1.95, -1.0, 1.98), (1.95, 1.0, 2.6), "cylinder_head")
    b.box((-1.8, -0.7, 2.58), (1.8, 0.7, 3.0), "valve_cover")
    b.box((-1.8, -0.9, -0.6), (1.8, 0.9, 0.02), "oil_pan")
    xs = np.array([-1.35, -0.45, 0.45, 1.35])
    for n, x in enumerate(xs, 1):
        b.cyl((x, 0, 0.9), (x, 0, 1.5), 0.36, f"piston_{n}")  # inside the block
        b.cyl((x, 0.35, 2.85), (x, 0.35, 3.35), 0.07, f"spark_plug_{n}")  # sunk into the cover
    bolt_x = np.array([-1.6, -0.55, 0.55, 1.6])
    for n, (x, y) in enumerate([(x, y) for y in (-0.55, 0.55) for x in bolt_x], 1):
        b.cyl((x, y, 2.9), (x, y, 3.12), 0.06, f"bolt_{n}", sec=6)  # hexagonal heads
    return xs


def _front(b: _Parts) -> None:
    """Add the front accessories (front = -x): pulleys, alternator, water pump and the fan."""
    import trimesh

    b.box((-2.1, -0.9, 0.2), (-1.98, 0.9, 1.9), "timing_cover", c=0.2)
    b.cyl((-2.05, 0.0, 0.5), (-2.35, 0.0, 0.5), 0.55, "crankshaft_pulley")
    b.cyl((-1.3, 1.45, 1.7), (0.2, 1.45, 1.7), 0.38, "alternator")
    b.cyl((-1.2, 1.45, 1.7), (-2.35, 1.45, 1.7), 0.2, "alternator_pulley")
    b.box((-2.2, -0.75, 1.25), (-2.05, -0.25, 1.75), "water_pump", c=0.1)
    b.cyl((-2.15, -0.5, 1.5), (-2.4, -0.5, 1.5), 0.3, "water_pump_pulley")
    # fan on the water pump axis: hub plus six blades whose roots sink into the hub
    fan_x = -2.75
    b.cyl((-2.35, -0.5, 1.5), (fan_x - 0.1, -0.5, 1.5), 0.15, "fan")
    for k in range(6):
        T = trimesh.transformations.rotation_matrix(2 * np.pi * k / 6 + 0.3, [1, 0, 0])
        T[:3, 3] = [fan_x, -0.5, 1.5]
        T = T @ trimesh.transformations.translation_matrix((0, 0, 0.47))
        bV, bF = _box((-0.02, -0.1, -0.375), (0.02, 0.1, 0.375), 0.075)
        b.add((bV @ T[:3, :3].T + T[:3, 3], bF), "fan")


def _back_and_pipes(b: _Parts, xs: np.ndarray) -> None:
    """Flywheel and starter at the back, the exhaust and intake manifolds, filter, dipstick, mounts."""
    sections = b.sections
    b.cyl((1.98, 0.0, 0.5), (2.15, 0.0, 0.5), 1.05, "flywheel", sec=2 * sections)
    b.cyl((1.3, -1.3, 0.3), (2.3, -1.3, 0.3), 0.25, "starter_motor")
    # exhaust manifold (-y side): four runners into a collector, then the exhaust pipe
    for x in xs:
        b.cyl((x, -0.95, 2.3), (x, -1.6, 2.3), 0.12, "exhaust_manifold")
    b.cyl((-1.6, -1.6, 2.3), (1.7, -1.6, 2.3), 0.16, "exhaust_manifold")
    b.cyl((1.6, -1.6, 2.3), (1.6, -1.6, -0.9), 0.14, "exhaust_pipe")
    # intake (+y side): runners into a plenum box, air filter on top
    for x in xs:
        b.cyl((x, 0.95, 2.3), (x, 1.6, 2.3), 0.1, "intake_manifold")
    b.box((-1.7, 1.55, 2.1), (1.7, 2.0, 2.9), "intake_manifold", c=0.2)
    b.cyl((0.0, 1.8, 2.85), (0.0, 1.8, 3.25), 0.45, "air_filter")
    b.cyl((1.0, 1.0, 0.5), (1.0, 1.5, 3.1), 0.03, "dipstick", sec=8)
    b.box((-0.8, 1.08, 0.4), (0.8, 1.4, 0.8), "engine_mount_left", c=0.2)
    b.box((-0.8, -1.4, 0.4), (0.8, -1.08, 0.8), "engine_mount_right", c=0.2)


def assembly(sections: int = 24, cell: float = 0.2) -> GroundTruth:
    """Build an engine-like assembly of about 30 named closed parts of very different sizes.

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
    b = _Parts(sections=sections, cell=cell)
    xs = _block_and_head(b)
    _front(b)
    _back_and_pipes(b, xs)
    return _closed_pieces_truth(
        b.pieces,
        b.parts,
        "assembly",
        "engine-like assembly of named closed parts of very different sizes; pistons "
        "hidden in the block, bolts and plugs half sunk; for labeling and inside removal",
    )
