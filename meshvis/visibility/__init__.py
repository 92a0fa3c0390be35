"""From-region visibility (DESIGN.md §9): which face sides a viewer in a region can see.

:func:`visible_from` samples lines of sight from a region (:mod:`.regions`) with random
seeds and, by default, GVS guided sampling (:mod:`.sampling`: adaptive border sampling and
reverse sampling).
"""

from meshvis.visibility.regions import REGION_KINDS, Region, parse_region
from meshvis.visibility.visible import Visibility, visible_from

__all__ = ["REGION_KINDS", "Region", "Visibility", "parse_region", "visible_from"]
