"""The live labeling behind ``meshvis view``: ID buffers from elsewhere, the server, the CLI."""

from __future__ import annotations

import json
import os
import urllib.error
import urllib.request

import numpy as np
import pytest
import trimesh

from meshvis.errors import ParameterError
from meshvis.labeling.geometry2d import boxes_overlap
from meshvis.labeling.idbuffer import id_buffer
from meshvis.labeling.live import LiveLabeler, ids_from_rgba, ids_from_u16
from meshvis.labeling.server import ViewServer, _static
from meshvis.soup import Soup

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ASSEMBLY = os.path.join(ROOT, "models", "assembly.obj")


def _rgba(ids: np.ndarray) -> bytes:
    """What WebGL's readPixels gives for an ID buffer: part + 1 as 24-bit colour, rows bottom-up."""
    v = (ids + 1).astype(np.int64)
    px = np.stack([v & 255, (v >> 8) & 255, (v >> 16) & 255, np.full_like(v, 255)], axis=-1)
    return px[::-1].astype(np.uint8).tobytes()


@pytest.fixture(scope="module")
def live():
    return LiveLabeler(ASSEMBLY, layout="left-right")  # the model's own up axis (y: an OBJ file)


@pytest.fixture(scope="module")
def server(live):
    s = ViewServer(live, ASSEMBLY, port=0).start()
    yield s
    s.shutdown()


def test_rgba_round_trip():
    ids = np.array([[-1, 0, 1], [300, 70000, -1]])
    assert ids_from_rgba(_rgba(ids), 3, 2).tolist() == ids.tolist()
    small = np.array([[-1, 0, 1], [300, 65000, -1]])
    assert ids_from_u16(_u16(small), 3, 2).tolist() == small.tolist()
    with pytest.raises(ParameterError):
        ids_from_u16(b"\0" * 5, 3, 1)
    with pytest.raises(ParameterError):
        ids_from_rgba(b"\0" * 12, 3, 2)
    with pytest.raises(ParameterError):
        ids_from_rgba(b"", 0, 0)


def test_live_frame_matches_the_offline_layout(live):
    """A frame from an outside ID buffer gives the labels the offline pipeline gives."""
    from meshvis.labeling.pipeline import solve

    cam = live.camera((256, 256))
    ib = id_buffer(live.soup, cam, (256, 256))
    got = live.frame(ib.ids, cam, viewer="a")
    want = solve(ib, live.texts, layout="left-right")
    assert [lab.part for lab in got.labels] == [lab.part for lab in want.labels]
    assert all(np.allclose(a.box, b.box) for a, b in zip(got.labels, want.labels))
    # the anchors' 3D points come from rays (the ID buffer has no depth): on the surface seen
    for a, b in zip(got.labels, want.labels):
        assert np.allclose(a.anchor_3d, b.anchor_3d, atol=1e-6 * live.soup.diagonal)
    live.forget("a")


def test_live_frames_are_coherent_per_viewer(live):
    """The second frame of a viewer is laid out with its first; another viewer's is not."""
    cams = [live.camera((256, 256), azimuth=az) for az in (30.0, 35.0)]
    ids = [id_buffer(live.soup, c, (256, 256)).ids for c in cams]
    live.frame(ids[0], cams[0], viewer="v")
    follow = live.frame(ids[1], cams[1], viewer="v")
    fresh = live.frame(ids[1], cams[1], viewer="w")
    assert {lab.part for lab in follow.labels} == {lab.part for lab in fresh.labels}
    moved = [not np.allclose(a.anchor, b.anchor) for a, b in zip(follow.labels, fresh.labels)]
    assert any(moved)  # the previous frame changed where anchors went
    with pytest.raises(ParameterError):
        live.frame(np.full((16, 16), live.soup.n_parts), cams[0])
    live.forget("v")
    live.forget("w")


def _u16(ids: np.ndarray) -> bytes:
    """The page's packed ID buffer: part + 1 in two bytes, rows bottom-up."""
    return (ids + 1)[::-1].astype("<u2").tobytes()


def _post(server, ids, cam, fmt="rgba", **extra):
    h, w = ids.shape
    header = {"viewer": "t", "seq": 7, "width": w, "height": h, "format": fmt, **extra}
    header["camera"] = {
        "position": cam.position.tolist(),
        "target": cam.target.tolist(),
        "up": cam.up.tolist(),
        "fov": cam.fov,
    }
    req = urllib.request.Request(
        server.url + "layout",
        data=_rgba(ids) if fmt == "rgba" else _u16(ids),
        headers={"X-Meshvis-Frame": json.dumps(header)},
        method="POST",
    )
    with urllib.request.urlopen(req, timeout=30) as res:
        return json.loads(res.read())


def test_server_serves_the_page_the_model_and_layouts(server, live):
    assert server.url.startswith("http://127.0.0.1:")
    with urllib.request.urlopen(server.url, timeout=10) as res:
        assert b"view.js" in res.read()
    with urllib.request.urlopen(server.url + "vendor/three/build/three.module.js", timeout=10) as res:
        assert res.headers["Content-Type"].startswith("text/javascript")
    with urllib.request.urlopen(server.url + "scene.json", timeout=10) as res:
        scene = json.loads(res.read())
    assert scene["parts"] == list(live.soup.part_names) and scene["layout"] == "left-right"
    with urllib.request.urlopen(server.url + "model.glb", timeout=10) as res:
        glb = res.read()
    assert glb[:4] == b"glTF"  # an OBJ is converted to GLB in memory
    loaded = trimesh.load(trimesh.util.wrap_as_stream(glb), file_type="glb")
    assert len(loaded.geometry) == live.soup.n_parts
    with urllib.request.urlopen(server.url + "idmesh.bin", timeout=10) as res:
        blob = res.read()
    nv, nf = np.frombuffer(blob[:8], np.uint32)
    assert (nv, nf) == (len(live.soup.vertices), len(live.soup.faces))
    cam = live.camera((200, 160))
    ids = id_buffer(live.soup, cam, (200, 160)).ids
    answer = _post(server, ids, cam)
    assert answer["seq"] == 7 and (answer["width"], answer["height"]) == (200, 160)
    assert answer["labels"] and all(None not in lab["anchor3d"] for lab in answer["labels"])
    boxes = np.array([lab["box"] for lab in answer["labels"]])
    overlap = boxes_overlap(boxes, boxes)
    np.fill_diagonal(overlap, False)
    assert not overlap.any()
    packed = _post(server, ids, cam, fmt="u16", viewer="packed")
    assert [lab["box"] for lab in packed["labels"]] == [lab["box"] for lab in answer["labels"]]


@pytest.mark.parametrize(
    "path", ["/../pyproject.toml", "/vendor/../../server.py", "/%2e%2e/live.py", "/vendor/"]
)
def test_server_serves_nothing_outside_the_page(server, path):
    assert _static(path) is None
    with pytest.raises(urllib.error.HTTPError) as err:
        urllib.request.urlopen(server.url.rstrip("/") + path, timeout=10)
    assert err.value.code in (400, 404)


def test_server_refuses_bad_frames(server, live):
    cam = live.camera((64, 64))
    for header, body in [
        ("not json", b"\0" * 16),
        (json.dumps({"width": 4, "height": 4, "camera": {}}), b"\0" * 64),
        (json.dumps({"width": 3, "height": 3}), b"\0" * 64),
    ]:
        req = urllib.request.Request(
            server.url + "layout", data=body, headers={"X-Meshvis-Frame": header}, method="POST"
        )
        with pytest.raises(urllib.error.HTTPError) as err:
            urllib.request.urlopen(req, timeout=10)
        assert err.value.code == 400
    ids = np.full((64, 64), live.soup.n_parts + 5)
    with pytest.raises(urllib.error.HTTPError):
        _post(server, ids, cam)


def test_view_command_refuses_a_bad_port_and_a_missing_model(tmp_path, capsys):
    from meshvis.cli.main import main

    assert main(["view", ASSEMBLY, "--port", "70000", "--no-browser"]) == 2
    assert main(["view", str(tmp_path / "missing.obj"), "--no-browser"]) == 2
    assert "missing.obj" in capsys.readouterr().err


def test_a_converted_model_keeps_its_parts(tmp_path):
    a, b = trimesh.creation.box(), trimesh.creation.icosphere()
    b.apply_translation((2.0, 0, 0))
    soup = Soup.concatenate(
        [Soup(a.vertices, a.faces, part_names=["crate"]), Soup(b.vertices, b.faces, part_names=["ball"])]
    )
    from meshvis.labeling.server import model_glb

    live = LiveLabeler(soup)
    scene = trimesh.load(trimesh.util.wrap_as_stream(model_glb(live, None)), file_type="glb")
    assert sorted(scene.geometry) == ["ball", "crate"]


def test_notebook_widget_frames_the_page():
    pytest.importorskip("anywidget")
    from meshvis.labeling.widget import view

    w = view(ASSEMBLY, layout="silhouette", width=640, height=400)
    try:
        assert w.url == w.server.url and (w.width, w.height) == (640, 400)
        assert "iframe" in w._esm
        with urllib.request.urlopen(w.url + "scene.json", timeout=10) as res:
            assert json.loads(res.read())["layout"] == "silhouette"
    finally:
        w.server.shutdown()


@pytest.mark.parametrize("scale, shift", [(1e-6, 0.0), (1e6, 0.0), (1.0, 1e6)])
def test_live_frames_do_not_change_under_scale_and_translation(scale, shift):
    """The same view of the model scaled by 1e-6 or 1e6, or moved 1e6 away: the same labels."""
    a, b = trimesh.creation.box(extents=(2.0, 1.0, 1.0)), trimesh.creation.icosphere(radius=0.6)
    b.apply_translation((1.6, 0.0, 0.3))
    parts = [Soup(a.vertices, a.faces, part_names=["crate"]), Soup(b.vertices, b.faces, part_names=["ball"])]
    base = Soup.concatenate(parts)
    moved = Soup.concatenate(
        [Soup(p.vertices * scale + shift, p.faces, part_names=p.part_names) for p in parts]
    )
    out = []
    for soup in (base, moved):
        live = LiveLabeler(soup, up=(0, 0, 1))
        cam = live.camera((160, 120))
        r = live.frame(id_buffer(soup, cam, (160, 120)).ids, cam)
        assert all(np.isfinite(lab.anchor_3d).all() for lab in r.labels)
        out.append({lab.text: lab.box for lab in r.labels})
    assert out[0].keys() == out[1].keys() == {"crate", "ball"}
    for k in out[0]:
        assert np.allclose(out[0][k], out[1][k], atol=1.0)
