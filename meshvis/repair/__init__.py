"""The repairs built on a classification: :mod:`~meshvis.repair.orient`,
:mod:`~meshvis.repair.remove` (inside removal) and :mod:`~meshvis.repair.layers`;
:mod:`~meshvis.repair.operation` runs one of them on a model with its outputs (shared by
the single-file commands and batch); :mod:`~meshvis.repair.trimesh_style` wraps orientation
and removal as one-call functions on trimesh objects."""
