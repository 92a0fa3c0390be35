"""Time meshvis calls in one process under several ray-batch chunk sizes, alternately.

The outputs do not depend on the chunk size (a test checks that threads return the hits
of one thread), so the variants run the same work; each repetition runs every variant
once, in order, and the table gives each variant's fastest and median run.

    python docs/bench/chunk_sizes.py --chunks 16384,2048 --jobs vg_orient,mon_both --reps 4

Models are read from ``--models`` (default ``../shared/models``).
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

import meshvis
from meshvis.rays import caster


def _jobs(models: Path) -> dict:
    """The calls to time, each loading its model on first use."""
    cache: dict[str, meshvis.Soup] = {}

    def model(name: str) -> meshvis.Soup:
        if name not in cache:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                cache[name] = meshvis.load(models / name)
        return cache[name]

    monastery, van_gogh, pandora = (
        "real/pybullet__samurai_monastry.obj",
        "real2/van_gogh_room.glb",
        "real2/pandora_level.obj",
    )
    return {
        "vg_orient": lambda: meshvis.orient(model(van_gogh), seed=0),
        "pan_orient": lambda: meshvis.orient(model(pandora), seed=0),
        "mon_both": lambda: meshvis.remove_interior(model(monastery), seed=0),
        "mon_object": lambda: meshvis.remove_interior(model(monastery), seed=0, visibility="object"),
    }


def main() -> None:
    """Parse the arguments, run the jobs alternately, print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chunks", default="16384,2048", help="comma-separated values of caster.CHUNK")
    ap.add_argument("--jobs", default="vg_orient,mon_both", help="comma-separated job names")
    ap.add_argument("--reps", type=int, default=4)
    ap.add_argument("--models", type=Path, default=Path("../shared/models"))
    args = ap.parse_args()
    chunks = [int(c) for c in args.chunks.split(",")]
    jobs = _jobs(args.models)
    names = args.jobs.split(",")
    for name in names:  # warm-up: kernels loaded, models read
        jobs[name]()
    times: dict[tuple[str, int], list[float]] = {(n, c): [] for n in names for c in chunks}
    for _ in range(args.reps):
        for chunk in chunks:
            caster.CHUNK = chunk
            for name in names:
                start = time.perf_counter()
                jobs[name]()
                times[(name, chunk)].append(time.perf_counter() - start)
    for (name, chunk), ts in times.items():
        runs = " ".join(f"{t:.3f}" for t in ts)
        print(f"{name:11s} CHUNK={chunk:6d}  min {min(ts):.3f} s  median {np.median(ts):.3f} s  ({runs})")


if __name__ == "__main__":
    main()
