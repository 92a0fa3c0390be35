"""Every Python block of the docs and the README runs, and every command line parses.

Each page's Python blocks run in order in one namespace (a later block may use what an
earlier one made), as a script would (``__name__ == "__main__"``), in a fresh folder where
``models/`` is the repository's sample models: a block reads ``models/...`` and writes
where it likes.  The README's shell commands run in such a folder too.  Command lines of
the other pages (benchmarks that take minutes, clusters, files the reader has) are parsed
by the ``meshvis`` parser instead, so a renamed option or subcommand fails here.
"""

from __future__ import annotations

import contextlib
import io
import os
import shlex
import subprocess
import sys
import traceback
from pathlib import Path

import pytest
from markdown_pages import PYTHON, README, ROOT, SHELL, Block, blocks, page_id, pages

from meshvis.cli.main import build_parser

PAGES_WITH_PYTHON = [p for p in pages() if any(b.lang in PYTHON and not b.skip for b in blocks(p))]


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    """A fresh current folder holding ``models/``, a link to the sample models."""
    os.symlink(ROOT / "models", tmp_path / "models")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def run_python_blocks(page: Path) -> int:
    """Run the page's Python blocks in order in one namespace; fail naming the block."""
    namespace: dict = {"__name__": "__main__"}
    ran = 0
    for block in blocks(page):
        if block.lang not in PYTHON or block.skip:
            continue
        code = compile(block.text, block.where(), "exec")
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                exec(code, namespace)
        except Exception:  # noqa: BLE001 - report which block failed, with its traceback
            pytest.fail(f"the Python block at {block.where()} fails:\n{traceback.format_exc()}")
        ran += 1
    return ran


@pytest.mark.slow
@pytest.mark.parametrize("page", PAGES_WITH_PYTHON, ids=page_id)
def test_python_blocks_run(page, workdir):
    assert run_python_blocks(page) > 0


def readme_commands() -> list[tuple[str, str]]:
    """(where, command) of every line of the README's shell blocks not marked to skip."""
    found = []
    for block in blocks(README):
        if block.lang in SHELL and not block.skip:
            for offset, line in enumerate(block.text.splitlines()):
                command = line.split(" #")[0].strip()
                if command and not command.startswith("#"):
                    found.append((f"README.md:{block.line + offset}", command))
    return found


@pytest.mark.slow
def test_readme_commands_run(workdir):
    env = {**os.environ, "PATH": os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", "")}
    commands = readme_commands()
    assert any(command.startswith("meshvis demo") for _, command in commands)
    for where, command in commands:
        run = subprocess.run(
            command, shell=True, cwd=workdir, env=env, capture_output=True, text=True, timeout=600
        )
        assert run.returncode == 0, f"{where}: `{command}` exited with {run.returncode}:\n{run.stderr}"


def command_lines() -> list[tuple[str, list[str]]]:
    """(where, arguments after ``meshvis``) of every ``meshvis ...`` line of every shell block."""
    found = []
    for page in pages():
        for block in blocks(page):
            if block.lang not in SHELL:
                continue
            lines = block.text.replace("\\\n", " ").splitlines()
            for offset, line in enumerate(lines):
                words = shlex.split(line, comments=True)
                if words[:1] == ["$"]:
                    words = words[1:]
                if words[:1] == ["meshvis"]:
                    found.append((f"{page_id(page)}:{block.line + offset}", words[1:]))
    return found


def test_the_docs_show_commands():
    assert len(command_lines()) >= 30


@pytest.mark.parametrize("where, argv", command_lines(), ids=[w for w, _ in command_lines()])
def test_command_line_parses(where, argv):
    parser = build_parser(argv[0] if argv else None)
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr):
        try:
            args = parser.parse_args(argv)
        except SystemExit as stop:
            assert stop.code == 0, f"{where}: meshvis {shlex.join(argv)}\n{stderr.getvalue()}"
            return
    assert getattr(args, "func", None) is not None, f"{where}: meshvis {shlex.join(argv)} names no command"


def test_blocks_are_found_with_their_lines_and_skip_marks(tmp_path):
    page = tmp_path / "page.md"
    page.write_text(
        "# t\n\n```python\nx = 1\n```\n\n<!-- test: skip (why) -->\n```python\nraise SystemError\n```\n\n"
        "1. a step:\n\n   ```sh\n   meshvis info m.obj\n   ```\n"
    )
    found = blocks(page)
    assert [(b.lang, b.line, b.skip) for b in found] == [
        ("python", 4, False),
        ("python", 9, True),
        ("sh", 15, False),
    ]
    assert found[2].text == "meshvis info m.obj\n"


def test_a_failing_block_fails_its_page_naming_the_block(tmp_path, monkeypatch):
    page = tmp_path / "page.md"
    page.write_text("```python\nx = 1\n```\n\n```python\nprint(x + undefined_name)\n```\n")
    monkeypatch.setattr(Block, "where", lambda self: f"page.md:{self.line}")
    with pytest.raises(pytest.fail.Exception, match="page.md:6"):
        run_python_blocks(page)
    page.write_text(
        "```python\nx = 1\n```\n\n<!-- test: skip -->\n```python\nprint(x + undefined_name)\n```\n"
    )
    assert run_python_blocks(page) == 1
