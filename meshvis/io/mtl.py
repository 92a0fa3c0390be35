"""Materials across formats: write MTL files, describe materials for glTF.

A :class:`~meshvis.soup.Material` keeps what its reader produced in ``source``:

* :class:`meshvis.io.mtl.MtlSource` -- the MTL block text and its folder (OBJ);
* a trimesh material (``PBRMaterial`` / ``SimpleMaterial``) -- glTF, 3MF, trimesh scenes;
* None -- only the name is known (e.g. the MTL file is missing).

The writers go through the two functions here, which translate any of those into what
their format holds: an MTL block with copied textures, or a glTF PBR description with the
base colour texture as image bytes.

Files are handled by the rules of ``docs/security.md``: a texture is read only from the
model's own folder (and below), never through ``../`` or an absolute path outside it (a
warning names the skipped texture); a texture is written only under a new name inside the
output's folder (a name taken by a different file gets ``_1``, ``_2``...; a file with the
same bytes is reused), never over an existing file and never over an input; the MTL file
is never written over the input's own MTL.  The OBJ writer publishes the MTL and the
textures together with the OBJ (:func:`write_mtl` returns what it created, so that a
failure removes it).
"""

from __future__ import annotations

import contextlib
import filecmp
import io
import os
import re
import tempfile
import warnings
from dataclasses import dataclass

import numpy as np

from meshvis.errors import ModelFormatError, OutputError
from meshvis.io._common import atomic_write, one_line, register_created, temp_prefix
from meshvis.soup import Material

# MTL statements whose last token is a file name (texture maps)
_MAP_STATEMENTS = re.compile(r"^\s*(map_\w+|bump|disp|decal|refl|norm)\s", re.IGNORECASE)


#: a URL scheme or a drive letter at the start of a file name (``file:``, ``http:``, ``C:``)
_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")


class TextureWarning(UserWarning):
    """A texture was skipped: outside the model's folder, missing, or not an image."""


def inside_folder(path: str, folder: str) -> bool:
    """True when ``path`` (symbolic links resolved) lies in ``folder`` or below it."""
    real, root = os.path.realpath(path), os.path.realpath(folder)
    return real == root or real.startswith(root.rstrip(os.sep) + os.sep)


def outside_reference(name: str, folder: str, root: str) -> bool:
    """Whether a file reference of a model names a place outside the model's folder ``root``.

    Outside are a URL (``file:``, ``http:``), a drive (``C:``), and a path relative to
    ``folder`` that leaves ``root`` with ``..``, from ``/`` or through a symbolic link;
    backslashes count as separators too (files written on Windows use them).
    """
    if _SCHEME.match(name):
        return True
    return not all(inside_folder(os.path.join(folder, n), root) for n in {name, name.replace("\\", "/")})


@dataclass
class MtlSource:
    """How an OBJ material was defined, kept in :attr:`Material.source`.

    Parameters
    ----------
    text : str
        The statements of the material's ``newmtl`` block, without the ``newmtl`` line.
    folder : str
        Folder of the MTL file; texture paths in ``text`` are relative to it.
    root : str, optional
        The model's folder: no texture outside it is read (default: ``folder``).
    path : str, optional
        The MTL file, which a writer must never replace.
    label : str, optional
        The model's name in warnings.
    """

    text: str
    folder: str
    root: str | None = None
    path: str | None = None
    label: str | None = None

    @classmethod
    def checked(cls, text: str, folder: str, root: str, path: str, label: str) -> MtlSource:
        """A source whose textures outside ``root`` are named in a :class:`TextureWarning` now."""
        src = cls(text, folder, root, path, label)
        for _, fname in src.textures():
            src.texture_path(fname)
        return src

    def textures(self) -> list[tuple[str, str]]:
        """(statement keyword, file name) of every texture map the block references."""
        out = []
        for line in self.text.splitlines():
            if _MAP_STATEMENTS.match(line):
                parts = line.split()
                if len(parts) >= 2:
                    out.append((parts[0], parts[-1]))
        return out

    def where(self) -> str:
        """The start of a message about this block, ``"model.obj: model.mtl: "``.

        The MTL file is named relative to the model's folder.
        """
        parts = [self.label] if self.label else []
        if self.path:
            root = self.root if self.root is not None else self.folder
            parts.append(os.path.relpath(self.path, root) if inside_folder(self.path, root) else self.path)
        return "".join(f"{p}: " for p in parts)

    def outside(self, fname: str) -> bool:
        """Whether texture ``fname`` names a place outside the model's folder (:func:`outside_reference`)."""
        return outside_reference(fname, self.folder, self.root if self.root is not None else self.folder)

    def texture_path(self, fname: str, warn: bool = True) -> str | None:
        """The file of texture ``fname``, or None.

        None (with a :class:`TextureWarning`) when it is outside the model's folder
        (:meth:`outside`) or missing.  Backslashes are folder separators unless a file has
        the name as written.
        """
        who = self.where()
        if self.outside(fname):
            if warn:
                warnings.warn(
                    f"{who}texture {fname} is outside the model's folder; skipped", TextureWarning, 2
                )
            return None
        for name in (fname, fname.replace("\\", "/")):
            full = os.path.normpath(os.path.join(self.folder, name))
            if os.path.isfile(full):
                return full
        return None


# ---------------------------------------------------------------------------- file helpers


def publish_new(
    data_or_src: bytes | str, folder: str, wanted: str, taken: dict[str, str], prefix: str = ".meshvis-"
) -> tuple[str, bool]:
    """Put a texture into ``folder`` under ``wanted`` or a free variant of it, never replacing a file.

    Parameters
    ----------
    data_or_src : bytes or str
        The image's bytes, or the path of a file to copy.
    folder : str
        The output's folder.
    wanted : str
        The preferred file name.
    taken : dict
        Names already used by this writer -> what they hold (updated).
    prefix : str
        Start of the temporary file's name (the batch runner removes ``.<output stem>_*.tmp``).

    Returns
    -------
    name : str
        The file name used.
    created : bool
        Whether a new file was created (False: a file with the same bytes was reused).

    Notes
    -----
    The bytes go to a temporary file that is hard-linked to the final name: ``os.link``
    fails when the name exists, so two writers (batch workers) never overwrite each other.
    """
    key = data_or_src if isinstance(data_or_src, str) else f"<{hash(data_or_src)}>"
    base, ext = os.path.splitext(wanted)
    fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            if isinstance(data_or_src, str):
                with open(data_or_src, "rb") as fin:
                    while chunk := fin.read(1 << 20):
                        fh.write(chunk)
            else:
                fh.write(data_or_src)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        for k in range(10_000):
            name = wanted if k == 0 else f"{base}_{k}{ext}"
            if name in taken and taken[name] != key:
                continue
            dst = os.path.join(folder, name)
            if os.path.lexists(dst):
                if os.path.isfile(dst) and not os.path.islink(dst) and filecmp.cmp(dst, tmp, shallow=False):
                    taken[name] = key
                    return name, False
                continue
            try:
                os.link(tmp, dst)
            except FileExistsError:
                continue
            except OSError:  # no hard links on this file system: exclusive create instead
                try:
                    out = os.open(dst, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
                except FileExistsError:
                    continue
                with os.fdopen(out, "wb") as fh, open(tmp, "rb") as fin:
                    while chunk := fin.read(1 << 20):
                        fh.write(chunk)
            taken[name] = key
            register_created(dst)
            return name, True
        raise OutputError(f"no free name for texture {wanted}", folder)
    except OSError as exc:
        if isinstance(exc, OutputError):
            raise
        raise OutputError(f"cannot write texture {wanted}: {one_line(exc.strerror or exc)}", folder) from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def remove_created(paths: list[str]) -> None:
    """Remove files a failed write created (best effort)."""
    for p in paths:
        with contextlib.suppress(OSError):
            os.unlink(p)


_IMAGE_MIME = {b"\x89PNG": "image/png", b"\xff\xd8\xff": "image/jpeg"}


@dataclass
class PbrDescription:
    """What a glTF writer needs to know about one material.

    Attributes
    ----------
    name : str
        The material's name.
    base_color : (4,) float
        RGBA in [0, 1].
    image : bytes or None
        PNG or JPEG bytes of the base colour texture.
    mime : str or None
        The texture's MIME type.
    metallic, roughness : float or None
        The PBR factors, where the MTL gives them.
    double_sided : bool
        Both sides are drawn.
    alpha_mode : {"OPAQUE", "MASK", "BLEND"} or None
        glTF's alpha mode.
    """

    name: str
    base_color: np.ndarray
    image: bytes | None = None
    mime: str | None = None
    metallic: float | None = None
    roughness: float | None = None
    double_sided: bool = False
    alpha_mode: str | None = None


def _safe_file_name(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("._") or "texture"


def _image_bytes(image) -> tuple[bytes | None, str | None]:
    """PNG or JPEG bytes of an image: bytes, or a PIL image.

    PNG and JPEG bytes are kept as they are, and so are those a PIL image was read from
    (a glTF texture): nothing is decoded.  Any other image is decoded and written as PNG,
    unless it would decode to more than the expansion cap of :mod:`meshvis.limits` allows
    for its encoded size (a small file of many pixels).

    Raises
    ------
    OSError (PIL's ``UnidentifiedImageError``) when the bytes are not an image;
    ModelFormatError when the image decodes past the expansion cap.
    """
    from meshvis import limits

    if image is None:
        return None, None
    encoded = None
    if isinstance(image, (bytes, bytearray)):
        for magic, mime in _IMAGE_MIME.items():
            if bytes(image[: len(magic)]) == magic:
                return bytes(image), mime
        from PIL import Image

        encoded = len(image)
        image = Image.open(io.BytesIO(image))
    else:
        source = getattr(image, "fp", None)
        raw = source.getvalue() if isinstance(source, io.BytesIO) else None
        for magic, mime in _IMAGE_MIME.items():
            if raw is not None and raw[: len(magic)] == magic:
                return raw, mime
        encoded = None if raw is None else len(raw)
    decoded = 4 * image.width * image.height
    if decoded > max(limits.MIN_EXPANSION_BYTES, limits.MAX_EXPANSION * (encoded or 0)):
        raise ModelFormatError(
            f"an image of {image.width} x {image.height} pixels from {encoded} bytes would decode past the cap "
            "MAX_EXPANSION of meshvis.limits"
        )
    buf = io.BytesIO()
    img = image
    if img.mode not in ("RGB", "RGBA", "L", "LA"):
        img = img.convert("RGBA")
    img.save(buf, format="PNG", compress_level=1)  # fast; size matters less than time here
    return buf.getvalue(), "image/png"


def _texture_image(src: MtlSource, fname: str) -> tuple[bytes | None, str | None]:
    """Image bytes of an MTL texture for embedding, or (None, None) with a warning."""
    full = src.texture_path(fname, warn=False)  # the reader warned about outside paths
    if full is None:
        return None, None
    with open(full, "rb") as fh:
        data = fh.read()
    try:
        return _image_bytes(data)
    except Exception as exc:  # PIL raises several kinds for bytes that are not an image
        who = src.where()
        warnings.warn(
            f"{who}texture {fname} is not an image ({type(exc).__name__}); written without it",
            TextureWarning,
            3,
        )
        return None, None


def _mtl_values(text: str) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for line in text.splitlines():
        parts = line.split()
        if parts:
            out.setdefault(parts[0].lower(), parts[1:])
    return out


def describe_pbr(material: Material | None, name: str) -> PbrDescription:
    """A glTF description of any material (see the module docstring for the sources)."""
    desc = PbrDescription(name=name, base_color=np.array([0.8, 0.8, 0.8, 1.0]))
    src = None if material is None else material.source
    if isinstance(src, MtlSource):
        vals = _mtl_values(src.text)
        try:
            if "kd" in vals and len(vals["kd"]) >= 3:
                desc.base_color[:3] = [float(x) for x in vals["kd"][:3]]
            if "d" in vals and vals["d"]:
                desc.base_color[3] = float(vals["d"][-1])
            elif "tr" in vals and vals["tr"]:
                desc.base_color[3] = 1.0 - float(vals["tr"][-1])
        except ValueError:
            pass
        for key, fname in src.textures():
            if key.lower() == "map_kd":
                desc.image, desc.mime = _texture_image(src, fname)
                if desc.image is not None:
                    desc.base_color[:3] = 1.0  # the texture carries the colour
                break
        if desc.base_color[3] < 1.0:
            desc.alpha_mode = "BLEND"
        return desc
    if src is not None and (hasattr(src, "baseColorFactor") or hasattr(src, "to_pbr")):
        pbr = src.to_pbr() if not hasattr(src, "baseColorFactor") else src
        factor = getattr(pbr, "baseColorFactor", None)
        if factor is not None:
            f = np.asarray(factor, np.float64).reshape(-1)
            if np.asarray(factor).dtype == np.uint8:
                f = f / 255.0
            desc.base_color[: len(f)] = f[:4]
        tex = getattr(pbr, "baseColorTexture", None)
        if tex is not None:
            try:
                desc.image, desc.mime = _image_bytes(tex)
            except ModelFormatError as exc:
                warnings.warn(f"material {name}: {exc}; written without its texture", TextureWarning, 2)
        desc.metallic = getattr(pbr, "metallicFactor", None)
        desc.roughness = getattr(pbr, "roughnessFactor", None)
        desc.double_sided = bool(getattr(pbr, "doubleSided", False))
        desc.alpha_mode = getattr(pbr, "alphaMode", None)
    return desc


def _protected(materials: list[Material]) -> list[str]:
    """Input files an output must never replace: the source MTL files and textures."""
    out = []
    for mat in materials:
        src = mat.source
        if isinstance(src, MtlSource):
            if src.path:
                out.append(src.path)
            out += [p for _, f in src.textures() if (p := src.texture_path(f, warn=False))]
    return out


def _check_mtl_target(mtl_path: str, materials: list[Material]) -> None:
    if not os.path.exists(mtl_path):
        return
    for p in _protected(materials):
        if os.path.exists(p) and os.path.samefile(p, mtl_path):
            raise OutputError(
                "is a file of the input model (its MTL or a texture); choose another output name", mtl_path
            )


def _mtl_block(
    src: MtlSource, name: str, out_folder: str, taken: dict, created: list[str], prefix: str
) -> list[str]:
    """The lines of an OBJ-sourced block, its textures copied (or skipped) and renamed."""
    lines = [f"newmtl {name}"]
    map_keys = {k.lower() for k, _ in src.textures()}
    for line in src.text.splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0].lower() in map_keys:
            fname = parts[-1]
            full = src.texture_path(fname, warn=False)
            if full is None:
                if src.outside(fname):
                    continue  # never point the output at a file outside the model's folder
                lines.append(line)  # a missing texture: the reference stays as it was
                continue
            if inside_folder(full, out_folder):  # already in the output's folder: no copy
                new = os.path.relpath(os.path.realpath(full), os.path.realpath(out_folder))
            else:
                new, made = publish_new(
                    full, out_folder, _safe_file_name(os.path.basename(fname)), taken, prefix
                )
                if made:
                    created.append(os.path.join(out_folder, new))
            line = " ".join(parts[:-1] + [new.replace(os.sep, "/")])
        lines.append(line)
    return lines


def write_mtl(
    materials: list[Material], names: list[str], mtl_path: str, out_folder: str, stem: str
) -> list[str]:
    """Write an MTL file for ``materials`` (named ``names``) and put their textures next to it.

    OBJ-sourced blocks are written back as read; each texture they reference is copied
    into ``out_folder`` under a new name (unless it already is there) and the reference
    rewritten; a texture outside the model's folder is left out.  Other materials get
    ``Kd``/``d`` and a PNG of their base colour texture named ``<stem>_<material>.png``.

    Returns
    -------
    list of str
        The files this call created (textures, and the MTL when it did not exist), so a
        caller whose own write fails afterwards can remove them (:func:`remove_created`).

    Raises
    ------
    OutputError
        ``mtl_path`` is the input's MTL file or one of its textures; a file cannot be written.
    """
    out_folder = os.path.abspath(out_folder)
    _check_mtl_target(mtl_path, materials)
    taken: dict[str, str] = {}  # output file name -> what it holds (to avoid collisions)
    created: list[str] = []
    prefix = temp_prefix(os.path.join(out_folder, stem + "_"))[:-1]  # ".<stem>_", as the batch runner expects
    try:
        blocks = []
        for mat, name in zip(materials, names):
            src = mat.source
            if isinstance(src, MtlSource):
                lines = _mtl_block(src, name, out_folder, taken, created, prefix)
            else:
                lines = [f"newmtl {name}"]
                desc = describe_pbr(mat, name)
                r, g, b, a = desc.base_color.tolist()
                lines.append(f"Kd {r!r} {g!r} {b!r}")
                if a < 1.0:
                    lines.append(f"d {a!r}")
                if desc.image is not None:
                    ext = ".jpg" if desc.mime == "image/jpeg" else ".png"
                    new, made = publish_new(
                        desc.image, out_folder, _safe_file_name(f"{stem}_{name}") + ext, taken, prefix
                    )
                    if made:
                        created.append(os.path.join(out_folder, new))
                    lines.append(f"map_Kd {new}")
            blocks.append("\n".join(lines))
        existed = os.path.exists(mtl_path)
        with atomic_write(mtl_path, "w") as fh:
            fh.write("# written by meshvis\n\n" + "\n\n".join(blocks) + "\n")
        if not existed:
            created.append(mtl_path)
    except BaseException:
        remove_created(created)
        raise
    return created
