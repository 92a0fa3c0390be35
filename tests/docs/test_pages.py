"""The docs' pages: links that lead somewhere, no history in them, within their size limits.

Links: every relative link and image of every page (the README included) must name a file
that exists, and an anchor a heading of the target page (API reference pages are generated,
so only the page is checked there; ``mkdocs build --strict`` checks their anchors).  No
network: links with a scheme (``https:``) are not followed.

History belongs in ``CHANGELOG.md`` and commit messages, so the docs (every text file under
``docs/``) and the README must not name issue numbers, commits or the work that led to a
figure.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from markdown_pages import DOCS, README, ROOT, anchors, links, outside_fences, page_id, pages, slug

#: at most this many files under docs/, and lines per page
MAX_FILES = 80
MAX_LINES = 600
#: raw outputs of the benchmark runs: pages, but not in the navigation
OUTPUTS = DOCS / "bench-output"
#: files under docs/ read as text by the history check
TEXT = {".md", ".txt", ".csv", ".json", ".py", ".yml", ".html"}
#: what a lab notebook says and user docs do not
HISTORY = {
    "an issue number": re.compile(r"\bissues?\s*#?\d+\b|(?<![\w&/#])#\d{1,5}(?!\w)", re.I),
    "a commit hash": re.compile(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}\b"),
    "a work-log phrase": re.compile(
        r"\b(this session|we tried|tried and (dropped|reverted)|(before|after) (the |this )?(commit|change)"
        r"|on the (final|earlier|previous|old) code|(earlier|previous) (versions?|code)\b"
        r"|used to be|no longer|rerun on|as before|was measured before)",
        re.I,
    ),
}


def test_every_link_leads_somewhere():
    broken = []
    for page in pages():
        for line, target in links(page):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # https:, mailto: -- no network
                continue
            path, _, anchor = target.partition("#")
            file = (page.parent / path).resolve() if path else page
            if not file.exists():
                broken.append(f"{page_id(page)}:{line}: {target} (no such file)")
            elif anchor and file.suffix == ".md" and DOCS / "api" not in file.parents:
                if anchor not in anchors(file):
                    broken.append(f"{page_id(page)}:{line}: {target} (no heading #{anchor})")
    assert not broken, "\n".join(broken)


def test_the_link_check_finds_a_missing_page_and_a_missing_heading(tmp_path):
    page = tmp_path / "a.md"
    page.write_text(
        "# Title\n\n## A `code` heading\n\n[x](b.md) [y](#a-code-heading) [z](#nope) `[w](c.md)`\n"
    )
    assert slug("A `code` heading") == "a-code-heading"
    assert anchors(page) == {"title", "a-code-heading"}
    assert [t for _, t in links(page)] == ["b.md", "#a-code-heading", "#nope"]


def history_in(text: str) -> list[str]:
    """What of :data:`HISTORY` the text holds, as ``"kind: match"``."""
    return [f"{kind}: {m.group(0)!r}" for kind, rule in HISTORY.items() for m in rule.finditer(text)]


def doc_files() -> list[Path]:
    return [README, *sorted(p for p in DOCS.rglob("*") if p.is_file() and p.suffix in TEXT)]


@pytest.mark.parametrize("path", doc_files(), ids=page_id)
def test_no_history_in_the_docs(path):
    found = [
        f"{page_id(path)}:{n}: {hit}"
        for n, line in enumerate(path.read_text().splitlines(), 1)
        for hit in history_in(line)
    ]
    assert not found, "history belongs in CHANGELOG.md and commit messages:\n" + "\n".join(found)


@pytest.mark.parametrize(
    "text",
    [
        "fixed in issue 14",
        "see #14 for details",
        "measured on 2bc867f",
        "the monastery on `d6df2dc`",
        "In this session the error fell",
        "we tried a sign test",
        "0.64 s before this change",
        "rerun on the final code",
        "an earlier version took 3 s",
        "it no longer leaks",
    ],
)
def test_the_history_check_finds(text):
    assert history_in(text)


@pytest.mark.parametrize(
    "text",
    [
        "colour #1f77b4 and #ffffff",
        "see [files](files.md#layers)",
        "1e-5 of the diagonal",
        "## Layers",
        "faced decade",
    ],
)
def test_the_history_check_leaves_alone(text):
    assert not history_in(text)


def test_docs_stay_small():
    files = [p for p in DOCS.rglob("*") if p.is_file()]
    assert len(files) <= MAX_FILES, f"{len(files)} files under docs/ (at most {MAX_FILES})"
    long = {page_id(p): n for p in DOCS.rglob("*.md") if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert not long, f"pages over {MAX_LINES} lines: {long}"


def test_every_page_is_in_the_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    listed = set(re.findall(r":\s*([\w/.-]+\.md)\s*$", nav, re.M))
    pages = {str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md") if OUTPUTS not in p.parents}
    missing = pages - listed
    assert not missing, f"pages missing from mkdocs.yml's nav: {sorted(missing)}"


def test_headings_are_not_in_fences_by_mistake():
    # an unclosed fence would hide the rest of a page from every check above
    for page in pages():
        text = page.read_text().splitlines()
        hidden = sum(1 for a, b in zip(text, outside_fences(page)) if a.startswith("## ") and b == "")
        assert hidden == 0, f"{page_id(page)}: {hidden} headings inside fenced blocks (a fence not closed?)"
