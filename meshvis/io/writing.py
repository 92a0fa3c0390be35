"""Writing models.

:func:`save` checks the output path and the per-face arrays, then hands the soup to the
format's writer.

Each format module declares what it writes in a ``WRITERS`` mapping (format name ->
``writer(soup, path, groups, group_names, face_values)``); this module collects them.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from meshvis import _validate
from meshvis.errors import OutputError, ParameterError
from meshvis.io import gltf, obj, off, ply, stl
from meshvis.io._common import check_folder, companions
from meshvis.io.convert import as_soup
from meshvis.soup import Material, Soup

#: file extension -> format name, for writing
WRITE_FORMATS = {".obj": "obj", ".ply": "ply", ".stl": "stl", ".off": "off", ".glb": "glb", ".gltf": "gltf"}

#: format name -> writer, collected from the format modules
WRITERS = {**obj.WRITERS, **ply.WRITERS, **stl.WRITERS, **off.WRITERS, **gltf.WRITERS}

#: formats that hold face groups such as layers: OBJ groups, PLY face properties, glTF nodes
GROUP_FORMATS = ("obj", "ply", "glb", "gltf")


def check_format(path: str | os.PathLike, *, layers: bool = False) -> str:
    """The format that ``path``'s extension names, or :class:`OutputError` before any work.

    Parameters
    ----------
    path : str or path-like
        The output model.
    layers : bool
        The output holds layers: refuse the formats that cannot keep them apart (STL and
        OFF, whose faces carry no group), so that no copy of the input passes for layers.

    Returns
    -------
    str
        The format name (:data:`WRITE_FORMATS`).

    Raises
    ------
    OutputError
        Unknown extension, or a format without groups for ``layers``.

    Examples
    --------
    >>> check_format("out.PLY", layers=True)
    'ply'
    """
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext not in WRITE_FORMATS:
        known = ", ".join(sorted(WRITE_FORMATS))
        raise OutputError(f"cannot write '{ext or '(no extension)'}' files; known: {known}", path)
    fmt = WRITE_FORMATS[ext]
    if layers and fmt not in GROUP_FORMATS:
        raise OutputError(
            f"{fmt.upper()} files cannot hold layers (their faces carry no group); write .ply (a layer "
            "property per face), .glb / .gltf (a node per layer) or .obj (a group per layer)",
            path,
        )
    return fmt


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
    soup : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model to write.
    path : str or path-like
        The extension picks the format.
    face_groups : (m,) int, optional
        A group number per face (e.g. a layer); written as OBJ ``g`` groups inside the
        parts, as glTF nodes (an edited document: each node keeps the faces of the first
        group and gets a child node ``<node>.<group name>`` per other group; a rebuilt
        one: one node per group), and as a ``group`` face property in PLY.
    group_names : list of str, optional
        Name of each group number; default ``group<k>``.
    face_values : dict name -> (m,) array, optional
        Per-face numbers written as PLY face properties (ignored by the other formats).

    What each format keeps
    ----------------------
    A soup read from a file of the output's format whose faces are input faces (some
    removed, turned over, reordered or repeated; ``Soup.origin`` tells which) on the
    vertices as read (OBJ: saved without ``face_groups``), is written by editing the
    input file: everything but the face data is kept as it was (glTF nodes, instancing,
    accessors, materials, texture bytes, animations, extensions; OBJ ``vn``, smoothing
    groups, comments, polygons; every PLY element and property with its type; the STL
    header); turned faces get turned shading normals (docs/files.md).  Any other soup
    is written from scratch:

    * OBJ: parts (``o``), groups (``g``), materials (an MTL file next to the OBJ, textures
      copied next to it), UVs, vertex colours (RGB).
    * PLY (binary): vertex colours (RGBA), UVs (welded per vertex), part / material /
      group ids as face properties with their names in header comments, ``face_values``.
    * GLB / glTF: one node per part (or per group), one primitive per run of faces with
      the same material (face order is kept when each part's faces are contiguous), UVs,
      vertex colours, materials with their base colour texture; float32 positions
      relative to each node's centre.
    * STL (binary, float32): geometry only.  OFF: geometry and vertex colours.

    :func:`write` does the same and tells which of the two it did; :func:`rebuild_note`
    says in one line what a rebuilt output leaves out.

    Raises
    ------
    OutputError
        Unknown extension, missing or unwritable folder, or a path that is a file the
        input model reads (its MTL, a texture, an external glTF buffer or image).
    ParameterError
        ``face_groups`` / ``face_values`` of the wrong length.
    """
    write(soup, path, face_groups=face_groups, group_names=group_names, face_values=face_values)


def write(
    soup: Soup,
    path: str | os.PathLike,
    *,
    face_groups: np.ndarray | None = None,
    group_names: list[str] | None = None,
    face_values: Mapping[str, np.ndarray] | None = None,
) -> bool:
    """:func:`save`, telling whether it edited the input or wrote the soup from scratch.

    Parameters
    ----------
    soup, path, face_groups, group_names, face_values
        As for :func:`save`.

    Returns
    -------
    bool
        True when the file the soup was read from was edited, False when the soup was
        written from scratch.

    Raises
    ------
    OutputError, ParameterError
        As :func:`save`.

    Examples
    --------
    >>> import numpy as np
    >>> soup = as_soup((np.eye(3), np.array([[0, 1, 2]])))
    >>> import tempfile, os
    >>> write(soup, os.path.join(tempfile.mkdtemp(), "t.ply"))  # no file behind it: written anew
    False
    """
    path = _validate.path("path", path)
    soup = as_soup(soup)
    ext = os.path.splitext(path)[1].lower()
    check_format(path)
    check_folder(path)
    check_not_read(path, soup)
    m = soup.n_faces
    groups = None
    if face_groups is not None:
        groups = _validate.per_face("face_groups", face_groups, m, "iu").astype(np.int64, copy=False)
        if m and groups.min() < 0:
            raise ParameterError("face_groups must be non-negative")
        n_groups = int(groups.max()) + 1 if m else 0
        names = _validate.names("group_names", group_names)
        names += [f"group{k}" for k in range(len(names), n_groups)]
        group_names = [str(n) for n in names]
    values = {}
    for key, val in (
        _validate.instance("face_values", face_values, Mapping, True).items() if face_values else ()
    ):
        values[str(key)] = _validate.per_face(f"face_values[{key!r}]", val, m, "biuf")
    n_mat = int(soup.material_id.max()) + 1 if m else 0
    if n_mat > len(soup.materials):  # ids without a Material: give them one so writers can name them
        extra = [Material(f"material{i}") for i in range(len(soup.materials), n_mat)]
        soup = replace(soup, materials=list(soup.materials) + extra)
    return bool(WRITERS[WRITE_FORMATS[ext]](soup, path, groups, group_names, values))


def input_files(soup: Soup) -> list[str]:
    """The files a soup's model reads besides the model file, those that exist.

    They are its MTL files and textures, or a glTF file's external buffers and images.
    """
    from urllib.parse import unquote

    from meshvis.io.gltf_edit import GltfSource
    from meshvis.io.mtl import MtlSource

    out = []
    for mat in soup.materials:
        src = mat.source
        if isinstance(src, MtlSource):
            if src.path:
                out.append(src.path)
            out += [p for _, f in src.textures() if (p := src.texture_path(f, warn=False))]
    rec = soup.source
    if rec is not None and isinstance(rec.data, GltfSource):
        for kind in ("buffers", "images"):
            for item in rec.data.doc.get(kind) or []:
                uri = item.get("uri") if isinstance(item, dict) else None
                if isinstance(uri, str) and not uri.startswith("data:"):
                    out.append(os.path.join(rec.data.folder, unquote(uri)))
    return [p for p in dict.fromkeys(out) if os.path.isfile(p)]


def check_not_read(path: str, soup: Soup) -> None:
    """Refuse to write ``path`` (or the MTL written with it) over a file the soup's model reads.

    That is an MTL file, a texture, an external glTF buffer or image (:func:`input_files`).

    Raises
    ------
    OutputError
        ``path`` or its companion is one of :func:`input_files`.
    """
    files = input_files(soup)
    for p in [path, *companions(path)]:
        if os.path.exists(p) and any(os.path.samefile(p, f) for f in files):
            raise OutputError(
                "is a file of the input model (its MTL, a texture or a buffer); choose another output name",
                p,
            )


def rebuilds_groups(path: str) -> bool:
    """Whether the writer for ``path`` writes a soup with face groups from scratch (OBJ).

    An OBJ file's groups are its ``g`` statements, so a grouped soup is written anew with
    one group per face group.  The other writers edit the input: glTF gives every node a
    child node per further group, PLY adds the groups as a face property, STL and OFF have
    no groups to write.
    """
    return WRITE_FORMATS.get(os.path.splitext(path)[1].lower()) == "obj"


#: source format -> what a rebuilt output does not carry over from it
LOST_WHEN_REBUILT = {
    "glb": "node tree, instancing, animations, skins, vertex normals, extensions and all textures but the base colour",
    "gltf": "node tree, instancing, animations, skins, vertex normals, extensions and all textures but the base colour",
    "obj": "vn normals, smoothing groups, comments and polygons (written as triangles)",
    "ply": "other elements and properties and their types, comments",
    "stl": "header",
    "off": "comments and polygons (written as triangles)",
}


def rebuild_note(soup: Soup, path: str, why: str | None = None) -> str | None:
    """One line saying that ``path`` was written from scratch and what of the input it lacks.

    Parameters
    ----------
    soup : Soup
        The soup that :func:`write` wrote to ``path`` (and returned False for).
    path : str
        The output.
    why : str, optional
        The reason, when it is not the change of format (e.g. one node per layer).

    Returns
    -------
    str or None
        None when the soup was not read from a file (nothing to lose).

    Examples
    --------
    >>> import meshvis, numpy as np
    >>> soup = meshvis.as_soup((np.eye(3), np.array([[0, 1, 2]])))
    >>> rebuild_note(soup, "out.ply") is None
    True
    """
    rec = soup.source
    if rec is None or rec.format not in LOST_WHEN_REBUILT:
        return None
    out = WRITE_FORMATS.get(os.path.splitext(path)[1].lower(), "?")
    if why is None:
        same = out == rec.format or {out, rec.format} == {"glb", "gltf"}
        why = "the result is not an edit of the input's faces" if same else "formats differ"
    return (
        f"{path}: written anew, not edited from the {rec.format.upper()} input ({why}): "
        f"its {LOST_WHEN_REBUILT[rec.format]} are not carried over"
    )
