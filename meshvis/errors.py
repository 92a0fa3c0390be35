"""Exception classes of meshvis.

Every error caused by the user's input derives from :class:`MeshvisError`; the command line
prints its one-line message and exits with status 2.  Anything else is a bug.
"""

from __future__ import annotations

import os


class MeshvisError(Exception):
    """Base class of every documented meshvis error (bad input, bad arguments)."""


class ModelError(MeshvisError, ValueError):
    """A model (file or arrays) cannot be used: unreadable, empty, NaN coordinates, ...

    Parameters
    ----------
    problem : str
        What is wrong, in a few words.
    path : str or os.PathLike, optional
        The file the model came from; it leads the message when given.
    """

    def __init__(self, problem: str, path: str | os.PathLike | None = None):
        self.problem = problem
        self.path = None if path is None else os.fspath(path)
        super().__init__(f"{self.path}: {problem}" if self.path else problem)


class ModelFormatError(ModelError):
    """The file's format is unknown, or its content does not parse."""


class OutputError(MeshvisError, OSError):
    """An output cannot be written (exists without --force, unwritable folder, same as input)."""

    def __init__(self, problem: str, path: str | os.PathLike | None = None):
        self.problem = problem
        self.path = None if path is None else os.fspath(path)
        MeshvisError.__init__(self, f"{self.path}: {problem}" if self.path else problem)

    def __str__(self) -> str:  # OSError would otherwise format its own way
        return f"{self.path}: {self.problem}" if self.path else self.problem


class ParameterError(MeshvisError, ValueError):
    """An argument is out of its documented range."""


class MissingExtraError(MeshvisError, ImportError):
    """A feature needs an optional dependency that is not installed.

    Parameters
    ----------
    feature : str
        What the user asked for, e.g. ``"meshvis bench compare"``.
    module : str
        The module that could not be imported.
    extra : str
        The ``meshvis`` extra that installs it.
    """

    def __init__(self, feature: str, module: str, extra: str):
        self.feature = feature
        self.extra = extra
        message = f'{feature} needs {module}, which is not installed: pip install "meshvis[{extra}]"'
        ImportError.__init__(self, message, name=module)
        self.args = (message,)

    def __str__(self) -> str:  # ImportError keeps its own message handling
        return self.args[0]
