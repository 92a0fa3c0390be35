"""The choices of inside removal and their default.

Kept apart from :mod:`~meshvis.repair.remove` so that the command line and batch read
their defaults without importing the cut and the ray tracer.

``both`` is the default: a face goes only when the graph cut calls it hidden *and* a
guided search for a view of it failed, so that the default never deletes a face a viewer
outside was seen to see (on real scenes the cut alone deletes visible eave undersides and
wall strips: docs/benchmarks.md).
"""

from __future__ import annotations

#: what decides that a face is hidden: the graph cut, lines of sight, or both together
VISIBILITY_MODES = ("object", "view", "both")
#: the default of :func:`meshvis.remove_interior`, ``remove-interior`` and ``meshvis batch``
DEFAULT_VISIBILITY = "both"
#: what is removed together: single faces, edge-connected patches, named parts
LEVELS = ("face", "patch", "part")
