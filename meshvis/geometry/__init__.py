"""Mesh analysis without rays: connectivity and welding (:mod:`~meshvis.geometry.adjacency`),
conservative intersection and coplanarity tests (:mod:`~meshvis.geometry.intersect`) and
the defect counts of ``meshvis info`` (:mod:`~meshvis.geometry.diagnostics`)."""
