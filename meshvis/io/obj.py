r"""Wavefront OBJ (+ MTL) reader and writer.

The reader keeps what trimesh's loader loses: the file's face order, the polygon each
triangle came from, parts from ``o``/``g``, materials from ``usemtl`` (with the MTL text,
so that the writer can write it back), UVs, ``v x y z r g b`` vertex colours, negative
(relative) indices and ``\\`` line continuations.

Speed: one cheap pass over the lines sorts them by keyword; all numbers are then parsed
by numpy in one call per block (vertices, texture coordinates, face corners).

Part names: ``o`` starts an object and clears the group, ``g`` names a group.  A face
belongs to the part ``object``, ``group`` or ``object/group`` (when both are set); faces
before any ``o``/``g`` belong to a part named after the file's stem.  Parts with the same
name share one part id.

A face record with exactly two corners is an edge, not a polygon (some exporters write
edges that way): it is skipped with a warning.  A record with fewer corners is an error.
"""

from __future__ import annotations

import os
import re
import warnings
from dataclasses import dataclass, field

import numpy as np

from meshvis.errors import ModelError, ModelFormatError
from meshvis.io._common import atomic_write, decode_text, fmt_floats, unique_names, weld_corners
from meshvis.io.edits import FaceEdits, face_edits
from meshvis.io.mtl import (
    MtlSource,
    TextureWarning,
    inside_folder,
    outside_reference,
    remove_created,
    write_mtl,
)
from meshvis.io.triangulate import triangulate
from meshvis.soup import Material, Soup, SourceRecord

_ROW = -1.7976931348623157e308  # marks line starts while parsing lines of varying length


def _numbers(text: str, dtype, what: str, label: str) -> np.ndarray:
    """Parse whitespace-separated numbers with numpy; one-line error on junk."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            return np.fromstring(text, sep=" ", dtype=dtype)
    except (ValueError, DeprecationWarning):
        raise ModelFormatError(f"cannot read the numbers of the {what}", label) from None


def _first_bad_line(lines: list[str]) -> int:
    """Index of the first line of ``lines`` whose numbers do not parse (slow path for messages)."""
    for i, line in enumerate(lines):
        for tok in line.split()[1:]:
            try:
                float(tok)
            except ValueError:
                return i
    return -1


def _first_bad_face(f_lines: list[str]) -> int:
    """Index of the first face record with a corner that is not ``int[/[int][/[int]]]``."""
    corner = re.compile(r"^-?\d+(/(-?\d+)?(/(-?\d+)?)?)?$")
    for i, line in enumerate(f_lines):
        if not all(corner.match(tok) for tok in line.split()[1:]):
            return i
    return -1


#: numbers on one ``v``/``vt`` line: x y z [w] or x y z r g b [a], with room to spare
_MAX_ROW_NUMBERS = 16


def _parse_rows(
    lines: list[str], keyword: str, width: int, what: str, label: str, line_numbers
) -> tuple[np.ndarray, np.ndarray]:
    """Parse ``keyword n1 n2 ...`` lines into a (k, maxwidth) float array and per-line counts.

    The fast path assumes every line has ``width`` numbers (the common case) and checks it
    by the total count; otherwise the text is parsed again with a sentinel number in front
    of every line, which gives each line's count without a Python loop.
    """
    k = len(lines)
    if k == 0:
        return np.zeros((0, width)), np.zeros(0, np.int64)
    skip = len(keyword) + 1  # the keyword and the whitespace after it
    body = " ".join([ln[skip:] for ln in lines])
    try:
        values = _numbers(body, np.float64, what, label)
    except ModelFormatError:
        bad = _first_bad_line(lines)
        where = f"line {line_numbers(bad) + 1}: " if bad >= 0 else ""
        raise ModelFormatError(f"{where}cannot read the numbers of a {what} line", label) from None
    if len(values) == k * width:
        return values.reshape(k, width), np.full(k, width, np.int64)
    # lines of different lengths: parse again with a sentinel where each line starts
    marked = _numbers(
        f" {_ROW!r} " + f" {_ROW!r} ".join([ln[skip:] for ln in lines]), np.float64, what, label
    )
    starts = np.flatnonzero(marked == _ROW)
    if len(starts) != k:
        raise ModelFormatError(f"cannot read the numbers of the {what} lines", label)
    counts = np.diff(np.append(starts, len(marked))) - 1
    values = np.delete(marked, starts)
    widest = int(counts.max())
    if widest > _MAX_ROW_NUMBERS:  # the padded table below would be k x widest
        raise ModelFormatError(f"a {what} line has {widest} numbers (at most {_MAX_ROW_NUMBERS})", label)
    out = np.zeros((k, widest))
    mask = np.arange(widest) < counts[:, None]
    out[mask] = values
    return out, counts


# ---------------------------------------------------------------------------- reader
@dataclass(eq=False)
class ObjSource:
    """What the OBJ writer needs to edit the file instead of rebuilding it.

    Parameters
    ----------
    lines : list of str
        The file's lines (continuations joined).
    record_line : (p,) int64
        Line number of every face record.
    record : (m0,) int64
        Face record of every triangle as read.
    corners : (m0, 3) int64
        Corner numbers (0-based, within its record) of the three corners of every triangle.
    mtllibs : list of str
        The ``mtllib`` references, as written.
    default_part : str or None
        Name of the part of the faces before any ``o``/``g`` (the input's stem), None when
        there are none.
    folder : str or None
        The input's folder, from which its ``mtllib`` references resolve.
    """

    lines: list[str]
    record_line: np.ndarray
    record: np.ndarray
    corners: np.ndarray
    mtllibs: list[str]
    default_part: str | None = None
    folder: str | None = None


@dataclass(eq=False)
class _Statements:
    """The lines of an OBJ file sorted by keyword (one cheap pass, see :func:`_sort_lines`)."""

    v: list[str] = field(default_factory=list)
    vt: list[str] = field(default_factory=list)
    f: list[str] = field(default_factory=list)
    f_where: list[int] = field(default_factory=list)  # line number (0-based) of every face record
    kinds: list[int] = field(default_factory=list)  # 0 = v, 1 = vt, 2 = f, in file order
    groups: list[tuple[int, str, str]] = field(default_factory=list)  # (face index, "o" | "g", name)
    usemtl: list[tuple[int, str]] = field(default_factory=list)
    mtllibs: list[str] = field(default_factory=list)


def read_obj(path: str, label: str | None = None) -> Soup:
    """Read an OBJ file (see the module docstring for the rules).

    Parameters
    ----------
    path : str
        The OBJ file.
    label : str, optional
        Name of the file in messages.

    Returns
    -------
    Soup
        Vertices as in the file (unused ones kept), triangles in file order, ``source_face``
        = index of the ``f`` record in the file (0-based, counting skipped edge records),
        and a :class:`~meshvis.soup.SourceRecord` with the file's lines.
    """
    label = label or path
    lines = _read_lines(path, label)
    st = _sort_lines(lines)
    n_rec = len(st.f)
    if n_rec == 0:
        raise ModelError("the model has no faces" + ("" if st.v else " (no OBJ statements found)"), label)
    vertices, colors_v = _vertex_table(st, path, label)
    uv_table = _uv_table(st, path, label)
    counts, v_idx, vt_idx = _face_corners(st, len(vertices), 0 if uv_table is None else len(uv_table), label)
    keep_rec, kept_counts, v_idx, vt_idx = _drop_edges(counts, v_idx, vt_idx, st.f_where, label)

    tri, src = triangulate(vertices, kept_counts, v_idx)
    corner_start = np.concatenate([[0], np.cumsum(kept_counts)[:-1]])
    local = tri - corner_start[src][:, None]
    if keep_rec is not None:
        src = keep_rec[src]
    faces = v_idx[tri]

    uv = None
    if uv_table is not None and (vt_idx > 0).any():
        uv_flat = np.zeros((len(vt_idx), 2))
        has = vt_idx > 0
        uv_flat[has] = uv_table[vt_idx[has] - 1]
        uv = uv_flat[tri]
    colors = colors_v[faces] if colors_v is not None else None

    stem = os.path.splitext(os.path.basename(label))[0]
    part_id, part_names = _assign_parts(st.groups, n_rec, src, stem)
    material_id, materials = _assign_materials(st.usemtl, n_rec, src, st.mtllibs, path)
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
    before_any = not st.groups or st.groups[0][0] > 0
    data = ObjSource(
        lines,
        np.asarray(st.f_where, np.int64),
        src.copy(),
        local,
        st.mtllibs,
        stem if before_any else None,
        os.path.dirname(os.path.abspath(path)),
    )
    soup.source = SourceRecord("obj", soup.vertices, soup.faces.copy(), data)
    return soup


def _read_lines(path: str, label: str) -> list[str]:
    r"""The file's text lines (UTF-8 or Latin-1, a byte-order mark dropped, ``\\`` continuations joined)."""
    with open(path, "rb") as fh:
        data = fh.read()
    if b"\x00" in data[:65536]:
        raise ModelFormatError("binary data, not OBJ text", label)
    text = decode_text(data)
    del data
    if "\\\n" in text or "\\\r\n" in text:
        text = re.sub(r"\\\r?\n", " ", text)
    return text.splitlines()


def _sort_lines(lines: list[str]) -> _Statements:
    """One pass over the lines: the statements meshvis reads, by keyword (comments cut)."""
    st = _Statements()
    v_append, vt_append, f_append, k_append, fw_append = (
        st.v.append,
        st.vt.append,
        st.f.append,
        st.kinds.append,
        st.f_where.append,
    )
    for no, line in enumerate(lines):
        if not line:
            continue
        c = line[0]
        if c == " " or c == "\t":
            line = line.lstrip()
            if not line:
                continue
            c = line[0]
        if c == "v":
            c2 = line[1:2]
            if c2 == " " or c2 == "\t":
                if "#" in line:
                    line = line.partition("#")[0]
                v_append(line)
                k_append(0)
            elif c2 == "t":
                if "#" in line:
                    line = line.partition("#")[0]
                vt_append(line)
                k_append(1)
        elif c == "f":
            c2 = line[1:2]
            if c2 == " " or c2 == "\t" or not c2:
                if "#" in line:
                    line = line.partition("#")[0]
                f_append(line)
                k_append(2)
                fw_append(no)
        elif c == "o" or c == "g":
            word, _, rest = line.partition(" ") if " " in line else line.partition("\t")
            if word in ("o", "g"):
                st.groups.append((len(st.f), word, " ".join(rest.split())))
        elif c == "u" and line.startswith("usemtl"):
            st.usemtl.append((len(st.f), line[6:].strip()))
        elif c == "m" and line.startswith("mtllib"):
            st.mtllibs.append(line[6:].strip())
    return st


def _vertex_table(st: _Statements, path: str, label: str) -> tuple[np.ndarray, np.ndarray | None]:
    """(n, 3) vertex positions and (n, 4) uint8 colours (or None) of the ``v`` lines."""

    def vline(i: int) -> int:
        return _nth_line_number(path, "v", i)

    n_v = len(st.v)
    vals, v_counts = _parse_rows(st.v, "v", 3, "vertex", label, vline)
    if len(v_counts) and v_counts.min() < 3:
        bad = int(np.argmax(v_counts < 3))
        raise ModelFormatError(f"line {vline(bad) + 1}: a vertex needs 3 coordinates", label)
    vertices = np.ascontiguousarray(vals[:, :3])
    colors_v = None
    if len(v_counts) and v_counts.max() >= 6:
        has = v_counts >= 6
        rgba = np.ones((n_v, 4))
        rgba[has, :3] = vals[has, 3:6]
        has_a = v_counts >= 7
        if vals.shape[1] >= 7:
            rgba[has_a, 3] = vals[has_a, 6]
        if rgba[has, :3].max(initial=0.0) > 1.0:  # some exporters write 0..255
            rgba[has, :3] /= 255.0
            rgba[has_a, 3] /= 255.0
        colors_v = np.clip(np.round(np.nan_to_num(rgba) * 255.0), 0, 255).astype(np.uint8)
    return vertices, colors_v


def _uv_table(st: _Statements, path: str, label: str) -> np.ndarray | None:
    """(k, 2) texture coordinates of the ``vt`` lines, or None without any."""
    if not st.vt:
        return None
    tvals, t_counts = _parse_rows(
        st.vt, "vt", 2, "texture coordinate", label, lambda i: _nth_line_number(path, "vt", i)
    )
    if t_counts.min() < 1:
        raise ModelFormatError("a texture coordinate line has no numbers", label)
    uv_table = np.zeros((len(st.vt), 2))
    uv_table[:, : min(2, tvals.shape[1])] = tvals[:, :2]
    return uv_table


def _face_corners(st: _Statements, n_v: int, n_vt: int, label: str):
    """Corner counts and 0-based vertex / 1-based UV index per corner, relative indices resolved."""
    f_where = st.f_where
    try:
        counts, v_idx, vt_idx = _parse_faces(st.f, label)
    except ModelFormatError:
        bad = _first_bad_face(st.f)
        if bad < 0:
            raise
        raise ModelFormatError(
            f"line {f_where[bad] + 1}: cannot read the vertex indices of a face", label
        ) from None

    def record_of(corner: int) -> int:
        return int(np.searchsorted(np.cumsum(counts), corner, side="right"))

    # relative (negative) indices count back from the vertices defined so far
    if (v_idx < 0).any() or (vt_idx < 0).any():
        kinds_a = np.frombuffer(bytes(st.kinds), np.uint8)
        vt_relative = vt_idx < 0
        is_face = kinds_a == 2
        nv_c = np.repeat(np.cumsum(kinds_a == 0)[is_face], counts)
        nvt_c = np.repeat(np.cumsum(kinds_a == 1)[is_face], counts)
        v_idx = np.where(v_idx < 0, v_idx + nv_c + 1, v_idx)
        vt_idx = np.where(vt_idx < 0, vt_idx + nvt_c + 1, vt_idx)
        # a relative index that reaches past the first vertex lands on <= 0
        bad = (v_idx <= 0) | (vt_relative & (vt_idx <= 0))
        if bad.any():
            raise ModelFormatError(
                f"line {f_where[record_of(np.argmax(bad))] + 1}: relative index reaches before the first "
                "vertex or texture coordinate",
                label,
            )
    if (v_idx == 0).any():
        rec = record_of(np.argmax(v_idx == 0))
        raise ModelFormatError(f"line {f_where[rec] + 1}: vertex index 0 (OBJ indices start at 1)", label)
    over = v_idx > n_v
    if over.any():
        raise ModelFormatError(
            f"line {f_where[record_of(np.argmax(over))] + 1}: vertex index {int(v_idx[np.argmax(over)])} "
            f"out of range (the file has {n_v} vertices)",
            label,
        )
    if (vt_idx > n_vt).any():
        raise ModelFormatError(
            f"line {f_where[record_of(np.argmax(vt_idx > n_vt))] + 1}: texture coordinate index out of "
            f"range (the file has {n_vt})",
            label,
        )
    return counts, v_idx - 1, vt_idx


def _drop_edges(counts, v_idx, vt_idx, f_where, label):
    """Skip two-corner records (edges) with a warning; refuse shorter ones.

    Returns the kept record numbers (None when all are kept), their corner counts and
    their corners' vertex and UV indices.
    """
    if counts.min() >= 3:
        return None, counts, v_idx, vt_idx
    if counts.min() < 2:
        rec = int(np.argmax(counts < 2))
        raise ModelFormatError(
            f"line {f_where[rec] + 1}: a face needs at least 3 vertices, got {int(counts[rec])}", label
        )
    edges = counts == 2
    warnings.warn(
        f"{label}: skipped {int(edges.sum())} face records with 2 vertices (edges, not faces)",
        stacklevel=5,
    )
    keep_rec = np.flatnonzero(~edges)
    if len(keep_rec) == 0:
        raise ModelError(f"the model has no faces (only {int(edges.sum())} two-vertex records)", label)
    keep_corner = np.repeat(~edges, counts)
    return keep_rec, counts[keep_rec], v_idx[keep_corner], vt_idx[keep_corner]


def _nth_line_number(path: str, keyword: str, n: int) -> int:
    """0-based line number of the n-th line starting with ``keyword`` (for error messages)."""
    seen = -1
    with open(path, encoding="latin-1") as fh:
        for no, line in enumerate(fh):
            parts = line.split(None, 1)
            if parts and parts[0] == keyword:
                seen += 1
                if seen == n:
                    return no
    return -1


_RECORD = np.iinfo(np.int64).min + 1  # stands for the "f" keyword while parsing
_TWO_SLASHES = re.compile(r"/[^\s/]+/")
_BARE = re.compile(r"(?<!\S)(-?\d+)(?=\s|$)")
_THIRD = re.compile(r"(/[^\s/]*)/[^\s/]*")
#: a face record without a slash: bare corners only
_BARE_RECORD = re.compile(r"^[^/\n]*$", re.MULTILINE)


def _mixed_to_uv(body: str, n_corner: int, slashes: int) -> str:
    """Face records of mixed corner layouts rewritten to ``v/vt`` everywhere.

    Corners ``v/vt/vn`` lose their normal and bare corners ``v`` get the UV 0.  The common
    mix, ``v/vt`` records beside records of bare corners only (edges or faces without UVs
    in CAD exports), rewrites just the bare records; anything else goes through two
    regular-expression passes over all records.  Both give the same text.
    """
    if _TWO_SLASHES.search(body) is None:
        bare = list(_BARE_RECORD.finditer(body))
        if slashes == n_corner - sum(len(r.group().split()) - 1 for r in bare):  # the rest is v/vt
            pieces, end = [], 0
            for r in bare:
                pieces += [body[end : r.start()], _BARE.sub(r"\1/0", r.group())]
                end = r.end()
            return "".join(pieces) + body[end:]
    return _BARE.sub(r"\1/0", _THIRD.sub(r"\1", body))


def _parse_faces(f_lines: list[str], label: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Corner counts and (v, vt) index per corner of the face records.

    Corners may be ``v``, ``v/vt``, ``v//vn`` or ``v/vt/vn``; missing entries become 0.
    The ``f`` keywords are replaced by a sentinel number so that one numpy call parses all
    records and the sentinels mark where each record starts.  The corner layout is found
    by counting slashes against corners; a file mixing layouts is first rewritten to
    ``v/vt`` everywhere with two regular-expression passes.
    """
    n_rec = len(f_lines)
    body = "\n".join(f_lines)
    if "//" in body:
        body = body.replace("//", "/0/")
    if "/ " in body or "/\n" in body or body.endswith("/"):
        body = re.sub(r"/(?=\s|$)", "/0", body)
    n_corner = len(body.split()) - n_rec
    slashes = body.count("/")
    if slashes == 0:
        stride = 1
    elif slashes == 2 * n_corner:
        stride = 3
    elif slashes == n_corner and _TWO_SLASHES.search(body) is None:
        stride = 2
    else:  # mixed layouts: drop normals, give bare corners an empty UV
        body = _mixed_to_uv(body, n_corner, slashes)
        stride = 2
    body = body.replace("f", f" {_RECORD} ").replace("/", " ")
    values = _numbers(body, np.int64, "faces", label)
    del body
    starts = np.flatnonzero(values == _RECORD)
    if len(starts) != n_rec:
        raise ModelFormatError("cannot read the vertex indices of the faces", label)
    fields = np.diff(np.append(starts, len(values))) - 1
    counts = fields // stride
    if (fields % stride).any():
        raise ModelFormatError("cannot read the vertex indices of the faces (mixed corner layouts)", label)
    keep = np.ones(len(values), bool)
    keep[starts] = False
    table = values[keep].reshape(-1, stride)
    v = np.ascontiguousarray(table[:, 0])
    vt = np.ascontiguousarray(table[:, 1]) if stride > 1 else np.zeros(len(v), np.int64)
    return counts, v, vt


def _assign_parts(groups, n_rec: int, src: np.ndarray, stem: str) -> tuple[np.ndarray, list[str]]:
    """Per-triangle part id from the ``o``/``g`` statements (see the module docstring)."""
    if not groups:
        return np.zeros(len(src), np.int64), [stem]
    names = []
    obj, grp = None, None
    for _, word, name in groups:
        if word == "o":
            obj, grp = name or "object", None
        else:
            grp = name or "default"
        names.append(obj if grp is None else grp if obj is None else f"{obj}/{grp}")
    starts = np.array([g[0] for g in groups], np.int64)
    # state index per face record: the last statement at or before it (-1: none yet)
    state = np.searchsorted(starts, np.arange(n_rec), side="right") - 1
    labels = [stem] + names
    # part id by name, in order of first use by a face
    state_of_tri = state[src] + 1
    used_states, first = np.unique(state_of_tri, return_index=True)
    order = used_states[np.argsort(first)]
    name_to_id: dict[str, int] = {}
    state_to_id = np.zeros(len(labels), np.int64)
    for s in order:
        state_to_id[s] = name_to_id.setdefault(labels[s], len(name_to_id))
    return state_to_id[state_of_tri], list(name_to_id)


def _assign_materials(usemtl, n_rec: int, src: np.ndarray, mtllibs: list[str], path: str):
    """Per-triangle material id from ``usemtl`` (-1 before any), materials with MTL text."""
    if not usemtl:
        return np.full(len(src), -1, np.int64), []
    starts = np.array([u[0] for u in usemtl], np.int64)
    state = np.searchsorted(starts, np.arange(n_rec), side="right") - 1
    state_of_tri = state[src]
    used, first = np.unique(state_of_tri[state_of_tri >= 0], return_index=True)
    order = used[np.argsort(first)]
    name_to_id: dict[str, int] = {}
    state_to_id = np.full(len(usemtl), -1, np.int64)
    for s in order:
        state_to_id[s] = name_to_id.setdefault(usemtl[s][1], len(name_to_id))
    material_id = np.where(state_of_tri >= 0, state_to_id[np.maximum(state_of_tri, 0)], -1)
    lookup = _read_mtllibs(mtllibs, path)
    materials = [Material(name, lookup.get(name)) for name in name_to_id]
    return material_id, materials


def _read_mtllibs(mtllibs: list[str], path: str) -> dict[str, MtlSource]:
    """Material name -> :class:`MtlSource` from the MTL files that exist (missing ones are ignored)."""
    folder = os.path.dirname(os.path.abspath(path))
    out: dict[str, MtlSource] = {}
    for lib in mtllibs:
        candidates = [lib] + lib.split()
        for cand in candidates:
            mtl_path = os.path.normpath(os.path.join(folder, cand))
            if os.path.isfile(mtl_path):
                break
        else:
            continue
        if not inside_folder(mtl_path, folder):
            warnings.warn(f"{path}: MTL file {lib} is outside the model's folder; skipped", TextureWarning, 2)
            continue
        try:
            with open(mtl_path, "rb") as fh:
                raw = fh.read()
        except OSError:
            continue
        text = decode_text(raw)
        mtl_folder = os.path.dirname(mtl_path)
        name, block = None, []
        for line in text.splitlines() + ["newmtl"]:
            s = line.strip()
            if s.startswith("newmtl") and (len(s) == 6 or s[6] in " \t"):
                if name is not None and name not in out:
                    out[name] = MtlSource.checked("\n".join(block), mtl_folder, folder, mtl_path, path)
                name, block = s[6:].strip(), []
            elif name is not None and s and not s.startswith("#"):
                block.append(s)
    return out


# ---------------------------------------------------------------------------- writer
def write_obj(
    soup: Soup,
    path: str,
    groups: np.ndarray | None = None,
    group_names: list[str] | None = None,
    face_values=None,
) -> bool:
    """Write ``soup`` as OBJ, plus an MTL file and textures when it has materials; True when edited.

    A soup read from an OBJ file whose faces are input faces (some removed, turned over or
    repeated) on the vertices as read is written by editing the input's lines
    (:func:`_edited_lines`): ``v``, ``vt``, ``vn``, ``s``, ``o``/``g``, ``usemtl`` and
    comment lines stay as they were, a polygon whose triangles are all kept and wound alike
    stays one polygon (its corners reversed when turned over), the kept triangles of any
    other polygon take its place.

    Any other soup, or one with ``groups``, is written from scratch: parts become ``o``
    statements, ``groups`` become ``g`` statements inside them, materials ``usemtl``;
    faces keep their order (a statement is repeated when the part, group or material
    changes).  Vertices are written once per (vertex, colour) pair, UVs once per distinct
    pair.  Everything is written with :func:`meshvis.io.atomic_write`.
    """
    stem = os.path.splitext(os.path.basename(path))[0]
    folder = os.path.dirname(os.path.abspath(path))
    used_mats = soup.material_id >= 0
    mtl_name = stem + ".mtl" if used_mats.any() else None
    mat_names: list[str] = []
    edits = face_edits(soup, ("obj",)) if groups is None else None
    if edits is not None:
        mat_names = [m.name for m in soup.materials]
        text = _edited_lines(edits, mtl_name, stem)
    else:
        if mtl_name:
            mat_names = unique_names([m.name for m in soup.materials], "material")
        text = _rebuilt_text(soup, groups, group_names, mtl_name, mat_names)
    # the OBJ, its MTL and textures are published together: a failure in any leaves none
    created: list[str] = []
    try:
        with atomic_write(path, "w") as fh:
            fh.write(text)
            if mtl_name:
                created = write_mtl(soup.materials, mat_names, os.path.join(folder, mtl_name), folder, stem)
    except BaseException:
        remove_created(created)
        raise
    return edits is not None


def _edited_lines(edits: FaceEdits, mtl_name: str | None, stem: str) -> str:
    """The input's text with its face records replaced by the soup's faces (see :func:`write_obj`)."""
    src: ObjSource = edits.record.data
    lines = list(src.lines)
    src_face = src.record
    whole, turned = edits.polygons(src_face, len(src.record_line))
    rec_tris = np.bincount(src_face, minlength=len(src.record_line))
    normals = _TurnedNormals(src.lines) if turned.any() or edits.flipped.any() else None
    if normals is not None:  # geometric normal of every input triangle and record, as read
        p = edits.record.vertices[edits.record.faces]
        tri_n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        rec_n = np.column_stack([np.bincount(src_face, tri_n[:, j], len(src.record_line)) for j in range(3)])
    for r in np.flatnonzero(turned).tolist():
        assert normals is not None  # made above whenever a record is turned
        no = src.record_line[r]
        body, hash_, comment = lines[no].partition("#")
        tokens = body.split()[1:]
        tokens = normals.turn([tokens[0], *tokens[:0:-1]], no, -rec_n[r])
        lines[no] = " ".join(["f", *tokens]) + (f" {hash_}{comment}" if hash_ else "")
    split = np.flatnonzero(~whole & (rec_tris > 0))
    if len(split):
        order = np.argsort(src_face[edits.origin], kind="stable")
        by_rec = src_face[edits.origin][order]
        bounds = np.searchsorted(by_rec, np.stack([split, split + 1]))
        for r, a, b in zip(split.tolist(), bounds[0].tolist(), bounds[1].tolist()):
            no = src.record_line[r]
            tokens = lines[no].partition("#")[0].split()[1:]
            out = []
            for k in order[a:b].tolist():
                c = src.corners[edits.origin[k]]
                if edits.flipped[k]:
                    assert normals is not None  # made above whenever a face is flipped
                    t = normals.turn([tokens[i] for i in c[[0, 2, 1]]], no, -tri_n[edits.origin[k]])
                else:
                    t = [tokens[i] for i in c]
                out.append(f"f {t[0]} {t[1]} {t[2]}")
            lines[no] = "\n".join(out) if out else None
    if normals is not None:
        normals.insert(lines, src.record_line)
    if mtl_name:
        lines = [f"mtllib {mtl_name}" if ln is not None and ln.startswith("mtllib") else ln for ln in lines]
    if src.default_part is not None and src.default_part != stem:
        # the faces before any o/g are named after the file: keep the input's name
        first = int(src.record_line[0])
        lines[first : first + 1] = [f"o {src.default_part}", lines[first]]
    # without an MTL of its own the output keeps the input's references, but none outside its folder
    folder = None if mtl_name else src.folder
    return (
        "\n".join(ln for ln in lines if ln is not None and not (folder and _mtllib_outside(ln, folder)))
        + "\n"
    )


def _mtllib_outside(line: str, folder: str) -> bool:
    """Whether ``line`` is an ``mtllib`` statement naming a file outside ``folder``."""
    word, _, rest = line.partition("#")[0].strip().partition(" ")
    return word == "mtllib" and any(
        outside_reference(n, folder, folder) for n in [rest.strip(), *rest.split()]
    )


def _is_vn(line: str) -> bool:
    s = line.lstrip()
    return s.startswith("vn") and s[2:3] in (" ", "\t")


def _negated(line: str) -> str:
    """A ``vn`` line with every number negated as text (exact: only the sign changes)."""
    nums = line.partition("#")[0].split()[1:]
    return "vn " + " ".join(x[1:] if x[0] == "-" else "-" + x.lstrip("+") for x in nums)


class _TurnedNormals:
    """The ``vn`` lines a turned-over face points at: one negated copy of every normal it used.

    A turned face's corners are pointed at copies so that its shading normals turn with it,
    unless they already lie on its new front (their mean dot product with its geometric
    normal is positive: they disagreed with the old winding and point to the side the
    repair made the front).  Faces that were not turned keep their corners and the
    input's ``vn`` lines stay as they were.
    """

    def __init__(self, lines: list[str]) -> None:
        self.lines = lines
        self.vn_at = np.array([no for no, ln in enumerate(lines) if _is_vn(ln)], np.int64)
        rows = [(lines[no].partition("#")[0].split()[1:4] + ["0", "0", "0"])[:3] for no in self.vn_at]
        try:
            self.values = np.array(rows, np.float64).reshape(-1, 3)
        except ValueError:  # unreadable normals: turned with their faces, never read
            self.values = np.zeros((len(rows), 3))
        self.copies: dict[int, int] = {}  # input normal (0-based) -> its negated copy

    def _normal(self, token: str, line_no: int) -> int:
        """Input normal (0-based) of a corner ``v/vt/vn``, -1 without a valid one."""
        parts = token.split("/")
        if len(parts) < 3 or not parts[2]:
            return -1
        k = int(parts[2])
        k = int(np.searchsorted(self.vn_at, line_no)) + k if k < 0 else k - 1  # relative: count back
        return k if 0 <= k < len(self.vn_at) else -1  # a dangling reference stays as it was

    def turn(self, tokens: list[str], line_no: int, normal: np.ndarray) -> list[str]:
        """The corners of a turned face (new order), pointed at negated copies of their normals.

        ``normal`` is the face's geometric normal in its new winding.
        """
        ks = [self._normal(t, line_no) for t in tokens]
        have = [k for k in ks if k >= 0]
        if not have or float(np.mean(self.values[have] @ normal)) > 0:
            return tokens
        out = []
        for t, k in zip(tokens, ks):
            if k >= 0:
                parts = t.split("/")
                parts[2] = str(self.copies.setdefault(k, len(self.vn_at) + len(self.copies)) + 1)
                t = "/".join(parts)
            out.append(t)
        return out

    def insert(self, lines: list[str], record_line: np.ndarray) -> None:
        """Add the copies after the last ``vn`` line (at the end when a later face counts back)."""
        if not self.copies:
            return
        new = "\n".join(_negated(self.lines[self.vn_at[k]]) for k in self.copies)
        last = int(self.vn_at[-1])
        later = record_line[record_line > last].tolist()
        relative = any(_RELATIVE_VN.search(self.lines[no].partition("#")[0]) for no in later)
        at = len(lines) - 1 if relative else last
        while lines[at] is None:
            at -= 1
        lines[at] = lines[at] + "\n" + new


_RELATIVE_VN = re.compile(r"/[^\s/]*/-")


def _rebuilt_text(soup: Soup, groups, group_names, mtl_name: str | None, mat_names: list[str]) -> str:
    """The OBJ text of a soup written from scratch (see :func:`write_obj`)."""
    m = soup.n_faces
    corner_src, faces = weld_corners(soup, use_uv=False, use_colors=True)
    pos = soup.vertices[soup.faces.reshape(-1)[corner_src]]
    out = [f"# written by meshvis: {m} faces, {len(pos)} vertices, {soup.n_parts} parts\n"]
    if mtl_name:
        out.append(f"mtllib {mtl_name}\n")
    if soup.colors is not None:
        col = soup.colors.reshape(-1, 4)[corner_src, :3] / 255.0
        out.append(("v %s %s %s %s %s %s\n" * len(pos)) % tuple(fmt_floats(np.column_stack([pos, col]))))
    else:
        out.append(("v %s %s %s\n" * len(pos)) % tuple(fmt_floats(pos)))
    uv_faces = None
    if soup.uv is not None:
        uv_flat = soup.uv.reshape(-1, 2)
        _, uv_first, uv_inverse = np.unique(
            uv_flat[:, 0] + 1j * uv_flat[:, 1], return_index=True, return_inverse=True
        )
        out.append(("vt %s %s\n" * len(uv_first)) % tuple(fmt_floats(uv_flat[uv_first])))
        uv_faces = uv_inverse.reshape(-1, 3)
    out += _face_statements(soup, faces, uv_faces, groups, group_names, mat_names)
    return "".join(out)


def _face_statements(soup, faces, uv_faces, groups, group_names, mat_names) -> list[str]:
    """``o`` / ``g`` / ``usemtl`` / ``f`` lines, a statement repeated where its value changes."""
    m = soup.n_faces
    part_names = unique_names(soup.part_names, "part")
    keys = [soup.part_id, soup.material_id] + ([groups] if groups is not None else [])
    change = np.zeros(m, bool)
    if m:
        change[0] = True
    for k in keys:
        change[1:] |= k[1:] != k[:-1]
    starts = np.flatnonzero(change)
    ends = np.append(starts[1:], m)
    if uv_faces is not None:
        fvals = np.stack([faces + 1, uv_faces + 1], axis=-1).reshape(m, 6)
        face_fmt, per_face = "f %d/%d %d/%d %d/%d\n", 6
    else:
        fvals = faces + 1
        face_fmt, per_face = "f %d %d %d\n", 3
    fvals = fvals.ravel().tolist()
    out = []
    cur_part = cur_group = cur_mat = None
    for a, b in zip(starts.tolist(), ends.tolist()):
        p = int(soup.part_id[a])
        g = int(groups[a]) if groups is not None else None
        mt = int(soup.material_id[a])
        if p != cur_part:
            out.append(f"o {part_names[p]}\n")
            cur_part, cur_group = p, None
        if g is not None and g != cur_group:
            out.append(f"g {group_names[g]}\n")
            cur_group = g
        if mt != cur_mat and (mt >= 0 or cur_mat is not None):
            out.append(f"usemtl {mat_names[mt] if mt >= 0 else 'none'}\n")
            cur_mat = mt
        out.append((face_fmt * (b - a)) % tuple(fvals[a * per_face : b * per_face]))
    return out


#: format name -> reader / writer, collected by :mod:`meshvis.io.reading` and :mod:`meshvis.io.writing`
READERS = {"obj": read_obj}
WRITERS = {"obj": write_obj}
