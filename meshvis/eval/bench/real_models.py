"""The folder of real models that the benchmarks read, given by ``--models DIR``."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from meshvis.errors import ParameterError

#: default of ``--models``, relative to the current folder: where the shared real models sit
#: beside a checkout of the repository
DEFAULT_MODELS = os.path.join("..", "shared", "models", "real")


def models_folder(folder: str | os.PathLike) -> Path:
    """The folder of real models, checked to exist.

    Parameters
    ----------
    folder : str or os.PathLike
        Where the real models are.

    Returns
    -------
    Path
        ``folder`` as a path.

    Raises
    ------
    ParameterError
        When ``folder`` is not a folder (one line naming it).

    Examples
    --------
    >>> models_folder(".").is_dir()
    True
    """
    path = Path(folder)
    if not path.is_dir():
        raise ParameterError(f"{os.fspath(folder)}: folder of real models not found (give --models DIR)")
    return path


def add_models_argument(parser: argparse.ArgumentParser) -> None:
    """The ``--models DIR`` option of the benchmarks that read real models."""
    parser.add_argument(
        "--models",
        metavar="DIR",
        dest="models_dir",
        default=DEFAULT_MODELS,
        help=f"folder of the real models (default {DEFAULT_MODELS}, relative to the current folder)",
    )
