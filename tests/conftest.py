"""Suites that need Chromium, millions of faces or every shared model run only when asked for.

A test carrying one of the opt-in markers is left out unless the ``-m`` expression names that
marker, so ``pytest``, ``pytest -m "not slow"`` and ``pytest tests/cli`` all skip them, while
``pytest -m browser`` runs the browser suite.
"""

from __future__ import annotations

import re

OPT_IN_MARKERS = ("browser", "scale", "shared_models")


def pytest_collection_modifyitems(config, items):
    expression = config.getoption("markexpr") or ""
    asked = {m for m in OPT_IN_MARKERS if re.search(rf"\b{m}\b", expression)}
    kept, left_out = [], []
    for item in items:
        marks = {m.name for m in item.iter_markers()} & set(OPT_IN_MARKERS)
        (left_out if marks - asked else kept).append(item)
    if left_out:
        config.hook.pytest_deselected(items=left_out)
        items[:] = kept
