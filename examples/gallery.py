"""The pictures of the docs' gallery: real models before and after each command.

Reads the shared real models (``../shared/models/`` next to the checkout, or the folder
given with ``--models``; they are never copied into the repository) and writes one PNG per
row of the gallery in ``docs/index.md``, each a strip of panels with a caption under it.
CI runs it (``.ci/run``) before the docs are built, so the pictures show what the current
code does.  About half a minute on two cores once the compiled kernels are cached.

    python examples/gallery.py [OUTPUT_FOLDER] [--models DIR]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np
from PIL import Image, ImageDraw, ImageFont

import meshvis
import meshvis.labeling
from meshvis.eval.demo import run_demo
from meshvis.rays.render import render_layers

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, os.pardir, "docs", "img", "gallery")
DEFAULT_MODELS = os.path.join(HERE, os.pardir, os.pardir, "shared", "models")
#: height of every panel, in pixels; the width follows the model's picture
PANEL = 300
#: space between panels, in pixels
GAP = 24
#: the one seed of every command
SEED = 0


def crop(image: np.ndarray, pad: int = 8) -> Image.Image:
    """The picture cut down to the model's pixels (non-white) plus ``pad`` pixels."""
    ink = np.any(image < 250, axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if len(rows) == 0:
        return Image.fromarray(image)
    h, w = ink.shape
    box = (
        max(cols[0] - pad, 0),
        max(rows[0] - pad, 0),
        min(cols[-1] + pad + 1, w),
        min(rows[-1] + pad + 1, h),
    )
    return Image.fromarray(image).crop(box)


def strip(panels: list[tuple[np.ndarray, str]], path: str) -> None:
    """Panels side by side, each cropped to its model and captioned underneath."""
    font = ImageFont.load_default(size=15)
    pictures = [crop(image) for image, _ in panels]
    tallest = max(p.height for p in pictures)
    scaled = [
        p.resize((max(1, round(p.width * PANEL / tallest)), round(p.height * PANEL / tallest)))
        for p in pictures
    ]
    widths = [max(p.width, round(font.getlength(text))) for p, (_, text) in zip(scaled, panels)]
    sheet = Image.new("RGB", (sum(widths) + GAP * (len(widths) + 1), PANEL + 48), "white")
    draw = ImageDraw.Draw(sheet)
    x = GAP
    for picture, width, (_, text) in zip(scaled, widths, panels):
        sheet.paste(picture, (x + (width - picture.width) // 2, 8 + (PANEL - picture.height) // 2))
        draw.text((x, PANEL + 20), text, fill=(40, 40, 40), font=font)
        x += width + GAP
    sheet.save(path)


def orient_row(models: str, out: str) -> str:
    """The orient row: the Ferrari 348 as it is; front sides blue, back sides orange."""
    car = meshvis.load(os.path.join(models, "real2", "ferrari348_lowpoly.glb"))
    result = meshvis.orient(car, seed=SEED)
    camera = meshvis.Camera.fit(car, azimuth=30, elevation=20)
    panels = [
        (meshvis.render(car, camera, size=(640, 480)).image, "input: back sides (orange) face outward"),
        (
            meshvis.render(result.soup, camera, size=(640, 480)).image,
            f"orient: {int(result.flipped.sum())} faces turned",
        ),
    ]
    strip(panels, os.path.join(out, "orient.png"))
    return f"orient: {int(result.flipped.sum())} of {car.n_faces} faces turned"


def removal_strip(path: str, picture: str) -> str:
    """A removal's strip: the model seen through with its hidden faces, the output, the removed faces."""
    model = meshvis.load(path)
    result = meshvis.remove_interior(model, seed=SEED)
    camera = meshvis.Camera.fit(model, azimuth=30, elevation=20)
    see_through = render_layers(model, np.where(result.keep, 1, 2), camera, size=(640, 480))
    kept, removed = int(result.keep.sum()), int((~result.keep).sum())
    panels = [
        (see_through, f"input, seen through: {removed} hidden faces (green)"),
        (meshvis.render(result.kept, camera, size=(640, 480)).image, f"remove-interior: {kept} faces kept"),
        (meshvis.render(result.removed, camera, size=(640, 480)).image, "the faces removed"),
    ]
    strip(panels, picture)
    return f"remove-interior: {kept} of {model.n_faces} faces kept"


def remove_row(models: str, out: str) -> str:
    """The remove-interior row: boolean.glb seen through, the output, the removed faces."""
    return removal_strip(
        os.path.join(models, "real", "boolean.glb"), os.path.join(out, "remove-interior.png")
    )


def layers_row(models: str, out: str) -> str:
    """The layers row: the dm_control dog, skin, skull and rib cage (three STL files combined)."""
    files = ("SKINbody", "BONEMergedSkull", "BONERibcage")
    dog = meshvis.Soup.concatenate(
        [meshvis.load(os.path.join(models, "real", f"dm_control__{f}.stl")) for f in files]
    )
    result = meshvis.layers(dog, seed=SEED)
    camera = meshvis.Camera.fit(dog, azimuth=60, elevation=15)
    panels = [
        (meshvis.render(dog, camera, size=(640, 480)).image, "input: skin, skull and rib cage"),
        (
            render_layers(dog, result.layer, camera, size=(640, 480)),
            f"layers: {result.n_layers} layers, outer one veiled",
        ),
    ]
    strip(panels, os.path.join(out, "layers.png"))
    return f"layers: {result.n_layers} layers on {dog.n_faces} faces"


def generated_row(models: str, out: str) -> str:
    """The second remove-interior row: a generated helmet whose parts pass through each other."""
    return removal_strip(
        os.path.join(models, "ai", "holopart_helmet.glb"),
        os.path.join(out, "remove-interior-generated.png"),
    )


def label_row(models: str, out: str) -> str:
    """The label row: a generated cart of 12 named parts, silhouette layout."""
    result = meshvis.labeling.layout(os.path.join(models, "ai", "holopart_cart.glb"), layout="silhouette")
    meshvis.labeling.write(result, os.path.join(out, "label.png"))
    return f"label: {len(result.labels)} labels"


def demo_row(models: str, out: str) -> str:
    """The four previews of ``meshvis demo`` side by side (the README's picture)."""
    with tempfile.TemporaryDirectory() as folder:
        summary = run_demo(folder, size=256, say=lambda line: None)
        names = ("input.png", "oriented.png", "exterior.png", "layers.png")
        pictures = [Image.open(os.path.join(folder, name)).convert("RGB") for name in names]
        sheet = Image.new("RGB", (sum(p.width for p in pictures), max(p.height for p in pictures)), "white")
        for i, picture in enumerate(pictures):
            sheet.paste(picture, (sum(p.width for p in pictures[:i]), 0))
        sheet.save(os.path.join(out, "demo.png"))
    return f"demo: orientation right on {100 * summary['orientation_correct_area']:.2f} % of the area"


ROWS = (demo_row, orient_row, remove_row, generated_row, layers_row, label_row)


def main() -> None:
    """Write every row of the gallery into the folder given (default docs/img/gallery)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "out", nargs="?", default=DEFAULT_OUT, help="folder of the pictures (default docs/img/gallery)"
    )
    parser.add_argument(
        "--models", default=DEFAULT_MODELS, help="the shared models (default ../shared/models)"
    )
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    for row in ROWS:
        start = time.perf_counter()
        summary = row(args.models, args.out)
        print(f"{summary} ({time.perf_counter() - start:.1f} s)")
    print(f"gallery written to {os.path.normpath(args.out)}")


if __name__ == "__main__":
    main()
