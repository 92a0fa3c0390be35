"""glTF 2.0 / GLB reader (flattened scene, instancing applied) and writer.

Reading: trimesh decodes the primitives (accessors, sparse data, Draco through DracoPy,
textures; buffers compressed with meshoptimizer are refused); the
scene tree is walked here from the file's own JSON, in file order, so that every *node
instance* becomes one part named after the node (or after its mesh when the node has no
name), all primitives of the node's mesh belong to that part, and material ids are the
file's material indices.  A mirroring node transform turns the faces back
(:meth:`Soup.transformed`).

Writing: one node per part (or per group), one primitive per run of faces with the same
material (so face order is kept when each part is contiguous), positions as
float32 relative to the node's translation (the centre of its bounding box, kept in
float64 in the JSON, which limits the precision lost to float32), UVs, RGBA vertex
colours and PBR materials with their base colour texture embedded.
"""

from __future__ import annotations

import base64
import io
import json
import os
import struct
import warnings

import numpy as np

from meshvis.errors import ModelError, ModelFormatError
from meshvis.io._common import BOM, atomic_write, unique_names, weld_corners
from meshvis.io.edits import face_edits
from meshvis.io.gltf_edit import (
    BIN_CHUNK,
    GLB_MAGIC,
    JSON_CHUNK,
    GltfSource,
    can_edit,
    read_container,
    write_edited,
)
from meshvis.io.mtl import describe_pbr
from meshvis.io.scene import mesh_soup, soup_from_scene
from meshvis.soup import Material, Soup, SourceRecord

_GLB_MAGIC = GLB_MAGIC
_JSON_CHUNK = JSON_CHUNK
_BIN_CHUNK = BIN_CHUNK


# ---------------------------------------------------------------------------- reading
def _local_matrix(node: dict) -> np.ndarray:
    """4x4 transform of a glTF node: ``matrix``, or T * R * S."""
    if "matrix" in node:
        return np.array(node["matrix"], np.float64).reshape(4, 4).T
    m = np.eye(4)
    if "scale" in node:
        m = np.diag(np.append(np.asarray(node["scale"], np.float64), 1.0)) @ m
    if "rotation" in node:
        x, y, z, w = np.asarray(node["rotation"], np.float64)
        r = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
        rot = np.eye(4)
        rot[:3, :3] = r
        m = rot @ m
    if "translation" in node:
        t = np.eye(4)
        t[:3, 3] = node["translation"]
        m = t @ m
    return m


def _instances(doc: dict) -> list[tuple[int, np.ndarray]]:
    """(node index, world matrix) of every node with a mesh, depth first in file order.

    The node graph has no cycle (:func:`check_document` refuses one), so the walk needs no
    record of the path: linear in the instances, however deep the graph.
    """
    nodes = doc.get("nodes", [])
    out = []
    stack = [(r, np.eye(4)) for r in reversed(_roots(doc, nodes))]
    while stack:
        i, parent = stack.pop()
        if not _index(i, len(nodes)):
            continue
        node = nodes[i]
        world = parent @ _local_matrix(node)
        if "mesh" in node:
            out.append((i, world))
        for c in reversed(node.get("children", [])):
            stack.append((c, world))
    return out


def _roots(doc: dict, nodes: list) -> list:
    """The root nodes of the scene shown.

    That is ``scene`` (else the first scene), or every node nobody lists as a child when the
    file has no scenes.
    """
    scenes = doc.get("scenes")
    if isinstance(scenes, list) and scenes:
        s = doc.get("scene", 0)
        scene = scenes[s if _index(s, len(scenes)) else 0]
        return list(scene.get("nodes", [])) if isinstance(scene, dict) else []
    children = {c for n in nodes if isinstance(n, dict) for c in n.get("children", [])}
    return [i for i in range(len(nodes)) if i not in children]


# ---------------------------------------------------------------------------- checks
# (before trimesh sees the file: what it may read, how far it may expand, what must index what)
#: glTF extensions that meshvis reads as the specification asks (Draco through DracoPy,
#: see :func:`_check_compression`)
IMPLEMENTED_EXTENSIONS = frozenset({"KHR_draco_mesh_compression"})
#: glTF extensions that change only what meshvis does not read (shading, lights, texture
#: formats): a file that requires one is read without it, with a warning
IGNORABLE_EXTENSIONS = frozenset(
    {
        "KHR_materials_pbrSpecularGlossiness",
        "KHR_materials_unlit",
        "KHR_materials_emissive_strength",
        "KHR_materials_clearcoat",
        "KHR_materials_transmission",
        "KHR_materials_volume",
        "KHR_materials_ior",
        "KHR_materials_specular",
        "KHR_materials_sheen",
        "KHR_materials_iridescence",
        "KHR_materials_anisotropy",
        "KHR_materials_dispersion",
        "KHR_materials_variants",
        "KHR_texture_transform",
        "KHR_texture_basisu",
        "EXT_texture_webp",
        "EXT_texture_avif",
        "KHR_lights_punctual",
        "KHR_xmp_json_ld",
    }
)


def check_document(doc: dict, path: str, label: str, buffers: list | None = None) -> None:
    """Refuse a glTF document that is unsafe or broken (raises :class:`ModelFormatError`).

    Unsafe: it reads outside its folder or from something that is not a file, or expands
    past the caps of :mod:`meshvis.limits`; broken: its accessors point at nothing or read
    past their data, or it requires an extension meshvis does not implement.

    Parameters
    ----------
    doc : dict
        The JSON document.
    path : str
        The file, whose folder external references resolve from.
    label : str
        The file's name in messages.
    buffers : list of bytes or None, optional
        The data of every buffer held in the file (None for an external one), as
        :func:`~meshvis.io.gltf_edit.read_container` returns it; default: every buffer is
        taken as long as it says.
    """
    _check_compression(doc, label)  # before the required extensions: its message is the more precise
    _check_extensions(doc, label)
    sizes = _check_uris(doc, path, label, buffers)
    file_bytes = os.path.getsize(path) + sum(s for s in sizes if s is not None)
    _check_expansion(_check_accessors(doc, label, sizes), file_bytes, label)
    _check_node_graph(doc, label)


def _check_extensions(doc: dict, label: str) -> None:
    """Refuse a file that requires an extension meshvis does not implement (glTF 2.0 §3.12).

    A required extension that changes only what meshvis does not read gets a warning.
    """
    import warnings

    required = [str(e) for e in _list(doc, "extensionsRequired", label)]
    missing = [e for e in required if e not in IMPLEMENTED_EXTENSIONS and e not in IGNORABLE_EXTENSIONS]
    if missing:
        raise ModelFormatError(
            f"the file requires the glTF extension {', '.join(missing)}, which meshvis does not implement",
            label,
        )
    ignored = [e for e in required if e in IGNORABLE_EXTENSIONS]
    if ignored:
        warnings.warn(
            f"{label}: the file requires the glTF extension {', '.join(ignored)}; meshvis reads it without "
            "(it changes only materials, textures or lights)",
            stacklevel=4,
        )


def _check_uris(doc: dict, path: str, label: str, held: list | None) -> list[int | None]:
    """External buffers and images must be regular files in the model's folder (or below).

    Returns the size in bytes of the data of every buffer (None: unknown, e.g. a missing file).
    """
    from urllib.parse import unquote

    from meshvis.io.mtl import outside_reference

    folder = os.path.dirname(os.path.abspath(path))
    sizes: list[int | None] = []
    for kind in ("buffers", "images"):
        for i, item in enumerate(_list(doc, kind, label)):
            uri = item.get("uri") if isinstance(item, dict) else None
            data = held[i] if kind == "buffers" and held is not None and i < len(held) else None
            size = len(data) if data is not None else None
            if isinstance(uri, str) and not uri.startswith("data:"):
                full = os.path.join(folder, unquote(uri))
                if outside_reference(unquote(uri), folder, folder):
                    raise ModelFormatError(
                        f"{kind[:-1]} {i} refers to {uri}, outside the model's folder", label
                    )
                if os.path.exists(full) and not os.path.isfile(full):
                    raise ModelFormatError(
                        f"{kind[:-1]} {i} refers to {uri}, which is not a regular file (a FIFO, socket or device)",
                        label,
                    )
                size = os.path.getsize(full) if os.path.isfile(full) else None
            if kind == "buffers":
                sizes.append(size)
    return sizes


#: the extensions that store buffer views compressed with meshoptimizer (not decoded here)
MESHOPT_EXTENSIONS = ("EXT_meshopt_compression", "KHR_meshopt_compression")


def _check_compression(doc: dict, label: str) -> None:
    """Compressed geometry is decoded, or refused: never read as its placeholder zeros.

    Draco-compressed primitives (``KHR_draco_mesh_compression``) are decoded by trimesh
    with DracoPy; without DracoPy their accessors would read as zeros (one point, every
    face degenerate).  Buffer views compressed with meshoptimizer are refused.
    """
    for i, view in enumerate(_list(doc, "bufferViews", label)):
        used = [
            e for e in MESHOPT_EXTENSIONS if isinstance(view, dict) and e in (view.get("extensions") or {})
        ]
        if used:
            raise ModelFormatError(
                f"bufferView {i} is compressed with {used[0]}, which meshvis does not decode", label
            )
    draco = any(
        isinstance(prim, dict) and "KHR_draco_mesh_compression" in (prim.get("extensions") or {})
        for mesh in _list(doc, "meshes", label)
        if isinstance(mesh, dict)
        for prim in mesh.get("primitives", [])
    )
    if draco:
        try:
            import DracoPy  # noqa: F401
        except ImportError:
            raise ModelFormatError(
                "the geometry is Draco-compressed and DracoPy, which decodes it, is not installed", label
            ) from None


def _list(doc: dict, key: str, label: str) -> list:
    value = doc.get(key, [])
    if not isinstance(value, list):
        raise ModelFormatError(f"'{key}' is not a list", label)
    return value


def _index(value, n: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and 0 <= value < n


#: bytes of one component of each accessor componentType, and components of each type
_COMPONENT_BYTES = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
_TYPE_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


def _check_accessors(doc: dict, label: str, sizes: list[int | None]) -> int:
    """Check that every accessor's bufferView exists and holds it, and every view its buffer.

    Returns the bytes all accessors decode to.
    """
    buffers, views = _list(doc, "buffers", label), _list(doc, "bufferViews", label)
    for i, v in enumerate(views):
        if not isinstance(v, dict) or not _index(v.get("buffer"), len(buffers)):
            raise ModelFormatError(f"bufferView {i} refers to a buffer that does not exist", label)
        offset, length = _whole(v.get("byteOffset", 0)), _whole(v.get("byteLength", 0))
        buf = buffers[v["buffer"]]
        declared = _whole(buf.get("byteLength")) if isinstance(buf, dict) and "byteLength" in buf else None
        actual = sizes[v["buffer"]] if v["buffer"] < len(sizes) else None
        if (
            offset is None
            or length is None
            or any(n is not None and offset + length > n for n in (declared, actual))
        ):
            raise ModelFormatError(f"bufferView {i} lies outside its buffer", label)
        stride = v.get("byteStride")
        if stride is not None and (_whole(stride) is None or not 4 <= stride <= 252):
            raise ModelFormatError(
                f"bufferView {i} has a byteStride of {stride!r} (glTF allows 4 to 252)", label
            )
    decoded = 0
    for i, a in enumerate(_list(doc, "accessors", label)):
        if not isinstance(a, dict):
            raise ModelFormatError(f"accessor {i} is not an object", label)
        count = a.get("count", 0)
        if _whole(count) is None:
            raise ModelFormatError(f"accessor {i} has an invalid count {count!r}", label)
        item = _COMPONENT_BYTES.get(a.get("componentType"), 4) * _TYPE_WIDTH.get(a.get("type"), 16)
        decoded += count * item
        sparse = a.get("sparse")
        if sparse is not None and (not isinstance(sparse, dict) or _whole(sparse.get("count")) is None):
            raise ModelFormatError(f"accessor {i} has an invalid sparse count", label)
        if sparse is not None and sparse["count"] > count:
            raise ModelFormatError(
                f"accessor {i} replaces {sparse['count']} of its {count} elements (sparse)", label
            )
        if "bufferView" not in a:
            continue  # all zeros (or sparse): counted in the expansion, not in a view
        if not _index(a["bufferView"], len(views)):
            raise ModelFormatError(
                f"accessor {i} refers to bufferView {a['bufferView']!r}, which does not exist", label
            )
        view = views[a["bufferView"]]
        offset, stride = _whole(a.get("byteOffset", 0)), view.get("byteStride", item)
        if offset is None:
            raise ModelFormatError(f"accessor {i} has an invalid byteOffset", label)
        if stride < item:
            raise ModelFormatError(
                f"accessor {i} has {item}-byte elements, wider than the byteStride {stride} of its bufferView",
                label,
            )
        if count and offset + (count - 1) * stride + item > view.get("byteLength", 0):
            raise ModelFormatError(f"accessor {i} reads past the end of bufferView {a['bufferView']}", label)
    return decoded


def _check_expansion(decoded: int, file_bytes: int, label: str) -> None:
    """Refuse a file whose accessors decode to more than the expansion cap allows.

    Images are not decoded when a file is read (a rebuilt output copies their bytes, or
    decodes them under the same cap), so they are not counted here.
    """
    from meshvis import limits

    allowed = max(limits.MIN_EXPANSION_BYTES, limits.MAX_EXPANSION * file_bytes)
    if decoded > allowed:
        raise ModelFormatError(
            f"the accessors decode to {decoded} bytes, more than {limits.MAX_EXPANSION} times "
            f"the {file_bytes} bytes of the file and its buffers (the cap MAX_EXPANSION of meshvis.limits; "
            f"at least MIN_EXPANSION_BYTES, {limits.MIN_EXPANSION_BYTES})",
            label,
        )


def _whole(value) -> int | None:
    """``value`` when it is a non-negative integer of the JSON, else None."""
    return value if isinstance(value, int) and not isinstance(value, bool) and value >= 0 else None


def _check_node_graph(doc: dict, label: str) -> None:
    """Count node instances and instanced triangles by the paths through the node graph.

    Memoised, so a graph that doubles at every level is counted in linear time.
    """
    from meshvis import limits

    nodes, meshes, accessors = (_list(doc, k, label) for k in ("nodes", "meshes", "accessors"))

    def mesh_faces(mi) -> int:
        if not _index(mi, len(meshes)) or not isinstance(meshes[mi], dict):
            return 0
        total = 0
        for prim in meshes[mi].get("primitives", []):
            key = prim.get("indices", prim.get("attributes", {}).get("POSITION"))
            if _index(key, len(accessors)) and isinstance(accessors[key], dict):
                total += int(accessors[key].get("count", 0)) // 3
        return total

    memo: dict[int, tuple[int, int]] = {}
    for i in _node_order(nodes, label):  # children before parents
        node = nodes[i]
        inst, faces = (1, mesh_faces(node["mesh"])) if "mesh" in node else (0, 0)
        for c in node.get("children", []):
            inst, faces = inst + memo[c][0], faces + memo[c][1]
        memo[i] = (min(inst, 1 << 62), min(faces, 1 << 62))
    _list(doc, "scenes", label)
    roots = _roots(doc, nodes)
    inst = sum(memo[r][0] for r in roots if r in memo)
    faces = sum(memo[r][1] for r in roots if r in memo)
    if inst > limits.MAX_INSTANCES:
        raise ModelFormatError(
            f"the scene places {inst} mesh instances, more than the cap of {limits.MAX_INSTANCES}", label
        )
    if faces > limits.MAX_INSTANCED_FACES:
        raise ModelFormatError(
            f"the scene instances {faces} triangles, more than the cap of {limits.MAX_INSTANCED_FACES}", label
        )


def _node_order(nodes: list, label: str) -> list[int]:
    """Node indices with every child before its parents; refuses bad child indices and cycles."""
    state = [0] * len(nodes)  # 0 new, 1 on the stack, 2 done
    order: list[int] = []
    for start in range(len(nodes)):
        if state[start]:
            continue
        stack = [(start, iter(_children(nodes, start, label)))]
        state[start] = 1
        while stack:
            i, it = stack[-1]
            c = next(it, None)
            if c is None:
                stack.pop()
                state[i] = 2
                order.append(i)
            elif state[c] == 1:
                raise ModelFormatError(f"node {c} is its own ancestor (a cycle in the node graph)", label)
            elif state[c] == 0:
                state[c] = 1
                stack.append((c, iter(_children(nodes, c, label))))
    return order


def _children(nodes: list, i: int, label: str) -> list[int]:
    node = nodes[i]
    if not isinstance(node, dict):
        raise ModelFormatError(f"node {i} is not an object", label)
    kids = node.get("children", [])
    if not isinstance(kids, list) or not all(_index(c, len(nodes)) for c in kids):
        raise ModelFormatError(f"node {i} has a child that does not exist", label)
    return kids


def read_gltf(path: str, label: str | None = None) -> Soup:
    """Read a .glb / .gltf file into a flattened soup (see the module docstring)."""
    import trimesh
    from PIL import Image

    label = label or path
    doc, buffers, glb_bin = read_container(path, label)
    check_document(doc, path, label, buffers)
    with open(path, "rb") as fh:
        head = fh.read(4)
    ftype = "glb" if head == _GLB_MAGIC else "gltf"
    source: object = path
    options: dict = {"file_type": ftype, "force": "scene", "process": False, "maintain_order": True}
    if head.startswith(BOM):  # trimesh reads JSON without one: hand it the text after the mark
        from trimesh.resolvers import FilePathResolver

        with open(path, "rb") as fh:
            source = io.BytesIO(fh.read()[len(BOM) :])
        options["resolver"] = FilePathResolver(path)
    with warnings.catch_warnings():  # images are opened, not decoded: the expansion is checked above
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)
        scene = trimesh.load(source, **options)
    meshes = doc.get("meshes", [])
    geoms = list(scene.geometry.values())
    prim_counts = [len(m.get("primitives", [])) for m in meshes]
    if sum(prim_counts) != len(geoms):
        # trimesh skipped or split something: fall back to its own scene graph
        return soup_from_scene(scene, path=label)
    first = np.concatenate([[0], np.cumsum(prim_counts)]).astype(int)
    json_mats = doc.get("materials", [])

    materials: list[Material] = [
        Material(str(m.get("name") or f"material{i}"), None) for i, m in enumerate(json_mats)
    ]
    # a material that meshvis only wrote so that UVs survive stands for "no material"
    placeholder = {
        i
        for i, m in enumerate(json_mats)
        if isinstance(m.get("extras"), dict) and m["extras"].get("meshvis_placeholder")
    }
    pieces: list[Soup] = []
    piece_rows: list[tuple[int, ...]] = []  # node, mesh, primitive, mirrored (see GltfSource)
    piece_part: list[int] = []
    names: list[str] = []
    nodes = doc.get("nodes", [])
    for node_index, world in _instances(doc):
        node = nodes[node_index]
        mi = node["mesh"]
        if not (0 <= mi < len(meshes)):
            raise ModelFormatError(f"node {node_index} refers to mesh {mi}, which does not exist", label)
        name = node.get("name") or meshes[mi].get("name") or f"node{node_index}"
        added = False
        for k, prim in enumerate(meshes[mi].get("primitives", [])):
            geom = geoms[first[mi] + k]
            if not hasattr(geom, "faces") or len(geom.faces) == 0:
                continue  # points or lines
            mat_index = int(prim.get("material", -1))
            if mat_index in placeholder:
                mat_index = -1
            if 0 <= mat_index < len(materials) and materials[mat_index].source is None:
                materials[mat_index].source = getattr(getattr(geom, "visual", None), "material", None)
            piece = mesh_soup(geom, name, mat_index if 0 <= mat_index < len(materials) else -1)
            if not np.allclose(world, np.eye(4)):
                piece = piece.transformed(world)
            pieces.append(piece)
            piece_rows.append((node_index, mi, k, int(np.linalg.det(world[:3, :3]) < 0)))
            piece_part.append(len(names))
            added = True
        if added:
            names.append(name)
    if not pieces:
        raise ModelError("the model has no faces", label)
    soup = Soup.concatenate(pieces)
    soup.part_id = np.repeat(np.array(piece_part, np.int64), [p.n_faces for p in pieces])
    soup.part_names = unique_names(names, "node")
    if placeholder:  # drop the placeholders and renumber the others
        keep = [i for i in range(len(materials)) if i not in placeholder]
        new_id = np.full(len(materials), -1, np.int64)
        new_id[keep] = np.arange(len(keep))
        soup.material_id = np.where(soup.material_id >= 0, new_id[np.maximum(soup.material_id, 0)], -1)
        materials = [materials[i] for i in keep]
    soup.materials = materials
    soup.path = label
    soup.source = _source_record(soup, pieces, piece_rows, doc, buffers, glb_bin, path)
    return soup


def _source_record(soup, pieces, rows, doc, buffers, glb_bin, path) -> SourceRecord:
    """The record that lets :func:`write_gltf` edit this document (see :class:`GltfSource`)."""
    n_v = np.array([p.n_vertices for p in pieces], np.int64)
    n_f = np.array([p.n_faces for p in pieces], np.int64)
    v0 = np.concatenate([[0], np.cumsum(n_v)[:-1]])
    f0 = np.concatenate([[0], np.cumsum(n_f)[:-1]])
    r = np.array(rows, np.int64).reshape(-1, 4)
    table = np.column_stack([r[:, :3], v0, n_v, f0, r[:, 3]])
    data = GltfSource(doc, buffers, glb_bin, os.path.dirname(os.path.abspath(path)), table)
    fmt = "glb" if glb_bin >= 0 or path.lower().endswith(".glb") else "gltf"
    return SourceRecord(fmt, soup.vertices, soup.faces.copy(), data)


# ---------------------------------------------------------------------------- writing
class _Buffer:
    """Binary buffer with 4-byte aligned views."""

    def __init__(self) -> None:
        self.chunks: list[bytes] = []
        self.size = 0
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def view(self, data: bytes, target: int | None = None) -> int:
        pad = (-self.size) % 4
        if pad:
            self.chunks.append(b"\x00" * pad)
            self.size += pad
        v = {"buffer": 0, "byteOffset": self.size, "byteLength": len(data)}
        if target is not None:
            v["target"] = target
        self.chunks.append(data)
        self.size += len(data)
        self.views.append(v)
        return len(self.views) - 1

    def accessor(
        self,
        array: np.ndarray,
        kind: str,
        component: int,
        target: int | None,
        normalized: bool = False,
        with_bounds: bool = False,
    ) -> int:
        view = self.view(np.ascontiguousarray(array).tobytes(), target)
        acc = {"bufferView": view, "componentType": component, "count": int(len(array)), "type": kind}
        if normalized:
            acc["normalized"] = True
        if with_bounds:
            a = np.asarray(array).reshape(len(array), -1)
            acc["min"] = a.min(axis=0).tolist()
            acc["max"] = a.max(axis=0).tolist()
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def data(self) -> bytes:
        blob = b"".join(self.chunks)
        return blob + b"\x00" * ((-len(blob)) % 4)


def write_gltf(
    soup: Soup, path: str, groups=None, group_names=None, face_values=None, *, binary: bool = True
) -> bool:
    """Write ``soup`` as GLB (``binary=True``) or as one self-contained .gltf (see the module docstring).

    A soup read from a glTF file whose faces are input faces (some removed, turned over,
    reordered or repeated) on the vertices as read is written by editing the input
    document (:mod:`meshvis.io.gltf_edit`; with ``groups``, each node keeps the faces of
    the first group and gets a child node per other group); any other soup is written
    from scratch, with one node per part or per group.
    """
    edits = face_edits(soup, ("glb", "gltf"))
    if (
        edits is not None
        and can_edit(edits.record.data, path)
        and write_edited(edits, soup.faces, path, binary, groups, group_names)
    ):
        return True

    buf = _Buffer()
    if groups is not None:
        node_of_face = groups
        node_names = list(group_names or [])
    else:
        node_of_face = soup.part_id
        node_names = list(soup.part_names)
    node_names = unique_names(
        node_names + [f"node{i}" for i in range(len(node_names), int(node_of_face.max()) + 1)], "node"
    )

    gl_materials, images, textures = _materials(soup, buf)
    # UVs are only read back with a material: faces without one get a marked placeholder
    placeholder = -1
    if soup.uv is not None and (soup.material_id < 0).any():
        placeholder = len(gl_materials)
        gl_materials.append(
            {
                "name": "meshvis_none",
                "extras": {"meshvis_placeholder": True},
                "pbrMetallicRoughness": {"metallicFactor": 0.0},
            }
        )

    nodes, meshes = _nodes_and_meshes(soup, buf, node_of_face, node_names, placeholder)
    doc: dict = {
        "asset": {"version": "2.0", "generator": "meshvis"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": buf.accessors,
        "bufferViews": buf.views,
    }
    if gl_materials:
        doc["materials"] = gl_materials
    if textures:
        doc["textures"] = textures
        doc["images"] = images
        doc["samplers"] = [{}]
    _serialise(doc, buf.data(), path, binary)
    return False


def _materials(soup: Soup, buf: _Buffer) -> tuple[list, list, list]:
    """GlTF materials, images and textures of the soup's materials (images into ``buf``)."""
    mat_names = unique_names([m.name for m in soup.materials], "material")
    gl_materials, images, textures = [], [], []
    image_cache: dict[bytes, int] = {}
    for mat, name in zip(soup.materials, mat_names):
        desc = describe_pbr(mat, name)
        pbr = {"baseColorFactor": [float(x) for x in desc.base_color]}
        pbr["metallicFactor"] = float(desc.metallic) if desc.metallic is not None else 0.0
        pbr["roughnessFactor"] = float(desc.roughness) if desc.roughness is not None else 1.0
        if desc.image is not None:
            if desc.image not in image_cache:
                view = buf.view(desc.image)
                images.append({"bufferView": view, "mimeType": desc.mime or "image/png"})
                textures.append({"source": len(images) - 1, "sampler": 0})
                image_cache[desc.image] = len(textures) - 1
            pbr["baseColorTexture"] = {"index": image_cache[desc.image]}
        entry = {"name": name, "pbrMetallicRoughness": pbr}
        if desc.double_sided:
            entry["doubleSided"] = True
        if desc.alpha_mode in ("MASK", "BLEND"):
            entry["alphaMode"] = desc.alpha_mode
        gl_materials.append(entry)

    return gl_materials, images, textures


def _nodes_and_meshes(soup: Soup, buf: _Buffer, node_of_face, node_names, placeholder: int):
    """One node and mesh per node number, one primitive per run of faces with one material."""
    _, first = np.unique(node_of_face, return_index=True)
    node_order = node_of_face[np.sort(first)]
    nodes, meshes = [], []
    for g in node_order.tolist():
        sel = np.flatnonzero(node_of_face == g)
        part = soup.subset(sel)
        lo, hi = part.bounds
        centre = (lo + hi) / 2.0
        primitives = []
        # one primitive per run of faces with the same material: face order is kept
        mids = part.material_id
        change = np.ones(len(mids), bool)
        change[1:] = mids[1:] != mids[:-1]
        run_start = np.flatnonzero(change)
        for a, b in zip(run_start.tolist(), np.append(run_start[1:], len(mids)).tolist()):
            mt = int(mids[a])
            piece = part.subset(np.arange(a, b))
            corner_src, faces = weld_corners(piece)
            pos = (piece.vertices[piece.faces.reshape(-1)[corner_src]] - centre).astype(np.float32)
            attrs = {"POSITION": buf.accessor(pos, "VEC3", 5126, 34962, with_bounds=True)}
            if piece.uv is not None:
                uv = piece.uv.reshape(-1, 2)[corner_src].astype(np.float32)
                uv[:, 1] = 1.0 - uv[:, 1]  # glTF's v axis points down
                attrs["TEXCOORD_0"] = buf.accessor(uv, "VEC2", 5126, 34962)
            if piece.colors is not None:
                col = piece.colors.reshape(-1, 4)[corner_src]
                attrs["COLOR_0"] = buf.accessor(col, "VEC4", 5121, 34962, normalized=True)
            prim = {
                "attributes": attrs,
                "indices": buf.accessor(faces.astype(np.uint32).reshape(-1), "SCALAR", 5125, 34963),
                "mode": 4,
            }
            if mt >= 0:
                prim["material"] = mt
            elif placeholder >= 0:
                prim["material"] = placeholder
            primitives.append(prim)
        meshes.append({"name": node_names[g], "primitives": primitives})
        nodes.append(
            {"name": node_names[g], "mesh": len(meshes) - 1, "translation": [float(c) for c in centre]}
        )

    return nodes, meshes


def _serialise(doc: dict, blob: bytes, path: str, binary: bool) -> None:
    """Write the document with its buffer as GLB, or as .gltf with a data URI."""
    if binary:
        doc["buffers"] = [{"byteLength": len(blob)}]
        js = json.dumps(doc, separators=(",", ":")).encode("utf-8")
        js += b" " * ((-len(js)) % 4)
        total = 12 + 8 + len(js) + 8 + len(blob)
        with atomic_write(path, "wb") as fh:
            fh.write(struct.pack("<4sII", _GLB_MAGIC, 2, total))
            fh.write(struct.pack("<II", len(js), _JSON_CHUNK))
            fh.write(js)
            fh.write(struct.pack("<II", len(blob), _BIN_CHUNK))
            fh.write(blob)
    else:
        uri = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
        doc["buffers"] = [{"byteLength": len(blob), "uri": uri}]
        with atomic_write(path, "w") as fh:
            json.dump(doc, fh, separators=(",", ":"))


def _write_glb(soup, path, groups, group_names, face_values) -> bool:
    return write_gltf(soup, path, groups, group_names, binary=True)


def _write_gltf_json(soup, path, groups, group_names, face_values) -> bool:
    return write_gltf(soup, path, groups, group_names, binary=False)


#: format name -> reader / writer, collected by :mod:`meshvis.io.reading` and :mod:`meshvis.io.writing`
READERS = {"glb": read_gltf, "gltf": read_gltf}
WRITERS = {"glb": _write_glb, "gltf": _write_gltf_json}
