"""Reading models.

:func:`load` checks the path, recognises the format, dispatches to the format's reader and
turns every failure into a one-line :class:`~meshvis.errors.ModelError`.

Each format module declares what it reads in a ``READERS`` mapping (format name ->
``reader(path, label) -> Soup``); this module collects them, so formats never import it.
"""

from __future__ import annotations

import os
import re
import struct

from meshvis import _validate
from meshvis.errors import MeshvisError, ModelError, ModelFormatError
from meshvis.io import gltf, obj, off, ply, stl
from meshvis.io._common import describe_exception, one_line, without_bom
from meshvis.io.scene import soup_from_scene
from meshvis.io.up_axis import format_up
from meshvis.soup import Soup, validate

#: file extension -> format name, for reading
READ_FORMATS = {
    ".obj": "obj",
    ".ply": "ply",
    ".stl": "stl",
    ".off": "off",
    ".glb": "glb",
    ".gltf": "gltf",
    ".3mf": "3mf",
}

#: format name -> reader, collected from the format modules
READERS = {**obj.READERS, **ply.READERS, **stl.READERS, **off.READERS, **gltf.READERS}

_FORMAT_TITLES = {
    "obj": "OBJ text",
    "ply": "PLY",
    "stl": "STL",
    "off": "OFF text",
    "glb": "binary glTF (GLB)",
    "gltf": "glTF JSON",
    "3mf": "3MF (zip)",
    "zip": "a zip archive",
}


def load(path: str | os.PathLike, *, name: str | None = None) -> Soup:
    """Read a model file into a validated :class:`~meshvis.soup.Soup`.

    Parameters
    ----------
    path : str or path-like
        An ``.obj``, ``.ply``, ``.stl``, ``.off``, ``.glb``, ``.gltf`` or ``.3mf`` file.
        The extension picks the reader; the content must agree with it.
    name : str, optional
        Name used in messages and stored as ``Soup.path`` instead of ``path``.

    Returns
    -------
    Soup
        float64 vertices, int64 triangles (polygons triangulated; ``source_face`` is the
        index of the polygon in the file, or of the face within its glTF primitive
        after instancing), per-face part and material, per-corner UVs and RGBA colours
        where the file has them; ``up``, the up axis of the format
        (:data:`~meshvis.io.up_axis.FORMAT_UP`).

    Raises
    ------
    ModelError
        Missing, unreadable, empty file, folder instead of file, no faces, NaN or
        infinite coordinates, indices out of range.
    ModelFormatError
        Unknown extension, content of another format, content that does not parse.
    """
    path = _validate.path("path", path)
    label = name if name is not None else path
    fmt = _check_readable(path, label)
    with open(path, "rb") as fh:
        head = fh.read(4096)
    size = os.path.getsize(path)
    guess = sniff(head, size)
    if guess is not None and guess != fmt and not (fmt == "3mf" and guess == "zip"):
        if not (fmt == "gltf" and guess == "glb"):
            raise ModelFormatError(
                f"the content looks like {_FORMAT_TITLES.get(guess, guess)}, "
                f"not {_FORMAT_TITLES[fmt]} (wrong file extension?)",
                label,
            )
    try:
        soup = _read(fmt, path, label)
    except ModelError as exc:
        if exc.path is None:  # raised below the reader (triangulation): name the file
            raise type(exc)(exc.problem, label) from None
        raise
    except MeshvisError:
        raise
    except MemoryError:
        raise ModelFormatError("the file describes more data than fits in memory (corrupt?)", label) from None
    except Exception as exc:  # any parser failure becomes one clean line
        raise ModelFormatError(
            f"cannot read as {_FORMAT_TITLES[fmt]}: {describe_exception(exc)}", label
        ) from None
    soup.path = label
    soup.up = format_up(path)
    validate(soup.vertices, soup.faces, label)
    return soup


def _check_readable(path: str, label: str) -> str:
    """Check that ``path`` is a readable non-empty file with a known extension; return the format."""
    if not os.path.exists(path):
        raise ModelError("file not found", label)
    if os.path.isdir(path):
        raise ModelError("is a folder, not a model file", label)
    if not os.path.isfile(path):  # opening a FIFO would block until something writes to it
        raise ModelError("is not a regular file (a FIFO, socket or device)", label)
    ext = os.path.splitext(path)[1].lower()
    if ext not in READ_FORMATS:
        known = ", ".join(sorted(READ_FORMATS))
        shown = f"'{ext}'" if ext else "(none)"
        raise ModelFormatError(f"unknown file extension {shown}; known: {known}", label)
    try:
        with open(path, "rb"):
            pass
    except PermissionError:
        raise ModelError("cannot read the file: permission denied", label) from None
    except OSError as exc:
        raise ModelError(f"cannot read the file: {one_line(exc.strerror or exc)}", label) from None
    if os.path.getsize(path) == 0:
        raise ModelError("the file is empty", label)
    return READ_FORMATS[ext]


def sniff(head: bytes, size: int) -> str | None:
    """Guess a file's format from its first bytes and its size.

    Returns one of ``"glb", "zip", "ply", "stl", "off", "gltf", "obj"`` or None when
    the content gives no clear sign.  A binary STL is recognised by its size:
    84 header bytes plus 50 per triangle, the count being stored at byte 80.
    """
    head = without_bom(head)
    if head[:4] == b"glTF":
        return "glb"
    if head[:4] == b"PK\x03\x04":
        return "zip"
    if size >= 84 and len(head) >= 84:
        (n_tri,) = struct.unpack("<I", head[80:84])
        if 84 + 50 * n_tri == size:
            return "stl"
    stripped = head.lstrip()
    if stripped[:4] == b"ply\n" or stripped[:5] == b"ply\r\n":
        return "ply"
    if b"\x00" in head:
        return None
    text = head.decode("latin-1")
    lines = text.splitlines()
    if len(head) == 4096 and len(lines) > 1:
        lines = lines[:-1]  # the last line may be cut
    for line in lines:
        tokens = line.split()
        if not tokens or tokens[0].startswith("#"):
            continue
        word = tokens[0]
        if word == "solid":
            return "stl" if "facet" in text or "endsolid" in text else None
        if re.fullmatch(r"(ST)?C?N?4?n?OFF", word):
            return "off"
        if word.startswith("{"):
            return "gltf"
        if word in ("v", "vt", "vn", "f", "o", "g", "mtllib", "usemtl", "s", "l", "vp"):
            return "obj"
        return None
    return None


def _read(fmt: str, path: str, label: str) -> Soup:
    if fmt == "3mf":
        import trimesh  # 3MF is read through trimesh's loader

        check_zip(path, label)

        scene = trimesh.load(path, file_type="3mf", force="scene", process=False, maintain_order=True)
        return soup_from_scene(scene, path=label)
    return READERS[fmt](path, label)


def check_zip(path: str, label: str) -> None:
    """Refuse a zip archive with more entries or inflated bytes than :mod:`meshvis.limits` allows.

    The inflated bytes must stay within ``MAX_ZIP_BYTES`` and within ``MAX_ZIP_EXPANSION``
    times the archive's size (real 3MF files inflate about 5 times).  The sizes are those its
    directory declares, which :mod:`zipfile` enforces while inflating.
    """
    import zipfile

    from meshvis import limits

    try:
        with zipfile.ZipFile(path) as zf:
            infos = zf.infolist()
    except (zipfile.BadZipFile, OSError) as exc:
        raise ModelFormatError(f"not a valid zip archive: {one_line(exc)}", label) from None
    if len(infos) > limits.MAX_ZIP_ENTRIES:
        raise ModelFormatError(
            f"the archive has {len(infos)} entries, more than the cap of {limits.MAX_ZIP_ENTRIES}", label
        )
    total = sum(i.file_size for i in infos)
    if total > limits.MAX_ZIP_BYTES:
        raise ModelFormatError(
            f"the archive inflates to {total} bytes, more than the cap of {limits.MAX_ZIP_BYTES}", label
        )
    allowed = max(limits.MIN_EXPANSION_BYTES, limits.MAX_ZIP_EXPANSION * os.path.getsize(path))
    if total > allowed:
        raise ModelFormatError(
            f"the archive inflates to {total} bytes, more than {limits.MAX_ZIP_EXPANSION} times its "
            f"{os.path.getsize(path)} bytes (the cap MAX_ZIP_EXPANSION of meshvis.limits; at least "
            f"MIN_EXPANSION_BYTES, {limits.MIN_EXPANSION_BYTES})",
            label,
        )
