"""Label the parts of a model.

Each visible part gets a text box outside the picture of the model and a leader line to a
point on the part.

The input is a small assembly of named parts.  Writes the labelled view as SVG and PNG.

    python examples/label_parts.py [OUTPUT_FOLDER]
"""

import os

from _common import model, output_folder

import meshvis.labeling

out = output_folder()
result = meshvis.labeling.layout(model("assembly.obj"), layout="left-right", size=(480, 480))
written = meshvis.labeling.write(result, os.path.join(out, "labels.svg"))
written += meshvis.labeling.write(result, os.path.join(out, "labels.png"))
print(f"{len(result.labels)} labels -> {', '.join(written)}")
