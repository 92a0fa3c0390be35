"""The Blender tests run in Blender's Python (the ``bpy`` wheel) with the built extension installed.

Run them with ``pytest -m blender blender/tests`` (without ``-m blender`` they are left
out) in a virtual environment holding ``bpy``, ``pytest`` and Blender's NumPy only
(``.ci/run`` makes it): meshvis comes from the wheels inside the extension zip, installed into a fresh Blender profile, so the tests exercise
what a user installs.  The zip is ``dist/meshvis_blender-<version>.zip`` (``python
blender/build.py``) or the path in ``MESHVIS_BLENDER_ZIP``.  The command line the operators
are compared with is ``meshvis`` on the ``PATH`` (or ``MESHVIS_CLI``).
"""

from __future__ import annotations

import os
import re
import shutil
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: a Blender profile of its own: set before bpy is imported, removed at exit
PROFILE = tempfile.mkdtemp(prefix="meshvis-blender-profile-")
os.environ["BLENDER_USER_RESOURCES"] = PROFILE

sys.path.insert(0, str(Path(__file__).parent))
from blender_helpers import MODULE, extension_zip  # noqa: E402


def pytest_collection_modifyitems(config, items):
    """Mark every test ``blender``; leave them out unless ``-m`` names that marker."""
    for item in items:
        item.add_marker(pytest.mark.blender)
    if not re.search(r"\bblender\b", config.getoption("markexpr") or ""):
        config.hook.pytest_deselected(items=list(items))
        items[:] = []


def pytest_sessionfinish(session, exitstatus):
    shutil.rmtree(PROFILE, ignore_errors=True)


@pytest.fixture(scope="session")
def bpy():
    import bpy  # the bpy wheel: a test run without it fails here

    return bpy


@pytest.fixture(scope="session")
def installed(bpy):
    """The extension zip installed and enabled in the fresh profile; the add-on's module."""
    import importlib

    result = bpy.ops.extensions.package_install_files(
        filepath=extension_zip(), repo="user_default", enable_on_install=True
    )
    assert result == {"FINISHED"}
    enabled = [a.module for a in bpy.context.preferences.addons]
    assert MODULE in enabled, enabled
    return importlib.import_module(MODULE)


@pytest.fixture
def empty_scene(bpy, installed):
    """A scene without objects, in object mode, with an undo stack."""
    if bpy.context.object is not None and bpy.context.object.mode != "OBJECT":
        bpy.ops.object.mode_set(mode="OBJECT")
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    for data in (bpy.data.meshes, bpy.data.curves, bpy.data.materials):
        for block in list(data):
            data.remove(block)
    for coll in list(bpy.data.collections):
        bpy.data.collections.remove(coll)
    return bpy.context.scene
