"""The JSON report of a repair command.

Its schema version, where it goes, and its per-face arrays either inline or in a ``.npz``
file.

The schema is documented as a JSON Schema in ``docs/report.schema.json``; :data:`SCHEMA_VERSION`
is the ``schema`` field of every report and changes whenever a field changes meaning.
"""

from __future__ import annotations

import io
import os
from typing import Any

import numpy as np

from meshvis.io._common import atomic_write
from meshvis.io.jsonfile import write_json

#: the ``schema`` field of every report (docs/report.schema.json)
SCHEMA_VERSION = 1


def write_report(report: dict, path: str, per_face: str | None = None) -> None:
    """Write a report as JSON to ``path`` (``"-"``: standard output).

    Parameters
    ----------
    report : dict
        The report; a ``per_face`` entry maps names to (m,) arrays.
    path : str
        A ``.json`` file, or ``"-"`` for standard output.
    per_face : str, optional
        A ``.npz`` file for the per-face arrays; the report then names the file and lists
        each array's dtype and length instead of holding the numbers.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> folder = tempfile.mkdtemp()
    >>> write_report({"per_face": {"keep": np.ones(3, bool)}}, os.path.join(folder, "r.json"),
    ...              per_face=os.path.join(folder, "r.npz"))
    >>> sorted(np.load(os.path.join(folder, "r.npz")))
    ['keep']
    """
    report = with_schema(report)
    arrays = report.get("per_face")
    if per_face is not None and isinstance(arrays, dict):
        arrays = {k: np.asarray(v) for k, v in arrays.items()}
        buf = io.BytesIO()
        np.savez_compressed(buf, **arrays)
        with atomic_write(per_face, "wb") as fh:
            fh.write(buf.getvalue())
        report["per_face"] = {
            "file": os.path.basename(per_face),
            "arrays": {k: {"dtype": str(v.dtype), "length": int(len(v))} for k, v in arrays.items()},
        }
    write_json(path, report)


def with_schema(report: dict[str, Any]) -> dict[str, Any]:
    """``report`` with its ``schema`` version first."""
    return {"schema": SCHEMA_VERSION, **{k: v for k, v in report.items() if k != "schema"}}
