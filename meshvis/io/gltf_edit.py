"""Writing a repaired glTF/GLB by editing the input document.

The reader (:mod:`meshvis.io.gltf`) keeps the document, its buffers and, per *piece* (one
triangle primitive of one node instance), where its faces and vertices sit in the soup.
When a repair only removed, turned over, reordered or repeated input faces, the output is
the input document with only the index data of the changed primitives rewritten: nodes,
meshes, instancing, accessors, materials, textures (bytes untouched), animations, skins,
``extras`` and extensions stay as they were.

Rules:

* a primitive whose faces did not change keeps its accessor;
* new index data overwrites the old accessor's bytes when that accessor and its buffer
  view serve only this primitive and the data fits, else it is appended to the binary
  buffer as a new accessor;
* a mesh shared by several nodes is split only when its instances need different index
  data: instances needing the input's faces keep the mesh, every other variant gets a copy;
* a primitive left without faces is dropped from its mesh; a node whose mesh is left
  without primitives loses its mesh (and skin / morph weights), the mesh stays unused;
* a primitive drawn as a strip or a fan that changed is rewritten as a triangle list;
* a turned face's shading normals turn with it (:func:`turn_normals`);
* with face groups (e.g. layers), every node keeps the faces of the first group and gets
  a child node per other group it has faces in (:func:`_group_children`);
* a changed Draco-compressed primitive cannot be edited: the soup is then written anew.

The library pygltflib was measured as the document layer and not used: loading and saving
CesiumMilkTruck.glb with it adds default values to every material and accessor, rewrites
integer ``min``/``max`` as floats and moves every buffer view, so a no-op is not a no-op.
"""

from __future__ import annotations

import base64
import copy
import json
import os
import struct
from dataclasses import dataclass
from urllib.parse import unquote

import numpy as np

from meshvis.errors import ModelFormatError
from meshvis.io._common import atomic_write, without_bom
from meshvis.io.edits import FaceEdits, negate_in_type, split_turned_vertices
from meshvis.io.jsonfile import parse_json

GLB_MAGIC = b"glTF"
JSON_CHUNK = 0x4E4F534A
BIN_CHUNK = 0x004E4942
_DATA_URI = "data:"
_BASE64_PREFIX = "data:application/octet-stream;base64,"
#: glTF index component types and their numpy types, smallest first
_INDEX_TYPES = {5121: np.uint8, 5123: np.uint16, 5125: np.uint32}
_ELEMENT_ARRAY_BUFFER = 34963
_ARRAY_BUFFER = 34962
_TRIANGLES = 4
#: accessor component types and element widths
_COMPONENT_TYPES = {
    5120: np.int8,
    5121: np.uint8,
    5122: np.int16,
    5123: np.uint16,
    5125: np.uint32,
    5126: np.float32,
}
_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


@dataclass(eq=False)
class GltfSource:
    """The glTF input as the editing writer needs it.

    Parameters
    ----------
    doc : dict
        The JSON document as parsed (never modified; the writer edits a copy).
    buffers : list of bytes or None
        Data of every buffer: the GLB binary chunk or a decoded data URI; None for a buffer
        in an external file (kept by reference).
    glb_bin : int
        Index of the buffer stored as the GLB binary chunk, or -1.
    folder : str
        Folder of the input file (external references resolve from there).
    pieces : (k, 7) int64
        Per piece: node, mesh, primitive, first vertex in the soup, number of vertices,
        first face in the soup as read, mirrored (1 when the node's world transform has a
        negative determinant, so the soup's faces are the file's turned over).
    """

    doc: dict
    buffers: list
    glb_bin: int
    folder: str
    pieces: np.ndarray


# ---------------------------------------------------------------------------- reading
def read_container(path: str, label: str) -> tuple[dict, list, int]:
    """The JSON document, the buffer data and the index of the GLB binary buffer (-1 if none)."""
    with open(path, "rb") as fh:
        data = fh.read()
    chunk = None
    if data[:4] == GLB_MAGIC:
        raw, chunk = _glb_chunks(data, label)
    elif path.lower().endswith(".glb"):
        raise ModelFormatError("not a GLB file (it does not start with 'glTF')", label)
    else:
        raw = data
    try:
        doc = parse_json(without_bom(raw).decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        raise ModelFormatError(f"glTF JSON does not parse: {str(exc).splitlines()[0]}", label) from None
    if not isinstance(doc, dict) or "asset" not in doc:
        raise ModelFormatError("not a glTF document (no 'asset')", label)
    buffers: list = []
    glb_bin = -1
    for i, buf in enumerate(doc.get("buffers", []) if isinstance(doc.get("buffers"), list) else []):
        uri = buf.get("uri") if isinstance(buf, dict) else None
        if uri is None and chunk is not None and glb_bin < 0:
            size = buf.get("byteLength", len(chunk))  # the chunk may carry padding
            buffers.append(chunk[:size] if isinstance(size, int) and 0 <= size <= len(chunk) else chunk)
            glb_bin = i
        elif isinstance(uri, str) and uri.startswith(_DATA_URI) and ";base64," in uri:
            buffers.append(base64.b64decode(uri.split(";base64,", 1)[1]))
        else:
            buffers.append(None)
    return doc, buffers, glb_bin


def _glb_chunks(data: bytes, label: str) -> tuple[bytes, bytes | None]:
    """The JSON chunk and the binary chunk (or None) of a GLB file."""
    if len(data) < 20:
        raise ModelFormatError("GLB file is truncated (no JSON chunk)", label)
    _, _, total = struct.unpack_from("<III", data, 0)
    if total > len(data):
        raise ModelFormatError(f"GLB file is truncated: {total} bytes announced, {len(data)} found", label)
    length, kind = struct.unpack_from("<II", data, 12)
    if kind != JSON_CHUNK or 20 + length > len(data):
        raise ModelFormatError("GLB file has no valid JSON chunk", label)
    raw = data[20 : 20 + length]
    chunk = None
    for at in dict.fromkeys((20 + length, 20 + length + (-length) % 4)):  # tolerate an unaligned chunk
        if at + 8 <= len(data):
            blen, bkind = struct.unpack_from("<II", data, at)
            if bkind == BIN_CHUNK and at + 8 + blen <= len(data):
                chunk = data[at + 8 : at + 8 + blen]
                break
    return raw, chunk


# ---------------------------------------------------------------------------- writing
def can_edit(src: GltfSource, path: str) -> bool:
    """Whether the output at ``path`` can reference what the input references.

    External files (buffers, images) resolve from the input's folder: the document can be
    edited only when the output goes to the same folder, or when nothing is external.
    """
    external = any(b is None for b in src.buffers) or any(
        isinstance(im, dict) and isinstance(im.get("uri"), str) and not im["uri"].startswith(_DATA_URI)
        for im in src.doc.get("images", [])
    )
    if not external:
        return True
    out_folder = os.path.dirname(os.path.abspath(path))
    return os.path.abspath(src.folder) == out_folder


def write_edited(
    edits: FaceEdits,
    faces: np.ndarray,
    path: str,
    binary: bool,
    groups: np.ndarray | None = None,
    group_names: list[str] | None = None,
) -> bool:
    """Write the input document with the faces of the soup (see the module docstring).

    Parameters
    ----------
    edits : FaceEdits
        The soup as edits of its source (``edits.record.data`` is a :class:`GltfSource`).
    faces : (m, 3) int64
        The soup's faces (indices into its vertices).
    path : str
        Output file.
    binary : bool
        GLB (True) or a self-contained .gltf with data URIs (False).
    groups : (m,) int64, optional
        A group per face (e.g. a layer).  Every node keeps the faces of the first group
        present; the faces of every other group go to a new child node of each node,
        named ``<node>.<group name>`` (see :func:`_group_children`).
    group_names : list of str, optional
        Name of every group number.

    Returns
    -------
    bool
        False (nothing written) when a changed primitive is Draco-compressed.
    """
    src: GltfSource = edits.record.data
    if groups is None or len(groups) == 0:
        parts = [(0, _piece_indices(src, edits, faces))]
    else:
        parts = []
        for g in np.unique(groups).tolist():
            sel = groups == g
            sub = FaceEdits(edits.record, edits.origin[sel], edits.flipped[sel])
            parts.append((g, _piece_indices(src, sub, faces[sel])))
    if any(_compressed(src.doc, v) for _, v in parts):
        return False
    doc = copy.deepcopy(src.doc)
    buffers = [bytearray(b) if b is not None else None for b in src.buffers]
    state = _EditState(doc, buffers, src.glb_bin, src.folder)
    instances = list(dict.fromkeys(int(n) for n in src.pieces[:, 0]))
    users = list(instances)
    changes = dict(parts[0][1])
    for g, variant in parts[1:]:
        name = (group_names or [])[g] if g < len(group_names or []) else f"group{g}"
        children = _group_children(doc, instances, variant, name)
        changes.update(children)
        users += list(children)
    _apply_variants(state, users, changes)
    _write_document(state, path, binary)
    return True


def _group_children(doc: dict, users: list[int], variant: dict, name: str) -> dict:
    """One child node per node with faces in a group; returns child -> its primitive changes.

    The child has no transform of its own (it moves with its parent, animations
    included), the parent's mesh, skin and morph weights, and the name
    ``<parent>.<name>``; :func:`_apply_variants` then gives it the group's faces.
    """
    nodes = doc["nodes"]
    out = {}
    for node in users:
        change = variant.get(node, {})
        n_prims = len(doc["meshes"][nodes[node]["mesh"]]["primitives"])
        if change and sum(1 for v, _ in change.values() if len(v) == 0) == n_prims:
            continue  # no face of this node in the group
        parent = nodes[node]
        stem = (
            parent.get("name") or doc["meshes"][parent["mesh"]].get("name") or f"node{node}"
        )  # as the reader
        child = {"name": f"{stem}.{name}", "mesh": parent["mesh"]}
        child.update({k: parent[k] for k in ("skin", "weights") if k in parent})
        nodes.append(child)
        parent.setdefault("children", []).append(len(nodes) - 1)
        out[len(nodes) - 1] = change
    return out


def _compressed(doc: dict, changes: dict) -> bool:
    """Whether a changed primitive stores its data compressed (Draco): its indices cannot be edited."""
    nodes, meshes = doc.get("nodes", []), doc.get("meshes", [])
    for node, prims in changes.items():
        mesh = meshes[nodes[node]["mesh"]]
        for k in prims:
            if "KHR_draco_mesh_compression" in (mesh["primitives"][k].get("extensions") or {}):
                return True
    return False


def _piece_indices(src: GltfSource, edits: FaceEdits, faces: np.ndarray) -> dict:
    """Map node -> {primitive -> ((t, 3) local indices, (t,) turned over)} for every changed piece."""
    pieces = src.pieces
    first_face = pieces[:, 5]
    n_faces = np.diff(np.append(first_face, len(edits.record.faces)))
    piece_of = np.searchsorted(first_face, edits.origin, side="right") - 1
    order = np.argsort(piece_of, kind="stable")
    bounds = np.searchsorted(piece_of[order], np.arange(len(pieces) + 1))
    out: dict = {}
    for p in range(len(pieces)):
        node, _, prim, v0, _, f0, mirrored = (int(x) for x in pieces[p])
        sel = order[bounds[p] : bounds[p + 1]]
        local = faces[sel] - v0
        orig = edits.record.faces[f0 : f0 + n_faces[p]] - v0
        if mirrored:  # the reader turned these faces over; undo it for the file
            local, orig = local[:, [0, 2, 1]], orig[:, [0, 2, 1]]
        if not np.array_equal(local, orig):
            out.setdefault(node, {})[prim] = (local, edits.flipped[sel])
    return out


class _EditState:
    """The document being edited, its buffers and the accessors that may be overwritten."""

    def __init__(self, doc: dict, buffers: list, glb_bin: int, folder: str = ".") -> None:
        self.doc = doc
        self.buffers = buffers
        self.glb_bin = glb_bin
        self.folder = folder
        self.original = [bytes(b) if b is not None else None for b in buffers]
        self.uses = self._accessor_uses()

    def _buffer(self, index: int) -> bytes:
        """The input data of a buffer (an external one read from the input's folder once)."""
        data = self.original[index]
        if data is None:
            uri = self.doc["buffers"][index]["uri"]
            with open(os.path.join(self.folder, unquote(uri)), "rb") as fh:
                data = self.original[index] = fh.read()
        return data

    def read_accessor(self, index: int) -> np.ndarray:
        """(count, components) values of an accessor in its own component type, sparse applied."""
        acc = self.doc["accessors"][index]
        dt = np.dtype(_COMPONENT_TYPES[acc["componentType"]]).newbyteorder("<")
        width = _COMPONENTS[acc["type"]]
        out = np.zeros((acc["count"], width), dt)
        if "bufferView" in acc:
            bv = self.doc["bufferViews"][acc["bufferView"]]
            stride = bv.get("byteStride", width * dt.itemsize)
            start = bv.get("byteOffset", 0) + acc.get("byteOffset", 0)
            data = self._buffer(bv["buffer"])
            out[:] = np.ndarray(out.shape, dt, data, start, (stride, dt.itemsize))
        sparse = acc.get("sparse")
        if sparse:
            n = sparse["count"]
            at = self._view_array(sparse["indices"], _COMPONENT_TYPES[sparse["indices"]["componentType"]], n)
            out[at.astype(np.int64)] = self._view_array(sparse["values"], dt, n * width).reshape(n, width)
        return out

    def _view_array(self, ref: dict, dtype, n: int) -> np.ndarray:
        bv = self.doc["bufferViews"][ref["bufferView"]]
        dt = np.dtype(dtype).newbyteorder("<")
        start = bv.get("byteOffset", 0) + ref.get("byteOffset", 0)
        return np.frombuffer(self._buffer(bv["buffer"]), dt, n, start)

    def add_accessor(self, like: dict, values: np.ndarray) -> int:
        """A new vertex attribute accessor holding ``values`` with the type of accessor ``like``."""
        dt = values.dtype.newbyteorder("<")
        size = values.shape[1] * dt.itemsize
        stride = size + (-size) % 4  # vertex attribute elements are 4-byte aligned
        rows = np.zeros((len(values), stride), np.uint8)
        rows[:, :size] = np.ascontiguousarray(values.astype(dt)).view(np.uint8).reshape(len(values), size)
        view = self._append_view(rows.tobytes(), _ARRAY_BUFFER, stride if stride != size else None)
        acc = {k: like[k] for k in ("componentType", "normalized", "type") if k in like}
        acc.update(bufferView=view, count=int(len(values)))
        for key, fn in (("min", np.min), ("max", np.max)):
            if key in like and len(values):
                acc[key] = fn(values, axis=0).tolist()
        accs = self.doc["accessors"]
        accs.append(acc)
        return len(accs) - 1

    def _accessor_uses(self) -> dict[int, int]:
        """How many primitives (of all meshes) use each accessor as indices."""
        uses: dict[int, int] = {}
        for mesh in self.doc.get("meshes", []):
            for prim in mesh.get("primitives", []):
                if "indices" in prim:
                    uses[prim["indices"]] = uses.get(prim["indices"], 0) + 1
        return uses

    def _view_users(self, view: int) -> int:
        accs = self.doc.get("accessors", [])
        users = sum(1 for a in accs if a.get("bufferView") == view)
        users += sum(1 for im in self.doc.get("images", []) if im.get("bufferView") == view)
        for a in accs:
            sp = a.get("sparse")
            if sp and view in (sp["indices"].get("bufferView"), sp["values"].get("bufferView")):
                users += 1
        return users

    def set_indices(self, prim: dict, local: np.ndarray) -> None:
        """Give ``prim`` the triangle list ``local``: overwrite its accessor or add one."""
        flat = np.ascontiguousarray(local.reshape(-1))
        top = int(flat.max()) if len(flat) else 0
        acc_index = prim.get("indices")
        accs = self.doc.setdefault("accessors", [])
        if acc_index is not None and self._overwrite(acc_index, flat, top):
            if prim.get("mode", _TRIANGLES) != _TRIANGLES:
                prim["mode"] = _TRIANGLES
            return
        ctype = accs[acc_index]["componentType"] if acc_index is not None else 5125
        if ctype not in _INDEX_TYPES or top > np.iinfo(_INDEX_TYPES[ctype]).max:
            ctype = 5125
        data = flat.astype(_INDEX_TYPES[ctype]).tobytes()
        view = self._append_view(data)
        accs.append(
            {
                "bufferView": view,
                "componentType": ctype,
                "count": int(len(flat)),
                "type": "SCALAR",
                "min": [int(flat.min())],
                "max": [top],
            }
        )
        if acc_index is not None:
            self.uses[acc_index] -= 1
        prim["indices"] = len(accs) - 1
        if prim.get("mode", _TRIANGLES) != _TRIANGLES:
            prim["mode"] = _TRIANGLES

    def _overwrite(self, acc_index: int, flat: np.ndarray, top: int) -> bool:
        """Write ``flat`` over the accessor's own bytes when nothing else uses them."""
        acc = self.doc["accessors"][acc_index]
        view = acc.get("bufferView")
        ctype = acc.get("componentType")
        if self.uses.get(acc_index, 0) != 1 or view is None or "sparse" in acc or ctype not in _INDEX_TYPES:
            return False
        if top > np.iinfo(_INDEX_TYPES[ctype]).max or self._view_users(view) != 1:
            return False
        bv = self.doc["bufferViews"][view]
        data = self.buffers[bv["buffer"]] if bv["buffer"] < len(self.buffers) else None
        if data is None or "byteStride" in bv or "extensions" in bv:  # e.g. meshopt-compressed
            return False
        raw = flat.astype(_INDEX_TYPES[ctype]).tobytes()
        start = bv.get("byteOffset", 0) + acc.get("byteOffset", 0)
        if len(raw) > bv["byteLength"] - acc.get("byteOffset", 0) or len(flat) == 0:
            return False
        data[start : start + len(raw)] = raw
        acc["count"] = int(len(flat))
        if "min" in acc:
            acc["min"] = [int(flat.min())]
        if "max" in acc:
            acc["max"] = [top]
        return True

    def _append_view(self, data: bytes, kind: int = _ELEMENT_ARRAY_BUFFER, stride: int | None = None) -> int:
        """A new buffer view holding ``data``, at the end of the binary buffer."""
        target = (
            self.glb_bin if self.glb_bin >= 0 else (0 if self.buffers and self.buffers[0] is not None else -1)
        )
        bufs = self.doc.setdefault("buffers", [])
        if target < 0:
            bufs.append({"byteLength": 0})
            self.buffers.append(bytearray())
            target = len(bufs) - 1
            if self.glb_bin < 0 and target == 0:
                self.glb_bin = 0
        blob = self.buffers[target]
        blob.extend(b"\x00" * ((-len(blob)) % 4))
        offset = len(blob)
        blob.extend(data)
        views = self.doc.setdefault("bufferViews", [])
        view = {"buffer": target, "byteOffset": offset, "byteLength": len(data)}
        if stride:
            view["byteStride"] = stride
        views.append({**view, "target": kind})
        return len(views) - 1


def _apply_variants(state: _EditState, users: list[int], changes: dict) -> None:
    """Edit the meshes of the nodes ``users`` for their changes, splitting a shared mesh only when needed."""
    doc = state.doc
    nodes = doc.get("nodes", [])
    original = copy.deepcopy(doc.get("meshes", []))
    instances: dict[int, list[int]] = {}
    for node in users:
        instances.setdefault(int(nodes[node]["mesh"]), []).append(node)
    for mesh_index, users in instances.items():
        keyed: dict = {}
        for node in users:
            change = changes.get(node, {})
            key = tuple(sorted((k, v.shape[0], v.tobytes(), t.tobytes()) for k, (v, t) in change.items()))
            keyed.setdefault(key, []).append(node)
        if list(keyed) == [()]:
            continue
        base = () if () in keyed else next(iter(keyed))
        # copies first, so that the mesh kept by the base variant is the last user of its data
        for key in sorted(keyed, key=lambda k: k == base):
            if key == ():
                continue
            group = keyed[key]
            target = mesh_index
            n_prims = len(original[mesh_index]["primitives"])
            if sum(1 for v, _ in changes[group[0]].values() if len(v) == 0) == n_prims:
                _drop_mesh(doc, group)  # nothing left to draw: no copy needed
                continue
            if key != base:  # instances that need other faces than the mesh keeps: a copy
                doc["meshes"].append(copy.deepcopy(original[mesh_index]))
                target = len(doc["meshes"]) - 1
                for prim in doc["meshes"][target]["primitives"]:
                    if "indices" in prim:
                        state.uses[prim["indices"]] = state.uses.get(prim["indices"], 0) + 1
                for node in group:
                    nodes[node]["mesh"] = target
            _edit_mesh(state, target, changes[group[0]])


def turn_normals(state: _EditState, prim: dict, local: np.ndarray, turned: np.ndarray) -> np.ndarray:
    """Turn the shading normals of a primitive's turned-over faces; return its new indices.

    The normals of a turned face are turned unless they already lie on its new front
    (:func:`already_front`).  A vertex used only by turned faces gets its ``NORMAL`` negated (and its ``TANGENT``
    handedness ``w``, so that the bitangent keeps following the texture); a vertex used by
    turned and unturned faces is copied with every attribute (and morph target) and the
    turned faces point at the copy.  The primitive gets new
    accessors for the attributes that change; the input's accessors stay as they were.
    Without ``NORMAL`` and ``TANGENT`` (viewers then shade by the winding) nothing changes.

    Parameters
    ----------
    state : _EditState
    prim : dict
        The primitive, edited in place (its ``attributes`` and ``targets``).
    local : (t, 3) int64
        The primitive's new triangles (indices into its vertices).
    turned : (t,) bool
        Which of them are turned over.

    Returns
    -------
    (t, 3) int64
        ``local`` with the turned faces' corners on the copies.
    """
    attrs = prim.get("attributes", {})
    if not ({"NORMAL", "TANGENT"} & set(attrs)) or "POSITION" not in attrs:
        return local
    n = int(state.doc["accessors"][attrs["POSITION"]]["count"])
    if "NORMAL" in attrs:
        turned = turned & ~already_front(
            state.read_accessor(attrs["POSITION"]).astype(np.float64),
            state.read_accessor(attrs["NORMAL"]).astype(np.float64),
            local,
        )
    if not turned.any():
        return local
    plan = split_turned_vertices(local.reshape(-1), np.repeat(turned, 3), n)
    rows, negate, copied = plan.rows, plan.negate, len(plan.rows) > n
    for table, is_target in [(attrs, False)] + [(t, True) for t in prim.get("targets", [])]:
        for name, index in list(table.items()):
            if not copied and name not in ("NORMAL", "TANGENT"):
                continue
            values = state.read_accessor(index)[rows]
            if name == "NORMAL":
                values[negate] = negate_in_type(values[negate])
            elif name == "TANGENT" and not is_target:  # a target's TANGENT is an xyz delta
                values[negate, 3:] = negate_in_type(values[negate, 3:])
            table[name] = state.add_accessor(state.doc["accessors"][index], values)
    return plan.indices.reshape(-1, 3)


def already_front(positions: np.ndarray, normals: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Per face, whether its corners' shading normals already lie on the side its winding makes the front.

    The mean over the corners of (normal . geometric normal) is positive.  A turned face
    whose normals followed its old winding (the usual case) has them turned with it; one
    whose normals disagreed with its old winding keeps them, as they point to the side
    the repair made the front.  A degenerate face counts as not on the front.

    Parameters
    ----------
    positions : (n, 3) float64
    normals : (n, 3) float64
        Shading normal of every vertex (``faces`` index both).
    faces : (t, 3) int64
        The faces as written (turned faces in their new winding).

    Returns
    -------
    (t,) bool
    """
    p = positions[faces]
    g = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return np.einsum("tcj,tj->t", normals[faces], g) > 0


def _drop_mesh(doc: dict, users: list[int]) -> None:
    """The nodes keep their place in the tree, not their mesh (nor its skin and morph weights)."""
    for node in users:
        for key in ("mesh", "skin", "weights"):
            doc["nodes"][node].pop(key, None)


def _edit_mesh(state: _EditState, mesh_index: int, change: dict) -> None:
    """Give the primitives of one mesh their new faces; drop the ones left empty."""
    mesh = state.doc["meshes"][mesh_index]
    prims = mesh["primitives"]
    empty = [k for k, (local, _) in change.items() if len(local) == 0]
    for k, (local, turned) in change.items():
        if len(local):
            if turned.any():
                local = turn_normals(state, prims[k], local, turned)
            state.set_indices(prims[k], local)
    for k in sorted(empty, reverse=True):
        acc = prims[k].get("indices")
        if acc is not None:
            state.uses[acc] -= 1
        del prims[k]


def _write_document(state: _EditState, path: str, binary: bool) -> None:
    """Serialise the edited document as GLB or as .gltf with data URIs."""
    doc, buffers = state.doc, state.buffers
    bufs = doc.get("buffers", [])
    glb_bin = state.glb_bin if binary else -1
    if binary and glb_bin < 0 and bufs and buffers[0] is not None:
        glb_bin = 0  # a .gltf's first embedded buffer becomes the GLB binary chunk
    for i, (entry, data) in enumerate(zip(bufs, buffers)):
        if data is None:
            continue
        entry["byteLength"] = max(len(data), int(entry.get("byteLength", 0)))
        if i == glb_bin:
            entry.pop("uri", None)
        elif i == state.glb_bin or i >= len(state.original) or bytes(data) != state.original[i]:
            uri = entry.get("uri") or ""
            prefix = uri.split(",", 1)[0] + "," if uri.startswith(_DATA_URI) else _BASE64_PREFIX
            entry["uri"] = prefix + base64.b64encode(bytes(data)).decode("ascii")
    if not binary:
        with atomic_write(path, "w") as fh:
            json.dump(doc, fh, separators=(",", ":"))
        return
    js = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    js += b" " * ((-len(js)) % 4)
    blob = bytes(buffers[glb_bin]) if glb_bin >= 0 else b""
    blob += b"\x00" * ((-len(blob)) % 4)
    total = 12 + 8 + len(js) + (8 + len(blob) if glb_bin >= 0 else 0)
    with atomic_write(path, "wb") as fh:
        fh.write(struct.pack("<4sII", GLB_MAGIC, 2, total))
        fh.write(struct.pack("<II", len(js), JSON_CHUNK))
        fh.write(js)
        if glb_bin >= 0:
            fh.write(struct.pack("<II", len(blob), BIN_CHUNK))
            fh.write(blob)
