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

# the judging of meshvis_only.py beside this script
from meshvis_only import errors, judged_faces, judges, model_files

from meshvis.eval.bench.orientation import soup_of
from meshvis.io import load


def main() -> None:
    """Print one line per model and input."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs")
    ap.add_argument("stems", nargs="?", default="")
    ap.add_argument("--cache", default="/tmp/meshvis-refcache")
    args = ap.parse_args()
    files = model_files()
    dirs = args.dirs.split(",")
    found = {os.path.basename(p).split(".")[0] for d in dirs for p in glob.glob(os.path.join(d, "*.npy"))}
    stems = args.stems.split(",") if args.stems else sorted(found)
    for name in stems:
        soup = load(files[name])
        ref, sides = judges(name, soup, args.cache, recount=True)
        for kind in ("asis", "soup"):
            judged = judged_faces(soup if kind == "asis" else soup_of(soup, 0)[0])
            cells = []
            for d in dirs:
                paths = sorted(glob.glob(os.path.join(d, f"{name}.{kind}.*.npy")))
                if not paths:
                    continue
                # per seed: (by the reference, on the confirmed faces), in %
                e = np.array([errors(np.load(path), ref, sides, judged) for path in paths])
                spread = " / ".join(
                    f"{m:.4f} [{lo:.4f}-{hi:.4f}]" for m, lo, hi in zip(e.mean(0), e.min(0), e.max(0))
                )
                cells.append(f"{os.path.basename(d.rstrip('/'))} ({len(e)} seeds): {spread}")
            if cells:
                print(f"{name:28} {kind:5} " + "   ".join(cells), flush=True)


if __name__ == "__main__":
    main()
