"""Helpers every format shares.

One-line messages, atomic writes, output checks, welding corners into output vertices,
unique names, float text.

Format modules import from here and never from :mod:`meshvis.io.reading` or
:mod:`meshvis.io.writing`, which import them: the dependency runs one way.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import stat
import struct
import tempfile
from collections.abc import Iterator
from typing import IO, Any

import numpy as np

from meshvis.errors import OutputError
from meshvis.soup import Soup

#: the UTF-8 byte-order mark some editors put at the start of a text file
BOM = b"\xef\xbb\xbf"


def without_bom(data: bytes) -> bytes:
    """``data`` without a leading UTF-8 byte-order mark (which would otherwise be read as
    part of the first line's keyword, and that line lost)."""
    return data[len(BOM) :] if data.startswith(BOM) else data


def decode_text(data: bytes) -> str:
    """The text of a file's bytes: UTF-8 (a byte-order mark dropped), else Latin-1."""
    data = without_bom(data)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def one_line(text: object, limit: int = 200) -> str:
    """The first line of ``str(text)``, shortened to ``limit`` characters."""
    lines = [s.strip() for s in str(text).splitlines() if s.strip()]
    first = lines[0] if lines else ""
    return first if len(first) <= limit else first[: limit - 3] + "..."


def describe_exception(exc: BaseException) -> str:
    """A short one-line description of an exception raised by a parser."""
    text = one_line(exc)
    name = type(exc).__name__
    if not text:
        return name
    if isinstance(exc, (KeyError, IndexError, struct.error)):
        return f"{name}: {text}"
    return text


#: room a temporary name needs beyond its prefix: mkstemp's 8 random characters and ".tmp"
_TEMP_EXTRA = 12


def temp_prefix(path: str) -> str:
    """``.<file name>.`` -- the start of the temporary names of ``path``, shortened so that a
    temporary name fits the file system's name limit whenever ``path`` itself does."""
    name = os.path.basename(path)
    try:
        limit = os.pathconf(os.path.dirname(os.path.abspath(path)), "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):
        limit = 255
    return "." + name[: max(1, limit - _TEMP_EXTRA - 2)] + "."


class _Stage:
    """Outputs of one :func:`staged_outputs` block: renames still to do, files already made."""

    def __init__(self) -> None:
        self.pending: list[tuple[str, str]] = []
        self.created: list[str] = []


_STAGE: contextvars.ContextVar[_Stage | None] = contextvars.ContextVar("meshvis_stage", default=None)


@contextlib.contextmanager
def staged_outputs() -> Iterator[None]:
    """Publish every :func:`atomic_write` of the block together when the block succeeds.

    Inside the block each write stays in its temporary file; when the block ends normally
    all of them are renamed into place (renames need no disk space), with SIGINT and SIGTERM
    held back meanwhile.  When it raises (an error, Ctrl-C, SIGTERM) every temporary file is
    removed, and so is every file registered with :func:`register_created` (textures):
    a command's outputs appear together or not at all.
    """
    stage = _Stage()
    token = _STAGE.set(stage)
    try:
        yield
    except BaseException:
        for tmp, _ in stage.pending:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        for p in stage.created:
            with contextlib.suppress(OSError):
                os.unlink(p)
        raise
    finally:
        _STAGE.reset(token)
    with _signals_held():
        _publish(stage)


def _publish(stage: _Stage) -> None:
    """Rename every staged file into place, or, when one rename fails, none of them.

    Each existing target is first kept under a temporary name (a hard link, or the file
    itself moved there when the file system has no hard links).  When a rename fails, the
    targets already replaced get their old files back, the new ones are removed, and so are
    the stage's other files (textures).
    """
    done: list[tuple[str, str | None]] = []  # (target, temporary name of its old file or None)
    try:
        for tmp, path in stage.pending:
            kept = _keep_aside(path)
            try:
                os.replace(tmp, path)
            except OSError:
                if kept is not None:
                    os.replace(kept, path)
                raise
            done.append((path, kept))
    except OSError as exc:
        for path, kept in reversed(done):
            with contextlib.suppress(OSError):
                if kept is not None:
                    os.replace(kept, path)
                else:
                    os.unlink(path)
        for p in [tmp for tmp, _ in stage.pending] + stage.created:
            with contextlib.suppress(OSError):
                os.unlink(p)
        failed = next((path for tmp, path in stage.pending if tmp == exc.filename), exc.filename or "")
        raise OutputError(f"cannot write: {one_line(exc.strerror or exc)}", failed) from None
    for _, kept in done:
        if kept is not None:
            with contextlib.suppress(OSError):
                os.unlink(kept)


def _keep_aside(path: str) -> str | None:
    """A new temporary name in the folder of ``path`` for the file now there (None: no file)."""
    if not os.path.lexists(path) or os.path.isdir(path):
        return None
    folder = os.path.dirname(os.path.abspath(path))
    while True:
        kept = os.path.join(folder, f"{temp_prefix(path)}{os.urandom(6).hex()}.tmp")
        if os.path.lexists(kept):
            continue
        if os.path.isfile(path) and not os.path.islink(path):
            with contextlib.suppress(OSError):  # no hard links here: move the file instead
                os.link(path, kept)
                return kept
        os.replace(path, kept)
        return kept


def register_created(path: str) -> None:
    """Note a file made outside :func:`atomic_write`, to be removed if the stage fails."""
    stage = _STAGE.get()
    if stage is not None:
        stage.created.append(path)


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """Delay SIGINT/SIGTERM until the block ends (main thread on POSIX; else no effect)."""
    import signal
    import threading

    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    held = {signal.SIGINT, signal.SIGTERM}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "w", encoding: str = "utf-8") -> Iterator[IO]:
    """Open ``path`` for writing so that it is replaced only when writing succeeds.

    The data goes to a temporary file in the same folder; on leaving the ``with`` block
    normally it is flushed, synced to disk and renamed over ``path`` (``os.replace``, atomic
    on POSIX).  On any exception the temporary file is removed and an existing ``path`` is
    left untouched.  Inside :func:`staged_outputs` the rename waits for the end of that
    block.  The temporary name is ``.<file name>.<random>.tmp`` (the file name shortened
    when needed, see :func:`temp_prefix`).  The new file gets the permissions of the file it replaces, or the
    usual ones for a new file (0666 less the umask).  Text is UTF-8; a character it cannot
    hold (a lone surrogate, from a file name that is not valid UTF-8) is written as ``?``.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write.
    mode : {"w", "wb"}
        Text or binary.
    encoding : str
        Text encoding for ``"w"``.

    Yields
    ------
    file object
        The open temporary file.

    Raises
    ------
    OutputError
        The folder does not exist or is not writable, or ``path`` is a folder.
    """
    if mode not in ("w", "wb"):
        raise ValueError("mode must be 'w' or 'wb'")
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise OutputError("output path is a folder", path)
    if not os.path.isdir(folder):
        raise OutputError("output folder does not exist", path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=temp_prefix(path), suffix=".tmp", dir=folder)
    except PermissionError:
        raise OutputError("output folder is not writable", path) from None
    except OSError as exc:
        raise OutputError(f"cannot write: {one_line(exc.strerror or exc)}", path) from None
    try:
        text: dict[str, Any] = (
            {"encoding": encoding, "newline": "\n", "errors": "replace"} if mode == "w" else {}
        )
        with os.fdopen(fd, mode, **text) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        try:
            perm = stat.S_IMODE(os.stat(path).st_mode)
        except OSError:
            umask = os.umask(0)
            os.umask(umask)
            perm = 0o666 & ~umask
        os.chmod(tmp, perm)
        stage = _STAGE.get()
        if stage is None:
            os.replace(tmp, path)
        else:
            stage.pending.append((tmp, path))
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(f"cannot write: {one_line(exc.strerror or exc)}", path) from None
        raise


def weld_corners(soup: Soup, use_uv: bool = True, use_colors: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Share one output vertex between corners with the same vertex, UV and colour.

    Parameters
    ----------
    soup : Soup
        The model to write.
    use_uv : bool
        Whether UVs (when the soup has them) take part in the key.
    use_colors : bool
        Whether colours (when the soup has them) take part in the key.

    Returns
    -------
    corner_vertex : (k,) int64 array
        For each output vertex, the flat corner index (into ``faces.ravel()``) it is
        taken from: gather positions, UVs and colours with it.
    faces : (m, 3) int64 array
        Faces indexing the output vertices.

    Notes
    -----
    The key of a corner is built in steps, each a ``np.unique`` on one int64 array: the
    vertex index, then combined with the id of its UV pair, then with the id of its
    packed RGBA colour.  Output vertices are sorted by key, so the result is
    deterministic.
    """
    flat = soup.faces.reshape(-1)
    key = flat.astype(np.int64)
    if use_uv and soup.uv is not None:
        uv = soup.uv.reshape(-1, 2)
        # a complex number holds the UV pair exactly and sorts fast in one dimension
        _, uv_id = np.unique(uv[:, 0] + 1j * uv[:, 1], return_inverse=True)
        _, key = np.unique(key * (int(uv_id.max()) + 1) + uv_id.reshape(-1), return_inverse=True)
    if use_colors and soup.colors is not None:
        packed = np.ascontiguousarray(soup.colors.reshape(-1, 4)).view(np.uint32).reshape(-1)
        _, col_id = np.unique(packed, return_inverse=True)
        key = key.reshape(-1) * (int(col_id.max()) + 1) + col_id.reshape(-1)
    _, first, inverse = np.unique(key.reshape(-1), return_index=True, return_inverse=True)
    return first.astype(np.int64), inverse.reshape(-1, 3).astype(np.int64)


def unique_names(names: list[str], fallback: str) -> list[str]:
    """Make names non-empty and unique (``name``, ``name.1``, ...), keeping order."""
    out: list[str] = []
    seen: set[str] = set()
    for i, n in enumerate(names):
        base = " ".join(str(n or "").split()) or f"{fallback}{i}"
        cand, k = base, 1
        while cand in seen:
            cand = f"{base}.{k}"
            k += 1
        seen.add(cand)
        out.append(cand)
    return out


def companions(path: str) -> list[str]:
    """Files written along with ``path``: the MTL file of an OBJ output."""
    stem, ext = os.path.splitext(path)
    return [stem + ".mtl"] if ext.lower() == ".obj" else []


def check_outputs(paths: list[str], inputs: list[str], force: bool) -> None:
    """:func:`check_output` for every output of one command, and no two of them the same file.

    The files written with an output (:func:`companions`, e.g. the MTL of an OBJ) count as
    outputs too, so ``-o out/o.obj`` with ``--report out/o.mtl`` is refused before any work.

    Raises
    ------
    OutputError
        Two outputs (or companions) are one file, or :func:`check_output` refuses one.
    """
    seen: set[str] = set()
    for path in paths:
        for p in [path, *companions(path)]:
            key = os.path.normcase(os.path.realpath(p))
            if key in seen:
                raise OutputError("two outputs of the command are this one file; give each its own path", p)
            seen.add(key)
    for path in paths:
        check_output(path, inputs, force)


def check_output(path: str, inputs: list[str], force: bool) -> None:
    """Refuse an output path that cannot or must not be written.

    The same checks apply to the files written with it (:func:`companions`).

    Parameters
    ----------
    path : str
        The output path.
    inputs : list of str
        The input files, which are never overwritten.
    force : bool
        Allow replacing an existing file.

    Raises
    ------
    OutputError
        ``path`` is an input or a folder, its folder is missing or unwritable, or it exists
        while ``force`` is False.
    """
    _check_one(path, inputs, force)
    for extra in companions(path):
        _check_one(extra, inputs, force, what="the MTL file of the output")


def _check_one(path: str, inputs: list[str], force: bool, what: str = "") -> None:
    """:func:`check_output` for one path; ``what`` names a companion file in messages."""
    note = f" ({what})" if what else ""
    for inp in inputs:
        if os.path.exists(path) and os.path.exists(inp) and os.path.samefile(path, inp):
            raise OutputError(f"output path{note} is the input file; choose another path", path)
        if os.path.abspath(path) == os.path.abspath(inp):
            raise OutputError(f"output path{note} is the input file; choose another path", path)
    if os.path.isdir(path):
        raise OutputError(f"output path{note} is a folder", path)
    if os.path.exists(path) and not force:
        raise OutputError(f"exists{note}; use --force to overwrite", path)
    check_folder(path)


def check_folder(path: str) -> None:
    """Refuse an output path whose folder is missing or not writable, or whose name is
    longer than the file system allows (:class:`OutputError` naming the path)."""
    folder = os.path.dirname(os.path.abspath(path))
    # the folder as written too: "missing/../o.obj" names a folder that does not exist
    if not os.path.isdir(folder) or not os.path.isdir(os.path.dirname(os.fspath(path)) or "."):
        raise OutputError("output folder does not exist", path)
    if not os.access(folder, os.W_OK):
        raise OutputError("output folder is not writable", path)
    try:
        limit = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):
        limit = 255
    size = len(os.fsencode(os.path.basename(path)))
    if size > limit:
        raise OutputError(
            f"the file name is {size} bytes long, more than the file system allows ({limit})", path
        )


def ensure_folder(out_dir: str) -> None:
    """Create the output folder if needed and check that files can be created in it.

    Raises
    ------
    OutputError
        The path is a file, cannot be created, or is not writable.
    """
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise OutputError("the output folder is a file", out_dir)
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as exc:
        raise OutputError(
            f"cannot create the output folder: {one_line(exc.strerror or exc)}", out_dir
        ) from None
    try:  # os.access is not enough: root passes it, read-only mounts fail only on write
        fd, probe = tempfile.mkstemp(prefix=".meshvis-probe-", dir=out_dir)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise OutputError(
            f"output folder is not writable ({one_line(exc.strerror or exc)})", out_dir
        ) from None


def fmt_floats(values: np.ndarray) -> list[str]:
    """Shortest text that reads back to the same float64, per value."""
    return list(map(repr, np.asarray(values, np.float64).ravel().tolist()))
