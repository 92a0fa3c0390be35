"""Label boxes: stacking along the internal area and the corrections of appendix I §5.5.

The greedy step gives every label an anchor ``a`` and a candidate endpoint ``e`` on the
boundary of ``A_I``.  This module turns them into drawn leaders and boxes with no box
overlaps, no leader crossings and no box over the model:

* **west / east** (left, right, left-right layouts): the boxes of a side are stacked in one
  column just outside ``A_I`` (as in appendix I, Fig. 2a-b).  A box wants to sit at its
  endpoint's height; where boxes would overlap they are **shifted** apart along the
  column by the least total squared displacement that keeps their order (pool-adjacent-
  violators on the stacked positions).  Shifting rotates leaders ("relieving criterion 1"),
  which may make two of them cross; crossing pairs then **swap** their slots, which
  strictly shortens the sum of leader lengths, so the swapping ends (§5.5).
* **north / south** (top, bottom, top-bottom): leader ports are spread along a line just
  above (below) ``A_I`` with the same shift-then-swap step; the boxes hang like flags off
  the leaders and are stacked in tiers away from the model where they do not fit side by
  side; labels left of the centre extend left and fill tiers outside-in, those right of it
  extend right, which keeps every extended leader clear of the other boxes.
* **radial** (silhouette layout): labels are taken in order along the boundary of
  ``A_I``, their endpoints first moved apart to at least ``Spacing.endpoint_gap`` (labels
  of small neighbouring parts often share one); each box goes on the ray of the
  boundary's outward normal at its endpoint, just outside ``A_I``, and is pushed further
  out in tiers where it collides (the "extruded" leaders of Fig. 4b).  A box may hang
  off its port at any corner or edge middle; the cheapest valid place that blocks no
  later label's ray wins.  Normals of a convex boundary diverge, so the rays never meet.  A box that would be pushed out is
  instead hung, when that makes a shorter leader, off a *rotated* leader: endpoint moved
  up to ``Spacing.rotate`` pixels along the boundary to a stretch with room within two
  tiers.  A label whose own leader is blocked (e.g. it shares its endpoint with a placed
  one) gets its endpoint moved a few pixels along the boundary.

A last pass checks every pair of labels and re-places a label of any conflicting pair
(the one placed later by the greedy order) by the same candidate search; a label with no
valid place is left out and reported.  Everything is deterministic: sorts are stable
with the label index as the last key, and candidate ties go to the lowest index.

Modules: :mod:`.spacing` (distances, results), :mod:`.costs` (the cost terms),
:mod:`.context` (the shared state), :mod:`.stacking` (shift, swap, columns and rows),
:mod:`.collisions`, :mod:`.search` (column and row candidates), :mod:`.silhouette`,
:mod:`.place` (:func:`place_boxes`).
"""

from __future__ import annotations

from .place import place_boxes
from .spacing import BoxStats, Placement, Spacing
from .stacking import coherent_order, pack_1d, uncross

__all__ = ["Spacing", "Placement", "BoxStats", "pack_1d", "uncross", "coherent_order", "place_boxes"]
