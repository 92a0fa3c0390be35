"""Orient a triangle soup: turn every face so that its front faces the outside.

The input is two nested spheres with a crack in the outer one, stored as a soup (no shared
vertices, faces shuffled, half of them flipped).  Writes the oriented model and a preview
before and after (front sides blue, back sides orange).

    python examples/orient_soup.py [OUTPUT_FOLDER]
"""

import os

from _common import model, output_folder

import meshvis
from meshvis.rays.render import save_png

out = output_folder()
soup = meshvis.load(model("sphere_pair_soup.obj"))
result = meshvis.orient(soup, seed=0)
meshvis.save(result.soup, os.path.join(out, "oriented.obj"))
camera = meshvis.Camera.fit(soup, azimuth=30, elevation=20)
save_png(meshvis.render(soup, camera, size=(320, 320)).image, os.path.join(out, "before.png"))
save_png(meshvis.render(result.soup, camera, size=(320, 320)).image, os.path.join(out, "after.png"))
report = result.report()
print(f"flipped {report['flipped']} of {report['input_faces']} faces -> {out}")
