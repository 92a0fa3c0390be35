"""STL reader (binary and ASCII) and writer.

Binary STL: an 80-byte header, a uint32 triangle count, then 50 bytes per triangle
(normal, three corners as float32, a uint16 attribute).  The size must match the count
exactly; a mismatch is reported as a truncated or damaged file.

ASCII STL: ``solid name`` ... ``facet normal`` / ``outer loop`` / three ``vertex x y z`` /
``endloop`` / ``endfacet`` ... ``endsolid``.  Each solid becomes a part named after it.

STL has no shared vertices: every triangle gets its own three vertices, in file order.

Writing a soup read from STL (faces removed or turned over, vertices as read) keeps the
file's kind: binary in, binary out with the input's 80-byte header and each kept
triangle's record (normal and attribute bytes; a turned-over triangle's normal negated);
ASCII in, ASCII out with the solid names.  Any other soup is written as binary STL.
"""

from __future__ import annotations

import os
import re
import struct
import warnings
from dataclasses import dataclass

import numpy as np

from meshvis.errors import ModelError, ModelFormatError
from meshvis.io._common import atomic_write, fmt_floats, unique_names, without_bom
from meshvis.io.edits import face_edits
from meshvis.soup import Soup, SourceRecord

_BINARY = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attr", "<u2")])
_SOLID = re.compile(r"^[ \t]*solid\b[ \t]*(.*)$", re.MULTILINE)
_VERTEX = re.compile(r"vertex\s+(\S+)\s+(\S+)\s+(\S+)")


def read_stl(path: str, label: str | None = None) -> Soup:
    """Read a binary or ASCII STL file (see the module docstring)."""
    label = label or path
    with open(path, "rb") as fh:
        data = fh.read()
    stem = os.path.splitext(os.path.basename(label))[0]
    if len(data) >= 84:
        (n,) = struct.unpack("<I", data[80:84])
        if 84 + 50 * n == len(data):
            if n == 0:
                raise ModelError("the model has no faces", label)
            rec = np.frombuffer(data, _BINARY, count=n, offset=84)
            corners = rec["corners"].astype(np.float64).reshape(-1, 3)
            soup = Soup(
                corners, np.arange(3 * n, dtype=np.int64).reshape(n, 3), part_names=[stem], path=label
            )
            soup.source = SourceRecord("stl", soup.vertices, soup.faces.copy(), StlSource(data[:80], rec))
            return soup
    data = without_bom(data)
    head = data[:1024].lstrip()
    if not head.startswith(b"solid") or b"\x00" in data[:4096]:
        if len(data) >= 84:
            (n,) = struct.unpack("<I", data[80:84])
            expected = 84 + 50 * n
            if expected > 4 * len(data) + 1000:
                raise ModelFormatError(
                    "not an STL file: no 'solid' line, and the binary triangle count does not match the size",
                    label,
                )
            if expected > len(data):
                raise ModelFormatError(
                    f"binary STL is truncated: the header announces {n} triangles ({expected} bytes), "
                    f"the file has {len(data)} bytes",
                    label,
                )
            raise ModelFormatError(
                f"binary STL size does not match its triangle count ({n} triangles need {expected} bytes, "
                f"the file has {len(data)})",
                label,
            )
        raise ModelFormatError("too short for a binary STL and not an ASCII STL", label)
    return _read_ascii(data.decode("latin-1"), label, stem)


def _read_ascii(text: str, label: str, stem: str) -> Soup:
    starts = [(m.start(), m.group(1).strip()) for m in _SOLID.finditer(text)]
    if not starts:
        starts = [(0, stem)]
    bounds = [s for s, _ in starts[1:]] + [len(text)]
    chunks: list[np.ndarray] = []
    part_ids: list[np.ndarray] = []
    names: list[str] = []
    for k, ((a, name), b) in enumerate(zip(starts, bounds)):
        found = _VERTEX.findall(text, a, b)
        if not found:
            continue
        if len(found) % 3:
            raise ModelFormatError(
                f"solid {name or k!r} has {len(found)} vertices, not a multiple of 3 (truncated?)", label
            )
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                xyz = np.array(found, dtype=np.float64)
        except (ValueError, DeprecationWarning):
            raise ModelFormatError(
                f"cannot read the vertex coordinates of solid {name or k!r}", label
            ) from None
        chunks.append(xyz)
        part_ids.append(np.full(len(found) // 3, len(names), np.int64))
        names.append(name or (stem if len(starts) == 1 else f"{stem}{k}"))
    if not chunks:
        raise ModelError("the model has no faces", label)
    vertices = np.concatenate(chunks)
    m = len(vertices) // 3

    soup = Soup(
        vertices,
        np.arange(3 * m, dtype=np.int64).reshape(m, 3),
        part_id=np.concatenate(part_ids),
        part_names=unique_names(names, "solid"),
        path=label,
    )
    soup.source = SourceRecord("stl", soup.vertices, soup.faces.copy(), StlSource(None, None))
    return soup


@dataclass(eq=False)
class StlSource:
    """What the STL writer keeps of its input.

    Parameters
    ----------
    header : bytes or None
        The 80-byte header of a binary file; None for ASCII.
    records : structured array or None
        The triangle records of a binary file (normal, corners, attribute).
    """

    header: bytes | None
    records: np.ndarray | None


def write_stl(soup: Soup, path: str, groups=None, group_names=None, face_values=None) -> bool:
    """Write ``soup`` as STL, atomically (see the module docstring for which kind); True when edited."""
    edits = face_edits(soup, ("stl",))
    if edits is not None and edits.record.data.header is None:
        _write_ascii(soup, path)
        return True
    tri = soup.triangles
    if edits is not None:
        src: StlSource = edits.record.data
        assert src.records is not None  # a binary STL (the header check above)
        rec = src.records[edits.origin].copy()
        rec["normal"] = np.where(edits.flipped[:, None], -rec["normal"], rec["normal"])
        header = src.header
    else:
        rec = np.zeros(soup.n_faces, _BINARY)
        rec["normal"] = soup.normals.astype(np.float32)
        header = b"meshvis binary STL".ljust(80, b" ")
    rec["corners"] = tri.astype(np.float32)
    with atomic_write(path, "wb") as fh:
        fh.write(header)
        fh.write(struct.pack("<I", soup.n_faces))
        fh.write(rec.tobytes())
    return edits is not None


def _write_ascii(soup: Soup, path: str) -> None:
    """ASCII STL, one ``solid`` per part (in order of first face), coordinates as read."""
    normals = fmt_floats(soup.normals)
    corners = fmt_floats(soup.triangles)
    facet = "facet normal %s %s %s\nouter loop\nvertex %s %s %s\nvertex %s %s %s\nvertex %s %s %s\nendloop\nendfacet\n"
    out = []
    _, first = np.unique(soup.part_id, return_index=True)
    for p in soup.part_id[np.sort(first)].tolist():
        name = soup.part_names[p] if p < len(soup.part_names) else f"solid{p}"
        sel = np.flatnonzero(soup.part_id == p).tolist()
        out.append(f"solid {name}\n")
        out += [facet % tuple(normals[3 * i : 3 * i + 3] + corners[9 * i : 9 * i + 9]) for i in sel]
        out.append(f"endsolid {name}\n")
    with atomic_write(path, "w") as fh:
        fh.write("".join(out))


#: format name -> reader / writer, collected by :mod:`meshvis.io.reading` and :mod:`meshvis.io.writing`
READERS = {"stl": read_stl}
WRITERS = {"stl": write_stl}
