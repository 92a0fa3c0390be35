"""The built zip installs into a fresh Blender profile, and the four operators and the panel appear."""

from __future__ import annotations

import os
import zipfile

from blender_helpers import extension_zip

OPERATORS = ["orient", "remove_hidden", "layers", "label_parts"]


def test_the_zip_installs_into_a_fresh_profile_with_its_wheels(bpy, installed):
    import meshvis

    assert os.path.realpath(meshvis.__file__).startswith(
        os.path.realpath(os.environ["BLENDER_USER_RESOURCES"])
    )
    names = zipfile.ZipFile(extension_zip()).namelist()
    assert "blender_manifest.toml" in names and not any(n.startswith("wheels/numpy-") for n in names)


def test_the_four_operators_and_the_panel_appear(bpy, installed):
    for name in OPERATORS:
        assert hasattr(bpy.ops.meshvis, name), name
        assert bpy.ops.meshvis.__getattr__(name).get_rna_type().name
    assert hasattr(bpy.types, "MESHVIS_PT_panel")
    assert hasattr(bpy.context.scene, "meshvis")


def test_the_defaults_are_the_librarys(bpy, installed):
    import inspect

    import meshvis
    import meshvis.labeling

    identifier = installed.operators.identifier
    op = bpy.ops.meshvis.remove_hidden.get_rna_type().properties
    sig = inspect.signature(meshvis.remove_interior).parameters
    assert op["visibility"].default == identifier(sig["visibility"].default)
    assert op["level"].default == identifier(sig["level"].default)
    assert op["see_through"].default == (sig["transparent"].default == "see-through")
    layout = bpy.ops.meshvis.label_parts.get_rna_type().properties["layout"].default
    assert layout == identifier(inspect.signature(meshvis.labeling.layout).parameters["layout"].default)
