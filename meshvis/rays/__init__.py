"""The shared ray backend.

An Embree scene over a soup (:mod:`~meshvis.rays.caster`), random samples on triangles and
hemispheres (:mod:`~meshvis.rays.samples`), cameras (:mod:`~meshvis.rays.camera`) and
ray-cast previews (:mod:`~meshvis.rays.render`).
"""
