"""Costs of the candidate search, in pixels of leader length.

A candidate costs the leader length it adds (its shift along the side, its push-out).  The
penalties below are orders of magnitude apart, so that each one only decides between
candidates the terms under it cannot tell apart: a box behind its port loses to any box
that blocks a later label's ray, which loses to any box outside the image, which loses to
any box inside it.
"""

from __future__ import annotations

#: a box counts as shifted (``BoxStats.shifted``) once its port moved more than half a
#: pixel from its candidate endpoint: less is rounding, not a correction
SHIFTED = 0.5
#: a north/south flag box one tier further out costs twice the tier's pitch of leader: it
#: lengthens its own leader and stands in the way of its neighbours' leaders
ROW_TIER_COST = 2.0
#: cost per pixel between a silhouette box and its place in the previous frame moved with
#: its anchor (frame-to-frame coherence of the boxes)
COHERENCE_COST = 1.0
#: penalty of a box outside the image: taken only where no box inside the image is valid
OUTSIDE_IMAGE_COST = 1e4
#: penalty per later label whose push-out ray a silhouette box blocks
BLOCKED_RAY_COST = 1e5
#: penalty of a silhouette box hung behind its port (the leader would end inside its box)
BEHIND_PORT_COST = 1e6
#: cosine between the ray and the box-centre offset below which a box is behind its port
BEHIND_PORT_COS = 0.05
