"""``meshvis bench scale``: time, peak memory and per-stage times of classify from 20 k to 5 M faces.

With ``--real``, the commands on cities of real models instead (:mod:`meshvis.eval.bench.scale_real`).

The generated models are an icosphere subdivided ``5 .. 9`` times (20,480 .. 5,242,880 faces,
4x per step), made into a soup by :func:`meshvis.eval.generators.soupify` (30 % of the faces
turned over, every face its own corners, shuffled).  Real models are the largest of
``shared/models/real`` and ``real2`` (or the paths given).  Every size runs in a fresh
subprocess so that the peak memory (:func:`peak_mb` of the child) is that of one
classification alone, loading included.  Next to the scene stage the same triangles are
put into a raw ``embreex`` scene (one empty query forces the BVH build), in the same
process, so the ratio is measured side by side on a shared machine.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

from meshvis.eval.bench.real_models import add_models_argument
from meshvis.eval.bench.scale_real import peak_mb

#: icosphere subdivisions of the generated sizes (20 k ... 5 M faces)
SUBDIVISIONS = (5, 6, 7, 8, 9)
#: real models run by default (the largest of the shared folders)
REAL = ("real/pybullet__samurai_monastry.obj", "real2/zdm2_level.glb", "real2/pandora_level.obj")


def add_arguments(p) -> None:
    """Add the options of ``meshvis bench scale`` to ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The benchmark's sub-parser.
    """
    p.add_argument("models", nargs="*", help="real models (default: the largest shared ones)")
    p.add_argument(
        "--sizes", type=int, nargs="*", default=list(SUBDIVISIONS), help="icosphere subdivisions (5..9)"
    )
    p.add_argument("--no-real", action="store_true", help="generated sizes only")
    add_models_argument(p)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", metavar="FILE")
    from meshvis.eval.bench import scale_real

    scale_real.add_arguments(p)


def generated(subdivisions: int, seed: int = 0):
    """The soupified icosphere of ``subdivisions`` (a :class:`Soup`)."""
    import numpy as np
    import trimesh

    from meshvis.eval.generators import GroundTruth, soupify
    from meshvis.soup import Soup

    s = trimesh.creation.icosphere(subdivisions)
    soup = Soup(np.asarray(s.vertices, np.float64), np.asarray(s.faces, np.int64))
    truth = GroundTruth(soup=soup, outside=[True, False], layer=1, outward=True, name="icosphere")
    return soupify(truth, flip=0.3, seed=seed).soup


def raw_embree_seconds(soup) -> float:
    """Seconds to build a raw embreex scene of the soup's triangles and run one query."""
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rs
    import numpy as np

    t = time.perf_counter()
    v = soup.vertices.astype(np.float32)
    scene = rs.EmbreeScene()
    mc.TriangleMesh(scene, v, soup.faces.astype(np.int32))
    scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))
    return time.perf_counter() - t


def one(spec: str, seed: int) -> dict:
    """Load/generate one model, classify it, and measure (run inside the child process)."""
    from meshvis.graphcut.classify import classify
    from meshvis.io import load

    t0 = time.perf_counter()
    if spec.endswith(".npz"):  # a generated soup, written by the parent process
        import numpy as np

        from meshvis.soup import Soup

        with np.load(spec) as z:
            soup, name = Soup(z["vertices"], z["faces"]), str(z["name"])
    else:
        soup, name = load(spec), os.path.basename(spec)
    t_load = time.perf_counter() - t0
    t = time.perf_counter()
    c = classify(soup, seed=seed)
    total = time.perf_counter() - t
    peak = peak_mb()
    raw = raw_embree_seconds(soup)
    # the counts `meshvis info` prints must be the classification's (one shared pass)
    from meshvis.geometry.diagnostics import diagnose

    info, rep = diagnose(soup), c.report(per_face=False)
    keys = ("degenerate_faces", "duplicate_faces", "intersecting_faces", "coplanar_faces")
    scene = next(s.seconds for s in c.stages if s.name == "scene")
    return {
        "model": name,
        "faces": soup.n_faces,
        "load_seconds": t_load,
        "seconds": total,
        "peak_mb": peak,
        "info_counts_agree": all(info[k] == rep[k] for k in keys),
        "counts": {k: rep[k] for k in keys},
        "stages": {s.name: (s.seconds if s.ran else None) for s in c.stages},
        "raw_embree_seconds": raw,
        "scene_over_raw": scene / raw if raw > 0 else None,
        "rays": int(c.counts.rays + c.counts.reverse_rays),
        "nodes": int(c.graph.n),
        "load_average": os.getloadavg()[0],
    }


def warm_up() -> None:
    """Classify a small soup once, so that the numba kernels are compiled and cached on disk.

    Run in a child of its own before the measured sizes: a fresh checkout compiles its
    kernels on first use (tens of seconds), which would otherwise land in the first row.
    """
    from meshvis.graphcut.classify import classify

    classify(generated(2), seed=0)


def run(specs: list[str], seed: int = 0) -> list[dict]:
    """Run every spec (``ico:N`` or a path) in its own subprocess; return their results."""
    out = []
    code = "from meshvis.eval.bench.scale import warm_up; warm_up()"
    subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    with tempfile.TemporaryDirectory() as tmp:
        for spec in specs:
            out.append(_run_one(spec, seed, tmp))
            print(format(out[-1:], header=len(out) == 1), file=sys.stderr, flush=True)
    return out


def _run_one(spec: str, seed: int, tmp: str) -> dict:
    """Measure one size or model in a child process.

    A generated size is made here and handed over as an .npz file, so that the child's
    peak memory is that of loading and classifying only.
    """
    import numpy as np

    if spec.startswith("ico:"):
        soup = generated(int(spec[4:]), seed)
        path = os.path.join(tmp, "model.npz")
        np.savez(path, vertices=soup.vertices, faces=soup.faces, name=f"icosphere({spec[4:]}) soup")
        del soup
        spec = path
    code = f"import json; from meshvis.eval.bench.scale import one; print(json.dumps(one({spec!r}, {seed})))"
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if p.returncode:
        return {"model": spec, "error": (p.stderr.strip().splitlines() or ["?"])[-1]}
    return json.loads(p.stdout.strip().splitlines()[-1])


def format(results: list[dict], header: bool = True) -> str:
    """A table: faces, seconds, growth per 4x faces, peak memory, stage times, scene/raw."""
    stages = ("groups", "scene", "preprocess", "nodes", "sampling", "cut")
    lines = []
    if header:
        lines.append(
            f"{'model':<28} {'faces':>9} {'total s':>8} {'x4':>5} {'peak MB':>8} "
            + " ".join(f"{s:>10}" for s in stages)
            + f" {'raw emb s':>9} {'scene/raw':>9} {'info=cls':>8} {'load':>5}"
        )
    prev = None
    for r in results:
        if "error" in r:
            lines.append(f"{r['model']:<28} failed: {r['error']}")
            continue
        growth = ""
        if prev and prev["model"].startswith("icosphere") and r["model"].startswith("icosphere"):
            growth = f"{r['seconds'] / prev['seconds']:.2f}"
        st = " ".join(
            f"{r['stages'].get(s):>10.2f}" if r["stages"].get(s) is not None else f"{'skipped':>10}"
            for s in stages
        )
        lines.append(
            f"{r['model'][:28]:<28} {r['faces']:>9} {r['seconds']:>8.2f} {growth:>5} {r['peak_mb']:>8.0f} {st} "
            f"{r['raw_embree_seconds']:>9.2f} {r['scene_over_raw']:>9.2f} {'yes' if r['info_counts_agree'] else 'NO':>8} "
            f"{r['load_average']:>5.1f}"
        )
        prev = r
    return "\n".join(lines)


def main(args) -> int:
    """CLI entry of ``meshvis bench scale`` (``--real``: :func:`meshvis.eval.bench.scale_real.main`)."""
    from meshvis.eval.bench.real_models import models_folder

    if args.real:
        from meshvis.eval.bench import scale_real

        return scale_real.main(args)
    specs = [f"ico:{n}" for n in args.sizes]
    if not args.no_real:
        base = os.path.dirname(os.path.abspath(models_folder(args.models_dir)))
        specs += args.models or [os.path.join(base, r) for r in REAL]
    results = run(specs, seed=args.seed)
    print(format(results))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=1)
    return 0
