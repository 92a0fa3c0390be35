"""The max-flow solvers by name, and the default.

Kept apart from :mod:`~meshvis.graphcut.mincut` so that the command line and batch read
them without importing the compiled kernels.
"""

from __future__ import annotations

#: ``bk``: Boykov–Kolmogorov compiled here; ``pymaxflow``: the same algorithm through
#: PyMaxflow (the same labels); ``scipy``: integer capacities (a rounding check)
SOLVERS = ("bk", "pymaxflow", "scipy")
#: the solver of every command unless told otherwise
DEFAULT_SOLVER = "bk"
