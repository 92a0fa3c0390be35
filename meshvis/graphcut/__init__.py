"""Inside/outside of every triangle side by a visibility graph cut (thesis appendix H).

The data flow, one module per step: :mod:`~meshvis.graphcut.preprocess` (weld, flag
intersecting and coplanar faces) -> :mod:`~meshvis.graphcut.clusters` (consistently
oriented patches) -> :mod:`~meshvis.graphcut.nodes` (half-space nodes) ->
:mod:`~meshvis.graphcut.sampling` (rays from every node, counts) ->
:mod:`~meshvis.graphcut.weights` (Eq. 5-9) -> :mod:`~meshvis.graphcut.mincut` (s-t cut) ->
:mod:`~meshvis.graphcut.classify` (the whole pipeline, progressive rounds).
:mod:`~meshvis.graphcut.hints` adds user points inside or outside.
"""
