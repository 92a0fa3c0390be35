"""meshvis alone on the inputs of `meshvis bench orientation`, judged the same way.

Usage (from the repository root; references from the cache of the benchmark):
    python docs/bench/orientation/meshvis_only.py STEM[,STEM...]|all ["as is"|soup[,...]]
        [--seeds 0,1] [--cache /tmp/meshvis-refcache] [--confirm] [--dump DIR]

``all``: every model of ``../shared/models/real`` and ``real2`` but so101 (whose
reference and recount take long).  Prints per model, input and seed the time, the error
by the reference (and with ``--confirm`` on the faces a recount confirms, as ``--confirm``
of the benchmark), the evidence rays and the faces turned.
"""

import argparse
import os
import time

import numpy as np

from meshvis.eval.bench.orientation import soup_of
from meshvis.eval.reference import confirm, reference
from meshvis.geometry.adjacency import weld
from meshvis.geometry.duplicates import opposite_copies
from meshvis.io import load
from meshvis.repair.orient import orient

R = ["../shared/models/real", "../shared/models/real2"]
SKIPPED_BY_ALL = ("so101_arm_assembly",)


def model_files() -> dict[str, str]:
    """Path of every real model by its stem."""
    return {
        os.path.splitext(f)[0]: os.path.join(d, f)
        for d in R
        for f in sorted(os.listdir(d))
        if f != "README.md"
    }


def judges(name: str, soup, cache: str, recount: bool) -> tuple:
    """The reference, and its judges: ``(decisive, outside_side)`` by the reference, then by the recount."""
    ref = reference(soup, seed=0, cache=os.path.join(cache, f"{name}.seed0.npz"))
    sides = [(ref.decisive, ref.outside_side)]
    if recount:
        sides.append(
            confirm(soup, ref, seed=0, cache=os.path.join(cache, f"{name}.confirm2048.npz")).judged(
                soup.n_faces
            )
        )
    return ref, sides


def judged_faces(s) -> np.ndarray:
    """(m,) bool: the faces judged one by one (a double-sided pair of ``s`` is judged as a pair)."""
    judged = np.ones(s.n_faces, bool)
    judged[opposite_copies(weld(s.vertices, s.faces)[1]).ravel()] = False
    return judged


def errors(turned: np.ndarray, ref, sides, judged: np.ndarray) -> list[float]:
    """% of the judged decisive area whose front is not the outside side, per judge.

    ``turned``: (m,) bool, each face turned over relative to the file the reference is of.
    """
    out = []
    for decisive, side in sides:
        d = judged & decisive
        wrong = d & (turned != side.astype(bool))
        out.append(100 * ref.area[wrong].sum() / max(ref.area[d].sum(), 1e-300))
    return out


def main() -> None:
    """Run the models and print one line per input and seed."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("stems")
    ap.add_argument("kinds", nargs="?", default="as is,soup")
    ap.add_argument("--seeds", default="0")
    ap.add_argument("--cache", default="/tmp/meshvis-refcache")
    ap.add_argument("--confirm", action="store_true", help="also judge on the faces a recount confirms")
    ap.add_argument("--dump", metavar="DIR", help="save the faces each run turns (judge_dumps.py reads them)")
    args = ap.parse_args()
    files = model_files()
    stems = [s for s in files if s not in SKIPPED_BY_ALL] if args.stems == "all" else args.stems.split(",")
    for name in stems:
        soup = load(files[name])
        ref, sides = judges(name, soup, args.cache, args.confirm)
        for kind in args.kinds.split(","):
            s, turned = (soup, np.zeros(soup.n_faces, bool)) if kind == "as is" else soup_of(soup, 0)
            judged = judged_faces(s)
            for seed in (int(x) for x in args.seeds.split(",")):
                t = time.perf_counter()
                r = orient(s, seed=seed)
                sec = time.perf_counter() - t
                relative = np.asarray(r.flipped, bool) ^ turned  # turned relative to the file
                if args.dump:
                    np.save(os.path.join(args.dump, f"{name}.{kind.replace(' ', '')}.{seed}.npy"), relative)
                err = " / ".join(f"{e:.4f}" for e in errors(relative, ref, sides, judged))
                rays = r.visibility["rays"] if r.visibility else 0
                print(
                    f"{name:32} {kind:6} seed {seed} {sec:7.2f} s  error {err} %"
                    f"  rays {rays}  turned {int(r.flipped.sum())}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
