"""Judge the turned faces that ``meshvis_only.py --dump`` saved, from any commits, by one judge.

Usage (from the repository root, on the commit whose judge you want):
    python docs/bench/orientation/judge_dumps.py DIR[,DIR...] [STEM,...] [--cache /tmp/meshvis-refcache]

Every ``<stem>.<asis|soup>.<seed>.npy`` of each folder is judged by the reference and by the
faces the recount of this checkout confirms (``meshvis.eval.reference.confirm``), as
``meshvis_only.py --confirm`` judges; prints per model and input the mean and range over
the seeds of each folder.  Runs of two commits saved to two folders are so compared on
the same judge.
"""

import argparse
import glob
import os

import numpy as np

from meshvis.eval.bench.orientation import soup_of
from meshvis.eval.reference import confirm, reference
from meshvis.geometry.adjacency import weld
from meshvis.geometry.duplicates import opposite_copies
from meshvis.io import load

R = ["../shared/models/real", "../shared/models/real2"]


def main() -> None:
    """Print one line per model and input."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs")
    ap.add_argument("stems", nargs="?", default="")
    ap.add_argument("--cache", default="/tmp/meshvis-refcache")
    args = ap.parse_args()
    files = {os.path.splitext(f)[0]: os.path.join(d, f) for d in R for f in os.listdir(d) if f != "README.md"}
    dirs = args.dirs.split(",")
    stems = (
        args.stems.split(",")
        if args.stems
        else sorted(
            {os.path.basename(p).split(".")[0] for d in dirs for p in glob.glob(os.path.join(d, "*.npy"))}
        )
    )
    for name in stems:
        soup = load(files[name])
        ref = reference(soup, seed=0, cache=os.path.join(args.cache, f"{name}.seed0.npz"))
        recount = confirm(soup, ref, seed=0, cache=os.path.join(args.cache, f"{name}.confirm2048.npz"))
        judges = [(ref.decisive, ref.outside_side), recount.judged(soup.n_faces)]
        for kind in ("asis", "soup"):
            s = soup if kind == "asis" else soup_of(soup, 0)[0]
            judged = np.ones(soup.n_faces, bool)
            judged[opposite_copies(weld(s.vertices, s.faces)[1]).ravel()] = False  # pairs: as pairs
            cells = []
            for d in dirs:
                errors = []  # per seed: (by the reference, on the confirmed faces), in %
                for path in sorted(glob.glob(os.path.join(d, f"{name}.{kind}.*.npy"))):
                    turned = np.load(path)
                    row = []
                    for decisive, side in judges:
                        dd = judged & decisive
                        wrong = dd & (turned != side.astype(bool))
                        row.append(100 * ref.area[wrong].sum() / max(ref.area[dd].sum(), 1e-300))
                    errors.append(row)
                if errors:
                    e = np.array(errors)
                    cells.append(
                        f"{os.path.basename(d.rstrip('/'))} ({len(e)} seeds): "
                        + " / ".join(
                            f"{m:.4f} [{lo:.4f}-{hi:.4f}]" for m, lo, hi in zip(e.mean(0), e.min(0), e.max(0))
                        )
                    )
            if cells:
                print(f"{name:28} {kind:5} " + "   ".join(cells), flush=True)


if __name__ == "__main__":
    main()
