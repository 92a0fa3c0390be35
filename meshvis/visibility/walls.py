"""What stops a line of sight: every face, or every face but the see-through ones.

A face whose material lets light through (:attr:`meshvis.soup.Soup.see_through`: glass,
blended or cut-out materials) does not hide what lies behind it: with ``transparent=
"see-through"`` (the default of every search by sight) it is left out of the scene that
rays are traced against, so sight passes it, and it is still seen itself (seed rays start
on it).  ``"opaque"`` treats it as a wall like any other face.

Kept apart from :mod:`.visible`, and free of numpy at import, so that the command line
reads the choices without loading numerical modules.

>>> import numpy as np
>>> from meshvis.soup import Material, Soup
>>> s = Soup(np.eye(3), [[0, 1, 2]], material_id=[0], materials=[Material("glass", see_through=True)])
>>> walls(s).tolist(), walls(s, "opaque") is None
([False], True)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from meshvis.errors import ParameterError

if TYPE_CHECKING:
    import numpy as np

#: how see-through materials are treated by sight: they let it through, or they are walls
TRANSPARENT_MODES = ("see-through", "opaque")
#: the default of :func:`meshvis.visible_from`, :func:`meshvis.remove_interior`,
#: :func:`meshvis.layers` and their commands
DEFAULT_TRANSPARENT = "see-through"


def check_transparent(transparent: str) -> str:
    """``transparent`` if it is one of :data:`TRANSPARENT_MODES`, else a :class:`ParameterError`."""
    if transparent not in TRANSPARENT_MODES:
        raise ParameterError(
            f"unknown transparent {transparent!r}; choose one of {', '.join(TRANSPARENT_MODES)}"
        )
    return transparent


def walls(soup, transparent: str = DEFAULT_TRANSPARENT) -> np.ndarray | None:
    """The faces that stop a line of sight, or None when every face does.

    Parameters
    ----------
    soup : Soup
    transparent : {"see-through", "opaque"}
        Whether faces of see-through materials let sight pass.

    Returns
    -------
    (m,) bool or None
        For :class:`meshvis.rays.caster.RayCaster` (``walls=``).

    Raises
    ------
    ParameterError
        Unknown ``transparent``.
    """
    if check_transparent(transparent) == "opaque":
        return None
    clear = soup.see_through
    return ~clear if clear.any() else None
