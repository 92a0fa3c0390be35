"""OFF reader and writer (text; ``OFF``, ``COFF``, ``NOFF``, ``STOFF`` and combinations).

Layout: a keyword line (``[ST][C][N][4][n]OFF``, the counts may follow on the same
line), ``n_vertices n_faces n_edges``, one line per vertex (``x y z`` followed by the
optional normal, colour and texture coordinate the keyword announces), then one line per
face: ``k i_1 ... i_k`` optionally followed by a colour.  ``#`` starts a comment.

Vertex colours (``C``) and face colours (trailing numbers on face lines) are read as RGBA,
floats in [0, 1] or integers in [0, 255]; texture coordinates (``ST``) become UVs.
"""

from __future__ import annotations

import os
import re
import warnings
from dataclasses import dataclass

import numpy as np

from meshvis.errors import ModelError, ModelFormatError
from meshvis.io._common import atomic_write, fmt_floats, weld_corners, without_bom
from meshvis.io.edits import FaceEdits, face_edits
from meshvis.io.triangulate import triangulate
from meshvis.soup import Soup, SourceRecord

_KEYWORD = re.compile(r"^(ST)?(C)?(N)?(4)?(n)?OFF$")


def _to_rgba(vals: np.ndarray) -> np.ndarray:
    """(k, 3|4) colour numbers -> (k, 4) uint8; floats <= 1 are scaled to 0..255."""
    vals = np.nan_to_num(np.asarray(vals, np.float64))
    out = np.full((len(vals), 4), 255, np.uint8)
    if len(vals) == 0:
        return out
    scale = 255.0 if vals.max() <= 1.0 else 1.0
    out[:, : vals.shape[1]] = np.clip(np.round(vals * scale), 0, 255).astype(np.uint8)
    return out


@dataclass(eq=False)
class OffSource:
    """What the OFF writer needs to edit the file instead of rebuilding it.

    Parameters
    ----------
    lines : list of str
        The file's lines as read.
    count_line : int
        Line holding ``n_vertices n_faces n_edges``.
    record_line : (p,) int64
        Line of every face record.
    record : (m0,) int64
        Face record of every triangle as read.
    corners : (m0, 3) int64
        Corner numbers (0-based, within its record) of the three corners of every triangle.
    """

    lines: list[str]
    count_line: int
    record_line: np.ndarray
    record: np.ndarray
    corners: np.ndarray


def read_off(path: str, label: str | None = None) -> Soup:
    """Read an OFF file (see the module docstring); polygons are triangulated."""
    label = label or path
    raw_lines, lines, where = _read_lines(path, label)
    flags, n_v, n_f, body_start = _header(lines, label)
    has_st, has_c, has_n = flags
    vlines = lines[body_start : body_start + n_v]
    flines = lines[body_start + n_v : body_start + n_v + n_f]
    vertices, vcolors, uv_table = _vertex_table(vlines, has_st, has_c, has_n, label)
    counts, corners, extras = _face_records(flines, label)
    keep = _polygon_records(counts, label)
    keep_corner = np.repeat(keep, counts)
    kept = np.flatnonzero(keep)
    k_corners = corners[keep_corner]
    if k_corners.min() < 0 or k_corners.max() >= n_v:
        bad = int(k_corners.min()) if k_corners.min() < 0 else int(k_corners.max())
        raise ModelError(f"vertex index {bad} is out of range (the model has {n_v} vertices)", label)
    tri, src_local = triangulate(vertices, counts[keep], k_corners)
    src = kept[src_local]
    faces = k_corners[tri]
    local = tri - (np.cumsum(counts[keep]) - counts[keep])[src_local][:, None]

    colors = vcolors[faces] if vcolors is not None else None
    if colors is None and extras.min() >= 3 and extras.min() == extras.max():
        k = int(min(extras[0], 4))
        try:
            fvals = np.array([t[1 + int(t[0]) : 1 + int(t[0]) + k] for t in flines], np.float64)
            colors = np.repeat(_to_rgba(fvals)[src][:, None, :], 3, axis=1)
        except ValueError:
            colors = None  # not colours after all: ignore the extra numbers
    uv = uv_table[faces] if uv_table is not None else None
    stem = os.path.splitext(os.path.basename(label))[0]
    soup = Soup(vertices, faces, part_names=[stem], source_face=src, uv=uv, colors=colors, path=label)
    count_line = int(where[0 if lines[0][1:] else 1])
    record_line = np.asarray(where[body_start + n_v : body_start + n_v + n_f], np.int64)
    data = OffSource(raw_lines, count_line, record_line, src.copy(), local)
    soup.source = SourceRecord("off", soup.vertices, soup.faces.copy(), data)
    return soup


def _read_lines(path: str, label: str) -> tuple[list[str], list[list[str]], list[int]]:
    """The raw lines, the tokens of every line with content (comments cut) and their line numbers."""
    with open(path, "rb") as fh:
        data = fh.read()
    if b"\x00" in data[:4096]:
        raise ModelFormatError("binary data, not OFF text (binary OFF is not supported)", label)
    raw = without_bom(data).decode("latin-1").splitlines()
    tokens = [ln.partition("#")[0].split() for ln in raw]
    where = [i for i, t in enumerate(tokens) if t]
    lines = [tokens[i] for i in where]
    if not lines:
        raise ModelError("the file has no content", label)
    return raw, lines, where


def _header(lines: list[list[str]], label: str):
    """(has ST, has C, has N), vertex count, face count, first body line."""
    word = lines[0][0]
    match = _KEYWORD.match(word)
    if match is None:
        raise ModelFormatError(f"first keyword {word[:20]!r} is not an OFF keyword", label)
    has_st, has_c, has_n, has_4, has_dim = (g is not None for g in match.groups())
    if has_4 or has_dim:
        raise ModelFormatError("only 3D OFF files are supported", label)
    rest = lines[0][1:] or (lines[1] if len(lines) > 1 else [])
    body_start = 1 if lines[0][1:] else 2
    try:
        n_v, n_f = int(rest[0]), int(rest[1])
    except (IndexError, ValueError):
        raise ModelFormatError(
            "the vertex and face counts after the OFF keyword are missing", label
        ) from None
    if n_v < 0 or n_f < 0:
        raise ModelFormatError("negative vertex or face count", label)
    if len(lines) < body_start + n_v + n_f:
        raise ModelFormatError(
            f"the file is truncated: {n_v} vertices and {n_f} faces announced, "
            f"{len(lines) - body_start} lines found",
            label,
        )
    if n_f == 0:
        raise ModelError("the model has no faces", label)
    return (has_st, has_c, has_n), n_v, n_f, body_start


def _vertex_table(vlines, has_st: bool, has_c: bool, has_n: bool, label: str):
    """(n, 3) positions, (n, 4) uint8 colours or None, (n, 2) UVs or None."""
    n_v = len(vlines)
    widths = np.fromiter((len(t) for t in vlines), np.int64, n_v)
    if n_v and widths.min() < 3:
        raise ModelFormatError(f"vertex {int(np.argmax(widths < 3))} has fewer than 3 coordinates", label)
    width = int(widths.max()) if n_v else 3
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            if n_v and widths.min() == width:
                vals = np.array([v for t in vlines for v in t], np.float64).reshape(n_v, width)
            else:
                vals = np.zeros((n_v, width))
                for i, t in enumerate(vlines):
                    vals[i, : len(t)] = np.array(t, np.float64)
    except ValueError:
        raise ModelFormatError("cannot read the vertex coordinates", label) from None
    vertices = np.ascontiguousarray(vals[:, :3])
    col = 3 + (3 if has_n else 0)
    vcolors = uv_table = None
    if has_c and width >= col + 3:
        n_col = 4 if width - col - (2 if has_st else 0) >= 4 else 3
        vcolors = _to_rgba(vals[:, col : col + n_col])
        col += n_col
    if has_st and width >= col + 2:
        uv_table = vals[:, col : col + 2]
    return vertices, vcolors, uv_table


def _face_records(flines, label: str):
    """Corner count, flat vertex indices and number of trailing values of every face record."""
    n_f = len(flines)
    try:
        counts = np.fromiter((int(t[0]) for t in flines), np.int64, n_f)
        corner_lists = [t[1 : 1 + int(t[0])] for t in flines]
        corners = np.array([c for cl in corner_lists for c in cl], np.int64)
    except ValueError:
        raise ModelFormatError("cannot read the vertex indices of the faces", label) from None
    lengths = np.fromiter((len(cl) for cl in corner_lists), np.int64, n_f)
    if (lengths != counts).any():
        bad = int(np.argmax(lengths != counts))
        raise ModelFormatError(
            f"face {bad} announces {int(counts[bad])} vertices but lists {int(lengths[bad])}", label
        )
    extras = np.fromiter((len(t) - 1 - int(t[0]) for t in flines), np.int64, n_f)
    return counts, corners, extras


def _polygon_records(counts: np.ndarray, label: str) -> np.ndarray:
    """(p,) bool, the records that are polygons; two-corner records are skipped with a warning."""
    if (counts < 3).any():
        if (counts < 2).any():
            bad = int(np.argmax(counts < 2))
            raise ModelFormatError(
                f"face {bad} has {int(counts[bad])} vertices; a face needs at least 3", label
            )
        warnings.warn(
            f"{label}: skipped {int((counts == 2).sum())} faces with 2 vertices (edges, not faces)",
            stacklevel=5,
        )
    keep = counts >= 3
    if not keep.any():
        raise ModelError("the model has no faces (only two-vertex records)", label)
    return keep


def write_off(soup: Soup, path: str, groups=None, group_names=None, face_values=None) -> bool:
    """Write ``soup`` as OFF, or COFF with RGBA vertex colours (welded per vertex and colour).

    A soup read from an OFF file whose faces are input faces (some removed, turned over or
    repeated) on the vertices as read is written by editing the input's lines: every line
    but the face count and the changed face records is kept; a polygon whose triangles are
    all kept and wound alike stays one polygon, its trailing values (a face colour) kept.
    """
    edits = face_edits(soup, ("off",))
    if edits is not None:
        with atomic_write(path, "w") as fh:
            fh.write(_edited_lines(edits))
        return True

    corner_src, faces = weld_corners(soup, use_uv=False)
    flat = soup.faces.reshape(-1)
    pos = soup.vertices[flat[corner_src]]
    with atomic_write(path, "w") as fh:
        if soup.colors is not None:
            col = soup.colors.reshape(-1, 4)[corner_src]
            fh.write(f"COFF\n{len(pos)} {soup.n_faces} 0\n")
            table = np.empty((len(pos), 7), object)
            table[:, :3] = np.array(fmt_floats(pos), object).reshape(-1, 3)
            table[:, 3:] = col.astype(np.int64)
            fh.write(("%s %s %s %d %d %d %d\n" * len(pos)) % tuple(table.ravel().tolist()))
        else:
            fh.write(f"OFF\n{len(pos)} {soup.n_faces} 0\n")
            fh.write(("%s %s %s\n" * len(pos)) % tuple(fmt_floats(pos)))
        fh.write(("3 %d %d %d\n" * soup.n_faces) % tuple(faces.ravel().tolist()))
    return False


def _edited_lines(edits: FaceEdits) -> str:
    """The input's text with its face records replaced by the soup's faces."""
    src: OffSource = edits.record.data
    lines = list(src.lines)
    n_rec = len(src.record_line)
    whole, turned = edits.polygons(src.record, n_rec)
    rec_tris = np.bincount(src.record, minlength=n_rec)
    n_out = int(whole.sum())
    for r in np.flatnonzero(turned).tolist():
        no = src.record_line[r]
        body, hash_, comment = lines[no].partition("#")
        t = body.split()
        k = int(t[0])
        lines[no] = " ".join([t[0], t[1], *t[k:1:-1], *t[1 + k :]]) + (f" {hash_}{comment}" if hash_ else "")
    split = np.flatnonzero(~whole & (rec_tris > 0))
    if len(split):
        by_rec = src.record[edits.origin]
        order = np.argsort(by_rec, kind="stable")
        bounds = np.searchsorted(by_rec[order], np.stack([split, split + 1]))
        for r, a, b in zip(split.tolist(), bounds[0].tolist(), bounds[1].tolist()):
            no = src.record_line[r]
            t = lines[no].partition("#")[0].split()
            k = int(t[0])
            corners, tail = t[1 : 1 + k], t[1 + k :]
            out = []
            for i in order[a:b].tolist():
                c = src.corners[edits.origin[i]]
                c = c[[0, 2, 1]] if edits.flipped[i] else c
                out.append(" ".join(["3", corners[c[0]], corners[c[1]], corners[c[2]], *tail]))
            n_out += len(out)
            lines[no] = "\n".join(out) if out else None  # type: ignore[assignment]  # None: dropped
    head, hash_, comment = lines[src.count_line].partition("#")
    t = head.split()
    at = 1 if t and _KEYWORD.match(t[0]) else 0  # the counts may follow the keyword
    t[at + 1] = str(n_out)
    lines[src.count_line] = " ".join(t) + (f" {hash_}{comment}" if hash_ else "")
    return "\n".join(ln for ln in lines if ln is not None) + "\n"


#: format name -> reader / writer, collected by :mod:`meshvis.io.reading` and :mod:`meshvis.io.writing`
READERS = {"off": read_off}
WRITERS = {"off": write_off}
