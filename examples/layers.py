"""Peel a model into layers.

Layer 1 is what is seen from outside, layer 2 what is seen once layer 1 is gone, and so on.

The input is three nested closed shells.  Writes a PLY file with a ``layer`` property per
face and a picture with the outer layers translucent.

    python examples/layers.py [OUTPUT_FOLDER]
"""

import os

import numpy as np
from _common import model, output_folder

import meshvis
from meshvis.rays.render import render_layers, save_png

out = output_folder()
soup = meshvis.load(model("nested_shells.obj"))
result = meshvis.layers(soup, seed=0)
meshvis.save(soup, os.path.join(out, "layers.ply"), face_values={"layer": result.layer})
save_png(render_layers(soup, result.layer, size=(320, 320)), os.path.join(out, "layers.png"))
counts = np.bincount(result.layer)[1:].tolist()
print(f"{result.n_layers} layers, faces per layer {counts} -> {out}")
