"""The pictures of docs/blender.md, made headless with the ``bpy`` wheel.

Run in the Blender tests' environment (bpy, Blender's NumPy): ``python -P blender/pictures.py``
after ``python blender/build.py``.  The extension zip is installed into a fresh profile,
the operators run on the project's sample models, and Cycles renders the results on the
CPU.  Blender's interface cannot be drawn without a window, so the panel's picture is its
``draw`` function run against a recording layout and drawn with Pillow.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "img" / "blender"
SIZE = (480, 360)
LABELS_SIZE = (720, 540)
SAMPLES = 24
os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp(prefix="meshvis-blender-pictures-")

import bpy  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(ROOT / "blender" / "tests"))
from blender_helpers import MODULE, extension_zip  # noqa: E402


def install():
    """Install the built zip into the fresh profile; the add-on's module."""
    import importlib

    bpy.ops.extensions.package_install_files(
        filepath=extension_zip(), repo="user_default", enable_on_install=True
    )
    return importlib.import_module(MODULE)


def reset() -> None:
    """An empty scene rendered by Cycles on the CPU, colours shown as they are."""
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = SAMPLES
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    world = bpy.data.worlds.new("white")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.9, 0.9, 0.9, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world
    scene.view_settings.view_transform = "Standard"


def look(location, target, lens=50.0, clip_start=0.1):
    """A new active camera at ``location`` looking at ``target``."""
    from mathutils import Vector

    bpy.ops.object.camera_add(location=location)
    cam = bpy.context.active_object
    cam.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()
    cam.data.lens = lens
    cam.data.clip_start = clip_start
    bpy.context.scene.camera = cam
    return cam


def sides_material():
    """Front faces blue, back faces orange (the colours of meshvis' previews)."""
    mat = bpy.data.materials.new("sides")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    geometry = nodes.new("ShaderNodeNewGeometry")
    mix = nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.inputs["A"].default_value = (0.15, 0.35, 0.8, 1)
    mix.inputs["B"].default_value = (0.95, 0.5, 0.1, 1)
    links.new(geometry.outputs["Backfacing"], mix.inputs["Factor"])
    links.new(mix.outputs["Result"], bsdf.inputs["Base Color"])
    return mat


def render(path: Path):
    """Render the scene to ``path``; the picture."""
    bpy.context.scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    from PIL import Image

    return Image.open(path).convert("RGB")


def side_by_side(images, captions, path: Path) -> None:
    """Pictures in a row, each under its caption."""
    from PIL import Image, ImageDraw

    w, h = images[0].size
    sheet = Image.new("RGB", (w * len(images), h + 28), "white")
    draw = ImageDraw.Draw(sheet)
    for k, (im, caption) in enumerate(zip(images, captions)):
        sheet.paste(im, (k * w, 28))
        draw.text((k * w + 8, 8), caption, fill="black", font=_font(15))
    sheet.save(path)


def _font(size: int):
    from meshvis.labeling.text import font

    return font(size)


def select(objects):
    """Select exactly ``objects``, the first one active."""
    for ob in bpy.context.scene.objects:
        ob.select_set(ob in objects)
    bpy.context.view_layer.objects.active = objects[0]


def orient_picture(addon, tmp: Path) -> None:
    """Spot, unwelded and partly flipped, before and after Orient Outside."""
    import meshvis

    reset()
    soup = meshvis.load(str(ROOT.parent / "shared" / "models" / "real" / "spot.obj"))
    corners = soup.triangles.reshape(-1, 3)
    faces = np.arange(len(corners)).reshape(-1, 3)
    flip = np.random.default_rng(1).random(len(faces)) < 0.3
    faces[flip] = faces[flip][:, ::-1]
    ob = addon.convert.new_mesh_object("spot", corners[:, [0, 2, 1]] * (1, -1, 1), faces)  # y up to z up
    ob.data.materials.append(sides_material())
    bpy.ops.object.light_add(type="SUN", rotation=(0.6, 0.2, 0.8))
    look((2.2, -2.6, 1.2), (0, 0, 0.1), lens=45)
    before = render(tmp / "orient_before.png")
    select([ob])
    bpy.ops.meshvis.orient()
    after = render(tmp / "orient_after.png")
    side_by_side(
        [before, after],
        ["spot, unwelded, 30 % of the faces flipped", "after Orient Outside"],
        OUT / "orient.png",
    )


def flat_material(name: str, front, back):
    """Shading that needs no light: front faces lit by how squarely they face the camera.

    Inside a closed part no light arrives, so a lit material shows a cut-open part black;
    this one shows it in ``back``, the colour of the faces' back sides.
    """
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.remove(nodes["Principled BSDF"])
    facing = nodes.new("ShaderNodeLayerWeight")
    facing.inputs["Blend"].default_value = 0.4
    shade = nodes.new("ShaderNodeMix")
    shade.data_type = "RGBA"
    shade.inputs["A"].default_value = front
    shade.inputs["B"].default_value = tuple(0.45 * c for c in front[:3]) + (1,)
    links.new(facing.outputs["Facing"], shade.inputs["Factor"])
    sides = nodes.new("ShaderNodeMix")
    sides.data_type = "RGBA"
    sides.inputs["B"].default_value = back
    links.new(nodes.new("ShaderNodeNewGeometry").outputs["Backfacing"], sides.inputs["Factor"])
    links.new(shade.outputs["Result"], sides.inputs["A"])
    glow = nodes.new("ShaderNodeEmission")
    links.new(sides.outputs["Result"], glow.inputs["Color"])
    links.new(glow.outputs["Emission"], nodes["Material Output"].inputs["Surface"])
    return mat


def assembly(addon):
    """The sample engine assembly, one object per part, in the flat material."""
    reset()
    bpy.ops.wm.obj_import(filepath=str(ROOT / "models" / "assembly.obj"), forward_axis="Y", up_axis="Z")
    parts = [ob for ob in bpy.context.scene.objects if ob.type == "MESH"]
    mat = flat_material("metal", front=(0.62, 0.68, 0.78, 1), back=(0.85, 0.45, 0.15, 1))
    for ob in parts:
        ob.data.materials.clear()
        ob.data.materials.append(mat)
    return parts


def _centre(addon, parts) -> np.ndarray:
    v = addon.convert.read_scene(parts).vertices
    return 0.5 * (v.min(axis=0) + v.max(axis=0))


def remove_picture(addon, tmp: Path) -> None:
    """The assembly cut open by the camera's clipping plane, before and after Remove Hidden."""
    parts = assembly(addon)
    centre = _centre(addon, parts)
    # a section view: the camera's clipping plane, through the middle, cuts the block open
    eye = centre + (0.0, -6.0, 2.5)
    cam = look(eye, centre, lens=35, clip_start=float(np.linalg.norm(eye - centre)))
    before = render(tmp / "remove_before.png")
    select(parts)
    bpy.ops.meshvis.remove_hidden(action="DELETE")
    after = render(tmp / "remove_after.png")
    cam.data.clip_start = 0.1
    whole = render(tmp / "remove_whole.png")
    side_by_side(
        [before, after, whole],
        ["cut open: the parts inside", "after Remove Hidden, cut open", "after, whole"],
        OUT / "remove.png",
    )


def labels_picture(addon, tmp: Path) -> None:
    """The assembly labelled by Label Parts for the active camera."""
    parts = assembly(addon)
    centre = _centre(addon, parts)
    bpy.context.scene.render.resolution_x, bpy.context.scene.render.resolution_y = LABELS_SIZE
    look(centre + (4.0, -6.0, 3.5), centre, lens=30)
    select(parts)
    bpy.ops.meshvis.label_parts(layout="LEFT_RIGHT", resolution=LABELS_SIZE[0])
    ink = flat_material("ink", front=(0.0, 0.0, 0.0, 1), back=(0.0, 0.0, 0.0, 1))
    for ob in bpy.data.collections["meshvis labels"].objects:
        ob.data.materials.append(ink)
    render(OUT / "labels.png")


class _Recorder:
    """A stand-in for Blender's UILayout: records rows of what the panel draws."""

    def __init__(self, rows, indent=0):
        self.rows, self.indent = rows, indent

    def box(self):
        self.rows.append(("box", self.indent, ""))
        return _Recorder(self.rows, self.indent + 1)

    def column(self, align=False):
        self.rows.append(("gap", self.indent, ""))
        return self

    def label(self, text="", icon=None):
        self.rows.append(("label", self.indent, text))

    def prop(self, data, key, text=None):
        prop = data.bl_rna.properties[key]
        value = getattr(data, key)
        if prop.type == "ENUM":
            value = next(i.name for i in prop.enum_items if i.identifier == value)
        elif prop.type == "POINTER":
            value = value.name if value else "(none)"
        elif prop.type == "BOOLEAN":
            self.rows.append(("check", self.indent, f"{'[x]' if value else '[ ]'} {prop.name}"))
            return
        name = prop.name if text is None else text
        self.rows.append(("prop", self.indent, f"{name}: {value}" if name else str(value)))

    def operator(self, idname, icon=None):
        module, name = idname.split(".")
        op = getattr(getattr(bpy.ops, module), name)
        self.rows.append(("button", self.indent, op.get_rna_type().name))
        return _Settable()


class _Settable:
    def __setattr__(self, key, value):
        pass


def panel_picture(addon) -> None:
    """The sidebar panel as its ``draw`` function lays it out."""
    from PIL import Image, ImageDraw

    reset()
    rows: list = []
    addon.panel.draw(_Recorder(rows), bpy.context.scene.meshvis)
    line, width = 24, 300
    height = (
        36 + line * sum(kind != "gap" for kind, _, _ in rows) + 8 * sum(kind == "gap" for kind, _, _ in rows)
    )
    im = Image.new("RGB", (width, height), (48, 48, 48))
    draw = ImageDraw.Draw(im)
    draw.rectangle((0, 0, width, 28), fill=(38, 38, 38))
    draw.text((10, 6), "meshvis", fill=(230, 230, 230), font=_font(14))
    y = 36
    for kind, indent, text in rows:
        if kind == "gap":
            y += 8
            continue
        x = 10 + 12 * indent
        if kind == "button":
            draw.rounded_rectangle((x, y, width - 10, y + line - 4), 4, fill=(84, 84, 84))
            draw.text((x + 8, y + 3), text, fill=(240, 240, 240), font=_font(13))
        elif kind == "prop":
            draw.rounded_rectangle((x, y, width - 10, y + line - 4), 4, fill=(34, 34, 34))
            draw.text((x + 8, y + 3), text, fill=(220, 220, 220), font=_font(13))
        else:
            draw.text((x, y + 3), text, fill=(220, 220, 220), font=_font(13))
        y += line
    im.save(OUT / "panel.png")


def main() -> None:
    """Write the four pictures."""
    OUT.mkdir(parents=True, exist_ok=True)
    addon = install()
    with tempfile.TemporaryDirectory() as tmp:
        orient_picture(addon, Path(tmp))
        remove_picture(addon, Path(tmp))
        labels_picture(addon, Path(tmp))
    panel_picture(addon)
    print(f"wrote {', '.join(sorted(p.name for p in OUT.glob('*.png')))} in {OUT}")


if __name__ == "__main__":
    main()
