"""``meshvis bench scale --real``: the commands on cities of real models, 1 M to 10 M faces.

A *city* is a grid of the shared real models (:data:`CITY_MODELS`, from ``real/`` and
``real2/``), each scaled to unit diagonal and turned at random, one model per grid cell
(1.2 diagonals apart), in turn until the faces reach the size asked for: intersecting and
coincident parts, hidden interiors, open sheets and twin faces, as real assets have them.
The city is written as a binary PLY; every command then runs on it in a fresh process
(``python -m meshvis ...``, its defaults), so that each time is end to end (start-up,
reading, analysis, rays, writing) and each peak memory (``VmHWM``) is that command's alone.

Next to each command, the *floor*: the seconds raw Embree (``embreex``, no meshvis code)
takes to build the same scene in float32, plus the seconds Embree spent casting the
command's own rays (:data:`meshvis.rays.caster.RAYS`, timed around each query).  Random rays
are no substitute: rays cast from random faces of a city in cosine directions took 4-6
times as long per ray as the commands' own.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

#: the models a city is built of (relative to the shared models' folder ``..``), in turn
CITY_MODELS = (
    "real/pybullet__samurai_monastry.obj",
    "real2/so101_arm_assembly.ply",
    "real2/zdm2_level.glb",
    "real2/pandora_level.obj",
    "real2/dutch_ship.glb",
    "real2/van_gogh_room.glb",
    "real2/mannequiny.glb",
    "real/dm_control__BONERibcage.stl",
    "real2/ferrari348_lowpoly.glb",
    "real/CesiumMilkTruck.glb",
)
#: faces of the default cities
SIZES = (1_000_000, 5_000_000, 10_000_000)
#: the commands run on every city, with their arguments after the input (OUT: an output file)
COMMANDS = {
    "info": [],
    "orient": ["-o", "OUT.ply"],
    "remove-interior": ["-o", "OUT.ply"],
    "layers": ["-o", "OUT.ply"],
    "visible": ["--report", "OUT.json"],
}
#: grid spacing of the city, in model diagonals
SPACING = 1.2


def add_arguments(p) -> None:
    """Add the options of ``meshvis bench scale --real`` to ``p`` (``meshvis bench scale``'s parser)."""
    p.add_argument("--real", action="store_true", help="the commands on cities of the real models")
    p.add_argument(
        "--faces",
        type=float,
        nargs="*",
        default=[float(s) for s in SIZES],
        help="with --real: faces of each city (default 1e6 5e6 1e7)",
    )
    p.add_argument(
        "--commands", nargs="*", default=list(COMMANDS), help="with --real: the commands to run (default all)"
    )


def city(faces: int, folder: str, seed: int = 0):
    """A city of about ``faces`` faces (at least that many) of the real models in ``folder``.

    Parameters
    ----------
    faces : int
        Faces to reach; the last model placed may pass it.
    folder : str
        The shared models' folder (holding ``real/`` and ``real2/``).
    seed : int
        Seed of the turns.

    Returns
    -------
    Soup
        One part per placed model, named after it.

    Examples
    --------
    >>> import os
    >>> if os.path.isdir("../shared/models/real2"):
    ...     assert city(10_000, "../shared/models").n_faces >= 10_000
    """
    import numpy as np
    from scipy.spatial.transform import Rotation

    from meshvis.io import load
    from meshvis.soup import Soup

    rng = np.random.default_rng(seed)
    models, vertices, faces_list, parts, names = [], [], [], [], []
    n = placed = n_vertices = 0
    while n < faces:
        k = placed % len(CITY_MODELS)
        if k == len(models):
            s = load(os.path.join(folder, CITY_MODELS[k]))
            lo, hi = s.bounds
            models.append(((s.vertices - 0.5 * (lo + hi)) / np.linalg.norm(hi - lo), s.faces))
        v, f = models[k]
        turn = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
        per_row = max(2, int(np.ceil(np.sqrt(faces / 100_000))))
        at = SPACING * np.array([placed % per_row, placed // per_row, 0.0])
        vertices.append(v @ turn.T + at)
        faces_list.append(f + n_vertices)
        parts.append(np.full(len(f), placed))
        names.append(f"{os.path.splitext(os.path.basename(CITY_MODELS[k]))[0]}_{placed}")
        n_vertices += len(v)
        n += len(f)
        placed += 1
    return Soup(
        np.concatenate(vertices), np.concatenate(faces_list), part_id=np.concatenate(parts), part_names=names
    )


def peak_mb() -> float:
    """Peak resident memory of this process, in MB.

    ``VmHWM`` of ``/proc/self/status`` where there is one: Linux carries the parent's
    resident size at the fork into the child's ``ru_maxrss`` across the ``exec``, so a child
    started by a parent that had just built a 5 M-face soup reported the parent's peak.
    ``VmHWM`` belongs to the child's own address space.  Elsewhere ``ru_maxrss``.
    """
    import resource

    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def record(status: int, seconds: float, out: str) -> None:
    """Write a finished command's exit status, seconds, CPU seconds, peak memory and rays to ``out`` (JSON).

    Called in the child process that ran the command (:data:`STAGE`), so that the peak
    memory is the command's own and the rays those of its casters.
    """
    import resource

    from meshvis.rays import caster

    usage = resource.getrusage(resource.RUSAGE_SELF)
    with open(out, "w") as fh:
        json.dump(
            {
                "status": status,
                "seconds_in_process": seconds,
                "cpu_seconds": usage.ru_utime + usage.ru_stime,
                "peak_mb": peak_mb(),
                "rays": caster.RAYS["rays"],
                "embree_seconds": caster.RAYS["seconds"],
            },
            fh,
        )


#: the child process of one command: its start-up and imports count in the parent's time
STAGE = (
    "import sys, time\n"
    "from meshvis.cli.main import main\n"
    "from meshvis.eval.bench.scale_real import record\n"
    "t = time.perf_counter()\n"
    "status = main({argv!r})\n"
    "record(status, time.perf_counter() - t, {out!r})\n"
)


def floor_build_seconds(path: str) -> float:
    """Seconds raw Embree takes to build the scene of the model at ``path`` (no meshvis code).

    The triangles in float32, centred and scaled like meshvis' scene, one empty query to
    build the BVH.
    """
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rs
    import numpy as np

    from meshvis.io import load

    soup = load(path)
    lo, hi = soup.bounds
    t = time.perf_counter()
    v = ((soup.vertices - 0.5 * (lo + hi)) / np.linalg.norm(hi - lo)).astype(np.float32)
    scene = rs.EmbreeScene()
    mc.TriangleMesh(scene, v, soup.faces.astype(np.int32))
    scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))
    return time.perf_counter() - t


def run(sizes: list[int], commands: list[str], folder: str, seed: int = 0) -> list[dict]:
    """Build each city, run each command on it in a fresh process, and measure the floor.

    Returns one dict per (city, command): ``faces``, ``command``, ``seconds`` (end to end),
    ``cpu_seconds`` (user + system, all threads of the command's process), ``peak_mb``, ``rays``, ``embree_seconds``, ``status``, ``floor_seconds`` (raw Embree's
    build of the scene + ``embree_seconds``) and the machine's ``load_average`` at the end.
    """
    from meshvis.io import save

    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for faces in sizes:
            path = os.path.join(tmp, f"city{faces}.ply")
            soup = city(int(faces), folder, seed)
            n_faces = soup.n_faces
            save(soup, path)
            del soup
            rows = []
            for name in commands:
                args = [a.replace("OUT", os.path.join(tmp, "out")) for a in COMMANDS[name]]
                record = os.path.join(tmp, "stage.json")
                argv = [name, path, *args, "--force", "--quiet"] if name != "info" else [name, path]
                code = STAGE.format(argv=argv, out=record)
                t = time.perf_counter()
                p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
                seconds = time.perf_counter() - t
                row = {"faces": n_faces, "command": name, "seconds": seconds}
                if p.returncode or not os.path.exists(record):
                    row["error"] = (p.stderr.strip().splitlines() or ["?"])[-1]
                else:
                    with open(record) as fh:
                        row.update(json.load(fh))
                    os.remove(record)
                row["load_average"] = os.getloadavg()[0]
                rows.append(row)
                print(format([row], header=len(results) + len(rows) == 1), file=sys.stderr, flush=True)
            build = floor_build_seconds(path)
            for r in rows:
                r["floor_build_seconds"] = build
                r["floor_seconds"] = build + r.get("embree_seconds", 0.0)
            results += rows
    return results


def growth(results: list[dict]) -> dict[tuple[str, int], float]:
    """Time growth per 4x faces of each command, from each city to the next larger one.

    ``(t2 / t1) ** (log 4 / log(f2 / f1))``: the factor the time grows by when the faces
    grow 4 times, at the rate measured between the two cities.
    """
    import math

    out = {}
    by_command: dict[str, list[dict]] = {}
    for r in results:
        if "error" not in r:
            by_command.setdefault(r["command"], []).append(r)
    for name, rows in by_command.items():
        rows.sort(key=lambda r: r["faces"])
        for a, b in zip(rows, rows[1:]):
            if b["faces"] > a["faces"] and a["seconds"] > 0:
                out[(name, b["faces"])] = (b["seconds"] / a["seconds"]) ** (
                    math.log(4) / math.log(b["faces"] / a["faces"])
                )
    return out


def format(results: list[dict], header: bool = True) -> str:
    """A table: faces, command, seconds, CPU seconds, growth per 4x faces, peak MB, rays, Embree seconds, floor."""
    lines = []
    if header:
        lines.append(
            f"{'faces':>10} {'command':<16} {'seconds':>8} {'cpu s':>7} {'x4':>5} {'peak MB':>8} {'rays':>11} "
            f"{'embree s':>8} {'floor s':>8} {'load':>5}"
        )
    grow = growth(results)
    for r in results:
        if "error" in r:
            lines.append(f"{r['faces']:>10} {r['command']:<16} failed: {r['error']}")
            continue
        g = grow.get((r["command"], r["faces"]))
        fl = r.get("floor_seconds")
        lines.append(
            f"{r['faces']:>10} {r['command']:<16} {r['seconds']:>8.1f} {r.get('cpu_seconds', 0.0):>7.1f} "
            f"{'' if g is None else f'{g:.2f}':>5} "
            f"{r['peak_mb']:>8.0f} {r['rays']:>11} {r['embree_seconds']:>8.1f} "
            f"{'' if fl is None else f'{fl:.1f}':>8} {r['load_average']:>5.1f}"
        )
    return "\n".join(lines)


def main(args) -> int:
    """CLI entry of ``meshvis bench scale --real``."""
    from meshvis.eval.bench.real_models import models_folder

    folder = os.path.dirname(os.path.abspath(models_folder(args.models_dir)))
    unknown = [c for c in args.commands if c not in COMMANDS]
    if unknown:
        print(
            f"meshvis: error: unknown command {unknown[0]!r}; choose from {', '.join(COMMANDS)}",
            file=sys.stderr,
        )
        return 2
    results = run([int(f) for f in args.faces], args.commands, folder, seed=args.seed)
    print(format(results))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=1)
    return 0
