"""The user documentation as the doc tests see it: pages, fenced blocks, links, headings.

Every ``*.md`` under ``docs/`` and the README are pages, so a page added later is checked
without registering it.  A fenced block is skipped by the tests when the line before its
opening fence is an HTML comment ``<!-- test: skip (why) -->``; the comment does not show on
the rendered page.
"""

from __future__ import annotations

import re
import unicodedata
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = ROOT / "README.md"
#: fenced-block languages whose blocks the tests run as Python, and read as shell commands
PYTHON = {"python", "py"}
SHELL = {"sh", "bash", "shell", "console"}
SKIP = re.compile(r"<!--\s*test:\s*skip\b")
FENCE = re.compile(r"^(?P<indent>\s*)(?P<fence>`{3,}|~{3,})\s*(?P<lang>[\w+-]*)")


@dataclass
class Block:
    """A fenced block of a page: its language, first line of content (1-based) and text."""

    page: Path
    lang: str
    line: int
    text: str
    skip: bool

    def where(self) -> str:
        """``page:line``, relative to the repository, for failure messages."""
        return f"{self.page.relative_to(ROOT)}:{self.line}"


def pages() -> list[Path]:
    """Every page: the README and each Markdown file under docs/, in a fixed order."""
    return [README, *sorted(DOCS.rglob("*.md"))]


def page_id(page: Path) -> str:
    """The page's path relative to the repository (a readable test id)."""
    return str(page.relative_to(ROOT))


def blocks(page: Path) -> list[Block]:
    """The fenced blocks of ``page``, their content dedented by the opening fence's indent."""
    lines = page.read_text(encoding="utf-8").splitlines()
    found: list[Block] = []
    i = 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if not opening:
            i += 1
            continue
        indent, fence = len(opening["indent"]), opening["fence"]
        previous = next((line for line in reversed(lines[:i]) if line.strip()), "")
        body: list[str] = []
        j = i + 1
        while j < len(lines) and not lines[j].strip().startswith(fence):
            body.append(lines[j][indent:] if lines[j][:indent].strip() == "" else lines[j])
            j += 1
        found.append(
            Block(page, opening["lang"].lower(), i + 2, "\n".join(body) + "\n", bool(SKIP.search(previous)))
        )
        i = j + 1
    return found


def outside_fences(page: Path) -> list[str]:
    """The page's lines, those of fenced blocks (fences included) blanked."""
    kept: list[str] = []
    inside = None
    for line in page.read_text(encoding="utf-8").splitlines():
        opening = FENCE.match(line)
        if inside is None and opening:
            inside = opening["fence"]
            kept.append("")
        elif inside is not None:
            if line.strip().startswith(inside):
                inside = None
            kept.append("")
        else:
            kept.append(line)
    return kept


def prose(page: Path) -> str:
    """The page without its fenced blocks and inline code spans (links live only in prose)."""
    return "\n".join(re.sub(r"`[^`]*`", "``", line) for line in outside_fences(page))


def slug(heading: str) -> str:
    """The anchor MkDocs (Python-Markdown's toc) gives a heading's text."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link reads as its text
    text = re.sub(r"[`*]", "", text)
    text = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode("ascii")
    text = re.sub(r"[^\w\s-]", "", text).strip().lower()
    return re.sub(r"[-\s]+", "-", text)


def anchors(page: Path) -> set[str]:
    """The anchors of the page's headings (duplicates numbered ``_1``, ``_2`` as toc does)."""
    seen: dict[str, int] = {}
    out: set[str] = set()
    for line in outside_fences(page):
        heading = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if heading:
            name = slug(heading[1])
            count = seen.get(name, 0)
            out.add(name if count == 0 else f"{name}_{count}")
            seen[name] = count + 1
    return out


def links(page: Path) -> list[tuple[int, str]]:
    """``(line, target)`` of every Markdown link and image of the page's prose."""
    found = []
    for number, line in enumerate(prose(page).splitlines(), 1):
        for target in re.findall(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)", line):
            found.append((number, target))
    return found
