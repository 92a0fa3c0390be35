"""MkDocs hook: let mkdocstrings see the installed layout of the package.

``labeling/`` and ``cli/`` are installed as ``meshvis.labeling`` and ``meshvis.cli``
(pyproject's package-dir), but griffe reads packages from folders and finds
``meshvis/labeling`` in neither the source tree nor an editable install.  Before the build
this hook puts a folder of symbolic links shaped like the installed package at the front
of ``sys.path``: ``meshvis/*`` from the source tree, plus ``meshvis/labeling`` and
``meshvis/cli``.
"""

from __future__ import annotations

import ast
import atexit
import os
import re
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent
MAPPED = {"labeling": ROOT / "labeling", "cli": ROOT / "cli"}


def on_startup(command: str, dirty: bool) -> None:
    """Build the link tree once per mkdocs run."""
    tree = Path(tempfile.mkdtemp(prefix="meshvis-docs-"))
    atexit.register(shutil.rmtree, tree, ignore_errors=True)
    package = tree / "meshvis"
    package.mkdir()
    for entry in (ROOT / "meshvis").iterdir():
        if entry.name != "__pycache__":
            os.symlink(entry, package / entry.name)
    for name, folder in MAPPED.items():
        os.symlink(folder, package / name)
    sys.path.insert(0, str(tree))


# Sphinx roles in docstrings (:func:`meshvis.load`) are not Markdown: as prose they reach
# the page as ":func:" followed by a code span, and inside a code span (a parameter type)
# they stay literal.  Prose roles become optional cross-references, which mkdocs-autorefs
# turns into links where the target is rendered and into plain code where it is not.
ROLE = r":(?:py:)?(?:func|class|meth|mod|attr|data|obj|exc|const):"
PROSE_ROLE = re.compile(ROLE + r"<code>~?([\w.]+)(?:\(\))?</code>")
LITERAL_ROLE = re.compile(ROLE + r"`~?([^`]+)`")


def _public_names() -> dict[str, str]:
    """``meshvis.NAME`` -> the defining module's path, from the package's lazy table."""
    tree = ast.parse((ROOT / "meshvis" / "__init__.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", None) == "_LAZY":
            table = ast.literal_eval(node.value)
            return {f"meshvis.{name}": f"{module}.{name}" for name, module in table.items()}
    return {}


PUBLIC = _public_names()


def _autoref(match: re.Match[str]) -> str:
    name = match.group(1)
    target = PUBLIC.get(name, name)
    return f'<autoref identifier="{target}" optional><code>{name}</code></autoref>'


def on_page_content(html: str, page: object, config: object, files: object) -> str:
    """Render the Sphinx roles of docstrings as cross-references or plain names."""
    html = PROSE_ROLE.sub(_autoref, html)
    return LITERAL_ROLE.sub(r"\1", html)
