"""The local web server of ``meshvis view``: the page, the model and a label layout per frame.

Routes (all on 127.0.0.1 only):

``GET /``             the page (``web/index.html``; its script ``web/view.js`` and the vendored
                      three.js under ``web/vendor/`` are served from the installed package)
``GET /scene.json``   part names and texts, the layout, the first camera
``GET /model.glb``    the model to show: a ``.glb`` file's own bytes; any other format
                      converted to GLB in memory
``GET /idmesh.bin``   the triangles the page renders its part-ID buffer from, in the same
                      coordinates: ``uint32`` vertex and face counts, ``float32`` vertices,
                      ``uint32`` faces, ``uint32`` part id per face
``POST /layout``      one frame: header ``X-Meshvis-Frame`` = JSON ``{"viewer", "seq", "width",
                      "height", "format", "camera": {"position", "target", "up", "fov"}}``, body =
                      the ID buffer, ``"rgba"`` bytes (:func:`meshvis.labeling.live.ids_from_rgba`)
                      or ``"u16"`` (:func:`meshvis.labeling.live.ids_from_u16`);
                      answers :func:`meshvis.labeling.live.frame_json`

Requests are answered one at a time (one lock around the layout): a frame takes a few
milliseconds and a page waits for its answer before it sends the next one.
"""

from __future__ import annotations

import io
import json
import os
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import numpy as np

from meshvis.errors import MeshvisError, ParameterError
from meshvis.rays.camera import Camera

from .live import MAX_SIDE, LiveLabeler, frame_json, ids_from_rgba, ids_from_u16

#: the page and its scripts, inside the installed package
WEB = Path(__file__).resolve().parent / "web"
#: the only address the server listens on
HOST = "127.0.0.1"
#: default port of ``meshvis view`` (0: any free port)
PORT = 8765
CONTENT_TYPES = {
    ".html": "text/html; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".json": "application/json",
    ".md": "text/plain; charset=utf-8",
    "": "text/plain; charset=utf-8",
}
#: the largest frame header (bytes)
MAX_HEADER = 4096


def model_glb(live: LiveLabeler, path: str | None) -> bytes:
    """The model as GLB bytes: a ``.glb`` file as it is, anything else converted in memory.

    The conversion writes one mesh per part, named after it, in the soup's coordinates
    (those of the ID mesh).
    """
    if path and str(path).lower().endswith(".glb"):
        with open(path, "rb") as fh:
            return fh.read()
    import trimesh

    soup = live.soup
    scene = trimesh.Scene()
    colours = np.array([[0.62, 0.68, 0.76], [0.80, 0.70, 0.55], [0.60, 0.75, 0.62], [0.78, 0.60, 0.62]]) * 255
    for p, name in enumerate(soup.part_names):
        faces = soup.faces[soup.part_id == p]
        if len(faces) == 0:
            continue
        used, inverse = np.unique(faces, return_inverse=True)
        mesh = trimesh.Trimesh(soup.vertices[used], inverse.reshape(-1, 3), process=False)
        mesh.visual.face_colors = np.append(colours[p % len(colours)], 255).astype(np.uint8)
        scene.add_geometry(mesh, node_name=name, geom_name=name)
    buf = io.BytesIO()
    buf.write(scene.export(file_type="glb"))
    return buf.getvalue()


def id_mesh(live: LiveLabeler) -> bytes:
    """The ID mesh of ``GET /idmesh.bin`` (see the module docstring)."""
    soup = live.soup
    v = np.ascontiguousarray(soup.vertices, np.float32)
    f = np.ascontiguousarray(soup.faces, np.uint32)
    part = np.ascontiguousarray(soup.part_id, np.uint32)
    head = np.array([len(v), len(f)], np.uint32)
    return head.tobytes() + v.tobytes() + f.tobytes() + part.tobytes()


def scene_json(live: LiveLabeler) -> dict[str, Any]:
    """The page's start-up data (``GET /scene.json``)."""
    cam = live.camera((512, 512))
    lo, hi = live.soup.bounds
    return {
        "parts": list(live.soup.part_names),
        "texts": live.texts,
        "layout": live.layout,
        "camera": {k: v for k, v in cam.to_json().items() if k in ("position", "target", "up", "fov")},
        "center": (0.5 * (lo + hi)).tolist(),
        "radius": 0.5 * float(live.soup.diagonal or 1.0),
        "fitMargin": live.fit_margin,
    }


def _camera(d: Any) -> Camera:
    """The camera of a frame header."""
    if not isinstance(d, dict):
        raise ParameterError("frame camera must be an object")
    try:
        return Camera(
            np.asarray(d["position"], np.float64),
            np.asarray(d["target"], np.float64),
            np.asarray(d["up"], np.float64),
            float(d["fov"]),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise ParameterError(f"bad frame camera: {exc}") from None


class ViewServer:
    """The server of one model; :meth:`start` runs it in a thread, :meth:`serve_forever` in this one.

    Parameters
    ----------
    live : LiveLabeler
    path : the model's file (a ``.glb`` is shown as it is), or None
    port : TCP port on 127.0.0.1 (0: any free one)
    verbose : print every request on standard error
    """

    def __init__(
        self, live: LiveLabeler, path: str | None = None, *, port: int = PORT, verbose: bool = False
    ):
        self.live = live
        self.verbose = verbose
        self._files = {
            "/scene.json": (json.dumps(scene_json(live)).encode(), CONTENT_TYPES[".json"]),
            "/model.glb": (model_glb(live, path), "model/gltf-binary"),
            "/idmesh.bin": (id_mesh(live), "application/octet-stream"),
        }
        self._lock = threading.Lock()
        self.frames = 0
        self.httpd = ThreadingHTTPServer((HOST, int(port)), self._handler())
        self.httpd.daemon_threads = True
        self._thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        """The page's address."""
        return f"http://{HOST}:{self.httpd.server_address[1]}/"

    def start(self) -> ViewServer:
        """Serve in a daemon thread; returns self."""
        self._thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self._thread.start()
        return self

    def serve_forever(self) -> None:
        """Serve until :meth:`shutdown` (or Ctrl-C)."""
        self.httpd.serve_forever()

    def shutdown(self) -> None:
        """Stop serving and close the socket."""
        if self._thread is not None:
            self.httpd.shutdown()
            self._thread.join()
        self.httpd.server_close()

    def layout(self, header: dict, body: bytes) -> dict[str, Any]:
        """Answer one ``POST /layout``."""
        t0 = time.perf_counter()
        width, height = int(header.get("width", 0)), int(header.get("height", 0))
        fmt = header.get("format", "rgba")
        if fmt not in ("rgba", "u16"):
            raise ParameterError(f"unknown ID buffer format {fmt!r}")
        ids = (ids_from_u16 if fmt == "u16" else ids_from_rgba)(body, width, height)
        camera = _camera(header.get("camera"))
        with self._lock:
            result = self.live.frame(ids, camera, str(header.get("viewer", ""))[:64])
            self.frames += 1
        answer = frame_json(result, int(header.get("seq", 0)))
        answer["serverMs"] = round(1000.0 * (time.perf_counter() - t0), 3)
        return answer

    def _handler(self) -> type[BaseHTTPRequestHandler]:
        server = self

        class Handler(BaseHTTPRequestHandler):
            # keep-alive: the page's frames reuse one connection
            protocol_version = "HTTP/1.1"
            # the headers and the body of an answer go out as two writes: with Nagle's
            # algorithm the body waits for the client's delayed ACK of the headers (40 ms)
            disable_nagle_algorithm = True

            def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 - the base class's name
                if server.verbose:
                    super().log_message(format, *args)

            def _send(self, status: int, data: bytes, ctype: str) -> None:
                self.send_response(status)
                self.send_header("Content-Type", ctype)
                self.send_header("Content-Length", str(len(data)))
                self.send_header("Cache-Control", "no-store")
                if status >= 400:  # the request's body may be unread: do not reuse the connection
                    self.send_header("Connection", "close")
                    self.close_connection = True
                self.end_headers()
                self.wfile.write(data)

            def do_GET(self) -> None:
                path = self.path.split("?", 1)[0]
                if path == "/favicon.ico":
                    self._send(204, b"", CONTENT_TYPES[""])
                    return
                if path in server._files:
                    self._send(200, *server._files[path])
                    return
                file = _static(path)
                if file is None:
                    self._send(404, b"not found\n", CONTENT_TYPES[""])
                    return
                self._send(200, file.read_bytes(), CONTENT_TYPES.get(file.suffix, "application/octet-stream"))

            def do_POST(self) -> None:
                if self.path.split("?", 1)[0] != "/layout":
                    self._send(404, b"not found\n", CONTENT_TYPES[""])
                    return
                try:
                    length = int(self.headers.get("Content-Length", "0"))
                    raw = self.headers.get("X-Meshvis-Frame", "")
                    if not 0 < length <= MAX_SIDE * MAX_SIDE * 4 or len(raw) > MAX_HEADER:
                        raise ParameterError("frame too large or empty")
                    header = json.loads(raw)
                    if not isinstance(header, dict):
                        raise ParameterError("frame header must be a JSON object")
                    answer = server.layout(header, self.rfile.read(length))
                except (MeshvisError, ValueError) as exc:
                    self._send(400, json.dumps({"error": str(exc)}).encode(), CONTENT_TYPES[".json"])
                    return
                self._send(200, json.dumps(answer).encode(), CONTENT_TYPES[".json"])

        return Handler


def _static(path: str) -> Path | None:
    """The file of the page's folder that ``path`` names, or None (nothing outside it is served)."""
    rel = path.lstrip("/") or "index.html"
    if rel.endswith("/"):
        return None
    target = (WEB / rel).resolve()
    if WEB not in target.parents or not target.is_file() or os.path.basename(rel).startswith("."):
        return None
    return target
