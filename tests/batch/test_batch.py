"""Tests of meshvis.batch and ``meshvis batch``: discovery, output names, per-file tasks,
worker processes with time limit and crash recovery, resume, Ctrl-C, and Dask."""

from __future__ import annotations

import csv
import errno
import json
import os
import signal
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np
import pytest

import meshvis.batch as mb
import meshvis.batch.cluster
import meshvis.io as mio
from meshvis.cli.main import main
from meshvis.errors import ParameterError

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


# ---------------------------------------------------------------- models
def _sphere(path, subdivisions: int = 1, flip_every: int = 3) -> str:
    """A sphere with every ``flip_every``-th face turned inward."""
    import trimesh

    s = trimesh.creation.icosphere(subdivisions)
    f = s.faces.copy()
    f[::flip_every] = f[::flip_every, ::-1]
    mio.save((s.vertices, f), path)
    return str(path)


def _nested(path) -> str:
    """Two nested spheres: the inner one is hidden."""
    import trimesh

    a, b = trimesh.creation.icosphere(1), trimesh.creation.icosphere(1)
    mio.save(
        (np.vstack([a.vertices, 0.5 * b.vertices]), np.vstack([a.faces, b.faces + len(a.vertices)])), path
    )
    return str(path)


def _triangle(path) -> str:
    mio.save((np.eye(3), np.array([[0, 1, 2]])), path)
    return str(path)


def _noise(path) -> str:
    with open(path, "wb") as fh:
        fh.write(np.random.default_rng(1).integers(0, 256, 999, dtype=np.uint8).tobytes())
    return str(path)


def _touch(path, text: str = "") -> str:
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as fh:
        fh.write(text)
    return str(path)


def _tmp_files(folder) -> list[str]:
    return [os.path.join(r, f) for r, _, fs in os.walk(folder) for f in fs if f.endswith(".tmp")]


# ---------------------------------------------------------------- runners used by the worker tests
#: the folder of stuck_runners.py; worker processes import it by name, and the folder holds
#: no meshvis/ that could shadow the installed package
HERE = os.path.dirname(os.path.abspath(__file__))


@pytest.fixture
def stuck_runners(monkeypatch):
    """Make ``stuck_runners`` importable here and in worker processes (they get sys.path)."""
    monkeypatch.syspath_prepend(HERE)
    return "stuck_runners"


# ---------------------------------------------------------------- discovery and names
def test_discover_files_folders_patterns(tmp_path):
    d = tmp_path / "in"
    a = _touch(d / "a.obj")
    _touch(d / "sub" / "b.ply")
    _touch(d / "sub" / "deep" / "c.STL")
    for skipped in (
        ".hidden/d.obj",
        ".e.obj",
        "notes.txt",
        "a.orient.obj",
        "a.remove-interior.report.json",
        "x.layers.ply",
    ):
        _touch(d / skipped)
    found = mb.discover([str(d)])
    assert [rel for _, rel in found] == [
        "a.obj",
        os.path.join("sub", "b.ply"),
        os.path.join("sub", "deep", "c.STL"),
    ]
    # a file given twice (directly and through its folder) is processed once, named by the first
    assert [rel for _, rel in mb.discover([a, str(d)])][:2] == ["a.obj", os.path.join("sub", "b.ply")]
    assert len(mb.discover([a, str(d)])) == 3
    # patterns: relative to their fixed leading folders; '**' spans folders
    assert [rel for _, rel in mb.discover([str(d / "**" / "*.ply")])] == [os.path.join("sub", "b.ply")]
    assert [rel for _, rel in mb.discover([str(d / "*")])] == [
        "a.obj",
        os.path.join("sub", "b.ply"),
        os.path.join("sub", "deep", "c.STL"),
    ]
    # a file named explicitly is taken whatever its name: its error shows up in its row
    assert mb.discover([str(d / "notes.txt")]) == [(str(d / "notes.txt"), "notes.txt")]
    with pytest.raises(ParameterError, match="no such file"):
        mb.discover([str(d / "missing.obj")])
    (tmp_path / "empty").mkdir()
    with pytest.raises(ParameterError, match="no model files"):
        mb.discover([str(tmp_path / "empty")])
    with pytest.raises(ParameterError, match="matches no model"):
        mb.discover([str(d / "*.off")])


def test_plan_output_names(tmp_path):
    d = tmp_path / "in"
    files = [
        _touch(d / "x.obj"),
        _touch(d / "x.stl"),
        _touch(d / "m.3mf"),
        _touch(d / "s.off"),
        _touch(d / "one" / "y.obj"),
        _touch(d / "two" / "y.obj"),
    ]
    out = str(tmp_path / "out")
    tasks = mb.plan(files, "layers", out, {"seed": 3})
    names = [os.path.relpath(t.output, out) for t in tasks]
    assert names == [
        "x.obj.layers.obj",
        "x.stl.layers.ply",
        "m.layers.glb",
        "s.layers.ply",
        "y.layers.obj",
        "y-2.layers.obj",
    ]
    assert [os.path.relpath(t.report, out) for t in tasks][0] == "x.obj.layers.report.json"
    assert all(t.options == {"seed": 3} and t.op == "layers" for t in tasks)
    # orient keeps STL and OFF (they hold a turned face); a folder keeps its structure
    tasks = mb.plan([str(d)], "orient", out)
    assert sorted(os.path.relpath(t.output, out) for t in tasks) == sorted(
        [
            "x.obj.orient.obj",
            "x.stl.orient.stl",
            "m.orient.glb",
            "s.orient.off",
            os.path.join("one", "y.orient.obj"),
            os.path.join("two", "y.orient.obj"),
        ]
    )
    # an output may not overwrite an input
    victim = _touch(tmp_path / "out" / "x.orient.obj")
    with pytest.raises(ParameterError, match="overwrite an input"):
        mb.plan([str(d / "x.obj"), victim], "orient", out)
    with pytest.raises(ParameterError, match="unknown operation"):
        mb.plan(files, "classify", out)


# ---------------------------------------------------------------- one file, in this process
def test_run_file_matches_the_single_file_command(tmp_path, capsys):
    src = _sphere(tmp_path / "ball.ply")
    out = tmp_path / "out"
    task = mb.plan([src], "orient", str(out), {"seed": 5, "rays_per_node": 16})[0]
    row = mb.run_file(task)
    assert row["status"] == "ok" and row["error"] == ""
    assert row["faces_in"] == row["faces_out"] == 80 and row["rays"] > 0
    report = json.load(open(task.report))
    assert report["status"] == "ok" and report["operation"] == "orient"
    assert report["batch"]["options"] == {"seed": 5, "rays_per_node": 16}
    assert report["flipped"] == 27  # every third face of 80 was turned inward
    single = str(tmp_path / "single.ply")
    assert main(["orient", src, "-o", single, "--seed", "5", "--rays-per-node", "16", "-q"]) == 0
    assert open(single, "rb").read() == open(task.output, "rb").read()


def test_the_rows_rays_are_every_ray_of_a_removal_by_sight(tmp_path):
    src = _sphere(tmp_path / "ball.ply")
    task = mb.plan([src], "remove-interior", str(tmp_path / "out"))[0]
    row = mb.run_file(task)
    report = json.load(open(task.report))
    assert "classification" not in report  # by sight: no cut
    searched = report["view"]["rays"]["total"]
    assert searched > 0 and row["rays"] == searched + report["rescue"]["rays"] + report["self_check"]["rays"]


def test_run_file_reports_a_bad_file(tmp_path):
    out = tmp_path / "out"
    task = mb.plan([_noise(tmp_path / "noise.ply")], "remove-interior", str(out))[0]
    _touch(task.output, "stale output of an earlier run")
    row = mb.run_file(task)
    assert row["status"] == "error"
    assert row["error"].startswith(task.input + ": ") and "\n" not in row["error"]
    assert json.load(open(task.report))["status"] == "error"
    assert not os.path.exists(task.output)
    # warnings are kept in the row
    obj = _touch(tmp_path / "edge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n")
    row = mb.run_file(mb.plan([obj], "orient", str(out))[0])
    assert row["status"] == "ok" and "2 vertices" in row["warnings"]


def test_run_file_disk_full(tmp_path, monkeypatch):
    task = mb.plan([_triangle(tmp_path / "tri.obj")], "orient", str(tmp_path / "out"))[0]
    real_fdopen = os.fdopen

    class Full:
        def __init__(self, fh):
            self.fh = fh

        def write(self, data):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        def __getattr__(self, name):
            return getattr(self.fh, name)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

    monkeypatch.setattr(os, "fdopen", lambda *a, **kw: Full(real_fdopen(*a, **kw)))
    row = mb.run_file(task)
    assert row["status"] == "error" and "No space left on device" in row["error"]
    assert os.listdir(tmp_path / "out") == []


# ---------------------------------------------------------------- the command, local workers
def _rows(folder) -> dict[str, dict]:
    with open(os.path.join(folder, "summary.csv"), newline="") as fh:
        return {os.path.basename(r["input"]): r for r in csv.DictReader(fh)}


@pytest.mark.slow
def test_batch_command_local_and_resume(tmp_path, capsys):
    src = tmp_path / "in"
    src.mkdir()
    _sphere(src / "ball.obj")
    (src / "sub").mkdir()
    _nested(src / "sub" / "nested.ply")
    _triangle(src / "sub" / "tri.stl")
    _noise(src / "noise.ply")
    out = str(tmp_path / "out")
    rc = main(
        ["batch", str(src), "--op", "remove-interior", "--out", out, "--jobs", "2", "--rays-per-node", "16"]
    )
    stdout, stderr = capsys.readouterr()
    assert rc == 1, stderr  # one file failed
    assert "Traceback" not in stderr
    rows = _rows(out)
    assert {k: r["status"] for k, r in rows.items()} == {
        "ball.obj": "ok",
        "nested.ply": "ok",
        "tri.stl": "ok",
        "noise.ply": "error",
    }
    assert rows["nested.ply"]["faces_in"] == "160" and rows["nested.ply"]["faces_out"] == "80"
    assert rows["noise.ply"]["error"].startswith(str(src / "noise.ply"))
    summary = json.load(open(os.path.join(out, "summary.json")))
    assert summary["counts"] == {"ok": 3, "error": 1} and summary["operation"] == "remove-interior"
    assert summary["options"]["rays_per_node"] == 16 and summary["interrupted"] is False
    assert "noise.ply" in stdout  # the summary table
    kept = mio.load(os.path.join(out, "sub", "nested.remove-interior.ply"))
    assert kept.n_faces == 80 and np.allclose(np.linalg.norm(kept.vertices[np.unique(kept.faces)], axis=1), 1)
    assert os.path.isfile(os.path.join(out, "ball.remove-interior.obj"))
    assert not _tmp_files(out)

    # --resume skips the finished files and retries the failed one
    done = os.path.join(out, "ball.remove-interior.obj")
    stamp = os.stat(done).st_mtime_ns
    rc = main(
        [
            "batch",
            str(src),
            "--op",
            "remove-interior",
            "--out",
            out,
            "--resume",
            "--rays-per-node",
            "16",
            "-q",
        ]
    )
    assert rc == 1
    rows = _rows(out)
    assert [rows[k]["status"] for k in ("ball.obj", "nested.ply", "tri.stl", "noise.ply")] == [
        "skipped",
        "skipped",
        "skipped",
        "error",
    ]
    assert rows["nested.ply"]["faces_out"] == "80"  # carried over from the earlier report
    assert os.stat(done).st_mtime_ns == stamp
    # other options, or an input newer than its report: not complete
    task = mb.plan([str(src / "ball.obj")], "remove-interior", out, {"rays_per_node": 16})[0]
    assert mb.completed_row(task) is not None
    assert (
        mb.completed_row(mb.plan([str(src / "ball.obj")], "remove-interior", out, {"rays_per_node": 8})[0])
        is None
    )
    later = time.time() + 10
    os.utime(src / "ball.obj", (later, later))
    assert mb.completed_row(task) is None


@pytest.mark.slow
def test_time_limit_and_crashed_workers_do_not_stop_the_batch(tmp_path, stuck_runners):
    src = _triangle(tmp_path / "tri.obj")
    out = str(tmp_path / "out")
    good = mb.plan([src], "orient", out)[0]
    bad = []
    for runner in ("hang", "stubborn", "die"):
        t = mb.plan([src], "orient", os.path.join(out, runner))[0]
        t.runner = f"{stuck_runners}:{runner}"
        bad.append(t)
    tasks = bad + [good]
    seen = []
    result = mb.run_batch(tasks, jobs=2, time_limit=2.0, on_done=lambda i, row: seen.append(i))
    assert [r["status"] for r in result.rows] == ["timeout", "timeout", "crashed", "ok"]
    assert "time limit of 2 s" in result.rows[0]["error"]
    assert "SIGKILL" in result.rows[2]["error"]
    assert sorted(seen) == [0, 1, 2, 3] and not result.ok
    for t in bad:  # no partial output, no temporary file, an error report
        assert not os.path.exists(t.output)
        assert json.load(open(t.report))["status"] in ("timeout", "crashed")
    assert not _tmp_files(out)
    assert mio.load(good.output).n_faces == 1


@pytest.mark.slow
def test_run_file_isolated_kills_a_hung_file(tmp_path, stuck_runners):
    task = mb.plan([_triangle(tmp_path / "tri.obj")], "orient", str(tmp_path / "out"))[0]
    task.runner = f"{stuck_runners}:hang"
    row = mb.run_file_isolated(task, time_limit=1.0)
    assert row["status"] == "timeout"
    assert not _tmp_files(tmp_path / "out") and not os.path.exists(task.output)
    task.runner = mb.DEFAULT_RUNNER
    assert mb.run_file_isolated(task, time_limit=60.0)["status"] == "ok"


def _icosphere():
    import trimesh

    return trimesh.creation.icosphere(1)


def _files(folder) -> list[str]:
    return sorted(os.path.relpath(os.path.join(r, f), folder) for r, _, fs in os.walk(folder) for f in fs)


DRIVER = textwrap.dedent(
    '''
    """Runs ``meshvis batch`` with the task of slow.obj replaced by one that starts writing
    its output, records its pid and then waits: the batch is stopped at a known point."""
    import os
    import sys
    import time

    import meshvis.batch as mb

    _OPEN = []


    def hang(op, soup, args, progress):
        from meshvis.io import atomic_write

        writer = atomic_write(args["output"], "w")
        _OPEN.append(writer)
        writer.__enter__().write("partial")
        with open(os.environ["MESHVIS_TEST_PID"] + ".part", "w") as fh:
            fh.write(str(os.getpid()))
        os.rename(os.environ["MESHVIS_TEST_PID"] + ".part", os.environ["MESHVIS_TEST_PID"])
        time.sleep(3600)


    def _plan(*args, **kw):
        tasks = _real_plan(*args, **kw)
        for t in tasks:
            if os.path.basename(t.input) == "slow.obj":
                t.runner = "batch_driver:hang"
        return tasks


    if __name__ == "__main__":
        _real_plan = mb.plan
        mb.plan = _plan
        from meshvis.cli.main import main

        sys.exit(main(sys.argv[1:]))
    '''
)


def _stopped_batch(tmp_path, how: str) -> tuple[subprocess.CompletedProcess, str, int]:
    """Start a batch of a.obj, b.obj and the hanging slow.obj, stop it with ``how`` once
    a and b are done and slow is writing; return (result, output folder, pid of slow's worker)."""
    src = tmp_path / "in"
    src.mkdir()
    for name in ("a", "b", "slow"):
        mio.save(_icosphere(), src / f"{name}.obj")
    (tmp_path / "batch_driver.py").write_text(DRIVER)
    out = tmp_path / "out"
    pid_file = str(tmp_path / "worker.pid")
    argv = ["batch", str(src), "--op", "orient", "--out", str(out), "--jobs", "2", "--rays-per-node", "8"]
    proc = subprocess.Popen(
        [sys.executable, str(tmp_path / "batch_driver.py"), *argv, "-q"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,  # the installed package, not the repository's meshvis/ folder
        env=dict(os.environ, MESHVIS_TEST_PID=pid_file),
        start_new_session=True,
    )
    try:
        t0 = time.monotonic()
        done = [out / "a.orient.report.json", out / "b.orient.report.json", tmp_path / "worker.pid"]
        while not all(p.exists() for p in done):
            assert proc.poll() is None and time.monotonic() - t0 < 180, proc.stderr.read()
            time.sleep(0.05)
        if how == "SIGINT":
            os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C in a terminal reaches the whole process group
        else:
            proc.send_signal(signal.SIGTERM)  # `kill PID`: the main process only
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    worker = int(open(pid_file).read())
    return subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr), str(out), worker


def _assert_clean_stop(out: str, worker: int) -> None:
    assert not [f for f in _files(out) if f.endswith(".tmp")]
    summary = json.load(open(os.path.join(out, "summary.json")))
    assert summary["interrupted"] is True
    status = {os.path.basename(f["input"]): f["status"] for f in summary["files"]}
    assert status == {"a.obj": "ok", "b.obj": "ok", "slow.obj": "interrupted"}
    assert _files(out) == [
        "a.orient.obj",
        "a.orient.report.json",
        "b.orient.obj",
        "b.orient.report.json",
        "summary.csv",
        "summary.json",
    ]
    for name in ("a", "b"):  # every output that exists is complete
        assert mio.load(os.path.join(out, f"{name}.orient.obj")).n_faces == 80
    time.sleep(0.5)
    with pytest.raises(ProcessLookupError):  # the worker is gone, not writing on
        os.kill(worker, 0)


@pytest.mark.slow
def test_sigterm_to_batch_stops_workers_and_writes_the_summary(tmp_path):
    r, out, worker = _stopped_batch(tmp_path, "SIGTERM")
    assert r.returncode == 143, r.stderr
    assert r.stderr == "meshvis: terminated\n"
    _assert_clean_stop(out, worker)


@pytest.mark.slow
def test_ctrl_c_leaves_no_partial_outputs(tmp_path):
    """Ctrl-C once a.obj and b.obj are done and slow.obj is half written (a known point, not a time)."""
    r, out, worker = _stopped_batch(tmp_path, "SIGINT")
    assert r.returncode == 130, r.stderr
    assert r.stderr == "meshvis: interrupted\n"
    _assert_clean_stop(out, worker)


# ---------------------------------------------------------------- usage errors
@pytest.mark.slow
def test_usage_errors(tmp_path, capsys, monkeypatch):
    src = _triangle(tmp_path / "tri.obj")

    def one_line(argv, *words):
        rc = main(argv)
        err = capsys.readouterr().err
        assert rc == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
        for w in words:
            assert w in err, err

    one_line(
        ["batch", str(tmp_path / "nope.obj"), "--op", "orient", "--out", str(tmp_path / "o")], "no such file"
    )
    one_line(["batch", src, "--op", "orient", "--out", src], "is a file")
    one_line(
        [
            "batch",
            src,
            "--op",
            "orient",
            "--out",
            str(tmp_path / "o"),
            "--jobs",
            "2",
            "--dask-scheduler",
            "tcp://127.0.0.1:1",
        ],
        "--jobs",
    )

    def refuse(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    one_line(["batch", src, "--op", "orient", "--out", str(tmp_path / "ro")], "not writable")
    monkeypatch.undo()
    with pytest.raises(SystemExit) as exc:
        main(["batch", src, "--op", "orient", "--out", str(tmp_path / "o"), "--time-limit", "-1"])
    assert exc.value.code == 2
    capsys.readouterr()
    monkeypatch.setattr(meshvis.batch.cluster, "DASK_CONNECT_TIMEOUT", "1s")
    one_line(
        [
            "batch",
            src,
            "--op",
            "orient",
            "--out",
            str(tmp_path / "o"),
            "--dask-scheduler",
            "tcp://127.0.0.1:9",
        ],
        "cannot connect",
    )


# ---------------------------------------------------------------- Dask
@pytest.mark.slow
def test_dask_local_cluster_gives_the_same_outputs(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    src = tmp_path / "in"
    src.mkdir()
    _sphere(src / "ball.obj")
    _nested(src / "nested.glb")
    _noise(src / "noise.stl")
    args = ["batch", str(src), "--op", "remove-interior", "--rays-per-node", "16", "-q"]
    assert main(args + ["--out", str(tmp_path / "local"), "--jobs", "1"]) == 1
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=":0"
    ) as cluster:
        address = cluster.scheduler_address
        assert main(args + ["--out", str(tmp_path / "dask"), "--dask-scheduler", address]) == 1
        # with a time limit every file runs in a child process of its Dask worker
        assert (
            main(
                args
                + ["--out", str(tmp_path / "dask_limit"), "--dask-scheduler", address, "--time-limit", "120"]
            )
            == 1
        )
    capsys.readouterr()
    local = _rows(tmp_path / "local")
    for name in ("dask", "dask_limit"):
        rows = _rows(tmp_path / name)
        assert {k: r["status"] for k, r in rows.items()} == {
            "ball.obj": "ok",
            "nested.glb": "ok",
            "noise.stl": "error",
        }
        assert {k: r["faces_out"] for k, r in rows.items()} == {k: r["faces_out"] for k, r in local.items()}
        for f in ("ball.remove-interior.obj", "nested.remove-interior.glb"):
            assert open(tmp_path / name / f, "rb").read() == open(tmp_path / "local" / f, "rb").read()
        assert json.load(open(tmp_path / name / "summary.json"))["dask_scheduler"] == address


def test_largest_files_start_first(tmp_path):
    files = [
        _triangle(tmp_path / "small.obj"),
        _sphere(tmp_path / "big.obj", subdivisions=3),
        _sphere(tmp_path / "mid.obj", subdivisions=2),
        str(tmp_path / "missing.obj"),
    ]
    tasks = mb.plan(files[:3], "orient", str(tmp_path / "out"))
    tasks.append(mb.FileTask(files[3], "missing", "x", "y", "orient"))
    assert mb.largest_first(tasks, [0, 1, 2, 3]) == [1, 2, 0, 3]
    assert mb.largest_first(tasks, [3, 0]) == [0, 3]


@pytest.mark.parametrize("stem_length", [8, 240])
def test_discard_partial_finds_the_temporary_files_of_long_names(tmp_path, stem_length):
    from meshvis.batch.work import discard_partial
    from meshvis.io._common import temp_prefix

    stem = "m" * stem_length
    output = tmp_path / f"{stem}.orient.obj"
    other = tmp_path / "n.orient.obj"
    task = mb.FileTask(
        input=str(tmp_path / "in.obj"),
        name=stem,
        output=str(output),
        report=str(tmp_path / f"{stem}.orient.json"),
        op="orient",
    )
    leftovers = [tmp_path / (temp_prefix(str(p)) + "x1y2z3.tmp") for p in (output, task.report)]
    keep = tmp_path / (temp_prefix(str(other)) + "x1y2z3.tmp")
    for p in [*leftovers, keep]:
        p.write_text("partial")
    discard_partial(task)
    assert not any(p.exists() for p in leftovers)
    assert keep.exists()


def test_batch_passes_the_removal_options_to_remove_interior_only(tmp_path, capsys):
    """``--visibility``, ``--budget`` and the other removal options reach each file's
    ``remove-interior`` (its report says so); ``--op orient`` runs without them (its own
    ``--from`` would orient toward a region)."""
    src = os.path.join(ROOT, "models", "house.obj")
    out = str(tmp_path / "out")
    argv = ["batch", src, "--out", out, "--jobs", "1", "-q"]
    assert main(argv + ["--op", "remove-interior", "--visibility", "both", "--budget", "3000"]) == 0
    report = json.load(open(os.path.join(out, "house.remove-interior.report.json")))
    assert report["visibility"] == "both" and report["view"]["stopped"] == "budget"
    assert main(argv + ["--op", "remove-interior", "--visibility", "object"]) == 0
    report = json.load(open(os.path.join(out, "house.remove-interior.report.json")))
    assert report["visibility"] == "object" and "view" not in report
    assert main(argv + ["--op", "orient"]) == 0, capsys.readouterr().err
    report = json.load(open(os.path.join(out, "house.orient.report.json")))
    assert "classification" in report and "view" not in report  # the cut, not orient --from
