"""The tolerances and codes shared by both formulations of the geometry kernels.

The compiled kernels (:mod:`meshvis.geometry._kernels`) and their numpy versions
(:mod:`meshvis.geometry._vectorised`) read them from here, a module that imports nothing,
so that the numpy side never imports numba.
"""

#: relative slack of every reporting comparison (far above float64 reordering error)
SLACK = 1e-12
#: angular slack of the wedge test at a shared corner
WEDGE_SLACK = 1e-9
#: widening of each face's projection interval on its own axes (unit-diagonal coordinates):
#: above the rounding of a 3-term dot product in any order (a few 1e-16), so gaps can only
#: shrink and an evaluation order never hides a pair (more reports, never fewer)
PROJ_SLACK = 1e-15
#: bits of the pair codes of ``_vectorised.flagged_pairs`` and ``_kernels.broad_narrow``
INTERSECTS, COPLANAR, TOO_CLOSE = 1, 2, 4
#: smallest cell of ``near_labels`` (both formulations), as a fraction of the points' largest extent: cell
#: coordinates stay below 2**40, far inside int64, whatever the radius
NEAR_CELL_FLOOR = 2.0**-40
