"""The summary of a batch: ``summary.csv`` and ``summary.json``."""

from __future__ import annotations

import csv
import io
import os

from meshvis.io import atomic_write

from .tasks import COLUMNS, BatchResult
from .work import _write_json


def write_summary(result: BatchResult, out_dir: str, meta: dict | None = None) -> tuple[str, str]:
    """Write ``summary.csv`` and ``summary.json`` into ``out_dir`` (atomically); return their paths.

    The CSV has one line per file with the columns :data:`COLUMNS`; the JSON has the same
    rows under ``"files"``, plus ``meta`` (operation, options, ...), the counts per status,
    the wall time and whether the batch was interrupted.
    """
    from meshvis._version import __version__

    csv_path = os.path.join(out_dir, "summary.csv")
    json_path = os.path.join(out_dir, "summary.json")
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(COLUMNS), extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for r in result.rows:
        writer.writerow({k: "" if r.get(k) is None else r.get(k) for k in COLUMNS})
    with atomic_write(csv_path, "w") as fh:
        fh.write(buf.getvalue())
    data = {
        "meshvis": __version__,
        **(meta or {}),
        "seconds_total": round(result.seconds, 3),
        "interrupted": result.interrupted,
        "counts": result.counts,
        "files": [{k: r.get(k) for k in COLUMNS} for r in result.rows],
    }
    _write_json(json_path, data)
    return csv_path, json_path
