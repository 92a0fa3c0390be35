"""The unit of work of a batch (:class:`FileTask`), its summary row and the statuses."""

from __future__ import annotations

from dataclasses import dataclass, field

#: operations a batch can run
OPERATIONS = ("orient", "remove-interior", "layers")
#: the per-file operation: ``module:function`` called as ``f(op, soup, options, progress) -> report``
DEFAULT_RUNNER = "meshvis.repair.operation:run_operation"
#: columns of a summary row, in the order of ``summary.csv``
COLUMNS = (
    "input",
    "status",
    "error",
    "faces_in",
    "faces_out",
    "rays",
    "seconds",
    "output",
    "report",
    "warnings",
)
#: statuses of a summary row; the first two count as success
OK, SKIPPED, ERROR, TIMEOUT, CRASHED, INTERRUPTED, NOT_RUN = (
    "ok",
    "skipped",
    "error",
    "timeout",
    "crashed",
    "interrupted",
    "not run",
)
SUCCESS = (OK, SKIPPED)


# ------------------------------------------------------------------------------- tasks
@dataclass
class FileTask:
    """One file of a batch.

    Attributes
    ----------
    input : str
        Path of the model file.
    name : str
        Output name without operation and extension (relative to the output folder).
    output, report : str
        Paths of the output model and of its JSON report.
    op : str
        One of :data:`OPERATIONS`.
    options : dict
        Algorithm options (``seed``, ``rays_per_node``, ...: the ``dest`` names of
        the command-line options); the others keep the defaults of ``meshvis <op>``
    runner : str
        ``module:function`` performing the operation (see :data:`DEFAULT_RUNNER`).
    """

    input: str
    name: str
    output: str
    report: str
    op: str
    options: dict = field(default_factory=dict)
    runner: str = DEFAULT_RUNNER


@dataclass
class BatchResult:
    """Rows of a batch in task order, its wall time, and whether it was interrupted."""

    rows: list[dict]
    seconds: float
    interrupted: bool = False

    @property
    def counts(self) -> dict[str, int]:
        """Number of rows per status."""
        out: dict[str, int] = {}
        for r in self.rows:
            out[r["status"]] = out.get(r["status"], 0) + 1
        return out

    @property
    def ok(self) -> bool:
        """True when every file succeeded (or was skipped as already done)."""
        return not self.interrupted and all(r["status"] in SUCCESS for r in self.rows)


def empty_row(task: FileTask, status: str = NOT_RUN, error: str = "") -> dict:
    """A summary row for ``task`` with nothing measured yet."""
    return {
        "input": task.input,
        "status": status,
        "error": error,
        "faces_in": None,
        "faces_out": None,
        "rays": None,
        "seconds": None,
        "output": task.output,
        "report": task.report,
        "warnings": "",
    }
