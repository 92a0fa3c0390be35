"""The caps on everything a small input can make meshvis expand (docs/security.md).

A file of a few kilobytes can describe gigabytes: a zip that inflates 1000-fold, a glTF
node graph that doubles at every level, one polygon with millions of corners.  Each such
expansion is checked against a cap here before the work starts and refused with a one-line
error (:class:`~meshvis.errors.ModelError` for a file, :class:`~meshvis.errors.ParameterError`
for an argument).  The caps are module attributes read at call time, so a program that
needs more can raise them (``meshvis.limits.MAX_PIXELS = ...``).
"""

from __future__ import annotations

#: entries in a 3MF (zip) archive; a 3MF holds a handful (model, relationships, textures)
MAX_ZIP_ENTRIES = 10_000
#: bytes a 3MF archive inflates to (the sizes its directory declares, which the zip reader
#: enforces): 1 GiB of XML is about 10 M triangles, and parsing takes several times as much memory
MAX_ZIP_BYTES = 1 << 30
#: node instances (meshes placed by the scene graph) in a glTF scene, counted without expanding it
MAX_INSTANCES = 100_000
#: triangles after glTF instancing (each instance counts its mesh's triangles)
MAX_INSTANCED_FACES = 50_000_000
#: corners of one polygon: its triangles all meet in one region, so the intersection tests
#: of the graph cut grow with the square of the corners (a 4,000-corner fan: 0.8 GB, 23 s);
#: real n-gons (cylinder caps, CAD outlines) stay in the hundreds
MAX_POLYGON_CORNERS = 4_096
#: rays per node of the graph cut (default 32); memory grows with nodes x rays
MAX_RAYS_PER_NODE = 65_536
#: rays of one classification (all rounds; each ray takes about 110 bytes while its round
#: runs): the monastery (125 k faces) casts 4 M at the defaults
MAX_RAYS = 100_000_000
#: sample points per intersecting or coplanar face (default 4)
MAX_SAMPLES_PER_FACE = 1_024
#: pixels of one rendered image: one primary ray each, about 150 bytes per pixel while
#: rendering (8192 x 8192 took 10.3 GB and 80 s), so 4096 x 4096 stays near 2.6 GB
MAX_PIXELS = 4096 * 4096
#: absolute value of a coordinate: products of up to six coordinates (squared areas of
#: cross products, squared lengths of Newell normals) must stay below the float64 maximum 1.8e308
MAX_COORDINATE = 1e50
#: bits of the PVS of all view cells together (cells x faces, a bit each): 2**34 bits are 2 GiB
MAX_PVS_BITS = 1 << 34
