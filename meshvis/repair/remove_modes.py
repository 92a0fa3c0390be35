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


def cut_rays_per_point(
    visibility: str, rays_per_node: int, samples_per_face: int, rays_per_point: int | None = None
) -> int | None:
    """The ray budget of the cut's sample points in inside removal by ``visibility``.

    In ``both`` the cut only proposes the faces that the search then tries to see, so
    unless ``rays_per_point`` is given each sample point of an intersecting face gets
    ``rays_per_node // samples_per_face`` rays: a flagged face's side then has the budget
    of an unflagged face's.  Otherwise ``rays_per_point`` is returned as given (None:
    :func:`meshvis.classify` gives the sample points ``rays_per_node``).

    Examples
    --------
    >>> cut_rays_per_point("both", 32, 4), cut_rays_per_point("object", 32, 4)
    (8, None)
    >>> cut_rays_per_point("both", 32, 4, rays_per_point=32)
    32
    """
    if rays_per_point is not None or visibility != "both":
        return rays_per_point
    return max(1, int(rays_per_node) // int(samples_per_face))
