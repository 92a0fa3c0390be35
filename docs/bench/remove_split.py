"""Where the time of the default ``remove_interior`` goes, per real scene, in one process.

For every scene: reading the file, the classification (its stage times), the from-region
search of the ``both`` mode (its time and rays) and the whole call, seed 0.  A warm-up
on the smallest scene loads the compiled kernels first.

    python docs/bench/remove_split.py [--models ../shared/models]
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import meshvis
import meshvis.repair.remove as remove

SCENES = (
    "real/pybullet__samurai_monastry.obj",
    "real2/so101_arm_assembly.ply",
    "real2/pandora_level.obj",
    "real2/dutch_ship.glb",
    "real2/zdm2_level.glb",
    "real2/van_gogh_room.glb",
    "real2/mannequiny.glb",
    "real2/ferrari348_lowpoly.glb",
)


def main() -> None:
    """Time every scene and print a Markdown table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", type=Path, default=Path("../shared/models"))
    args = ap.parse_args()
    search: dict[str, float] = {}
    visible_from = remove.visible_from

    def timed(*a, **k):
        start = time.perf_counter()
        vis = visible_from(*a, **k)
        search["seconds"], search["rays"] = time.perf_counter() - start, vis.rays["total"]
        return vis

    remove.visible_from = timed
    warnings.simplefilter("ignore")  # the models' own warnings (skipped edge records)
    meshvis.remove_interior(meshvis.load(args.models / SCENES[-1]), seed=0)
    print("| scene | faces | read | classify | search | search rays | remove_interior |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name in SCENES:
        t0 = time.perf_counter()
        soup = meshvis.load(args.models / name)
        t1 = time.perf_counter()
        r = meshvis.remove_interior(soup, seed=0)
        t2 = time.perf_counter()
        assert r.classification is not None
        classify = sum(s.seconds for s in r.classification.stages)
        print(
            f"| {Path(name).stem} | {soup.n_faces:,} | {t1 - t0:.2f} s | {classify:.2f} s "
            f"| {search['seconds']:.2f} s | {search['rays'] / 1e6:.2f} M | {t2 - t1:.2f} s |"
        )


if __name__ == "__main__":
    main()
