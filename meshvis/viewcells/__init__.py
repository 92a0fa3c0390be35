"""Potentially visible sets for view cells (DESIGN.md §11): AGVS on a view-cell hierarchy.

:func:`pvs` computes the PVS of every view cell of a model's view space at once, by
adaptive global visibility sampling (``000_*.txt``), on cells that are a uniform grid, boxes
from a file, or a kD-tree built by expected render cost (``002_*.txt``).  The result
(:class:`PVS`) is written to and read from an ``.npz`` file.
"""

from meshvis.viewcells.agvs import pvs
from meshvis.viewcells.cells import ViewCells
from meshvis.viewcells.result import PVS
from meshvis.viewcells.viewspace import ViewSpace, default_view_space

__all__ = ["PVS", "ViewCells", "ViewSpace", "default_view_space", "pvs"]
