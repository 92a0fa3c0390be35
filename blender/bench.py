"""What the Blender extension adds to the library's time: ``python -P blender/bench.py``.

Run in the Blender tests' environment (bpy, Blender's NumPy) after ``python
blender/build.py``: the zip is installed into a fresh profile, and each operator runs from
a script (in the foreground, as *Adjust Last Operation* runs it) on a sample model, beside
the library call it makes on the same soup and the conversion of the selection to that
soup (medians of three runs after a first one).  Prints a Markdown table; ``--out FILE``
also writes it there.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp(prefix="meshvis-blender-bench-")

import bpy  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(ROOT / "blender" / "tests"))
from blender_helpers import MODULE, extension_zip  # noqa: E402

SPOT = ROOT.parent / "shared" / "models" / "real" / "spot.obj"
ASSEMBLY = ROOT / "models" / "assembly.obj"
#: timed runs of each warm call (the median is shown)
REPEATS = 3


def install():
    """Install the built zip into the fresh profile; the add-on's module."""
    import importlib

    bpy.ops.extensions.package_install_files(
        filepath=extension_zip(), repo="user_default", enable_on_install=True
    )
    return importlib.import_module(MODULE)


def select(objects) -> None:
    """Select exactly ``objects``, the first one active."""
    for ob in bpy.context.scene.objects:
        ob.select_set(ob in objects)
    bpy.context.view_layer.objects.active = objects[0]


def timed(call) -> tuple[float, object]:
    """Seconds of ``call()`` and its result."""
    t0 = time.perf_counter()
    out = call()
    return time.perf_counter() - t0, out


def spot(addon) -> list:
    """Spot unwelded with 30 % of its faces flipped, as one object."""
    import meshvis

    bpy.ops.wm.read_homefile(use_empty=True)
    corners = meshvis.load(str(SPOT)).triangles.reshape(-1, 3)
    faces = np.arange(len(corners)).reshape(-1, 3)
    flip = np.random.default_rng(1).random(len(faces)) < 0.3
    faces[flip] = faces[flip][:, ::-1]
    return [addon.convert.new_mesh_object("spot", corners, faces)]


def assembly(addon) -> list:
    """The sample engine assembly, one object per part, and a camera looking at it."""
    from mathutils import Vector

    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.wm.obj_import(filepath=str(ASSEMBLY), forward_axis="Y", up_axis="Z")
    parts = [ob for ob in bpy.context.scene.objects if ob.type == "MESH"]
    v = addon.convert.read_scene(parts).vertices
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    bpy.ops.object.camera_add(location=tuple(centre + (4.0, -6.0, 3.5)))
    cam = bpy.context.active_object
    cam.rotation_euler = (Vector(centre) - cam.location).to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = cam
    return parts


def row(addon, name: str, make, operator, library) -> list:
    """One operator's times: first library call, conversion, library and operator (medians), ratio.

    The first call in a process compiles the kernels it is the first to use (their cache
    is kept per installed copy of meshvis, and the profile is fresh).
    """
    objects = make(addon)
    select(objects)
    t_convert, soup = timed(lambda: addon.convert.read_scene(objects).soup())
    t_first, _ = timed(lambda: library(soup))
    t_library = float(np.median([timed(lambda: library(soup))[0] for _ in range(REPEATS)]))
    times = []
    for _ in range(REPEATS):
        objects = make(addon)
        select(objects)
        t, result = timed(operator)
        assert result == {"FINISHED"}, result
        times.append(t)
    t_operator = float(np.median(times))
    return [name, soup.n_faces, t_first, t_convert, t_library, t_operator, t_operator / t_library]


def main() -> None:
    """Time the four operators and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", help="also write the table to this file")
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:])
    addon = install()
    import meshvis
    from meshvis.labeling import layout

    def label(soup):
        size = addon.labels.image_size(bpy.context.scene, 768)
        return layout(soup, addon.labels.camera(bpy.context.scene.camera, size), size=size)

    rows = [
        row(addon, "Orient Outside, spot", spot, bpy.ops.meshvis.orient, lambda s: meshvis.orient(s, seed=0)),
        row(
            addon,
            "Remove Hidden, assembly",
            assembly,
            bpy.ops.meshvis.remove_hidden,
            lambda s: meshvis.remove_interior(s, seed=0),
        ),
        row(
            addon,
            "Layers, assembly",
            assembly,
            bpy.ops.meshvis.layers,
            lambda s: meshvis.layers(s, classification=meshvis.classify(s, seed=0)),
        ),
        row(addon, "Label Parts, assembly", assembly, bpy.ops.meshvis.label_parts, label),
    ]
    lines = [
        "| operator, model | triangles | first library call (s) | selection to soup (s) "
        "| library (s) | operator (s) | operator / library |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    lines += [
        f"| {n} | {f:,} | {first:.1f} | {c:.3f} | {lib:.2f} | {op:.2f} | {r:.2f} |"
        for n, f, first, c, lib, op, r in rows
    ]
    table = "\n".join(lines)
    print(table)
    if args.out:
        Path(args.out).write_text(table + "\n")


if __name__ == "__main__":
    main()
