"""Remove the inside of a model: keep only the faces that can be seen from outside.

The input is a box and a sphere passing through each other; the parts of each solid inside
the other cannot be seen.  Writes the kept faces and the removed ones (together they are
the input, face for face) and a preview of the kept part.

    python examples/remove_interior.py [OUTPUT_FOLDER]
"""

import os

from _common import model, output_folder

import meshvis
from meshvis.rays.render import save_png

out = output_folder()
soup = meshvis.load(model("overlapping_solids.obj"))
result = meshvis.remove_interior(soup, seed=0)
meshvis.save(result.kept, os.path.join(out, "exterior.obj"))
meshvis.save(result.removed, os.path.join(out, "interior.obj"))
save_png(meshvis.render(result.kept, size=(320, 320)).image, os.path.join(out, "exterior.png"))
assert result.kept.n_faces + result.removed.n_faces == soup.n_faces  # every face accounted for
print(f"kept {result.kept.n_faces}, removed {result.removed.n_faces} of {soup.n_faces} faces -> {out}")
