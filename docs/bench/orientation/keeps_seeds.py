"""Never worse over seeds: the consistently wound real models must keep every face's winding.

Usage (from the repository root):
    python docs/bench/orientation/keeps_seeds.py [FIRST LAST]    # seeds FIRST..LAST-1, default 0..15

Prints per model the seeds with which ``orient`` turned a face, and the first faces turned.
The models are those of ``tests/repair/test_orient_keeps.py`` (the tests run seed 0, and
the teapot seeds 0-7): the open ones first, whose faces are tested with rays of their own,
then the closed ones, whose faces follow their patch.
"""

import sys
import warnings

import numpy as np

from meshvis.io import load
from meshvis.repair.orient import orient

MODELS = "../shared/models/real"
OPEN = [
    "stanford-bunny.obj",
    "suzanne.obj",
    "teapot.obj",
    "bunny10k_textured.obj",
    "CesiumMilkTruck.glb",
    "wallhole.obj",
    "boolean.glb",
    "pymeshlab_face000.ply",
    "dm_control__SKINbody.stl",
]
CLOSED = ["cow.obj", "spot.obj", "nested.glb", "pyvista__ant.ply", "pins.glb", "busted.STL"]
CLOSED += ["dm_control__BONEMergedSkull.stl"]


def main() -> None:
    """Print one line per model."""
    first, last = (int(a) for a in sys.argv[1:3]) if len(sys.argv) > 2 else (0, 16)
    warnings.simplefilter("ignore")  # the loaders' notes on skipped records
    for name in OPEN + CLOSED:
        soup = load(f"{MODELS}/{name}")
        turned = []
        for seed in range(first, last):
            flipped = orient(soup, seed=seed).flipped
            if flipped.any():
                turned.append((seed, np.flatnonzero(flipped)[:5].tolist()))
        print(
            f"{name:28} seeds {first}-{last - 1}: " + (f"turned {turned}" if turned else "none turned"),
            flush=True,
        )


if __name__ == "__main__":
    main()
