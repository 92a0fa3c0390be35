"""What several test modules need: the shared real models, the glTF validator, a GLB writer, a scene.

``pyproject.toml`` puts this folder on ``sys.path`` (pytest's ``pythonpath``), so a test
module imports it as ``from helpers import real_model``.  The real models are read from
``../shared/models/`` next to the checkout; tests that need them skip where it is absent.
"""

from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

from meshvis.soup import Soup

HERE = Path(__file__).resolve().parent
#: the shared real models, next to the checkout (never copied into it)
REAL = HERE.parents[1] / "shared" / "models" / "real"
#: the second set of real scenes (real2/)
REAL2 = REAL.parent / "real2"
#: where ``.ci/run`` installs the Khronos glTF validator
VALIDATOR_MODULES = HERE.parent / ".tools" / "gltf" / "node_modules"
#: seconds the validator may take on the largest scene
VALIDATOR_TIMEOUT = 300


def real_model(name: str) -> str:
    """Path of a shared real model (``real/NAME``, or ``real2/NAME``); skip the test without it."""
    path = REAL / name
    if not path.exists():
        path = REAL2 / name
    if not path.exists():
        pytest.skip(f"{REAL / name} not available")
    return str(path)


def validate_gltf(path: str) -> dict:
    """The Khronos validator's report of a glTF/GLB file; skip the test without the validator."""
    node = shutil.which("node")
    roots = [r for r in (os.environ.get("NODE_PATH", ""), str(VALIDATOR_MODULES)) if r]
    root = next((r for r in roots if os.path.isdir(os.path.join(r, "gltf-validator"))), None)
    if node is None or root is None:
        pytest.skip("gltf-validator (npm) not installed; .ci/run installs it")
    run = subprocess.run(
        [node, str(HERE / "io" / "validate_gltf.js"), path],
        capture_output=True,
        text=True,
        env={**os.environ, "NODE_PATH": root},
        timeout=VALIDATOR_TIMEOUT,
    )
    return json.loads(run.stdout)


def write_glb(doc: dict, blob: bytes, path: str) -> None:
    """Write a glTF document and its one binary buffer as a GLB container (chunks padded to 4)."""
    js = json.dumps(doc).encode()
    js += b" " * ((-len(js)) % 4)
    blob += b"\x00" * ((-len(blob)) % 4)
    with open(path, "wb") as fh:
        fh.write(struct.pack("<4sII", b"glTF", 2, 28 + len(js) + len(blob)))
        fh.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
        fh.write(struct.pack("<II", len(blob), 0x004E4942) + blob)


def two_holes(top: float, bottom: float) -> Soup:
    """A small triangle (front down) in the middle of a 2 x 2 x 2 box with a square hole of
    half-side ``top`` in its lid and one of half-side ``bottom`` in its floor: its back
    sees out through the lid's hole, its front through the floor's."""
    t, lo, hi = 0.01, -1.0, 1.0
    tri = [[-t, -t, 0.0], [0.0, t, 0.0], [t, -t, 0.0]]  # clockwise seen from +z: front down
    box = [[x, y, z] for z in (lo, hi) for y in (lo, hi) for x in (lo, hi)]  # 3..10
    walls = [[3, 4, 8], [3, 8, 7], [5, 6, 10], [5, 10, 9], [3, 5, 9], [3, 9, 7], [4, 6, 10], [4, 10, 8]]
    points, faces = tri + box, [[0, 1, 2]] + walls
    for z, h in ((hi, top), (lo, bottom)):
        first = len(points)
        points += [
            [x, y, z] for x, y in [[lo, lo], [hi, lo], [hi, hi], [lo, hi], [-h, -h], [h, -h], [h, h], [-h, h]]
        ]
        ring = [[0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]]
        faces += [[first + a for a in f] for f in ring]
    return Soup(np.array(points, float), np.array(faces))
