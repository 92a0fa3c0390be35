"""Shared by the examples: where the bundled models are and where the outputs go."""

from __future__ import annotations

import os
import sys
import tempfile

#: the sample models of the repository (models/README.md)
MODELS = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "models")


def output_folder() -> str:
    """The folder named on the command line (created if missing), or a new temporary one."""
    if len(sys.argv) > 1:
        os.makedirs(sys.argv[1], exist_ok=True)
        return sys.argv[1]
    return tempfile.mkdtemp(prefix="meshvis-example-")


def model(name: str) -> str:
    """Path of a bundled model, e.g. ``model("cup.obj")``."""
    return os.path.normpath(os.path.join(MODELS, name))
