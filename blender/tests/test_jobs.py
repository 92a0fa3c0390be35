"""The background job: progress from the library's callback, cancel, errors handed over."""

from __future__ import annotations

import threading

import pytest


def test_a_job_reports_progress_and_its_result_from_its_thread(installed):
    jobs = installed.jobs
    seen = []
    release = threading.Event()

    def work(progress):
        progress("preprocess", 0.5)
        seen.append(threading.current_thread().name)
        release.wait(5)
        progress("sampling", 1.0)
        return "done"

    job = jobs.Job(work).start()
    release.set()
    assert job.wait(5) and job.result == "done" and job.error is None
    assert seen == ["meshvis"] and job.fraction == 1.0


def test_cancel_stops_the_work_at_its_next_progress_report(installed):
    jobs = installed.jobs
    started, go_on = threading.Event(), threading.Event()
    after = []

    def work(progress):
        started.set()
        go_on.wait(5)
        progress("sampling", 0.5)
        after.append("went on")

    job = jobs.Job(work).start()
    started.wait(5)
    job.cancel()
    go_on.set()
    assert job.wait(5)
    assert isinstance(job.error, jobs.Cancelled) and after == []


def test_a_cancelled_classification_stops_inside_the_library(installed):
    import trimesh

    import meshvis

    ball = trimesh.creation.icosphere(3)
    job = installed.jobs.Job(lambda progress: meshvis.orient((ball.vertices, ball.faces), progress=progress))
    job.cancel()
    with pytest.raises(installed.jobs.Cancelled):
        job.run()


def test_progress_never_goes_back(installed):
    job = installed.jobs.Job(lambda progress: None)
    fractions = []
    for stage, f in [
        ("scene", 0),
        ("preprocess", 0.5),
        ("preprocess", 1),
        ("sampling", 0.2),
        ("preprocess", 0.1),
    ]:
        job.progress(stage, f)
        fractions.append(job.fraction)
    assert fractions == sorted(fractions) and fractions[-1] < 1
