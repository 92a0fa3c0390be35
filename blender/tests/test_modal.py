"""The modal path, driven by hand: Blender's bpy module has no event loop to send timer events.

A stand-in operator inherits the add-on's shared steps (:class:`_Background`), so its
``modal`` is the add-on's own; the events are plain objects with a ``type``.
"""

from __future__ import annotations

import threading
import time
from types import SimpleNamespace

#: seconds a test waits for the worker at most
PATIENCE = 60


def _stand_in(installed, work, applied):
    base = installed.operators._Background

    class StandIn(base):
        def __init__(self):
            self.reports = []

        def report(self, kind, text):
            self.reports.append((set(kind), text))

        def prepare(self, context):
            return work

        def apply(self, context, result):
            applied.append(result)
            return f"applied {result}"

    return StandIn()


def _start(op, context):
    job = op._start(context)
    op._job = job.start()
    wm = context.window_manager
    op._timer = wm.event_timer_add(0.1, window=context.window)
    wm.progress_begin(0, 100)
    return job


def test_timer_events_poll_the_worker_until_it_is_done(bpy, installed, empty_scene):
    applied = []
    release = threading.Event()
    op = _stand_in(
        installed, lambda progress: (progress("sampling", 0.5), release.wait(PATIENCE), 7)[2], applied
    )
    job = _start(op, bpy.context)
    timer = SimpleNamespace(type="TIMER")
    assert op.modal(bpy.context, timer) == {"RUNNING_MODAL"}
    assert op.modal(bpy.context, SimpleNamespace(type="MIDDLEMOUSE")) == {"PASS_THROUGH"}
    assert op.modal(bpy.context, SimpleNamespace(type="X")) == {"RUNNING_MODAL"}  # editing waits
    release.set()
    job.wait(PATIENCE)
    assert op.modal(bpy.context, timer) == {"FINISHED"}
    assert applied == [7] and op.reports[-1][1].startswith("meshvis: applied 7")


def test_esc_cancels_and_nothing_is_applied(bpy, installed, empty_scene):
    applied = []
    started = threading.Event()

    def work(progress):
        started.set()
        for _ in range(PATIENCE * 100):
            progress("sampling", 0.1)
            time.sleep(0.01)

    op = _stand_in(installed, work, applied)
    job = _start(op, bpy.context)
    started.wait(PATIENCE)
    assert op.modal(bpy.context, SimpleNamespace(type="ESC")) == {"CANCELLED"}
    assert job.wait(5) and isinstance(job.error, installed.jobs.Cancelled)
    assert applied == [] and "cancelled" in op.reports[-1][1]
