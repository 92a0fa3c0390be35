"""Materials across formats: write MTL files, describe materials for glTF.

A :class:`~meshvis.soup.Material` keeps what its reader produced in ``source``:

* :class:`meshvis.io.mtl.MtlSource` -- the MTL block text and its folder (OBJ);
* a trimesh material (``PBRMaterial`` / ``SimpleMaterial``) -- glTF, 3MF, trimesh scenes;
* None -- only the name is known (e.g. the MTL file is missing).

The writers go through the two functions here, which translate any of those into what
their format holds: an MTL block with copied textures, or a glTF PBR description with the
base colour texture as image bytes.
"""

from __future__ import annotations

import io
import os
import re
import shutil
from dataclasses import dataclass

import numpy as np

from meshvis.io._common import atomic_write
from meshvis.soup import Material

# MTL statements whose last token is a file name (texture maps)
_MAP_STATEMENTS = re.compile(r"^\s*(map_\w+|bump|disp|decal|refl|norm)\s", re.IGNORECASE)


@dataclass
class MtlSource:
    """How an OBJ material was defined, kept in :attr:`Material.source`.

    Parameters
    ----------
    text : str
        The statements of the material's ``newmtl`` block, without the ``newmtl`` line.
    folder : str
        Folder of the MTL file; texture paths in ``text`` are relative to it.
    """

    text: str
    folder: str

    def textures(self) -> list[tuple[str, str]]:
        """(statement keyword, file name) of every texture map the block references."""
        out = []
        for line in self.text.splitlines():
            if _MAP_STATEMENTS.match(line):
                parts = line.split()
                if len(parts) >= 2:
                    out.append((parts[0], parts[-1]))
        return out


# ---------------------------------------------------------------------------- parsing helpers


def copy_texture(src: str, dst: str) -> None:
    """Copy a texture file with :func:`meshvis.io.atomic_write`."""
    with open(src, "rb") as fin, atomic_write(dst, "wb") as fout:
        shutil.copyfileobj(fin, fout)


_IMAGE_MIME = {b"\x89PNG": "image/png", b"\xff\xd8\xff": "image/jpeg"}


@dataclass
class PbrDescription:
    """What a glTF writer needs to know about one material.

    Attributes
    ----------
    name : str
    base_color : (4,) float in [0, 1]
    image : bytes or None
        PNG or JPEG bytes of the base colour texture.
    mime : str or None
    metallic, roughness : float or None
    double_sided : bool
    alpha_mode : str or None ("OPAQUE", "MASK", "BLEND")
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
    """PNG bytes of a PIL image (kept as JPEG/PNG bytes when they are already bytes)."""
    if image is None:
        return None, None
    if isinstance(image, (bytes, bytearray)):
        for magic, mime in _IMAGE_MIME.items():
            if bytes(image[: len(magic)]) == magic:
                return bytes(image), mime
        from PIL import Image

        image = Image.open(io.BytesIO(image))
    buf = io.BytesIO()
    img = image
    if img.mode not in ("RGB", "RGBA", "L", "LA"):
        img = img.convert("RGBA")
    img.save(buf, format="PNG", compress_level=1)  # fast; size matters less than time here
    return buf.getvalue(), "image/png"


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
                full = os.path.join(src.folder, fname)
                if os.path.isfile(full):
                    with open(full, "rb") as fh:
                        desc.image, desc.mime = _image_bytes(fh.read())
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
            desc.image, desc.mime = _image_bytes(tex)
        desc.metallic = getattr(pbr, "metallicFactor", None)
        desc.roughness = getattr(pbr, "roughnessFactor", None)
        desc.double_sided = bool(getattr(pbr, "doubleSided", False))
        desc.alpha_mode = getattr(pbr, "alphaMode", None)
    return desc


def write_mtl(materials: list[Material], names: list[str], mtl_path: str, out_folder: str, stem: str) -> None:
    """Write an MTL file for ``materials`` (named ``names``) and put their textures next to it.

    OBJ-sourced blocks are written back as read; each texture they reference is copied
    into ``out_folder`` (unless it already is there) and the reference rewritten.  Other
    materials get ``Kd``/``d`` and a PNG of their base colour texture named
    ``<stem>_<material>.png``.  Every file is written with :func:`meshvis.io.atomic_write`.
    """
    out_folder = os.path.abspath(out_folder)
    taken: dict[str, str] = {}  # output file name -> source path (to avoid collisions)
    blocks = []
    for mat, name in zip(materials, names):
        src = mat.source
        lines = [f"newmtl {name}"]
        if isinstance(src, MtlSource):
            map_keys = {k.lower() for k, _ in src.textures()}
            for line in src.text.splitlines():
                parts = line.split()
                if len(parts) >= 2 and parts[0].lower() in map_keys:
                    fname = parts[-1]
                    full = os.path.normpath(os.path.join(src.folder, fname))
                    if os.path.isfile(full):
                        inside = os.path.normpath(os.path.join(out_folder, fname))
                        if os.path.abspath(src.folder) == out_folder or inside == full:
                            new = fname
                        else:
                            new = _free_name(os.path.basename(fname), full, taken)
                            dst = os.path.join(out_folder, new)
                            if not (os.path.exists(dst) and os.path.samefile(dst, full)):
                                copy_texture(full, dst)
                            taken[new] = full
                        line = " ".join(parts[:-1] + [new])
                lines.append(line)
        else:
            desc = describe_pbr(mat, name)
            r, g, b, a = desc.base_color.tolist()
            lines.append(f"Kd {r!r} {g!r} {b!r}")
            if a < 1.0:
                lines.append(f"d {a!r}")
            if desc.image is not None:
                ext = ".jpg" if desc.mime == "image/jpeg" else ".png"
                new = _free_name(_safe_file_name(f"{stem}_{name}") + ext, f"<{id(mat)}>", taken)
                taken[new] = f"<{id(mat)}>"
                with atomic_write(os.path.join(out_folder, new), "wb") as fh:
                    fh.write(desc.image)
                lines.append(f"map_Kd {new}")
        blocks.append("\n".join(lines))
    with atomic_write(mtl_path, "w") as fh:
        fh.write("# written by meshvis\n\n" + "\n\n".join(blocks) + "\n")


def _free_name(wanted: str, source: str, taken: dict[str, str]) -> str:
    """``wanted``, or ``stem_1.ext``... when another source already uses that name."""
    if wanted not in taken or taken[wanted] == source:
        return wanted
    base, ext = os.path.splitext(wanted)
    k = 1
    while f"{base}_{k}{ext}" in taken and taken[f"{base}_{k}{ext}"] != source:
        k += 1
    return f"{base}_{k}{ext}"
