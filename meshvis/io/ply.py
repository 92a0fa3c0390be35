"""PLY reader (ASCII, binary little and big endian) and binary writer.

The reader handles any element layout, lists of varying length included (mixed
triangles and polygons), reads vertex colours, UVs (per vertex ``u v``/``s t``/
``texture_u texture_v``, or per face ``texcoord`` lists), face colours, and the part /
material / group ids and names that :func:`write_ply` stores (face properties plus
``comment meshvis ...`` header lines).

Reading strategy: each element is first read as if every list had the length found in
its first row (one ``np.frombuffer`` / reshape); when the list lengths turn out to vary,
row starts are found by a Python walk over the rows and every property is then gathered
with numpy index arithmetic.
"""

from __future__ import annotations

import os
import struct
import warnings
from dataclasses import dataclass, field

import numpy as np

from meshvis.errors import ModelError, ModelFormatError
from meshvis.io._common import atomic_write, one_line, weld_corners, without_bom
from meshvis.io.edits import face_edits
from meshvis.io.ply_edit import NewProperty, write_edited
from meshvis.io.triangulate import triangulate
from meshvis.soup import Material, Soup, SourceRecord

_TYPES = {
    "char": "i1",
    "int8": "i1",
    "uchar": "u1",
    "uint8": "u1",
    "short": "i2",
    "int16": "i2",
    "ushort": "u2",
    "uint16": "u2",
    "int": "i4",
    "int32": "i4",
    "uint": "u4",
    "uint32": "u4",
    "float": "f4",
    "float32": "f4",
    "double": "f8",
    "float64": "f8",
}


class _Prop:
    __slots__ = ("name", "dtype", "count_dtype")

    def __init__(self, name: str, dtype: str, count_dtype: str | None = None):
        self.name, self.dtype, self.count_dtype = name, dtype, count_dtype


def _parse_header(data: bytes, label: str):
    """(format, elements [(name, n, [props])], comments, body offset)."""
    end = data.find(b"end_header")
    if end < 0:
        raise ModelFormatError("PLY header has no end_header line (truncated?)", label)
    nl = data.find(b"\n", end)
    body = len(data) if nl < 0 else nl + 1
    lines = data[:end].decode("latin-1").splitlines()
    if not lines or lines[0].strip() != "ply":
        raise ModelFormatError("not a PLY file (the first line is not 'ply')", label)
    fmt = None
    elements: list[tuple[str, int, list[_Prop]]] = []
    comments: list[str] = []
    for line in lines[1:]:
        tok = line.split()
        if not tok:
            continue
        if tok[0] == "format":
            if len(tok) < 2 or tok[1] not in ("ascii", "binary_little_endian", "binary_big_endian"):
                raise ModelFormatError(f"unknown PLY format line {line.strip()!r}", label)
            fmt = tok[1]
        elif tok[0] in ("comment", "obj_info"):
            comments.append(line.strip()[len(tok[0]) :].strip())
        elif tok[0] == "element":
            if len(tok) != 3 or not tok[2].isdigit():
                raise ModelFormatError(f"bad PLY element line {line.strip()!r}", label)
            elements.append((tok[1], int(tok[2]), []))
        elif tok[0] == "property":
            if not elements:
                raise ModelFormatError("PLY property before any element", label)
            try:
                if tok[1] == "list":
                    elements[-1][2].append(_Prop(tok[4], _TYPES[tok[3]], _TYPES[tok[2]]))
                else:
                    elements[-1][2].append(_Prop(tok[2], _TYPES[tok[1]]))
            except (KeyError, IndexError):
                raise ModelFormatError(f"bad PLY property line {line.strip()!r}", label) from None
    if fmt is None:
        raise ModelFormatError("PLY header has no format line", label)
    return fmt, elements, comments, body


def _read_binary(
    buf: memoryview, offset: int, n: int, props: list[_Prop], endian: str, label: str, name: str
):
    """Read ``n`` rows of one element from ``buf`` at ``offset``; returns (columns, new offset)."""
    total = len(buf)
    if not any(p.count_dtype for p in props):
        dt = np.dtype([(f"p{i}", endian + p.dtype) for i, p in enumerate(props)])
        if offset + n * dt.itemsize > total:
            raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label)
        arr = np.frombuffer(buf, dt, count=n, offset=offset)
        return {p.name: arr[f"p{i}"].astype(p.dtype) for i, p in enumerate(props)}, offset + n * dt.itemsize
    if n == 0:
        return {
            p.name: (np.zeros(0, np.int64), np.zeros(0, p.dtype)) if p.count_dtype else np.zeros(0, p.dtype)
            for p in props
        }, offset
    # every row holds at least its fixed properties and its list counts: a count of rows
    # the file cannot hold is refused before anything is allocated for them
    least = sum(np.dtype(p.count_dtype or p.dtype).itemsize for p in props)
    if offset + n * least > total:
        raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label)
    fixed = _read_fixed_lists(buf, offset, n, props, endian, label, name)
    if fixed is not None:
        return fixed
    row_start, counts, end = _walk_rows(buf, offset, n, props, endian, label, name)
    return _gather_rows(buf, row_start, counts, props, endian), end


def _read_fixed_lists(buf, offset: int, n: int, props: list[_Prop], endian: str, label: str, name: str):
    """Fast path: every list as long as in the first row (one structured read), or None."""
    total = len(buf)
    fields, pos, first_len = [], offset, {}
    for i, p in enumerate(props):
        if p.count_dtype:
            csize = np.dtype(p.count_dtype).itemsize
            if pos + csize > total:
                raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label)
            k = int(np.frombuffer(buf, endian + p.count_dtype, count=1, offset=pos)[0])
            if k < 0:
                raise ModelFormatError(f"a list of the '{name}' data has {k} entries", label)
            first_len[i] = k
            pos += csize + k * np.dtype(p.dtype).itemsize
            if pos > total:  # the first row already runs past the end
                raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label)
            fields.append((f"c{i}", endian + p.count_dtype))
            fields.append((f"p{i}", endian + p.dtype, (k,)))
        else:
            fields.append((f"p{i}", endian + p.dtype))
            pos += np.dtype(p.dtype).itemsize
    dt = np.dtype(fields)
    if offset + n * dt.itemsize > total:
        return None
    arr = np.frombuffer(buf, dt, count=n, offset=offset)
    if not all((arr[f"c{i}"] == k).all() for i, k in first_len.items()):
        return None
    out = {}
    for i, p in enumerate(props):
        if p.count_dtype:
            k = first_len[i]
            out[p.name] = (np.full(n, k, np.int64), arr[f"p{i}"].reshape(-1).astype(p.dtype))
        else:
            out[p.name] = arr[f"p{i}"].astype(p.dtype)
    return out, offset + n * dt.itemsize


def _walk_rows(buf, offset: int, n: int, props: list[_Prop], endian: str, label: str, name: str):
    """Slow path: walk the rows to find where each starts; returns (row starts, list counts, end)."""
    layout = []  # per property: (is_list, struct format of count, count size, item size)
    for p in props:
        if p.count_dtype:
            c = np.dtype(p.count_dtype)
            layout.append((True, endian + c.char, c.itemsize, np.dtype(p.dtype).itemsize))
        else:
            layout.append((False, "", np.dtype(p.dtype).itemsize, 0))
    counts = np.empty((n, sum(1 for p in props if p.count_dtype)), np.int64)
    row_start = np.empty(n, np.int64)
    unpack = struct.unpack_from
    pos = offset
    try:
        for r in range(n):
            row_start[r] = pos
            j = 0
            for is_list, cfmt, csize, isize in layout:
                if is_list:
                    k = unpack(cfmt, buf, pos)[0]
                    if k < 0:
                        raise ModelFormatError(f"a list of the '{name}' data has {k} entries", label)
                    counts[r, j] = k
                    j += 1
                    pos += csize + k * isize
                else:
                    pos += csize
    except struct.error:
        raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label) from None
    if pos > len(buf):
        raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label)
    return row_start, counts, pos


def _gather_rows(buf, row_start: np.ndarray, counts: np.ndarray, props: list[_Prop], endian: str) -> dict:
    """Every property's values, gathered from the rows found by :func:`_walk_rows`."""
    raw = np.frombuffer(buf, np.uint8)
    out = {}
    cursor = row_start.copy()
    j = 0
    for p in props:
        isize = np.dtype(p.dtype).itemsize
        if p.count_dtype:
            csize = np.dtype(p.count_dtype).itemsize
            k = counts[:, j]
            j += 1
            item_start = np.repeat(cursor + csize, k) + isize * (
                np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k)
            )
            idx = item_start[:, None] + np.arange(isize)
            out[p.name] = (k, raw[idx.ravel()].view(endian + p.dtype).astype(p.dtype))
            cursor = cursor + csize + k * isize
        else:
            idx = cursor[:, None] + np.arange(isize)
            out[p.name] = raw[idx.ravel()].view(endian + p.dtype).astype(p.dtype)
            cursor = cursor + isize
    return out


def _read_ascii(values: np.ndarray, offset: int, n: int, props: list[_Prop], label: str, name: str):
    """Like :func:`_read_binary` on the array of all numbers of an ASCII body."""
    total = len(values)
    lists = [p for p in props if p.count_dtype]
    if not lists:
        w = len(props)
        if offset + n * w > total:
            raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label)
        block = values[offset : offset + n * w].reshape(n, w)
        return {p.name: block[:, i].astype(p.dtype) for i, p in enumerate(props)}, offset + n * w
    if n == 0:
        return {
            p.name: (np.zeros(0, np.int64), np.zeros(0, p.dtype)) if p.count_dtype else np.zeros(0, p.dtype)
            for p in props
        }, offset
    if offset + n * len(props) > total:  # a row has at least one number per property
        raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label)
    # fast path: lists as long as in the first row
    width, pos, first_len = 0, offset, {}
    for i, p in enumerate(props):
        if p.count_dtype:
            if pos >= total:
                raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label)
            k = _list_count(values[pos], label, name)
            first_len[i] = (width, k)
            width += 1 + k
            pos += 1 + k
        else:
            width += 1
            pos += 1
    if offset + n * width <= total:
        block = values[offset : offset + n * width].reshape(n, width)
        if all((block[:, c] == k).all() for c, k in first_len.values()):
            out, col = {}, 0
            for i, p in enumerate(props):
                if p.count_dtype:
                    k = first_len[i][1]
                    out[p.name] = (
                        np.full(n, k, np.int64),
                        block[:, col + 1 : col + 1 + k].reshape(-1).astype(p.dtype),
                    )
                    col += 1 + k
                else:
                    out[p.name] = block[:, col].astype(p.dtype)
                    col += 1
            return out, offset + n * width
    # slow path: walk the rows
    is_list = [bool(p.count_dtype) for p in props]
    starts = np.empty((n, len(props)), np.int64)
    counts = np.ones((n, len(props)), np.int64)
    pos = offset
    vals = values.tolist() if n > 1000 else values
    try:
        for r in range(n):
            for j, lst in enumerate(is_list):
                if lst:
                    k = _list_count(vals[pos], label, name)
                    starts[r, j] = pos + 1
                    counts[r, j] = k
                    pos += 1 + k
                else:
                    starts[r, j] = pos
                    pos += 1
    except IndexError:
        raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label) from None
    if pos > total:
        raise ModelFormatError(f"the file is truncated (in the '{name}' data)", label)
    out = {}
    for j, p in enumerate(props):
        if p.count_dtype:
            k = counts[:, j]
            idx = np.repeat(starts[:, j], k) + (np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k))
            out[p.name] = (k, values[idx].astype(p.dtype))
        else:
            out[p.name] = values[starts[:, j]].astype(p.dtype)
    return out, pos


def _list_count(value: float, label: str, name: str) -> int:
    """The entry count of a list of an ASCII body: a whole number of at least 0."""
    if not (value >= 0 and value == int(value)):
        raise ModelFormatError(f"a list of the '{name}' data has {float(value):g} entries", label)
    return int(value)


@dataclass(eq=False)
class PlyLayout:
    """A PLY file's layout as read: what the editing writer copies.

    Parameters
    ----------
    fmt : str
        ``ascii``, ``binary_little_endian`` or ``binary_big_endian``.
    header : list of str
        The header lines from ``ply`` to ``end_header``, as written (comments and
        ``obj_info`` included, in place).
    elements : list of (name, count, properties)
        Every element with its properties and their types.
    raw : list of bytes
        Binary files: the bytes of every element's rows (copied unchanged); empty for ASCII.
    """

    fmt: str
    header: list[str]
    elements: list
    raw: list = field(default_factory=list)


def read_elements(path: str, label: str, layout: list | None = None):
    """All elements of a PLY file: ``{element: {property: array or (counts, values)}}`` and comments.

    When ``layout`` is a list, a :class:`PlyLayout` of the file is appended to it.
    """
    with open(path, "rb") as fh:
        data = without_bom(fh.read())
    fmt, elements, comments, body = _parse_header(data, label)
    out: dict[str, dict] = {}
    raw = []
    if fmt == "ascii":
        text = data[body:].decode("latin-1")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                values = np.fromstring(text, sep=" ")
        except (ValueError, DeprecationWarning):
            raise ModelFormatError("cannot read the numbers of the ASCII PLY data", label) from None
        pos = 0
        for name, n, props in elements:
            out[name], pos = _read_ascii(values, pos, n, props, label, name)
    else:
        endian = "<" if fmt == "binary_little_endian" else ">"
        buf = memoryview(data)
        pos = body
        for name, n, props in elements:
            start = pos
            out[name], pos = _read_binary(buf, pos, n, props, endian, label, name)
            if layout is not None:
                raw.append(data[start:pos])
    if layout is not None:
        header = data[:body].decode("latin-1").splitlines()
        layout.append(PlyLayout(fmt, header, elements, raw))
    return out, comments


def _colors(columns: dict, n: int) -> np.ndarray | None:
    """(n, 4) uint8 RGBA from red/green/blue[/alpha] properties (float ones scaled from [0, 1])."""
    for names in (
        ("red", "green", "blue", "alpha"),
        ("r", "g", "b", "a"),
        ("diffuse_red", "diffuse_green", "diffuse_blue", "diffuse_alpha"),
    ):
        if all(k in columns and not isinstance(columns[k], tuple) for k in names[:3]):
            out = np.full((n, 4), 255, np.uint8)
            for i, k in enumerate(names):
                if k in columns and not isinstance(columns[k], tuple):
                    c = np.asarray(columns[k])
                    if c.dtype.kind == "f":
                        c = np.clip(np.round(np.nan_to_num(c) * 255.0), 0, 255)
                    out[:, i] = np.clip(c, 0, 255).astype(np.uint8)
            return out
    return None


@dataclass(eq=False)
class PlySource:
    """What the PLY writer needs to edit the file instead of rebuilding it.

    Parameters
    ----------
    layout : PlyLayout
        The header's elements and properties.
    elements : dict
        Every element's columns as read, by element name.
    columns : dict
        The face element's columns as read.
    face_element : int
        Position of the face element in ``layout.elements``.
    index_name : str
        The face property holding the vertex indices.
    record : (m0,) int64
        Face row of every triangle as read.
    corners : (m0, 3) int64
        Positions in the flat vertex index list of the three corners of every triangle.
    """

    layout: PlyLayout
    elements: dict
    columns: dict
    face_element: int
    index_name: str
    record: np.ndarray
    corners: np.ndarray


def read_ply(path: str, label: str | None = None) -> Soup:
    """Read a PLY file into a :class:`Soup` (polygons triangulated, ``source_face`` = face row)."""
    label = label or path
    layout: list = []
    elements, comments = read_elements(path, label, layout)
    vert = elements.get("vertex")
    if vert is None or not all(k in vert for k in "xyz"):
        raise ModelFormatError("PLY file has no vertex x, y, z", label)
    vertices = np.column_stack([np.asarray(vert[k], np.float64) for k in "xyz"])
    face = elements.get("face")
    if face is None:
        raise ModelError("the model has no faces (a point cloud?)", label)
    index_name = _index_property(face, label)
    counts, corners = face[index_name]
    corners = corners.astype(np.int64)
    keep = _polygon_rows(counts, label)
    keep_corner = np.repeat(keep, counts)
    kept = np.flatnonzero(keep)
    k_corners = corners[keep_corner]
    if len(k_corners) and (k_corners.min() < 0 or k_corners.max() >= len(vertices)):
        bad = int(k_corners.min()) if k_corners.min() < 0 else int(k_corners.max())
        raise ModelError(
            f"vertex index {bad} is out of range (the model has {len(vertices)} vertices)", label
        )
    tri, src_local = triangulate(vertices, counts[keep], k_corners)
    src = kept[src_local]
    faces = k_corners[tri]
    uv = _uvs(vert, face, counts, keep_corner, tri, faces)
    colors = None
    vcol = _colors(vert, len(vertices))
    if vcol is not None:
        colors = vcol[faces]
    else:
        fcol = _colors(face, len(counts))
        if fcol is not None:
            colors = np.repeat(fcol[src][:, None, :], 3, axis=1)
    part_id, part_names, material_id, materials = _ids_and_names(face, comments, src, label)
    soup = Soup(
        vertices=vertices,
        faces=faces,
        part_id=part_id,
        part_names=part_names,
        source_face=src,
        material_id=material_id,
        materials=materials,
        uv=uv,
        colors=colors,
        path=label,
    )
    face_element = [e[0] for e in layout[0].elements].index("face")
    flat_pos = np.flatnonzero(keep_corner)[tri]
    data = PlySource(layout[0], elements, face, face_element, index_name, src.copy(), flat_pos)
    soup.source = SourceRecord("ply", soup.vertices, soup.faces.copy(), data)
    return soup


def _index_property(face: dict, label: str) -> str:
    """Name of the face property holding the vertex index lists."""
    name = next((k for k in ("vertex_indices", "vertex_index") if k in face), None)
    if name is None:
        name = next((k for k, v in face.items() if isinstance(v, tuple)), None)
    if name is None:
        raise ModelFormatError("PLY faces have no vertex index list", label)
    return name


def _polygon_rows(counts: np.ndarray, label: str) -> np.ndarray:
    """(p,) bool, the face rows that are polygons; two-corner rows are skipped with a warning."""
    if len(counts) == 0:
        raise ModelError("the model has no faces", label)
    keep = counts >= 3
    if not keep.all():
        if (counts < 2).any():
            raise ModelFormatError(
                f"face {int(np.argmax(counts < 2))} has {int(counts[np.argmax(counts < 2)])} vertices; "
                "a face needs at least 3",
                label,
            )
        warnings.warn(
            f"{label}: skipped {int((~keep).sum())} faces with 2 vertices (edges, not faces)", stacklevel=5
        )
        if not keep.any():
            raise ModelError("the model has no faces (only two-vertex records)", label)
    return keep


def _uvs(vert, face, counts, keep_corner, tri, faces) -> np.ndarray | None:
    """(m, 3, 2) per-corner UVs from a face ``texcoord`` list or per-vertex coordinates."""
    if "texcoord" in face and isinstance(face["texcoord"], tuple):
        tc_counts, tc = face["texcoord"]
        if np.array_equal(tc_counts, 2 * counts):
            return tc.astype(np.float64).reshape(-1, 2)[keep_corner][tri]
    for a, b in (("texture_u", "texture_v"), ("u", "v"), ("s", "t"), ("texture_s", "texture_t")):
        if a in vert and b in vert and not isinstance(vert[a], tuple):
            table = np.column_stack([np.asarray(vert[a], np.float64), np.asarray(vert[b], np.float64)])
            return table[faces]
    return None


def _ids_and_names(face, comments, src, label):
    """Part and material ids and names from the properties and comments :func:`write_ply` writes."""
    names = _comment_names(comments)
    part_id, part_names = None, []
    if "part_id" in face and not isinstance(face["part_id"], tuple):
        pid = np.asarray(face["part_id"], np.int64)[src]
        n_parts = int(pid.max()) + 1 if len(pid) else 0
        part_names = [names["part"].get(i, f"part{i}") for i in range(n_parts)]
        part_id = np.maximum(pid, 0)
    else:
        part_names = [os.path.splitext(os.path.basename(label))[0]]
    material_id, materials = None, []
    if "material_id" in face and not isinstance(face["material_id"], tuple):
        material_id = np.asarray(face["material_id"], np.int64)[src]
        n_mat = int(material_id.max()) + 1 if len(material_id) else 0
        materials = [Material(names["material"].get(i, f"material{i}")) for i in range(n_mat)]
    return part_id, part_names, material_id, materials


def _comment_names(comments: list[str]) -> dict[str, dict[int, str]]:
    """Names stored by :func:`write_ply` as ``comment meshvis <kind> <id> <name>``."""
    out: dict[str, dict[int, str]] = {"part": {}, "material": {}, "group": {}}
    for c in comments:
        tok = c.split(None, 3)
        if len(tok) >= 3 and tok[0] == "meshvis" and tok[1] in out and tok[2].lstrip("-").isdigit():
            out[tok[1]][int(tok[2])] = tok[3] if len(tok) > 3 else ""
    return out


# ---------------------------------------------------------------------------- writer
def _ply_type(values: np.ndarray) -> tuple[str, str]:
    """(PLY type name, numpy dtype) that holds ``values`` exactly when possible."""
    v = np.asarray(values)
    if v.dtype == bool:
        return "uchar", "u1"
    if v.dtype.kind in "iu":
        if len(v) == 0 or (v.min() >= -(2**31) and v.max() < 2**31):
            return "int", "<i4"
        return "double", "<f8"
    if v.dtype == np.float32:
        return "float", "<f4"
    return "double", "<f8"


def write_ply(soup: Soup, path: str, groups=None, group_names=None, face_values=None) -> bool:
    """Write ``soup`` as binary little-endian PLY (see :func:`meshvis.io.save`).

    Vertices are welded per (vertex, UV, colour); positions are written as doubles so the
    geometry round-trips exactly.  Face properties: ``part_id``, ``material_id`` (when
    there are materials), ``group`` (when given) and every ``face_values`` entry; the
    names of parts, materials and groups go into ``comment meshvis ...`` header lines.

    A soup read from a PLY file whose faces are input faces (some removed, turned over or
    repeated) on the vertices as read is written by editing the input instead
    (:mod:`meshvis.io.ply_edit`): every element and property keeps its type, the header
    its comments and ``obj_info``, binary stays binary, ASCII stays ASCII; ``groups`` and
    ``face_values`` are added as face properties (named groups in header comments).
    """
    edits = face_edits(soup, ("ply",))
    if edits is not None:
        added, comments = _added_properties(edits, groups, group_names, face_values)
        write_edited(edits, path, added, comments)
        return True
    corner_src, faces = weld_corners(soup)
    vdata, header_v = _vertex_rows(soup, corner_src)
    fdata, header_f, comments = _face_rows(soup, faces, groups, group_names, face_values)
    header = "\n".join(
        [
            "ply",
            "format binary_little_endian 1.0",
            *comments,
            f"element vertex {len(vdata)}",
            *header_v,
            f"element face {len(fdata)}",
            *header_f,
            "end_header",
        ]
    )
    with atomic_write(path, "wb") as fh:
        fh.write((header + "\n").encode("utf-8", "replace"))
        fh.write(vdata.tobytes())
        fh.write(fdata.tobytes())
    return False


def _added_properties(edits, groups, group_names, face_values) -> tuple[list[NewProperty], list[str]]:
    """``group`` and ``face_values`` as new face properties of an edited file, with comments."""
    taken = set(edits.record.data.columns)
    added, comments = [], []
    values = ({"group": groups} if groups is not None else {}) | dict(face_values or {})
    for key, val in values.items():
        safe = "".join(ch if ch.isalnum() or ch == "_" else "_" for ch in key) or "value"
        while safe in taken:
            safe += "_"
        taken.add(safe)
        ply_name, np_type = _ply_type(val)
        added.append(NewProperty(safe, ply_name, np.dtype(np_type).str[1:], np.asarray(val).astype(np_type)))
    if groups is not None:
        comments = [f"meshvis group {i} {one_line(nm, 1000)}" for i, nm in enumerate(group_names or [])]
    return added, comments


def _vertex_rows(soup: Soup, corner_src: np.ndarray) -> tuple[np.ndarray, list[str]]:
    """Vertex records (double positions, UVs, RGBA) and their header lines."""
    pos = soup.vertices[soup.faces.reshape(-1)[corner_src]]
    vfields = [("x", "<f8"), ("y", "<f8"), ("z", "<f8")]
    vcols = [pos[:, 0], pos[:, 1], pos[:, 2]]
    header_v = ["property double x", "property double y", "property double z"]
    if soup.uv is not None:
        uvc = soup.uv.reshape(-1, 2)[corner_src]
        vfields += [("texture_u", "<f8"), ("texture_v", "<f8")]
        vcols += [uvc[:, 0], uvc[:, 1]]
        header_v += ["property double texture_u", "property double texture_v"]
    if soup.colors is not None:
        col = soup.colors.reshape(-1, 4)[corner_src]
        for i, c in enumerate(("red", "green", "blue", "alpha")):
            vfields.append((c, "u1"))
            vcols.append(col[:, i])
            header_v.append(f"property uchar {c}")
    vdata = np.empty(len(pos), np.dtype(vfields))
    for (name, *_), col in zip(vfields, vcols):
        vdata[name] = col
    return vdata, header_v


def _face_rows(
    soup: Soup, faces, groups, group_names, face_values
) -> tuple[np.ndarray, list[str], list[str]]:
    """Face records (indices, ids, values), their header lines and the naming comments."""
    m = soup.n_faces
    ffields = [("n", "u1"), ("idx", "<i4", (3,))]
    fcols: list = [np.full(m, 3, np.uint8), faces.astype(np.int32)]
    header_f = ["property list uchar int vertex_indices"]
    comments = ["comment written by meshvis"]
    extra = {"part_id": soup.part_id}
    comments += [f"comment meshvis part {i} {one_line(nm, 1000)}" for i, nm in enumerate(soup.part_names)]
    if soup.materials or (soup.material_id >= 0).any():
        extra["material_id"] = soup.material_id
        comments += [
            f"comment meshvis material {i} {one_line(mt.name, 1000)}" for i, mt in enumerate(soup.materials)
        ]
    if groups is not None:
        extra["group"] = groups
        comments += [
            f"comment meshvis group {i} {one_line(nm, 1000)}" for i, nm in enumerate(group_names or [])
        ]
    for key, val in (face_values or {}).items():
        safe = "".join(ch if ch.isalnum() or ch == "_" else "_" for ch in key) or "value"
        while safe in extra or safe in ("n", "idx", "vertex_indices"):
            safe += "_"
        extra[safe] = val
    for key, val in extra.items():
        ply_name, np_type = _ply_type(val)
        ffields.append((key, np_type))
        fcols.append(np.asarray(val).astype(np_type))
        header_f.append(f"property {ply_name} {key}")
    fdata = np.empty(m, np.dtype(ffields))
    for (name, *_), col in zip(ffields, fcols):
        fdata[name] = col
    return fdata, header_f, comments


#: format name -> reader / writer, collected by :mod:`meshvis.io.reading` and :mod:`meshvis.io.writing`
READERS = {"ply": read_ply}
WRITERS = {"ply": write_ply}
