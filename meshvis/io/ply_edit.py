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

import numpy as np

from meshvis.io._common import atomic_write
from meshvis.io.edits import FaceEdits


def write_edited(edits: FaceEdits, path: str) -> None:
    """Write the input PLY with the soup's faces (see the module docstring).

    Parameters
    ----------
    edits : FaceEdits
        The soup as edits of its source (``edits.record.data`` is a ``PlySource``).
    path : str
        Output file.
    """
    src = edits.record.data
    layout = src.layout
    columns = _face_rows(edits, src)
    n_rows = len(columns[src.index_name][0])
    name, _, props = layout.elements[src.face_element]
    header = [f"element {name} {n_rows}" if _is_element_line(ln, name) else ln for ln in layout.header]
    head = ("\n".join(header) + "\n").encode("latin-1")
    if layout.fmt == "ascii":
        body = [
            _encode_ascii(columns, p, n_rows)
            if i == src.face_element
            else _encode_ascii(src.elements[e], p, n)
            for i, (e, n, p) in enumerate(layout.elements)
        ]
        data = head + "".join(body).encode("latin-1")
    else:
        endian = "<" if layout.fmt == "binary_little_endian" else ">"
        parts = list(layout.raw)
        parts[src.face_element] = _encode_binary(columns, props, n_rows, endian)
        data = head + b"".join(parts)
    with atomic_write(path, "wb") as fh:
        fh.write(data)


def _is_element_line(line: str, name: str) -> bool:
    tok = line.split()
    return len(tok) == 3 and tok[0] == "element" and tok[1] == name


def _face_rows(edits: FaceEdits, src) -> dict:
    """The face element's columns for the soup's faces."""
    counts, values = src.columns[src.index_name]
    n_rows = len(counts)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    whole, turned = edits.polygons(src.record, n_rows)
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
    out_src = np.concatenate([rows, tri_rows])
    out_k = np.concatenate([k, np.full(len(occ), 3, np.int64)])
    pieces = np.concatenate(
        [np.repeat(np.arange(len(rows)), k), len(rows) + np.repeat(np.arange(len(occ)), 3)]
    )
    flat = np.concatenate([whole_corners, tri.reshape(-1)])
    order = np.argsort(out_src, kind="stable")
    rank = np.empty(len(order), np.int64)
    rank[order] = np.arange(len(order))
    corner_order = np.argsort(rank[pieces], kind="stable")
    out_src, out_k, flat = out_src[order], out_k[order], flat[corner_order]
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
    return columns


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
