"""Argument checks shared by the public entry points: a wrong type or an out-of-range value
becomes a one-line :class:`~meshvis.errors.ParameterError` naming the argument, before any
work starts (never a ``TypeError``, ``IndexError`` or ``MemoryError`` from deep inside).

Each entry point calls one function of this module in one line.  Integers must be Python or
numpy integers (not ``bool``, not ``"32"``, not ``1.5``); numbers must be real and finite;
caps come from :mod:`meshvis.limits`.
"""

from __future__ import annotations

import inspect
import numbers
import os
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from meshvis import limits
from meshvis.errors import ParameterError

#: the random seed must fit numpy's SeedSequence (a non-negative integer); 2**128 is plenty
_MAX_SEED = 2**128


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def integer(name: str, value: Any, lo: int | None = None, hi: int | None = None, cap: str = "") -> int:
    """``value`` as an int, or :class:`ParameterError` when it is not an integer in [lo, hi]."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, np.integer)):
        raise ParameterError(f"{name} must be an integer, got {_shown(value)}")
    v = int(value)
    if lo is not None and v < lo:
        raise ParameterError(f"{name} must be at least {lo}, got {v}")
    if hi is not None and v > hi:
        where = f" (the cap {cap} of meshvis.limits)" if cap else ""
        raise ParameterError(f"{name} must be at most {hi}{where}, got {v}")
    return v


def real(
    name: str, value: Any, lo: float | None = None, hi: float | None = None, open_lo: bool = False
) -> float:
    """``value`` as a finite float in [lo, hi] (``(lo, hi]`` with ``open_lo``)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"{name} must be a number, got {_shown(value)}")
    try:
        v = float(value)
    except OverflowError:  # an integer past the float range
        v = float("inf")
    if not np.isfinite(v):
        raise ParameterError(f"{name} must be finite, got {v}")
    if lo is not None and (v <= lo if open_lo else v < lo):
        raise ParameterError(f"{name} must be {'above' if open_lo else 'at least'} {lo}, got {v}")
    if hi is not None and v > hi:
        raise ParameterError(f"{name} must be at most {hi}, got {v}")
    return v


def choice(name: str, value: Any, allowed: tuple) -> Any:
    """``value`` when it is one of ``allowed``."""
    if not any(value is a or (isinstance(value, str) and value == a) for a in allowed):
        shown = ", ".join("None" if a is None else str(a) for a in allowed)
        raise ParameterError(f"{name} must be one of {shown}; got {_shown(value)}")
    return value


def seed(value: Any) -> int:
    """A seed for :func:`numpy.random.default_rng`: an integer in [0, 2**128)."""
    return integer("seed", value, 0, _MAX_SEED - 1)


def flag(name: str, value: Any) -> bool:
    """``value`` when it is a boolean (``True``, ``False`` or a numpy bool; not ``"yes"``, not 1)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{name} must be True or False, got {_shown(value)}")
    return bool(value)


def budget(value: Any) -> int | None:
    """A ray budget: None (the default rule) or an integer of at least 1 (0 rays would call
    every face unseen), at most ``MAX_RAYS``."""
    if value is None:
        return None
    return integer("budget", value, 1, limits.MAX_RAYS, "MAX_RAYS")


def visibility_args(
    budget_value: Any, seed_value: Any, per_side: Any, min_new: Any, min_new_area: Any
) -> None:
    """The arguments of :func:`meshvis.visible_from` (see its docstring)."""
    budget(budget_value)
    seed(seed_value)
    flag("per_side", per_side)
    real("min_new", min_new, 0.0)
    real("min_new_area", min_new_area, 0.0)


def removal_args(keep_border: Any, budget_value: Any) -> None:
    """The numeric arguments of :func:`meshvis.remove_interior`: rings kept (an integer of
    at least 0) and the ray budget of the search for views."""
    integer("keep_border", keep_border, 0)
    budget(budget_value)


def instance(name: str, value: Any, kind: type | tuple, optional: bool = False) -> Any:
    """``value`` when it is an instance of ``kind`` (or None with ``optional``)."""
    if (value is None and optional) or isinstance(value, kind):
        return value
    kinds = kind if isinstance(kind, tuple) else (kind,)
    want = " or ".join(k.__name__ for k in kinds) + (" or None" if optional else "")
    raise ParameterError(f"{name} must be a {want}, got {type(value).__name__}")


def callback(name: str, value: Any) -> Any:
    if value is not None and not callable(value):
        raise ParameterError(f"{name} must be callable or None, got {type(value).__name__}")
    return value


def path(name: str, value: Any) -> str:
    """A file path (str or path-like)."""
    if not isinstance(value, (str, os.PathLike)):
        raise ParameterError(f"{name} must be a file path (str or path-like), got {type(value).__name__}")
    return os.fspath(value)


def points(name: str, value: Any, shape: tuple[int, ...] = (3,)) -> np.ndarray:
    """Finite float64 array of shape ``(k, *shape)`` (one item of ``shape`` is taken as k = 1)."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except OverflowError:  # an integer past the float range
        raise ParameterError(f"{name} must be finite") from None
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be numbers of shape (k, {', '.join(map(str, shape))})") from None
    if a.size == 0:
        return np.zeros((0, *shape))
    if a.shape == shape:
        a = a[None]
    if a.ndim != len(shape) + 1 or a.shape[1:] != shape:
        raise ParameterError(f"{name} must have shape (k, {', '.join(map(str, shape))}), got {a.shape}")
    if not np.isfinite(a.sum()) and not np.isfinite(a).all():  # one sum is 4x faster than isfinite
        raise ParameterError(f"{name} must be finite")
    return a


def image_size(size: Any) -> tuple[int, int]:
    """(width, height) of an image: two integers >= 1 whose product is within ``MAX_PIXELS``."""
    if isinstance(size, (str, bytes)) or not hasattr(size, "__len__") or len(size) != 2:
        raise ParameterError(f"size must be (width, height), got {_shown(size)}")
    w, h = integer("width", size[0], 1), integer("height", size[1], 1)
    if w * h > limits.MAX_PIXELS:
        raise ParameterError(
            f"size {w}x{h} is {w * h} pixels, more than the cap MAX_PIXELS of meshvis.limits ({limits.MAX_PIXELS})"
        )
    return w, h


def frames(n_frames: Any, size: Any = None) -> int:
    """The number of frames of a labelled sequence: an integer in [1, ``MAX_FRAMES``] whose
    pictures of ``size`` (width, height) hold at most ``MAX_SEQUENCE_PIXELS`` together."""
    n = integer("the number of frames", n_frames, 1, limits.MAX_FRAMES, "MAX_FRAMES")
    if size is not None:
        w, h = image_size(size)
        if n * w * h > limits.MAX_SEQUENCE_PIXELS:
            raise ParameterError(
                f"{n} frames of {w}x{h} are {n * w * h} pixels, more than the cap MAX_SEQUENCE_PIXELS of "
                f"meshvis.limits ({limits.MAX_SEQUENCE_PIXELS}); use fewer frames or smaller pictures"
            )
    return n


def classify_args(
    rays_per_node,
    seed_value,
    samples_per_face,
    sampling_scheme,
    opening,
    tolerance,
    solver,
    offset,
    progress,
    *,
    rays_per_point=None,
) -> None:
    """The arguments of :func:`meshvis.classify` (see its docstring)."""
    integer("rays_per_node", rays_per_node, 1, limits.MAX_RAYS_PER_NODE, "MAX_RAYS_PER_NODE")
    if rays_per_point is not None:
        integer("rays_per_point", rays_per_point, 1, limits.MAX_RAYS_PER_NODE, "MAX_RAYS_PER_NODE")
    seed(seed_value)
    integer("samples_per_face", samples_per_face, 1, limits.MAX_SAMPLES_PER_FACE, "MAX_SAMPLES_PER_FACE")
    choice("sampling_scheme", sampling_scheme, (1, 2))
    if opening is not None:
        real("opening", opening, 0.0, 1.0, open_lo=True)
    real("tolerance", tolerance, 0.0, 1.0)
    if offset is not None:
        real("offset", offset, 0.0, 0.1, open_lo=True)
    callback("progress", progress)


def keywords(given: Mapping[str, Any], function: Callable) -> None:
    """Refuse keyword arguments that ``function`` does not take (``**classify_kw`` pass-through)."""
    known = set(inspect.signature(function).parameters)
    unknown = sorted(set(given) - known)
    if unknown:
        raise ParameterError(f"unknown argument {unknown[0]!r} of {function.__name__}()")


def ray_arrays(origins: Any, directions: Any, name: str = "directions") -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) finite origins and (n, 3) finite directions (or targets) of equal length
    (zero directions are caught after normalising, :func:`unit_directions`)."""
    o = points("origins", origins)
    d = points(name, directions)
    if len(o) != len(d):
        raise ParameterError(f"origins ({len(o)}) and {name} ({len(d)}) differ in length")
    return o, d


def unit_directions(d: np.ndarray) -> np.ndarray:
    """``d`` (directions divided by their lengths) when no direction was zero (a zero one is NaN)."""
    if len(d) and not np.isfinite(d.sum()):
        raise ParameterError("directions must be non-zero")
    return d


def face_indices(name: str, value: Any, n_faces: int, allow_miss: bool = False) -> np.ndarray:
    """Integer face indices in [0, n_faces) (-1 allowed with ``allow_miss``)."""
    a = np.asarray(value)
    if a.size and a.dtype.kind not in "iu":
        raise ParameterError(f"{name} must be integer face indices, got dtype {a.dtype}")
    a = a.astype(np.int64)
    lo = -1 if allow_miss else 0
    if a.size and (a.min() < lo or a.max() >= n_faces):
        raise ParameterError(
            f"{name} must be in [{lo}, {n_faces}), got values up to {int(a.max())} / {int(a.min())}"
        )
    return a


def per_face(name: str, value: Any, n_faces: int, kind: str = "iuf") -> np.ndarray:
    """A (m,) array of numbers, one per face."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be one number per face") from None
    if a.ndim != 1 or len(a) != n_faces:
        raise ParameterError(f"{name} must have one value per face ({n_faces}), got shape {a.shape}")
    if a.dtype.kind not in kind:
        raise ParameterError(
            f"{name} must be {'integers' if kind == 'iu' else 'numbers'}, got dtype {a.dtype}"
        )
    return a


def repair_args(classification: Any, kind: type, classify_kw: Mapping[str, Any], classify: Callable) -> None:
    """The shared arguments of orient / remove_interior / layers: a reused classification of
    the right type, and only keywords :func:`meshvis.classify` takes."""
    instance("classification", classification, kind, optional=True)
    keywords(classify_kw, classify)


def render_args(size: Any, color_by: Any, face_values: Any, azimuth: Any, elevation: Any) -> tuple[int, int]:
    """The arguments of :func:`meshvis.render`; returns (width, height)."""
    choice("color_by", color_by, ("side", "part", "layer", None))
    if color_by == "layer" and face_values is None:
        raise ParameterError("color_by='layer' needs face_values")
    real("azimuth", azimuth)
    real("elevation", elevation)
    return image_size(size)


def max_distance(value: Any, n: int) -> np.ndarray:
    """A ray length limit: a number or (n,) numbers, each >= 0 (inf allowed)."""
    try:
        a = np.asarray(value, np.float64)
    except (TypeError, ValueError):
        raise ParameterError("max_distance must be a number or one number per ray") from None
    if a.ndim > 1 or (a.ndim == 1 and len(a) != n):
        raise ParameterError(
            f"max_distance must be a number or one number per ray ({n}), got shape {a.shape}"
        )
    if np.isnan(a).any() or (a < 0).any():
        raise ParameterError("max_distance must be >= 0")
    return a


def names(name: str, value: Any) -> list[str]:
    """A list of strings (None: empty)."""
    if value is None:
        return []
    if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple)):
        raise ParameterError(f"{name} must be a list of strings, got {type(value).__name__}")
    return [str(v) for v in value]


def operation_options(options: Mapping[str, Any]) -> None:
    """The numeric options of a repair operation, checked once before a batch starts: the
    classification's (``seed``, ``rays_per_node``, ``rays_per_point``,
    ``samples_per_face``) and, when given, inside removal's (``keep_border``, ``budget``)."""
    if "keep_border" in options or "budget" in options:
        removal_args(options.get("keep_border", 0), options.get("budget"))
    seed(options.get("seed", 0))
    integer(
        "rays_per_node", options.get("rays_per_node", 32), 1, limits.MAX_RAYS_PER_NODE, "MAX_RAYS_PER_NODE"
    )
    if options.get("rays_per_point") is not None:
        integer("rays_per_point", options["rays_per_point"], 1, limits.MAX_RAYS_PER_NODE, "MAX_RAYS_PER_NODE")
    integer(
        "samples_per_face",
        options.get("samples_per_face", 4),
        1,
        limits.MAX_SAMPLES_PER_FACE,
        "MAX_SAMPLES_PER_FACE",
    )


def ray_budget(soup, rays_per_node: int, rays_per_point: int, samples_per_face: int) -> None:
    """Refuse a classification that may ask for more rays than its input's size allows.

    The bound is taken before any work: every face flagged, ``2 x samples_per_face x
    rays_per_point`` rays and as many reverse rays per face, or ``2 x rays_per_node``,
    whichever is more.  The cap is :data:`meshvis.limits.RAYS_PER_INPUT_BYTE` rays per byte
    of the input (:func:`input_bytes`), at least :data:`meshvis.limits.MIN_RAY_CAP`: a small
    file that places many faces cannot ask for unbounded work, a large model may ask for
    as much as its size.
    """
    per_face = 2 * max(int(rays_per_node), 2 * int(samples_per_face) * int(rays_per_point))
    asked = soup.n_faces * per_face
    size = input_bytes(soup)
    cap = max(limits.RAYS_PER_INPUT_BYTE * size, limits.MIN_RAY_CAP)
    if asked > cap:
        where = f"{soup.path}: " if soup.path else ""
        raise ParameterError(
            f"{where}{soup.n_faces} faces may ask for {asked} rays ({per_face} per face at rays_per_node="
            f"{rays_per_node}, rays_per_point={rays_per_point}, samples_per_face={samples_per_face}), more than "
            f"the {cap} an input of {size} bytes may (RAYS_PER_INPUT_BYTE of meshvis.limits, "
            f"{limits.RAYS_PER_INPUT_BYTE}); lower rays_per_node, rays_per_point or samples_per_face"
        )


def input_bytes(soup) -> int:
    """Bytes of a model's input: its file (a ``.gltf``'s external buffers too), or its arrays.

    Examples
    --------
    >>> import numpy as np
    >>> from meshvis.soup import Soup
    >>> input_bytes(Soup(np.eye(3), np.array([[0, 1, 2]])))
    96
    """
    path = soup.path
    if path is None or not os.path.isfile(path):
        return int(soup.vertices.nbytes + soup.faces.nbytes)
    size = os.path.getsize(path)
    data = getattr(soup.source, "data", None)
    doc, folder = getattr(data, "doc", None), getattr(data, "folder", None)
    if isinstance(doc, dict) and isinstance(folder, str):  # a .gltf and its .bin files
        for buf in doc.get("buffers", []):
            uri = buf.get("uri") if isinstance(buf, dict) else None
            if isinstance(uri, str) and not uri.startswith("data:"):
                other = os.path.join(folder, uri)
                size += os.path.getsize(other) if os.path.isfile(other) else 0
    return int(size)
