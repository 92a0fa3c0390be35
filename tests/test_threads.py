"""The thread count and the sliced calls of meshvis._threads."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from meshvis import _threads


def _calls(n: int) -> tuple[list[tuple[int, int]], set[int]]:
    calls, threads = [], set()

    def work(a, b):
        calls.append((int(a), int(b)))
        threads.add(threading.get_ident())

    _threads.in_threads(work, n)
    return sorted(calls), threads


def test_meshvis_threads_sets_the_count_and_one_thread_makes_one_call(monkeypatch):
    monkeypatch.setenv("MESHVIS_THREADS", "3")
    assert _threads.default_threads() == 3
    monkeypatch.setenv("MESHVIS_THREADS", "1")  # as `meshvis batch` sets it for a worker
    calls, threads = _calls(1 << 20)
    assert calls == [(0, 1 << 20)] and threads == {threading.get_ident()}


def test_slices_cover_every_row_once_and_small_inputs_make_one_call(monkeypatch):
    monkeypatch.setenv("MESHVIS_THREADS", "2")
    calls, _ = _calls(1 << 20)
    assert len(calls) == 2 * _threads.THREAD_PARTS
    covered = np.concatenate([np.arange(a, b) for a, b in calls])
    assert np.array_equal(covered, np.arange(1 << 20))
    assert _calls(_threads.THREAD_ROWS)[0] == [(0, _threads.THREAD_ROWS)]


def test_rows_per_item_sizes_the_slices(monkeypatch):
    monkeypatch.setenv("MESHVIS_THREADS", "2")
    calls = []
    _threads.in_threads(lambda a, b: calls.append((int(a), int(b))), 4096, rows_per_item=64)
    assert len(calls) == 2 * _threads.THREAD_PARTS  # 4096 faces of 64 rays: 262,144 rows
    calls.clear()
    _threads.in_threads(lambda a, b: calls.append((int(a), int(b))), 3, rows_per_item=1 << 20)
    assert sorted(calls) == [(0, 1), (1, 2), (2, 3)]  # never more slices than items


def _kernel_calls(rng: np.random.Generator) -> dict:
    """Every kernel that runs on slices in threads, with inputs large enough to be sliced."""
    from meshvis.geometry import _kernels as geometry
    from meshvis.graphcut import _kernels as graphcut
    from meshvis.rays import _kernels as rays
    from meshvis.repair import _kernels as repair
    from meshvis.visibility import _kernels as visibility

    n, m = 1 << 17, 3000
    tri = rng.normal(size=(m, 3, 3))
    normals = rays.unit_rows(rng.normal(size=(m, 3)))
    face = rng.integers(0, m, n)
    flip = rng.random(n) < 0.5
    x, y = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    ru, rv = rng.random(n), rng.random(n)
    center = np.array([0.1, -0.2, 0.3])
    faces = rng.integers(0, m, (m, 3))
    k, per = 2048, 64
    return {
        "unit_rows": lambda: rays.unit_rows(x),
        "points_in_faces": lambda: rays.points_in_faces(tri, face, ru, rv),
        "cosine_directions": lambda: rays.cosine_directions(normals, x[:m], y[:m], face, flip, ru, rv),
        "pushed_points": lambda: rays.pushed_points(tri, normals, face, flip, ru, rv, 1e-3),
        "segment_queries": lambda: rays.segment_queries(x, y, center, 0.5, 1e-5),
        "ray_queries": lambda: rays.ray_queries(x, y, center, 0.5),
        "hit_results": lambda: rays.hit_results(
            np.where(face % 3 == 0, -1, face).astype(np.int32),
            ru.astype(np.float32),
            y.astype(np.float32),
            x,
            0.5,
        ),
        "escape_queries": lambda: repair.escape_queries(
            tri[:k],
            normals[:k],
            face[:k],
            face[k : 2 * k],
            per,
            repair.seed_key(5),
            face[:k] % 3 - 1,
            1e-4,
            2.0,
            center,
            0.5,
            1e-5,
        ),
        "facing_sides": lambda: visibility.facing_sides(x, normals, face),
        "seed_segments": lambda: visibility.seed_segments(
            x, normals, face, (face % 2).astype(np.int8), y, center, 0.5, 1e-5, 2.0
        ),
        "nearest_sample": lambda: graphcut.nearest_sample(
            np.abs(x),
            ru.astype(np.float32),
            rv.astype(np.float32),
            (face % 3 + 1).astype(np.int64),
            np.array([[0.3, 0.0, 0.0], [0.1, 0.5, 0.0], [0.1, 0.5, 0.3]]),
            np.array([[0.3, 0.0, 0.0], [0.2, 0.1, 0.0], [0.2, 0.1, 0.6]]),
        ),
        "gather_normalised": lambda: geometry.gather_normalised(x, np.vstack([faces] * 40), center, 0.5),
    }


def test_kernels_in_threads_give_the_bits_of_one_call(monkeypatch):
    calls = _kernel_calls(np.random.default_rng(5))
    monkeypatch.setenv("MESHVIS_THREADS", "1")
    one = {name: call() for name, call in calls.items()}
    monkeypatch.setenv("MESHVIS_THREADS", "3")
    sliced = []
    real = _threads.in_threads

    def counting(work, n, rows_per_item=1):
        before = len(sliced)
        real(lambda a, b: (sliced.append((a, b)), work(a, b)), n, rows_per_item)
        assert len(sliced) - before > 1  # the input was large enough to be sliced

    for name, call in calls.items():
        monkeypatch.setattr(_module_of(name), "in_threads", counting)
        got = call()
        want = one[name]
        for a, b in zip(
            got if isinstance(got, tuple) else (got,), want if isinstance(want, tuple) else (want,)
        ):
            assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), name


def _module_of(name: str):
    import importlib

    for mod in ("rays", "repair", "visibility", "graphcut", "geometry"):
        module = importlib.import_module(f"meshvis.{mod}._kernels")
        if hasattr(module, name) and hasattr(module, "_" + name):
            return module
    raise LookupError(name)


def test_work_in_a_pool_thread_is_not_sliced_again(monkeypatch):
    monkeypatch.setenv("MESHVIS_THREADS", "2")
    inner = []

    def outer(a, b):
        # slicing again here would wait for the pool's threads, which are busy with `outer`
        _threads.in_threads(lambda c, d: inner.append((int(c), int(d))), 1 << 20)

    _threads.in_threads(outer, 1 << 20)
    assert sorted(inner) == [(0, 1 << 20)] * (2 * _threads.THREAD_PARTS)
    assert _threads.pool(2) is _threads.pool(2)


def _sliced_sum(n: int) -> float:
    x = np.arange(float(n))
    parts = np.zeros(n)
    _threads.in_threads(lambda a, b: np.copyto(parts[a:b], x[a:b]), n)
    return float(parts.sum())


@pytest.mark.filterwarnings("ignore:This process .* is multi-threaded:DeprecationWarning")
def test_a_forked_process_gets_its_own_pool(monkeypatch):
    import multiprocessing

    monkeypatch.setenv("MESHVIS_THREADS", "2")
    assert _sliced_sum(1 << 20) == _sliced_sum(1 << 20)  # the parent's pool is running
    with multiprocessing.get_context("fork").Pool(1) as child:
        # the parent's threads do not exist in the child: reusing its pool would hang
        assert child.apply_async(_sliced_sum, (1 << 20,)).get(timeout=30) == float(np.arange(1 << 20).sum())
