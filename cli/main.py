"""Entry point of the ``meshvis`` command.

Each subcommand lives in its own module of this package with two functions:
``add_parser(subparsers)`` and ``run(args) -> int``.  User errors (:class:`MeshvisError`)
print one line and exit with status 2, as do refused file operations (``OSError``: disk
full, I/O error); warnings print as one line; Ctrl-C exits with 130 and SIGTERM with 143,
both after removing temporary files (:mod:`.signals`).
"""

from __future__ import annotations

import argparse
import gc
import importlib
import sys
import warnings
from typing import NoReturn

# subcommand name -> module in this package
COMMANDS = {
    "demo": "meshvis.cli.cmd_demo",
    "info": "meshvis.cli.cmd_info",
    "render": "meshvis.cli.cmd_render",
    "classify": "meshvis.cli.cmd_repair",
    "orient": "meshvis.cli.cmd_repair",
    "remove-interior": "meshvis.cli.cmd_repair",
    "layers": "meshvis.cli.cmd_repair",
    "visible": "meshvis.cli.cmd_visible",
    "pvs": "meshvis.cli.cmd_pvs",
    "label": "meshvis.cli.cmd_label",
    "view": "meshvis.cli.cmd_view",
    "batch": "meshvis.cli.cmd_batch",
    "bench": "meshvis.cli.cmd_bench",
}


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """Build the ``meshvis`` argument parser with one subcommand per module of :data:`COMMANDS`.

    Every subcommand module adds its parser through its ``add_parser(subparsers)``; a module
    that is not there at all is left out, so the other commands still work.

    Parameters
    ----------
    command : str, optional
        A name of :data:`COMMANDS`: add only the parser of its module (importing every
        module, labeling and the benchmarks included, takes about half a second, which a
        command that runs in seconds should not pay); any other name adds none.  Default:
        every command.

    Returns
    -------
    argparse.ArgumentParser
        The parser; a parsed subcommand sets ``func``, the handler called with the namespace.

    Raises
    ------
    ModuleNotFoundError
        A subcommand module imports a module that is missing (the module itself being
        missing is not an error).
    """
    from meshvis._version import __version__

    from .common import Parser

    parser = Parser(prog="meshvis", description="Visibility questions about real, broken 3D models.")
    parser.add_argument("--version", action="version", version=f"meshvis {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    seen = set()
    for name, module in COMMANDS.items():
        if module in seen or (command is not None and name != command):
            continue
        try:
            mod = importlib.import_module(module)
        except ModuleNotFoundError as exc:  # a command not written yet
            if exc.name == module:
                continue
            raise
        seen.add(module)
        mod.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the ``meshvis`` command and turn its failures into an exit status.

    Errors of the user (:class:`~meshvis.errors.MeshvisError`, a refused file operation)
    print one line on standard error; warnings print as one line without source location.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program name; default ``sys.argv[1:]``.

    Returns
    -------
    int
        The handler's exit status (0 on success; ``meshvis batch`` returns 1 when a file
        failed); 2 without a subcommand (the help is printed), for a ``MeshvisError`` or an
        ``OSError``; 130 after Ctrl-C; 143 after SIGTERM; 0 when the reader of standard
        output closed the pipe.

    Raises
    ------
    SystemExit
        From argparse: status 0 after ``--help`` or ``--version``, 2 for bad arguments.
    """
    from meshvis.errors import MeshvisError

    argv = sys.argv[1:] if argv is None else list(argv)
    # a file name that is not UTF-8 must not stop a message about it: print such bytes escaped
    if getattr(sys.stdout, "errors", None) == "strict" and hasattr(sys.stdout, "reconfigure"):
        sys.stdout.reconfigure(errors="backslashreplace")
    # the top level has only -h and --version, so a command is the first argument; the
    # version needs no subcommand (building them all imports labeling and the kernels)
    first = argv[0] if argv else None
    parser = build_parser(first if first in COMMANDS or first == "--version" else None)
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    from .signals import TERMINATED_STATUS, Terminated, sigterm_stops

    try:
        with warnings.catch_warnings(), sigterm_stops():
            warnings.showwarning = _show_warning
            return int(args.func(args) or 0)
    except MeshvisError as exc:
        print(f"meshvis: error: {exc}", file=sys.stderr)
        return 2
    except Terminated:
        print("meshvis: terminated", file=sys.stderr)
        return TERMINATED_STATUS
    except KeyboardInterrupt:
        print("meshvis: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    except OSError as exc:  # the system refused a file operation (disk full, I/O error): a user error
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"meshvis: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2


def program() -> NoReturn:
    """The ``meshvis`` program (``python -m meshvis`` and the installed command): :func:`main`, then exit.

    The interpreter's exit runs a last collection over every object still alive; after a
    compiled kernel has been called, numba's run-time holds hundreds of thousands of them,
    and that collection costs about 0.3 CPU seconds, a third of ``meshvis info`` on a small
    model.  They are moved out of its reach (:func:`gc.freeze`) once the command is done:
    the process is ending and its memory goes back to the system anyway.  Files, atexit
    handlers and standard output are closed and flushed as on any exit.

    Raises
    ------
    SystemExit
        Always, with the status of :func:`main`.
    """
    try:
        status = main()
    finally:
        gc.freeze()
    raise SystemExit(status)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Warnings about the input (skipped records, ...) as one line, without source location."""
    print(f"meshvis: warning: {message}", file=sys.stderr)


if __name__ == "__main__":
    program()
