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
#: face pairs the intersection tests compare (pairs whose boxes overlap, the copies of a
#: face set aside), per face: real models have tens (a 1.3 M-face city of the shared real
#: models 43); distinct faces stacked in one place make the pairs grow with their square
MAX_FACE_PAIRS_PER_FACE = 2_048
#: ... or this many, whatever the faces (a few seconds of work)
MIN_FACE_PAIRS = 1 << 26
#: rays per node of the graph cut (default 32); memory grows with nodes x rays
MAX_RAYS_PER_NODE = 65_536
#: copies of one triangle (the same corners, bit for bit) in a ray-casting scene: a ray
#: through a stack of copies tests every one of them, so 8,192 coincident cubes placed by a
#: 1 KB glTF made remove-interior take 10 minutes; the shared real models have at most 4
MAX_FACE_COPIES = 64
#: rays a classification may ask for, per byte of its input (the file, or the arrays of a
#: model given in memory), bounded before any work as if every face were flagged (512 rays
#: per face at the defaults, so a file needs 2 bytes per face; real files have 10-150): a
#: tiny file that places millions of faces is refused before its analysis (docs/scale.md)
RAYS_PER_INPUT_BYTE = 256
#: ... or this many, whatever the input (about 20 s of rays on two cores)
MIN_RAY_CAP = 1 << 24
#: most rays of the default budget of the from-region search
#: (:func:`meshvis.visibility.visible.default_budget`); an explicit budget may be larger
MAX_RAYS = 100_000_000
#: sample points per intersecting or coplanar face (default 4)
MAX_SAMPLES_PER_FACE = 1_024
#: pixels of one rendered image: one primary ray each, about 150 bytes per pixel while
#: rendering (8192 x 8192 took 10.3 GB and 80 s), so 4096 x 4096 stays near 2.6 GB
MAX_PIXELS = 4096 * 4096
#: absolute value of a coordinate: products of up to six coordinates (squared areas of
#: cross products, squared lengths of Newell normals) must stay below the float64 maximum 1.8e308
MAX_COORDINATE = 1e50
#: bytes the accessors of a glTF file may decode to, per byte of the file and the buffers it
#: names: real files decode about 1:1 (Draco about 10:1), but accessors of zeros (no
#: bufferView) or many accessors over the same bytes could ask for any amount
MAX_EXPANSION = 64
#: bytes the entries of a 3MF (zip) archive may inflate to, per byte of the archive: real
#: files inflate about 5:1, and parsing takes about 40 bytes of memory per byte of XML
MAX_ZIP_EXPANSION = 16
#: what any model file may expand to however small it is (16 MiB), for either rule above
MIN_EXPANSION_BYTES = 16 << 20
#: frames of one labelled sequence (``label --orbit``, a camera path): cameras are made
#: and read only up to this many
MAX_FRAMES = 1_000
#: pixels of all the frames of one labelled sequence together: each frame keeps its picture
#: and ID buffer (11 bytes a pixel) until the sequence is written, so 2**27 pixels (512
#: frames of 512 x 512) hold about 1.5 GB
MAX_SEQUENCE_PIXELS = 1 << 27
#: bits of the PVS of all view cells together (cells x faces, a bit each): 2**34 bits are 2 GiB
MAX_PVS_BITS = 1 << 34
