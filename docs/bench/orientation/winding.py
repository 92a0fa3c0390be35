"""Winding consistency of the runs that ``meshvis_only.py --dump`` saved.

Usage (from the repository root):
    python docs/bench/orientation/winding.py DIR[,DIR...] [STEM,...]

For every ``<stem>.<asis|soup>.<seed>.npy`` prints, per folder, the manifold edges (after
welding) whose two faces run along them the same way once the saved faces are turned
over (0: the output is consistently wound), with the file's own count for reference.
The saved faces are relative to the file, so a soup's output is compared with the model
it was made from.
"""

import argparse
import glob
import os

import numpy as np
from meshvis_only import model_files

from meshvis.geometry.adjacency import edges, weld
from meshvis.io import load


def inconsistent_edges(faces: np.ndarray, turned: np.ndarray) -> int:
    """Manifold edges whose two faces, ``turned`` ones reversed, run along them the same way."""
    return int((~edges(np.where(turned[:, None], faces[:, ::-1], faces)).consistent).sum())


def main() -> None:
    """Print one line per model, input and seed."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs")
    ap.add_argument("stems", nargs="?", default="")
    args = ap.parse_args()
    dirs = args.dirs.split(",")
    files = model_files()
    runs = sorted(
        {os.path.basename(p)[: -len(".npy")] for d in dirs for p in glob.glob(os.path.join(d, "*.npy"))}
    )
    stems = set(args.stems.split(",")) if args.stems else {r.split(".")[0] for r in runs}
    welded = {}
    for run in runs:
        stem = run.split(".")[0]
        if stem not in stems:
            continue
        if stem not in welded:
            soup = load(files[stem])
            welded[stem] = weld(soup.vertices, soup.faces)[1]
        faces = welded[stem]
        cells = [f"file {inconsistent_edges(faces, np.zeros(len(faces), bool))}"]
        for d in dirs:
            path = os.path.join(d, run + ".npy")
            if os.path.exists(path):
                cells.append(f"{os.path.basename(d.rstrip('/'))} {inconsistent_edges(faces, np.load(path))}")
        print(f"{run:40} " + "  ".join(cells), flush=True)


if __name__ == "__main__":
    main()
