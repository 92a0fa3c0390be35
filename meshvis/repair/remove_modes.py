"""The choices of inside removal and layers, and their defaults.

Kept apart from :mod:`~meshvis.repair.remove` so that the command line and batch read
their defaults without importing the cut and the ray tracer.

``view`` is the default of removal and of layers: a face goes when a guided search from
the region (default ``outside``) found no line of sight to it.  The cut (``object``) calls
"outside" whatever a path that crosses no geometry reaches, so it keeps the inside of an
engine block open at one end, which no viewer sees; ``both`` removes only what the cut
*and* the search call hidden, so it keeps all the cut keeps (docs/removal.md).
"""

from __future__ import annotations

from meshvis.visibility.check import CHECK_RAYS, RESCUE_RAYS
from meshvis.visibility.walls import DEFAULT_TRANSPARENT, TRANSPARENT_MODES

#: what decides that a face is hidden: the graph cut, lines of sight, or both together
VISIBILITY_MODES = ("object", "view", "both")
#: the default of :func:`meshvis.remove_interior`, ``remove-interior`` and ``meshvis batch``
DEFAULT_VISIBILITY = "view"
#: what peels the layers of :func:`meshvis.layers`: lines of sight, or the graph cut
#: (appendix H §5)
LAYER_MODES = ("view", "object")
#: the default of :func:`meshvis.layers` and ``layers``
DEFAULT_LAYER_VISIBILITY = "view"
#: what is removed together: single faces, edge-connected patches, named parts
LEVELS = ("face", "patch", "part")

__all__ = [
    "CHECK_RAYS",
    "DEFAULT_LAYER_VISIBILITY",
    "DEFAULT_TRANSPARENT",
    "DEFAULT_VISIBILITY",
    "LAYER_MODES",
    "LEVELS",
    "RESCUE_RAYS",
    "TRANSPARENT_MODES",
    "VISIBILITY_MODES",
    "cut_rays_per_point",
]


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


def reuse_note(params: dict, visibility: str) -> str | None:
    """Why a reused classification may keep other faces than the cut of ``visibility`` would.

    In ``both`` the cut's sample points get ``rays_per_node // samples_per_face`` rays
    (:func:`cut_rays_per_point`); a classification made for ``orient`` or ``layers`` gives
    them ``rays_per_node``, so its cut can call a few faces outside that the removal's own
    cut calls hidden.

    Parameters
    ----------
    params : dict
        ``Classification.params`` of the reused classification.
    visibility : str
        The removal's mode.

    Returns
    -------
    str or None
        One line saying so, or None when the budgets agree.

    Examples
    --------
    >>> reuse_note({"rays_per_node": 32, "samples_per_face": 4, "rays_per_point": 8}, "both") is None
    True
    >>> reuse_note({"rays_per_node": 32, "samples_per_face": 4, "rays_per_point": 32}, "both")[:44]
    'the classification given gave its sample poi'
    """
    expected = cut_rays_per_point(visibility, params["rays_per_node"], params["samples_per_face"])
    if expected is None or params.get("rays_per_point") == expected:
        return None
    return (
        f"the classification given gave its sample points {params.get('rays_per_point')} rays, "
        f"remove_interior's own cut gives them {expected} (visibility={visibility!r}); the faces kept can "
        f"differ from remove_interior(model): classify with rays_per_point={expected} for the same answer"
    )
