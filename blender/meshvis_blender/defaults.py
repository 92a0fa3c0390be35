# SPDX-License-Identifier: GPL-3.0-or-later
"""The library's defaults and choices, read from its source without importing it.

Blender registers the add-on's properties, with their defaults, when it starts; importing
meshvis' repairs then (numba, SciPy, Embree) would add seconds to every start.  The
defaults are written once, in the library's signatures and constants, and the library's
own source reader (the one its command line uses) reads them from there.
"""

from __future__ import annotations

from typing import Any

from meshvis._defaults import module_constant, signature_default

#: where the library defines what the add-on offers
REMOVE = "meshvis.repair.remove:remove_interior"
REMOVE_MODES = "meshvis.repair.remove_modes"
LAYOUTS = "meshvis.labeling.candidates:LAYOUTS"
LAYOUT = "meshvis.labeling.pipeline:layout"


def removal() -> dict[str, Any]:
    """The choices and defaults of :func:`meshvis.remove_interior` that the add-on offers.

    Examples
    --------
    >>> removal()["level"]
    'face'
    """
    return {
        "visibility": signature_default(REMOVE, "visibility"),
        "visibility_modes": tuple(module_constant(f"{REMOVE_MODES}:VISIBILITY_MODES")),
        "level": signature_default(REMOVE, "level"),
        "levels": tuple(module_constant(f"{REMOVE_MODES}:LEVELS")),
        "transparent": signature_default(REMOVE, "transparent"),
    }


def labeling() -> dict[str, Any]:
    """The layouts of :func:`meshvis.labeling.layout` and its default."""
    return {"layout": signature_default(LAYOUT, "layout"), "layouts": tuple(module_constant(LAYOUTS))}
