"""The scripts in examples/ run and write valid models and pictures.

``gallery.py`` reads the shared real models and takes about a minute; CI runs it in its own
step (``.ci/run``) before it builds the docs, whose build fails on a missing picture.
"""

from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from PIL import Image

from meshvis.io import load

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
#: script -> (models it writes, pictures it writes)
OUTPUTS = {
    "orient_soup.py": (["oriented.obj"], ["before.png", "after.png"]),
    "remove_interior.py": (["exterior.obj", "interior.obj"], ["exterior.png"]),
    "layers.py": (["layers.ply"], ["layers.png"]),
    "label_parts.py": ([], ["labels.png", "labels.svg"]),
}


#: run by CI's own step, not by the suite
GALLERY = "gallery.py"


def test_every_example_is_tested():
    assert {p.name for p in EXAMPLES.glob("*.py") if not p.name.startswith("_")} == set(OUTPUTS) | {GALLERY}


@pytest.mark.slow
@pytest.mark.parametrize("script", sorted(OUTPUTS))
def test_example_writes_its_outputs(script, tmp_path):
    out = tmp_path / "out"
    run = subprocess.run(
        [sys.executable, str(EXAMPLES / script), str(out)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr
    assert str(out) in run.stdout
    models, pictures = OUTPUTS[script]
    for name in models:
        assert load(str(out / name)).n_faces > 0
    for name in pictures:
        path = out / name
        if path.suffix == ".svg":
            root = ET.parse(path).getroot()
            assert root.tag.endswith("svg") and len(root.findall(".//{*}text")) > 0
        else:
            with Image.open(path) as im:
                im.verify()
                assert im.format == "PNG" and min(im.size) >= 100
