"""From-region visibility (DESIGN.md §9): which face sides a viewer in a region can see.

:func:`visible_from` samples lines of sight from a region (:mod:`.regions`) with random
seeds and, by default, GVS guided sampling (:mod:`.sampling`: adaptive border sampling and
reverse sampling); :mod:`.walls` says which faces stop a line of sight and
:mod:`.check` checks a removal with fresh random rays.

The names below are imported on first use, so that the command line reads the defaults of
:mod:`.walls` without loading the ray tracer.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from meshvis.visibility.regions import REGION_KINDS, Region, parse_region
    from meshvis.visibility.visible import Visibility, visible_from

#: public name -> module that defines it
_LAZY = {
    "REGION_KINDS": "meshvis.visibility.regions",
    "Region": "meshvis.visibility.regions",
    "parse_region": "meshvis.visibility.regions",
    "Visibility": "meshvis.visibility.visible",
    "visible_from": "meshvis.visibility.visible",
}

__all__ = ["REGION_KINDS", "Region", "Visibility", "parse_region", "visible_from"]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'meshvis.visibility' has no attribute {name!r}")
