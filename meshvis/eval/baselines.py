"""Baselines: what a user would run instead of meshvis, wrapped behind one signature.

Every function takes a model (anything :func:`meshvis.as_soup` accepts) and keyword
knobs, and returns a :class:`BaselineResult` with one value per **input** face and the
wall time of the call.  Each function answers one task:

========================  ==========  =============================================  ==========================
function                  task        library call                                   budget knob
========================  ==========  =============================================  ==========================
``libigl_reorient``       orient      ``igl.embree.reorient_facets_raycast``          ``rays_total`` (default
                                                                                     100 per face)
``trimesh_fix_normals``   orient      ``trimesh.repair.fix_normals``                  none
``pymeshlab_reorient``    orient      ``meshing_re_orient_faces_by_geometry``         ``rays`` (default 64)
``pymeshlab_ao``          remove      ``compute_scalar_ambient_occlusion`` and the   ``rays`` (default 64)
                                      selection ``fq == 0``
``libigl_peel``           layers      ``igl.copyleft.cgal.peel_outer_hull_layers``    none
========================  ==========  =============================================  ==========================

Common preparation, timed as part of every baseline: the input triangles are welded
(coincident corners merged, :func:`meshvis.geometry.adjacency.weld`) because every one of these
libraries needs connectivity and a triangle soup has none; meshvis welds internally too.
Results are mapped back to the input faces (welding keeps the face order).

A failure of the library (an exception, or for the CGAL peel — which may abort the
whole process on input that is not piecewise-constant winding — a crash or a time-out of
the worker process) is returned as ``ok=False`` with the message, never raised.
None of these libraries takes a seed: libigl and MeshLab draw their own random rays.
"""

from __future__ import annotations

import contextlib
import io
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshvis._extras import import_extra
from meshvis.geometry.adjacency import weld
from meshvis.io import as_soup

__all__ = [
    "BaselineResult",
    "Baseline",
    "welded",
    "libigl_reorient",
    "trimesh_fix_normals",
    "pymeshlab_reorient",
    "pymeshlab_ao",
    "libigl_peel",
    "BASELINES",
    "TASKS",
]

#: the three tasks and the per-face value each returns
TASKS = {"orient": "flipped", "remove": "keep", "layers": "layer"}


@dataclass
class BaselineResult:
    """Result of one baseline run.

    Attributes
    ----------
    method : str
        Name of the baseline (a key of :data:`BASELINES`).
    task : {"orient", "remove", "layers"}
        The task.
    values : (m,) array or None
        (m,) per input face: ``flipped`` (bool) for orient, ``keep`` (bool) for
        remove, ``layer`` (int64, 1 = outer) for layers; None when the run failed
    seconds : float
        Wall time of the call, welding included.
    ok : bool
        False when the library failed; ``message`` says how.
    params : dict
        The knobs used.
    """

    method: str
    task: str
    values: np.ndarray | None
    seconds: float
    ok: bool = True
    message: str = ""
    params: dict = field(default_factory=dict)


def welded(model: Any) -> tuple[np.ndarray, np.ndarray]:
    """Weld a model into compact ``(vertices, faces)``, faces in input order.

    Corners closer than :data:`meshvis.geometry.adjacency.WELD_TOL` × diagonal are merged; each
    welded vertex takes the position of one of its input corners.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (V, F) or path
        The model, as :func:`meshvis.as_soup` accepts it.

    Returns
    -------
    vertices : (k, 3) float64
        The welded vertices, each used by some face.
    faces : (m, 3) int64
        The input faces, as indices into ``vertices``.

    Raises
    ------
    ModelError
        The model cannot be used (see :func:`meshvis.as_soup`).

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> cube = trimesh.creation.box()
    >>> V, F = welded((cube.triangles.reshape(-1, 3), np.arange(36).reshape(-1, 3)))  # a soup
    >>> V.shape, F.shape
    ((8, 3), (12, 3))
    """
    soup = as_soup(model)
    index, faces = weld(soup.vertices, soup.faces)
    used = index >= 0
    verts = np.zeros((int(index.max()) + 1 if used.any() else 0, 3))
    verts[index[used]] = soup.vertices[used]
    return verts, faces


def _turned(before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """Find the rows of ``after`` that are not a cyclic rotation of the rows of ``before``.

    (m,) bool: such a face was written with the opposite winding.
    """
    same = np.zeros(len(before), bool)
    for k in range(3):
        same |= (np.roll(before, k, axis=1) == after).all(axis=1)
    return ~same


def _failed(method: str, task: str, t0: float, exc: BaseException, params: dict) -> BaselineResult:
    msg = f"{type(exc).__name__}: {exc}".strip().splitlines()[0][:300]
    return BaselineResult(method, task, None, time.perf_counter() - t0, False, msg, params)


# ============================================================================ orientation
def libigl_reorient(
    model: Any, *, rays_total: int | None = None, rays_minimum: int = 10, facet_wise: bool = False
) -> BaselineResult:
    """Orient by libigl's ray casting (Takayama et al. 2014) on the welded model.

    Faces are grouped into manifold patches that are oriented consistently; each patch is
    then turned so that its front is the less occluded side, judged by ``rays_total``
    rays spread over the patches by area (at least ``rays_minimum`` per patch).

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (V, F) or path
        The input, as :func:`meshvis.as_soup` accepts it.
    rays_total : int, optional
        Total rays; None for libigl's default, 100 × the number of faces.
    rays_minimum : int
        Rays per patch at least.
    facet_wise : bool
        Decide every face on its own (no patches).

    Returns
    -------
    BaselineResult
        ``values`` = flipped, (m,) bool; ``ok=False`` with the message when the library
        (or reading the model) failed.
    """
    params = {"rays_total": rays_total, "rays_minimum": rays_minimum, "facet_wise": facet_wise}
    t0 = time.perf_counter()
    try:
        import igl.embree

        V, F = welded(model)
        flip, _patch = igl.embree.reorient_facets_raycast(
            V,
            F,
            rays_total=-1 if rays_total is None else int(rays_total),
            rays_minimum=int(rays_minimum),
            facet_wise=bool(facet_wise),
        )
        values = np.asarray(flip, bool).reshape(len(F))
    except Exception as exc:  # a library failure is a result, not a crash
        return _failed("libigl_reorient", "orient", t0, exc, params)
    return BaselineResult("libigl_reorient", "orient", values, time.perf_counter() - t0, params=params)


def trimesh_fix_normals(model: Any, *, multibody: bool = True) -> BaselineResult:
    """Orient by trimesh's winding repair on the welded model.

    The winding is made consistent per body, then every body is turned so that its signed
    volume is positive (``multibody=True``; else only the whole mesh is).

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (V, F) or path
        The input, as :func:`meshvis.as_soup` accepts it.
    multibody : bool
        Turn every body on its own rather than the whole mesh.

    Returns
    -------
    BaselineResult
        ``values`` = flipped, (m,) bool; ``ok=False`` with the message when the library
        failed or changed the face count.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> cube = trimesh.creation.box()
    >>> faces = cube.faces.copy()
    >>> faces[0] = faces[0, ::-1]  # one face wound the wrong way
    >>> r = trimesh_fix_normals((cube.vertices, faces))
    >>> r.ok, np.flatnonzero(r.values).tolist()
    (True, [0])
    """
    params = {"multibody": multibody}
    t0 = time.perf_counter()
    try:
        import trimesh
        import trimesh.repair

        V, F = welded(model)
        mesh = trimesh.Trimesh(V, F, process=False, validate=False)
        # trimesh divides by the zero-area faces of real scenes (zdm2): its warnings are not ours
        with np.errstate(divide="ignore", invalid="ignore"):
            trimesh.repair.fix_normals(mesh, multibody=multibody)
        after = np.asarray(mesh.faces, np.int64)
        if after.shape != F.shape:
            raise RuntimeError(f"trimesh changed the face count ({len(F)} -> {len(after)})")
        values = _turned(F, after)
    except Exception as exc:
        return _failed("trimesh_fix_normals", "orient", t0, exc, params)
    return BaselineResult("trimesh_fix_normals", "orient", values, time.perf_counter() - t0, params=params)


def require_baselines() -> None:
    """Raise MissingExtraError unless every baseline's library is installed.

    Raises
    ------
    MissingExtraError
        pymeshlab (the ``bench`` extra) is missing.
    """
    import_extra("pymeshlab", "the MeshLab baseline")


def _meshlab(V: np.ndarray, F: np.ndarray):
    pymeshlab = import_extra("pymeshlab", "the MeshLab baseline")
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=V, face_matrix=F))
    return ms


def pymeshlab_reorient(model: Any, *, rays: int = 64, parity_sampling: bool = False) -> BaselineResult:
    """Orient by MeshLab's "re-orient faces by geometry" on the welded model.

    ``meshing_re_orient_faces_by_geometry`` casts rays as libigl's reorientation does
    (Takayama et al. 2014), ``rays`` from the centroid of every face.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (V, F) or path
        The input, as :func:`meshvis.as_soup` accepts it.
    rays : int
        Rays cast from the centroid of every face.
    parity_sampling : bool
        Decide by parity sampling (the parity of the hits along each ray) instead of
        visibility sampling.

    Returns
    -------
    BaselineResult
        ``values`` = flipped, (m,) bool; ``ok=False`` with the message when the library
        failed or changed the face count.

    Raises
    ------
    MissingExtraError
        pymeshlab (the ``bench`` extra) is not installed.
    """
    params = {"rays": rays, "parity_sampling": parity_sampling}
    require_baselines()  # a missing library is the user's to fix, not a failed run
    t0 = time.perf_counter()
    try:
        V, F = welded(model)
        ms = _meshlab(V, F)
        with contextlib.redirect_stdout(io.StringIO()):
            ms.meshing_re_orient_faces_by_geometry(rays=int(rays), parity_sampling=bool(parity_sampling))
        after = np.asarray(ms.current_mesh().face_matrix(), np.int64)
        if after.shape != F.shape:
            raise RuntimeError(f"MeshLab changed the face count ({len(F)} -> {len(after)})")
        values = _turned(F, after)
    except Exception as exc:
        return _failed("pymeshlab_reorient", "orient", t0, exc, params)
    return BaselineResult("pymeshlab_reorient", "orient", values, time.perf_counter() - t0, params=params)


# ============================================================================ inside removal
def pymeshlab_ao(model: Any, *, rays: int = 64, both_sides: bool = False) -> BaselineResult:
    """Remove the faces no light reaches, by ambient occlusion in MeshLab.

    ``compute_scalar_ambient_occlusion`` sets the per-face quality ``fq`` to the light
    reaching the face from ``rays`` directions; the faces with ``fq == 0`` are removed
    (``compute_selection_by_condition_per_face``).

    MeshLab lights a face on its front side only, so a face whose front points inward is
    never lit.  ``both_sides=True`` runs the occlusion on the model plus a turned-over copy
    and keeps a face lit on either side: the fair variant for soups with random winding.

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (V, F) or path
        The input, as :func:`meshvis.as_soup` accepts it.
    rays : int
        Light directions of the occlusion.
    both_sides : bool
        Light both sides of every face (method name ``pymeshlab_ao_2sided``).

    Returns
    -------
    BaselineResult
        ``values`` = keep, (m,) bool; ``ok=False`` with the message when the library failed
        or changed the face count.

    Raises
    ------
    MissingExtraError
        pymeshlab (the ``bench`` extra) is not installed.
    """
    params = {"rays": rays, "both_sides": both_sides}
    method = "pymeshlab_ao_2sided" if both_sides else "pymeshlab_ao"
    require_baselines()
    t0 = time.perf_counter()
    try:
        V, F = welded(model)
        m = len(F)
        FF = np.vstack([F, F[:, ::-1]]) if both_sides else F
        ms = _meshlab(V, FF)
        with contextlib.redirect_stdout(io.StringIO()):
            ms.compute_scalar_ambient_occlusion(rays=int(rays))
            ms.compute_selection_by_condition_per_face(condselect="(fq == 0)")
        dark = np.asarray(ms.current_mesh().face_selection_array(), bool)
        if len(dark) != len(FF):
            raise RuntimeError(f"MeshLab changed the face count ({len(FF)} -> {len(dark)})")
        keep = ~dark[:m]
        if both_sides:
            keep |= ~dark[m:]
    except Exception as exc:
        return _failed(method, "remove", t0, exc, params)
    return BaselineResult(method, "remove", keep, time.perf_counter() - t0, params=params)


# ============================================================================ layers
def _peel_main(in_path: str, out_path: str) -> None:  # pragma: no cover - runs in a child process
    """Worker entry: read ``V``, ``F`` from ``in_path`` (.npz), peel, write the answer."""
    with np.load(in_path) as z:
        V, F = z["V"], z["F"]
    import igl.copyleft.cgal

    t = time.perf_counter()
    try:
        index, _flip, n = igl.copyleft.cgal.peel_outer_hull_layers(V, F)
        out = dict(index=np.asarray(index, np.int64), n=np.int64(n), seconds=time.perf_counter() - t)
    except Exception as exc:
        out = dict(error=np.array(f"{type(exc).__name__}: {exc}"))
    np.savez(out_path, **out)


def libigl_peel(model: Any, *, timeout: float = 300.0) -> BaselineResult:
    """Peel layers by libigl's outer-hull peeling (CGAL, exact).

    Layer k is the outer hull of what is left once layers 1 … k-1 are gone.  The peel
    assumes a piecewise-constant-winding (closed, possibly self-intersecting) input; on
    other input CGAL may throw or abort the process.  It therefore runs in a separate
    Python process with a time limit; the reported time is the welding plus the library
    call timed inside the worker (not the worker's start-up).

    Parameters
    ----------
    model : Soup, trimesh.Trimesh, (V, F) or path
        The input, as :func:`meshvis.as_soup` accepts it.
    timeout : float
        Seconds to wait for the worker process.

    Returns
    -------
    BaselineResult
        ``values`` = layer, (m,) int64 (1 = outer), with the number of layers in
        ``params["layers"]``; ``ok=False`` with the message when the library failed, the
        worker died or gave no answer within ``timeout``.
    """
    import subprocess
    import sys
    import tempfile

    params = {"timeout": timeout}
    t0 = time.perf_counter()
    try:
        V, F = welded(model)
    except Exception as exc:
        return _failed("libigl_peel", "layers", t0, exc, params)
    t_weld = time.perf_counter() - t0
    with tempfile.TemporaryDirectory(prefix="meshvis-peel-") as tmp:
        src, dst = os.path.join(tmp, "in.npz"), os.path.join(tmp, "out.npz")
        np.savez(src, V=V, F=F)
        code = f"from meshvis.eval.baselines import _peel_main; _peel_main({src!r}, {dst!r})"
        try:
            # run in the temporary folder: "python -c" puts its working folder on sys.path
            run = subprocess.run(
                [sys.executable, "-c", code],
                capture_output=True,
                text=True,
                timeout=timeout,
                cwd=tmp,
            )
        except subprocess.TimeoutExpired:
            return BaselineResult(
                "libigl_peel",
                "layers",
                None,
                time.perf_counter() - t0,
                False,
                f"no answer within {timeout:g} s",
                params,
            )
        if run.returncode != 0 or not os.path.exists(dst):
            tail = (run.stderr.strip().splitlines() or [""])[-1][:200]
            return BaselineResult(
                "libigl_peel",
                "layers",
                None,
                time.perf_counter() - t0,
                False,
                f"worker died (exit code {run.returncode}) {tail}".strip(),
                params,
            )
        with np.load(dst) as z:
            if "error" in z.files:
                return BaselineResult(
                    "libigl_peel", "layers", None, time.perf_counter() - t0, False, str(z["error"]), params
                )
            layer = z["index"] + 1
            n, seconds = int(z["n"]), float(z["seconds"])
    return BaselineResult("libigl_peel", "layers", layer, t_weld + seconds, params=dict(params, layers=n))


# ============================================================================ registry
@dataclass(frozen=True)
class Baseline:
    """A baseline in the registry: its function, task, budget knob and the knob's values.

    ``sweep`` values are multiples of the face count when ``per_face`` is True.
    """

    run: Callable[..., BaselineResult]
    task: str
    label: str
    knob: str | None = None
    default: float | None = None
    sweep: tuple = ()
    per_face: bool = False
    fixed: dict = field(default_factory=dict)

    def knob_value(self, x: float, n_faces: int) -> int:
        """Convert sweep value ``x`` into the knob's argument for a model of ``n_faces`` faces.

        Parameters
        ----------
        x : float
            A value of :attr:`sweep` (a multiple of the face count when :attr:`per_face`).
        n_faces : int
            Faces of the model.

        Returns
        -------
        int
            ``round(x * n_faces)`` (at least 1) when :attr:`per_face`, else ``int(x)``.
        """
        return max(1, int(round(x * n_faces))) if self.per_face else int(x)


#: name -> Baseline; the sweeps are those of ``meshvis bench accuracy``
BASELINES: dict[str, Baseline] = {
    "libigl_reorient": Baseline(
        libigl_reorient,
        "orient",
        "libigl reorient_facets_raycast",
        "rays_total",
        100,
        (1, 3, 10, 30, 100),
        per_face=True,
    ),
    "trimesh_fix_normals": Baseline(trimesh_fix_normals, "orient", "trimesh fix_normals"),
    "pymeshlab_reorient": Baseline(
        pymeshlab_reorient, "orient", "MeshLab re-orient by geometry", "rays", 64, (4, 16, 64, 256)
    ),
    "pymeshlab_ao": Baseline(pymeshlab_ao, "remove", "MeshLab AO, fq == 0", "rays", 64, (4, 16, 64, 256)),
    "pymeshlab_ao_2sided": Baseline(
        pymeshlab_ao,
        "remove",
        "MeshLab AO both sides, fq == 0",
        "rays",
        64,
        (4, 16, 64, 256),
        fixed={"both_sides": True},
    ),
    "libigl_peel": Baseline(libigl_peel, "layers", "libigl peel_outer_hull_layers"),
}
