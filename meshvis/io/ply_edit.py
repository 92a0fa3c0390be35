"""Writing a repaired PLY by editing the input file.

The header is written as read (comments, ``obj_info`` and every element and property
with its type), except the face count; every element other than the faces is copied
(binary: byte for byte).  Face rows: a polygon whose triangles are all kept and wound
alike is written as its input row (index list reversed after its first corner when turned
over); the kept triangles of any other polygon become rows of their own with the polygon's
other properties; per-corner lists (e.g. ``texcoord``, two numbers per corner) follow
their corners.  A binary file stays binary in the same byte order, ASCII stays ASCII.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from meshvis.io._common import atomic_write
from meshvis.io.edits import FaceEdits, negate_in_type, split_turned_vertices


@dataclass(frozen=True)
class NewProperty:
    """A face property the editing writer adds (e.g. the ``layer`` of :func:`meshvis.layers`).

    Parameters
    ----------
    name : str
    type_name : str
        PLY type (``int``, ``uchar``, ``double``, ...).
    dtype : str
        numpy type without byte order (``i4``, ``u1``, ``f8``, ...).
    values : (m,) array
        One value per face of the soup.
    """

    name: str
    type_name: str
    dtype: str
    values: np.ndarray
    count_dtype: None = None


def write_edited(
    edits: FaceEdits, path: str, added: list[NewProperty] | None = None, comments: list[str] | None = None
) -> None:
    """Write the input PLY with the soup's faces (see the module docstring).

    Parameters
    ----------
    edits : FaceEdits
        The soup as edits of its source (``edits.record.data`` is a ``PlySource``).
    path : str
        Output file.
    added : list of NewProperty, optional
        Face properties to add after the input's; a polygon whose triangles have different
        values is written as its triangles.
    comments : list of str, optional
        Header comment lines to add (without ``comment``).
    """
    src = edits.record.data
    layout = src.layout
    added = list(added or [])
    columns, corner_turned = _face_rows(edits, src, added)
    n_rows = len(columns[src.index_name][0])
    name, _, props = layout.elements[src.face_element]
    props = list(props) + added
    rows = {src.face_element: (columns, props, n_rows)}
    vertex = _turned_normals(src, columns, corner_turned)
    if vertex is not None:
        rows[vertex[0]] = vertex[1:]
    counts = {layout.elements[i][0]: r[2] for i, r in rows.items()}
    head = _header(layout.header, name, counts, added, comments or [])
    if layout.fmt == "ascii":
        body = [
            _encode_ascii(*rows[i]) if i in rows else _encode_ascii(src.elements[e], p, n)
            for i, (e, n, p) in enumerate(layout.elements)
        ]
        data = head + "".join(body).encode("latin-1")
    else:
        endian = "<" if layout.fmt == "binary_little_endian" else ">"
        parts = list(layout.raw)
        for i, r in rows.items():
            parts[i] = _encode_binary(*r, endian)
        data = head + b"".join(parts)
    with atomic_write(path, "wb") as fh:
        fh.write(data)


def _header(lines: list[str], face: str, counts: dict, added: list, comments: list[str]) -> bytes:
    """The input's header with the new element counts, added face properties and comments."""
    out: list[str] = []
    in_face = False
    for line in lines:
        tok = line.split()
        if tok and tok[0] in ("element", "end_header"):
            if in_face:  # the face element's properties end here
                out += [f"property {p.type_name} {p.name}" for p in added]
            if tok[0] == "element" and comments and not any(t.split()[:1] == ["element"] for t in out):
                out += [f"comment {c}" for c in comments]
            in_face = _is_element_line(line, face)
            if len(tok) == 3 and tok[0] == "element" and tok[1] in counts:
                line = f"element {tok[1]} {counts[tok[1]]}"
        out.append(line)
    return ("\n".join(out) + "\n").encode("latin-1", "replace")


def _is_element_line(line: str, name: str) -> bool:
    tok = line.split()
    return len(tok) == 3 and tok[0] == "element" and tok[1] == name


#: vertex properties of a shading normal
_NORMAL = ("nx", "ny", "nz")


def _turned_normals(src, columns: dict, corner_turned: np.ndarray):
    """The vertex rows with the normals of turned faces turned, or None when none changes.

    A vertex used only by turned faces gets its normal negated in place; a vertex used by
    turned and unturned faces is copied (every property) with the normal negated, and the
    turned faces' corners point at the copy.  A turned row whose normals already lie on
    its new front keeps them (:func:`_rows_front`).  ``columns`` is
    updated in place (the index lists).  Returns (element position, columns, properties,
    row count).
    """
    names = [e[0] for e in src.layout.elements]
    if "vertex" not in names or not corner_turned.any():
        return None
    at = names.index("vertex")
    _, n, props = src.layout.elements[at]
    vert = src.elements["vertex"]
    if not all(k in vert and not isinstance(vert[k], tuple) for k in _NORMAL):
        return None
    counts, idx = columns[src.index_name]
    idx = np.asarray(idx).astype(np.int64)
    ok = (idx >= 0) & (idx < n)
    normals = np.column_stack([np.asarray(vert[k], np.float64) for k in _NORMAL])
    front = _rows_front(src, np.where(ok, idx, 0), np.asarray(counts, np.int64), normals)
    corner_turned = corner_turned & ~front
    if not corner_turned.any():
        return None
    index_type = np.asarray(columns[src.index_name][1]).dtype
    plan = split_turned_vertices(idx, corner_turned, n, valid=ok, limit=int(np.iinfo(index_type).max))
    if plan.not_split:
        warnings.warn(
            f"{plan.not_split} vertices shared by turned and unturned faces keep their normals: their "
            f"copies would not fit the file's {index_type} vertex indices",
            stacklevel=4,
        )
    columns[src.index_name] = (counts, plan.indices.astype(index_type))
    rows, negate = plan.rows, plan.negate
    out = {}
    for p in props:
        col = vert[p.name]
        if isinstance(col, tuple):  # a list per vertex: copied with its row
            c, v = col
            c = np.asarray(c, np.int64)
            start = np.concatenate([[0], np.cumsum(c)[:-1]]).astype(np.int64)
            k = c[rows]
            pick = np.repeat(start[rows], k) + np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k)
            out[p.name] = (k, v[pick])
            continue
        col = np.asarray(col)[rows]
        if p.name in _NORMAL:
            col = col.copy()
            col[negate] = negate_in_type(col[negate])
        out[p.name] = col
    return at, out, props, len(rows)


def _rows_front(src, idx: np.ndarray, counts: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Per index-list entry, whether its row's normals already lie on the row's front (see below).

    The mean over the row's corners of (normal . polygon normal), the polygon normal by
    Newell's sum over the row as written, is positive: a turned row whose normals
    disagreed with its old winding keeps them, they point to the side the repair made the
    front (as in :func:`meshvis.io.gltf_edit.already_front`).
    """
    vert = src.elements["vertex"]
    pos = np.column_stack([np.asarray(vert[k], np.float64) for k in "xyz"])
    row = np.repeat(np.arange(len(counts)), counts)
    start = np.repeat(np.cumsum(counts) - counts, counts)
    nxt = start + (np.arange(len(idx)) - start + 1) % np.maximum(np.repeat(counts, counts), 1)
    cross = np.cross(pos[idx], pos[idx[nxt]])
    g = np.column_stack([np.bincount(row, cross[:, j], len(counts)) for j in range(3)])
    dots = np.einsum("ij,ij->i", normals[idx], g[row])
    return (np.bincount(row, dots, len(counts)) > 0)[row]


def _face_rows(edits: FaceEdits, src, added: list) -> tuple[dict, np.ndarray]:
    """The face element's columns for the soup's faces (``added`` properties included).

    Also returns, per entry of the index list, whether its face is turned over.
    """
    counts, values = src.columns[src.index_name]
    n_rows = len(counts)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    whole, turned = edits.polygons(src.record, n_rows)
    row_of = src.record[edits.origin]
    for prop in added:  # a row is whole only where its triangles agree on every added value
        v = np.asarray(prop.values, np.float64)
        lo, hi = np.full(n_rows, np.inf), np.full(n_rows, -np.inf)
        np.minimum.at(lo, row_of, v)
        np.maximum.at(hi, row_of, v)
        agree = (lo == hi) | ~np.isfinite(lo)
        whole &= agree
        turned &= agree
    first = np.full(n_rows, -1, np.int64)
    first[row_of[::-1]] = np.arange(len(row_of))[::-1]  # first soup face of every row
    rows = np.flatnonzero(whole)
    # corners of the whole rows: in order, or the first one then the others backwards
    k = counts[rows].astype(np.int64)
    within = np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k)
    back = np.where(within == 0, 0, np.repeat(k, k) - within)
    within = np.where(np.repeat(turned[rows], k), back, within)
    whole_corners = np.repeat(start[rows], k) + within
    # the kept triangles of the other rows, in the soup's order within their row
    split = ~whole[src.record[edits.origin]]
    occ = np.flatnonzero(split)
    tri_rows = src.record[edits.origin[occ]]
    tri = src.corners[edits.origin[occ]]
    tri = np.where(edits.flipped[occ][:, None], tri[:, [0, 2, 1]], tri)
    # all rows in input order
    turned_corner = np.concatenate([np.repeat(turned[rows], k), np.repeat(edits.flipped[occ], 3)])
    out_src = np.concatenate([rows, tri_rows])
    out_k = np.concatenate([k, np.full(len(occ), 3, np.int64)])
    pieces = np.concatenate(
        [np.repeat(np.arange(len(rows)), k), len(rows) + np.repeat(np.arange(len(occ)), 3)]
    )
    flat = np.concatenate([whole_corners, tri.reshape(-1)])
    rep = first[rows]  # rows without triangles (skipped edges) get 0
    added_values = {
        p.name: np.concatenate([np.where(rep >= 0, p.values[np.maximum(rep, 0)], 0), p.values[occ]])
        for p in added
    }
    order = np.argsort(out_src, kind="stable")
    rank = np.empty(len(order), np.int64)
    rank[order] = np.arange(len(order))
    corner_order = np.argsort(rank[pieces], kind="stable")
    out_src, out_k, flat = out_src[order], out_k[order], flat[corner_order]
    turned_corner = turned_corner[corner_order]
    columns = {}
    n_corners = len(values)
    for name, col in src.columns.items():
        if not isinstance(col, tuple):
            columns[name] = col[out_src]
            continue
        c, v = col
        if len(v) % max(n_corners, 1) == 0 and np.array_equal(c, counts * (len(v) // max(n_corners, 1))):
            stride = len(v) // max(n_corners, 1)  # one value (or a few) per corner
            idx = (flat[:, None] * stride + np.arange(stride)).reshape(-1)
            columns[name] = (out_k * stride, v[idx])
        else:  # a list unrelated to the corners: the row's list, as it was
            c_start = np.concatenate([[0], np.cumsum(c)[:-1]]).astype(np.int64)
            kk = c[out_src].astype(np.int64)
            idx = (
                np.repeat(c_start[out_src], kk) + np.arange(int(kk.sum())) - np.repeat(np.cumsum(kk) - kk, kk)
            )
            columns[name] = (kk, v[idx])
    for name, v in added_values.items():
        columns[name] = v[order]
    return columns, turned_corner


def _encode_binary(columns: dict, props: list, n: int, endian: str) -> bytes:
    """The rows of one element as binary PLY (vectorised over rows, lists of any length)."""
    widths = np.zeros(n, np.int64)
    for p in props:
        size = np.dtype(p.dtype).itemsize
        if p.count_dtype:
            widths += np.dtype(p.count_dtype).itemsize + size * np.asarray(columns[p.name][0], np.int64)
        else:
            widths += size
    out = np.zeros(int(widths.sum()), np.uint8)
    cursor = np.concatenate([[0], np.cumsum(widths)[:-1]]).astype(np.int64)
    for p in props:
        size = np.dtype(p.dtype).itemsize
        if p.count_dtype:
            k, vals = columns[p.name]
            k = np.asarray(k, np.int64)
            csize = np.dtype(p.count_dtype).itemsize
            _scatter(out, cursor, k.astype(endian + p.count_dtype), csize)
            item = np.repeat(cursor + csize, k) + size * (
                np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k)
            )
            _scatter(out, item, np.asarray(vals).astype(endian + p.dtype), size)
            cursor = cursor + csize + k * size
        else:
            _scatter(out, cursor, np.asarray(columns[p.name]).astype(endian + p.dtype), size)
            cursor = cursor + size
    return out.tobytes()


def _scatter(out: np.ndarray, at: np.ndarray, values: np.ndarray, size: int) -> None:
    """Write the bytes of ``values`` (one item of ``size`` bytes each) at the offsets ``at``."""
    raw = np.ascontiguousarray(values).view(np.uint8).reshape(-1, size)
    out[(at[:, None] + np.arange(size)).reshape(-1)] = raw.reshape(-1)


def _text(values: np.ndarray) -> list[str]:
    """Numbers as text that reads back to the same value of their type."""
    v = np.asarray(values)
    if v.dtype.kind in "iu":
        return [str(x) for x in v.tolist()]
    if v.dtype == np.float32:
        return [np.format_float_positional(x, unique=True, trim="-") for x in v]
    return [repr(x) for x in v.astype(np.float64).tolist()]


def _encode_ascii(columns: dict, props: list, n: int) -> str:
    """The rows of one element as ASCII PLY lines."""
    per_prop = []
    for p in props:
        col = columns[p.name]
        if p.count_dtype:
            k, vals = col
            k = np.asarray(k, np.int64)
            texts = _text(vals)
            ends = np.cumsum(k).tolist()
            starts = [0] + ends[:-1]
            per_prop.append([f"{kk} " + " ".join(texts[a:b]) for kk, a, b in zip(k.tolist(), starts, ends)])
        else:
            per_prop.append(_text(col))
    return "".join(" ".join(parts) + "\n" for parts in zip(*per_prop)) if n else ""
