"""Reading and writing models: one entry point per direction.

:func:`load` reads OBJ, PLY (ASCII and binary), STL (ASCII and binary), OFF, glTF/GLB and
3MF into a :class:`~meshvis.soup.Soup`; :func:`save` writes OBJ, PLY, STL, OFF and
glTF/GLB, keeping every attribute the format can hold.  The format readers and writers
live in ``io_<format>.py``; this module checks the path, recognises the format, turns
every failure into a one-line :class:`~meshvis.errors.ModelError` /
:class:`~meshvis.errors.OutputError`, and validates what was read.

Every file is written through :func:`atomic_write`: an existing file is replaced only
once its successor is complete on disk.
"""
from __future__ import annotations

import contextlib
import os
import re
import stat
import struct
import tempfile
from typing import IO, Iterator, Mapping

import numpy as np

from .errors import MeshvisError, ModelError, ModelFormatError, OutputError
from .soup import Soup, as_soup, validate

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
#: file extension -> format name, for writing
WRITE_FORMATS = {".obj": "obj", ".ply": "ply", ".stl": "stl", ".off": "off", ".glb": "glb", ".gltf": "gltf"}

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


# ---------------------------------------------------------------------------- messages
def one_line(text: object, limit: int = 200) -> str:
    """The first line of ``str(text)``, shortened to ``limit`` characters."""
    lines = [s.strip() for s in str(text).splitlines() if s.strip()]
    first = lines[0] if lines else ""
    return first if len(first) <= limit else first[: limit - 3] + "..."


def _describe(exc: BaseException) -> str:
    """A short one-line description of an exception raised by a parser."""
    text = one_line(exc)
    name = type(exc).__name__
    if not text:
        return name
    if isinstance(exc, (KeyError, IndexError, struct.error)):
        return f"{name}: {text}"
    return text


# ---------------------------------------------------------------------------- reading
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
        where the file has them.

    Raises
    ------
    ModelError
        Missing, unreadable, empty file, folder instead of file, no faces, NaN or
        infinite coordinates, indices out of range.
    ModelFormatError
        Unknown extension, content of another format, content that does not parse.
    """
    path = os.fspath(path)
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
    except MeshvisError:
        raise
    except MemoryError:
        raise ModelFormatError("the file describes more data than fits in memory (corrupt?)", label) from None
    except Exception as exc:  # any parser failure becomes one clean line
        raise ModelFormatError(f"cannot read as {_FORMAT_TITLES[fmt]}: {_describe(exc)}", label) from None
    soup.path = label
    validate(soup.vertices, soup.faces, label)
    return soup


def _check_readable(path: str, label: str) -> str:
    """Check that ``path`` is a readable non-empty file with a known extension; return the format."""
    if not os.path.exists(path):
        raise ModelError("file not found", label)
    if os.path.isdir(path):
        raise ModelError("is a folder, not a model file", label)
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
    if fmt == "obj":
        from .io_obj import read_obj

        return read_obj(path, label)
    if fmt == "ply":
        from .io_ply import read_ply

        return read_ply(path, label)
    if fmt == "stl":
        from .io_stl import read_stl

        return read_stl(path, label)
    if fmt == "off":
        from .io_off import read_off

        return read_off(path, label)
    if fmt in ("glb", "gltf"):
        from .io_gltf import read_gltf

        return read_gltf(path, label)
    if fmt == "3mf":
        import trimesh

        scene = trimesh.load(path, file_type="3mf", force="scene", process=False, maintain_order=True)
        return soup_from_scene(scene, path=label)
    raise ModelFormatError(f"no reader for {fmt}", label)  # pragma: no cover


def soup_from_scene(scene, path: str | None = None) -> Soup:
    """Flatten a ``trimesh.Scene`` into a :class:`~meshvis.soup.Soup`, instancing applied.

    Every geometry node of the scene graph becomes its own part, named after the node;
    the node's world transform is
    applied (a mirroring transform turns the faces back, see
    :meth:`Soup.transformed`).  UVs, vertex or face colours and materials are kept where
    the geometry's visual exposes them.  Non-mesh geometry (paths, point clouds) is
    skipped.

    Parameters
    ----------
    scene : trimesh.Scene
    path : str, optional
        Name for messages.

    Returns
    -------
    Soup
    """
    from .io_gltf import soup_from_trimesh

    parts: list[Soup] = []
    materials: dict[int, int] = {}
    mats: list = []
    for node in scene.graph.nodes_geometry:
        matrix, geom_name = scene.graph[node]
        geom = scene.geometry.get(geom_name)
        if geom is None or not hasattr(geom, "faces") or len(geom.faces) == 0:
            continue
        part = soup_from_trimesh(geom, str(node), mats, materials)
        parts.append(part.transformed(matrix) if not np.allclose(matrix, np.eye(4)) else part)
    if not parts:
        raise ModelError("the model has no faces", path)
    soup = Soup.concatenate(parts)
    soup.materials = mats
    soup.path = path
    validate(soup.vertices, soup.faces, path)
    return soup


# ---------------------------------------------------------------------------- writing
@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "w", encoding: str = "utf-8") -> Iterator[IO]:
    """Open ``path`` for writing so that it is replaced only when writing succeeds.

    The data goes to a temporary file in the same folder; on leaving the ``with`` block
    normally it is flushed, synced to disk and renamed over ``path`` (``os.replace``, atomic
    on POSIX).  On any exception the temporary file is removed and an existing ``path`` is
    left untouched.  The new file gets the permissions of the file it replaces, or the
    usual ones for a new file (0666 less the umask).

    Parameters
    ----------
    path : str or path-like
    mode : ``"w"`` (text) or ``"wb"`` (binary)
    encoding : text encoding for ``"w"``

    Raises
    ------
    OutputError
        The folder does not exist or is not writable, or ``path`` is a folder.
    """
    if mode not in ("w", "wb"):
        raise ValueError("mode must be 'w' or 'wb'")
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise OutputError("output path is a folder", path)
    if not os.path.isdir(folder):
        raise OutputError("output folder does not exist", path)
    try:
        fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp", dir=folder)
    except PermissionError:
        raise OutputError("output folder is not writable", path) from None
    except OSError as exc:
        raise OutputError(f"cannot write: {one_line(exc.strerror or exc)}", path) from None
    try:
        with os.fdopen(fd, mode, **({"encoding": encoding, "newline": "\n"} if mode == "w" else {})) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        try:
            perm = stat.S_IMODE(os.stat(path).st_mode)
        except OSError:
            umask = os.umask(0)
            os.umask(umask)
            perm = 0o666 & ~umask
        os.chmod(tmp, perm)
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(f"cannot write: {one_line(exc.strerror or exc)}", path) from None
        raise


def save(
    soup: Soup,
    path: str | os.PathLike,
    *,
    face_groups: np.ndarray | None = None,
    group_names: list[str] | None = None,
    face_values: Mapping[str, np.ndarray] | None = None,
) -> None:
    """Write a soup to an OBJ, PLY, STL, OFF, GLB or glTF file, atomically.

    Parameters
    ----------
    soup : Soup (or anything :func:`meshvis.soup.as_soup` accepts)
    path : str or path-like
        The extension picks the format.
    face_groups : (m,) int, optional
        A group number per face (e.g. a layer); written as OBJ ``g`` groups inside the
        parts, as one glTF node per group, and as a ``group`` face property in PLY.
    group_names : list of str, optional
        Name of each group number; default ``group<k>``.
    face_values : dict name -> (m,) array, optional
        Per-face numbers written as PLY face properties (ignored by the other formats).

    What each format keeps
    ----------------------
    * OBJ: parts (``o``), groups (``g``), materials (an MTL file next to the OBJ, textures
      copied next to it), UVs, vertex colours (RGB).
    * PLY (binary): vertex colours (RGBA), UVs (welded per vertex), part / material /
      group ids as face properties with their names in header comments, ``face_values``.
    * GLB / glTF: one node per part (or per group), one primitive per run of faces with
      the same material (face order is kept when each part's faces are contiguous), UVs,
      vertex colours, materials with their base colour texture; float32 positions
      relative to each node's centre.
    * STL (binary, float32): geometry only.  OFF: geometry and vertex colours.

    Raises
    ------
    OutputError
        Unknown extension, missing or unwritable folder.
    ParameterError
        ``face_groups`` / ``face_values`` of the wrong length.
    """
    from .errors import ParameterError

    path = os.fspath(path)
    soup = as_soup(soup)
    ext = os.path.splitext(path)[1].lower()
    if ext not in WRITE_FORMATS:
        known = ", ".join(sorted(WRITE_FORMATS))
        raise OutputError(f"cannot write '{ext or '(no extension)'}' files; known: {known}", path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise OutputError("output folder does not exist", path)
    if not os.access(folder, os.W_OK):
        raise OutputError("output folder is not writable", path)
    m = soup.n_faces
    groups = None
    if face_groups is not None:
        groups = np.asarray(face_groups).astype(np.int64, copy=False).reshape(-1)
        if len(groups) != m:
            raise ParameterError(f"face_groups has {len(groups)} entries for {m} faces")
        if m and groups.min() < 0:
            raise ParameterError("face_groups must be non-negative")
        n_groups = int(groups.max()) + 1 if m else 0
        names = list(group_names) if group_names is not None else []
        names += [f"group{k}" for k in range(len(names), n_groups)]
        group_names = [str(n) for n in names]
    values = {}
    for key, val in (face_values or {}).items():
        val = np.asarray(val)
        if val.shape[:1] != (m,) or val.ndim != 1:
            raise ParameterError(f"face_values[{key!r}] must have one value per face ({m})")
        values[str(key)] = val
    n_mat = int(soup.material_id.max()) + 1 if m else 0
    if n_mat > len(soup.materials):  # ids without a Material: give them one so writers can name them
        from dataclasses import replace

        from .soup import Material

        extra = [Material(f"material{i}") for i in range(len(soup.materials), n_mat)]
        soup = replace(soup, materials=list(soup.materials) + extra)
    fmt = WRITE_FORMATS[ext]
    if fmt == "obj":
        from .io_obj import write_obj

        write_obj(soup, path, groups, group_names)
    elif fmt == "ply":
        from .io_ply import write_ply

        write_ply(soup, path, groups, group_names, values)
    elif fmt == "stl":
        from .io_stl import write_stl

        write_stl(soup, path)
    elif fmt == "off":
        from .io_off import write_off

        write_off(soup, path)
    else:
        from .io_gltf import write_gltf

        write_gltf(soup, path, groups, group_names, binary=fmt == "glb")


def weld_corners(soup: Soup, use_uv: bool = True, use_colors: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Share one output vertex between corners with the same vertex, UV and colour.

    Parameters
    ----------
    soup : Soup
    use_uv, use_colors : bool
        Whether UVs / colours (when the soup has them) take part in the key.

    Returns
    -------
    corner_vertex : (k,) int64
        For each output vertex, the flat corner index (into ``faces.ravel()``) it is
        taken from: gather positions, UVs and colours with it.
    faces : (m, 3) int64
        Faces indexing the output vertices.

    Notes
    -----
    The key of a corner is built in steps, each a ``np.unique`` on one int64 array: the
    vertex index, then combined with the id of its UV pair, then with the id of its
    packed RGBA colour.  Output vertices are sorted by key, so the result is
    deterministic.
    """
    flat = soup.faces.reshape(-1)
    key = flat.astype(np.int64)
    if use_uv and soup.uv is not None:
        uv = soup.uv.reshape(-1, 2)
        # a complex number holds the UV pair exactly and sorts fast in one dimension
        _, uv_id = np.unique(uv[:, 0] + 1j * uv[:, 1], return_inverse=True)
        _, key = np.unique(key * (int(uv_id.max()) + 1) + uv_id.reshape(-1), return_inverse=True)
    if use_colors and soup.colors is not None:
        packed = np.ascontiguousarray(soup.colors.reshape(-1, 4)).view(np.uint32).reshape(-1)
        _, col_id = np.unique(packed, return_inverse=True)
        key = key.reshape(-1) * (int(col_id.max()) + 1) + col_id.reshape(-1)
    _, first, inverse = np.unique(key.reshape(-1), return_index=True, return_inverse=True)
    return first.astype(np.int64), inverse.reshape(-1, 3).astype(np.int64)


def unique_names(names: list[str], fallback: str) -> list[str]:
    """Make names non-empty and unique (``name``, ``name.1``, ...), keeping order."""
    out: list[str] = []
    seen: set[str] = set()
    for i, n in enumerate(names):
        base = " ".join(str(n or "").split()) or f"{fallback}{i}"
        cand, k = base, 1
        while cand in seen:
            cand = f"{base}.{k}"
            k += 1
        seen.add(cand)
        out.append(cand)
    return out


def check_output(path: str, inputs: list[str], force: bool) -> None:
    """Refuse an output path that is an input, a folder, in a missing or unwritable folder,
    or that exists while ``force`` is False (raises :class:`OutputError`)."""
    for inp in inputs:
        if os.path.exists(path) and os.path.exists(inp) and os.path.samefile(path, inp):
            raise OutputError("output path is the input file; choose another path", path)
        if os.path.abspath(path) == os.path.abspath(inp):
            raise OutputError("output path is the input file; choose another path", path)
    if os.path.isdir(path):
        raise OutputError("output path is a folder", path)
    if os.path.exists(path) and not force:
        raise OutputError("exists; use --force to overwrite", path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise OutputError("output folder does not exist", folder)
    if not os.access(folder, os.W_OK):
        raise OutputError("output folder is not writable", folder)


def ensure_folder(out_dir: str) -> None:
    """Create the output folder if needed and check that files can be created in it.

    Raises
    ------
    OutputError
        The path is a file, cannot be created, or is not writable.
    """
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise OutputError("the output folder is a file", out_dir)
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the output folder: {one_line(exc.strerror or exc)}", out_dir) from None
    try:  # os.access is not enough: root passes it, read-only mounts fail only on write
        fd, probe = tempfile.mkstemp(prefix=".meshvis-probe-", dir=out_dir)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise OutputError(f"output folder is not writable ({one_line(exc.strerror or exc)})", out_dir) from None
