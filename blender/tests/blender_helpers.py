"""What the Blender tests share: the extension zip, the shared models, the command line."""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
#: the add-on's module once installed from the zip
MODULE = "bl_ext.user_default.meshvis_blender"


def _version() -> str:
    text = (ROOT / "meshvis" / "_version.py").read_text()
    return re.search(r'__version__ = "([^"]+)"', text).group(1)


def extension_zip() -> str:
    path = os.environ.get("MESHVIS_BLENDER_ZIP") or str(ROOT / "dist" / f"meshvis_blender-{_version()}.zip")
    assert os.path.isfile(path), f"{path} not built: run python blender/build.py"
    return path


def shared_model(name: str) -> str:
    path = ROOT.parent / "shared" / "models" / "real" / name
    if not path.exists():
        pytest.skip(f"{path} not available")
    return str(path)


def cli() -> list[str]:
    """The meshvis command line of the project's own environment."""
    command = os.environ.get("MESHVIS_CLI") or shutil.which("meshvis")
    assert command, "meshvis is not on the PATH (pip install . in the main environment)"
    return [command]


def polygons(ob) -> list[np.ndarray]:
    """Each polygon's vertex indices, in corner order."""
    me = ob.data
    n, nl = len(me.polygons), len(me.loops)
    start, total, vert = np.empty(n, np.int32), np.empty(n, np.int32), np.empty(nl, np.int32)
    me.polygons.foreach_get("loop_start", start)
    me.polygons.foreach_get("loop_total", total)
    me.loops.foreach_get("vertex_index", vert)
    return [vert[s : s + t] for s, t in zip(start, total)]


def triangles(ob) -> np.ndarray:
    """(m, 3, 3) corner coordinates of a triangulated object's polygons, in its own space."""
    me = ob.data
    co = np.empty(3 * len(me.vertices), np.float32)
    me.vertices.foreach_get("co", co)
    faces = np.array(polygons(ob))
    return co.reshape(-1, 3)[faces].astype(np.float64)


def same_winding(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(m,) bool: triangles a[i] and b[i] have the same corners in the same cyclic order."""
    return np.array([any(np.array_equal(x, np.roll(y, k, axis=0)) for k in range(3)) for x, y in zip(a, b)])
