"""Ground-truth generators: models whose inside/outside answer is known by construction.

Every generator returns a :class:`GroundTruth`: a :class:`~meshvis.soup.Soup` plus, per face,

- ``outside`` (m, 2) bool: whether side 0 (the counter-clockwise front, DESIGN.md §5) and
  side 1 are *outside*: reachable from far away along a path that crosses no geometry,
  where hairline cracks and small holes (defects) do not count as paths but real openings
  do (DESIGN.md §4, "Semantics");
- ``layer`` (m,) int under *layer semantics*: 1 for every face with an outside side,
  2 for what becomes visible once layer 1 is removed, and so on (appendix H, §5);
- ``outward`` (m,) bool: True where the current front side is the side that faces outward
  with respect to the face's own layer (the orientation truth; for two-sided sheets the
  side facing the larger open region);
- ``two_sided`` (m,) bool: sheets whose both sides are meant to be seen (a cup wall, a cave);
- ``ambiguous`` (m,) bool: faces whose answer depends on a convention (faces lying on
  another solid's surface, faces straddling an intersection curve); evaluations should
  leave them out.

Truth arrays stay consistent through :func:`soupify`, which turns any truth into a messy
triangle soup (unwelded, randomly flipped, shuffled, duplicated, with small holes) and
records for every output face which input face it came from and whether it was flipped.

All geometry is float64 and deterministic for a given ``seed`` (randomness only from
``numpy.random.default_rng(seed)``).

The generators live in modules by family (:mod:`.shells`, :mod:`.buildings`, :mod:`.sheets`,
:mod:`.open_surfaces`, :mod:`.assemblies`, :mod:`.real`); :mod:`.truth` holds the container,
:mod:`.closed` the truth of closed models, :mod:`.soups` the soupification.  Every public
name is re-exported here.
"""

from __future__ import annotations

from ._shapes import signed_volume
from .assemblies import assembly
from .buildings import house
from .closed import from_closed_mesh, is_closed
from .open_surfaces import cup, terrain
from .real import skin_and_ribcage
from .sheets import box_with_opening, cracked_box
from .shells import nested_shells, overlapping_solids, sphere_pair
from .soups import soupify
from .truth import GroundTruth

__all__ = [
    "GroundTruth",
    "nested_shells",
    "house",
    "cracked_box",
    "box_with_opening",
    "cup",
    "terrain",
    "overlapping_solids",
    "sphere_pair",
    "skin_and_ribcage",
    "assembly",
    "soupify",
    "from_closed_mesh",
    "is_closed",
    "signed_volume",
    "GENERATORS",
]

#: name -> generator, for benchmarks and the models script
GENERATORS = {
    "nested_shells": nested_shells,
    "house": house,
    "cracked_box": cracked_box,
    "box_with_opening": box_with_opening,
    "cup": cup,
    "terrain": terrain,
    "overlapping_solids": overlapping_solids,
    "sphere_pair": sphere_pair,
    "assembly": assembly,
}
