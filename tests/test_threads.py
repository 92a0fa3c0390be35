"""The thread count and the sliced calls of meshvis._threads."""

from __future__ import annotations

import threading

import numpy as np

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
