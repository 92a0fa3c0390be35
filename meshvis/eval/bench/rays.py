"""``meshvis bench rays``: throughput of the ray backend next to raw embreex on the same rays.

Three ways to use the cores are measured in one run on the same batch:

* raw: one plain ``embreex`` call on rays already converted to the scene's float32 frame;
* backend: :meth:`RayCaster.intersect` (input coordinates in and out, side of the hit,
  float64 distance refinement) with one thread and with all threads;
* processes: a pool of worker processes, each building its own scene and tracing a share
  of the rays (scene build and transfer of rays and results included).
"""

from __future__ import annotations

import multiprocessing as mp
import time
from typing import Any

import numpy as np

from meshvis.graphcut.nodes import side_normals
from meshvis.io import as_soup
from meshvis.rays.caster import RayCaster, default_threads
from meshvis.rays.samples import cosine_hemisphere, uniform_in_triangles
from meshvis.soup import Soup


def surface_rays(soup: Soup, n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Draw ``n`` rays like the sampling stage casts: area-uniform origins, cosine directions.

    Every ray starts on a random side of a face drawn by area, pushed 1e-5 × the diagonal
    off the surface, in a cosine-weighted direction about that side's normal.

    Parameters
    ----------
    soup : Soup
        The model.
    n : int
        Number of rays.
    seed : int
        Seeds the faces, sides, origins and directions.

    Returns
    -------
    origins : (n, 3) float64
        Ray origins.
    directions : (n, 3) float64
        Unit ray directions.
    """
    rng = np.random.default_rng(seed)
    p = soup.areas / soup.areas.sum()
    face = rng.choice(soup.n_faces, size=n, p=p)
    side = rng.integers(0, 2, n)
    nrm = side_normals(soup.normals[face], side)
    origins = uniform_in_triangles(soup.triangles[face], rng) + 1e-5 * soup.diagonal * nrm
    return origins, cosine_hemisphere(nrm, rng)


def _best(fn, repeat: int) -> float:
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def _worker(args):
    vertices, faces, origins, directions = args
    rc = RayCaster((vertices, faces), threads=1)
    h = rc.intersect(origins, directions)
    return h.face


def run(model: Any, n_rays: int = 1_000_000, repeat: int = 3, seed: int = 0) -> dict:
    """Measure rays/s of every variant on the same ``n_rays`` rays (see the module docstring).

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (V, F) or path
        The model, as :func:`meshvis.as_soup` accepts it.
    n_rays : int
        Rays of one measurement (from :func:`surface_rays`).
    repeat : int
        Measurements per variant; the fastest counts.
    seed : int
        Seed of the rays.

    Returns
    -------
    dict
        The model and its faces, rays and threads; rays per second of the raw embreex call,
        the backend with one thread and with all threads, and the worker processes; each
        variant's time ratio to the raw call; whether all threads hit what one thread hits.

    Raises
    ------
    ModelError
        The model cannot be used (see :func:`meshvis.as_soup`).
    """
    soup = as_soup(model)
    origins, directions = surface_rays(soup, n_rays, seed)
    one = RayCaster(soup, threads=1)
    many = RayCaster(soup)
    o32 = one.to_unit(origins)
    d32 = (directions / np.linalg.norm(directions, axis=1, keepdims=True)).astype(np.float32)
    t_raw = _best(lambda: one._scene.run(o32, d32, output=1), repeat)
    t_one = _best(lambda: one.intersect(origins, directions), repeat)
    t_many = _best(lambda: many.intersect(origins, directions), repeat)
    procs = many.threads
    chunks = np.array_split(np.arange(n_rays), procs)
    jobs = [(soup.vertices, soup.faces, origins[c], directions[c]) for c in chunks]
    ctx = mp.get_context("spawn")
    with ctx.Pool(procs) as pool:
        pool.map(_worker, jobs[:1])  # warm the workers up (imports)
        t_proc = _best(lambda: pool.map(_worker, jobs), repeat)
    faces_one = one.intersect(origins, directions).face
    faces_many = many.intersect(origins, directions).face
    rate = lambda t: n_rays / t  # noqa: E731
    return {
        "model": soup.path or "arrays",
        "faces": soup.n_faces,
        "rays": n_rays,
        "threads": many.threads,
        "default_threads": default_threads(),
        "raw_embreex_single_call": rate(t_raw),
        "backend_1_thread": rate(t_one),
        "backend_threads": rate(t_many),
        "processes": rate(t_proc),
        "ratio_backend_1_thread_to_raw": t_raw / t_one,
        "ratio_backend_threads_to_raw": t_raw / t_many,
        "ratio_processes_to_raw": t_raw / t_proc,
        "same_hits_threads_vs_one": bool(np.array_equal(faces_one, faces_many)),
    }


def format(r: dict) -> str:
    """Format a result of :func:`run` as a table: rays/s and ratio to raw embreex per variant.

    Parameters
    ----------
    r : dict
        A result of :func:`run`.

    Returns
    -------
    str
        The table, one line per variant, with a header and the hit check.
    """
    lines = [
        f"model {r['model']}: {r['faces']} faces, {r['rays']} surface rays (cosine directions)",
        f"{'variant':<34}{'Mrays/s':>10}{'x raw':>8}",
        f"{'raw embreex, one call':<34}{r['raw_embreex_single_call'] / 1e6:>10.2f}{1.0:>8.2f}",
        f"{'meshvis backend, 1 thread':<34}{r['backend_1_thread'] / 1e6:>10.2f}{r['ratio_backend_1_thread_to_raw']:>8.2f}",
        f"{'meshvis backend, %d threads' % r['threads']:<34}{r['backend_threads'] / 1e6:>10.2f}{r['ratio_backend_threads_to_raw']:>8.2f}",
        f"{'%d processes (own scenes)' % r['threads']:<34}{r['processes'] / 1e6:>10.2f}{r['ratio_processes_to_raw']:>8.2f}",
        f"threads and one thread give identical hits: {r['same_hits_threads_vs_one']}",
    ]
    return "\n".join(lines)
