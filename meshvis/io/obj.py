"""Wavefront OBJ (+ MTL) reader and writer.

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

import numpy as np

from meshvis.errors import ModelError, ModelFormatError
from meshvis.io._common import atomic_write, fmt_floats, unique_names, weld_corners
from meshvis.io.mtl import MtlSource, TextureWarning, inside_folder, remove_created, write_mtl
from meshvis.io.triangulate import triangulate
from meshvis.soup import Material, Soup

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
def read_obj(path: str, label: str | None = None) -> Soup:
    """Read an OBJ file (see the module docstring for the rules).

    Parameters
    ----------
    path : str
    label : str, optional
        Name of the file in messages.

    Returns
    -------
    Soup
        Vertices as in the file (unused ones kept), triangles in file order, ``source_face``
        = index of the ``f`` record in the file (0-based, counting skipped edge records).
    """
    label = label or path
    with open(path, "rb") as fh:
        data = fh.read()
    if b"\x00" in data[:65536]:
        raise ModelFormatError("binary data, not OBJ text", label)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    del data
    if "\\\n" in text or "\\\r\n" in text:
        text = re.sub(r"\\\r?\n", " ", text)
    lines = text.splitlines()
    del text

    v_lines: list[str] = []
    vt_lines: list[str] = []
    f_lines: list[str] = []
    f_where: list[int] = []  # line number (0-based) of every face record
    kinds: list[int] = []  # 0 = v, 1 = vt, 2 = f, in file order (for relative indices)
    groups: list[tuple[int, str, str]] = []  # (face index, "o" | "g", name)
    usemtl: list[tuple[int, str]] = []
    mtllibs: list[str] = []
    v_append, vt_append, f_append, k_append, fw_append = (
        v_lines.append,
        vt_lines.append,
        f_lines.append,
        kinds.append,
        f_where.append,
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
                groups.append((len(f_lines), word, " ".join(rest.split())))
        elif c == "u" and line.startswith("usemtl"):
            usemtl.append((len(f_lines), line[6:].strip()))
        elif c == "m" and line.startswith("mtllib"):
            mtllibs.append(line[6:].strip())
    del lines
    n_v, n_vt, n_rec = len(v_lines), len(vt_lines), len(f_lines)
    if n_rec == 0:
        raise ModelError("the model has no faces" + ("" if n_v else " (no OBJ statements found)"), label)

    # ------------------------------------------------------------ vertices and UVs
    def vline(i: int) -> int:
        return _nth_line_number(path, "v", i)

    vals, v_counts = _parse_rows(v_lines, "v", 3, "vertex", label, vline)
    del v_lines
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
    del vals
    uv_table = None
    if n_vt:
        tvals, t_counts = _parse_rows(
            vt_lines, "vt", 2, "texture coordinate", label, lambda i: _nth_line_number(path, "vt", i)
        )
        if t_counts.min() < 1:
            raise ModelFormatError("a texture coordinate line has no numbers", label)
        uv_table = np.zeros((n_vt, 2))
        uv_table[:, : min(2, tvals.shape[1])] = tvals[:, :2]
    del vt_lines

    # ------------------------------------------------------------ face records
    try:
        counts, v_idx, vt_idx = _parse_faces(f_lines, label)
    except ModelFormatError:
        bad = _first_bad_face(f_lines)
        if bad < 0:
            raise
        raise ModelFormatError(
            f"line {f_where[bad] + 1}: cannot read the vertex indices of a face", label
        ) from None
    del f_lines

    # relative (negative) indices count back from the vertices defined so far
    if (v_idx < 0).any() or (vt_idx < 0).any():
        kinds_a = np.frombuffer(bytes(kinds), np.uint8)
        vt_relative = vt_idx < 0
        is_face = kinds_a == 2
        nv_before = np.cumsum(kinds_a == 0)[is_face]
        nvt_before = np.cumsum(kinds_a == 1)[is_face]
        nv_c = np.repeat(nv_before, counts)
        nvt_c = np.repeat(nvt_before, counts)
        v_idx = np.where(v_idx < 0, v_idx + nv_c + 1, v_idx)
        vt_idx = np.where(vt_idx < 0, vt_idx + nvt_c + 1, vt_idx)
        # a relative index that reaches past the first vertex lands on <= 0
        bad = (v_idx <= 0) | (vt_relative & (vt_idx <= 0))
        if bad.any():
            rec = int(np.searchsorted(np.cumsum(counts), np.argmax(bad), side="right"))
            raise ModelFormatError(
                f"line {f_where[rec] + 1}: relative index reaches before the first vertex or texture coordinate",
                label,
            )
    del kinds
    if (v_idx == 0).any():
        rec = int(np.searchsorted(np.cumsum(counts), np.argmax(v_idx == 0), side="right"))
        raise ModelFormatError(f"line {f_where[rec] + 1}: vertex index 0 (OBJ indices start at 1)", label)
    over = v_idx > n_v
    if over.any():
        rec = int(np.searchsorted(np.cumsum(counts), np.argmax(over), side="right"))
        raise ModelFormatError(
            f"line {f_where[rec] + 1}: vertex index {int(v_idx[np.argmax(over)])} out of range "
            f"(the file has {n_v} vertices)",
            label,
        )
    if (vt_idx > n_vt).any():
        rec = int(np.searchsorted(np.cumsum(counts), np.argmax(vt_idx > n_vt), side="right"))
        raise ModelFormatError(
            f"line {f_where[rec] + 1}: texture coordinate index out of range (the file has {n_vt})", label
        )
    v_idx -= 1

    # ------------------------------------------------------------ short records
    if counts.min() < 3:
        if counts.min() < 2:
            rec = int(np.argmax(counts < 2))
            raise ModelFormatError(
                f"line {f_where[rec] + 1}: a face needs at least 3 vertices, got {int(counts[rec])}", label
            )
        edges = counts == 2
        warnings.warn(
            f"{label}: skipped {int(edges.sum())} face records with 2 vertices (edges, not faces)",
            stacklevel=4,
        )
        keep_rec = np.flatnonzero(~edges)
        if len(keep_rec) == 0:
            raise ModelError(f"the model has no faces (only {int(edges.sum())} two-vertex records)", label)
        keep_corner = np.repeat(~edges, counts)
        v_idx, vt_idx = v_idx[keep_corner], vt_idx[keep_corner]
        kept_counts = counts[keep_rec]
    else:
        keep_rec = None
        kept_counts = counts

    tri, src = triangulate(vertices, kept_counts, v_idx)
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

    # ------------------------------------------------------------ parts and materials
    stem = os.path.splitext(os.path.basename(label))[0]
    part_id, part_names = _assign_parts(groups, n_rec, src, stem)
    material_id, materials = _assign_materials(usemtl, n_rec, src, mtllibs, path)

    return Soup(
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
        body = _BARE.sub(r"\1/0", _THIRD.sub(r"\1", body))
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
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            text = raw.decode("latin-1")
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
) -> None:
    """Write ``soup`` as OBJ, plus an MTL file and textures when it has materials.

    Parts become ``o`` statements, ``groups`` become ``g`` statements inside them,
    materials ``usemtl``; faces keep their order (a statement is repeated when the
    part, group or material changes).  Vertices are written once per (vertex, colour)
    pair, UVs once per distinct pair.  Everything is written with
    :func:`meshvis.io.atomic_write`.
    """

    m = soup.n_faces
    corner_src, faces = weld_corners(soup, use_uv=False, use_colors=True)
    flat = soup.faces.reshape(-1)
    pos = soup.vertices[flat[corner_src]]
    uv_faces = None
    if soup.uv is not None:
        uv_flat = soup.uv.reshape(-1, 2)
        _, uv_first, uv_inverse = np.unique(
            uv_flat[:, 0] + 1j * uv_flat[:, 1], return_index=True, return_inverse=True
        )
        uv_unique = uv_flat[uv_first]
        uv_faces = uv_inverse.reshape(-1, 3)
    stem = os.path.splitext(os.path.basename(path))[0]
    folder = os.path.dirname(os.path.abspath(path))

    used_mats = soup.material_id >= 0
    mtl_name = None
    mat_names: list[str] = []
    if used_mats.any():
        mtl_name = stem + ".mtl"
        mat_names = unique_names([m.name for m in soup.materials], "material")

    part_names = unique_names(soup.part_names, "part")
    # runs of faces with the same (part, group, material)
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
        face_fmt = "f %d/%d %d/%d %d/%d\n"
        per_face = 6
    else:
        fvals = faces + 1
        face_fmt = "f %d %d %d\n"
        per_face = 3
    fvals = fvals.ravel().tolist()

    # the whole text is made before any file is touched: a failure leaves no partial output
    out = [f"# written by meshvis: {m} faces, {len(pos)} vertices, {soup.n_parts} parts\n"]
    if mtl_name:
        out.append(f"mtllib {mtl_name}\n")
    if soup.colors is not None:
        col = soup.colors.reshape(-1, 4)[corner_src, :3] / 255.0
        vals = np.column_stack([pos, col])
        out.append(("v %s %s %s %s %s %s\n" * len(pos)) % tuple(fmt_floats(vals)))
    else:
        out.append(("v %s %s %s\n" * len(pos)) % tuple(fmt_floats(pos)))
    if uv_faces is not None:
        out.append(("vt %s %s\n" * len(uv_unique)) % tuple(fmt_floats(uv_unique)))
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
    text = "".join(out)
    del out
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


#: format name -> reader / writer, collected by :mod:`meshvis.io.reading` and :mod:`meshvis.io.writing`
READERS = {"obj": read_obj}
WRITERS = {"obj": write_obj}
