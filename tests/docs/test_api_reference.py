"""The API reference renders every documented parameter and attribute with a description.

mkdocstrings reads numpydoc: ``name : type`` on one line, the description indented under
it.  A one-line entry ``name : (m,) bool, faces turned over`` puts the whole text in the
type column, where it renders as code with an empty description.  This test parses the
docstrings of every module the reference pages show (``::: module`` in ``docs/api/``) the
way mkdocstrings does (griffe) and fails on such entries.
"""

from __future__ import annotations

import os
import re

import pytest
from markdown_pages import DOCS, ROOT

griffe = pytest.importorskip("griffe", reason="the docs extra (mkdocstrings) brings griffe")

#: folders installed under other names (pyproject's package-dir), as mkdocs_hooks.py maps them
MAPPED = {"labeling": ROOT / "labeling", "cli": ROOT / "cli"}
ENTRY_SECTIONS = {"parameters", "other parameters", "attributes"}
#: words a type may start with (``int``, ``list of Label``, ``callable, optional`` ...)
TYPE_WORDS = {
    "int",
    "float",
    "str",
    "bool",
    "bytes",
    "dict",
    "list",
    "tuple",
    "set",
    "callable",
    "sequence",
    "mapping",
    "iterable",
    "optional",
    "array",
    "ndarray",
    "path",
    "none",
    "anything",
    "or",
    "object",
    "file",
    "structured",
    "trimesh",
    "numpy",
}
RESULT_SECTIONS = {"returns", "yields", "receives"}


def shown_modules() -> list[tuple[str, bool]]:
    """(module, with its members) of every ``::: module`` directive of the reference pages."""
    found = []
    for page in sorted((DOCS / "api").glob("*.md")):
        text = page.read_text()
        for match in re.finditer(r"^::: ([\w.]+)\n((?:\s{4}.*\n)*)", text, re.M):
            found.append((match[1], "members: false" not in match[2]))
    return found


@pytest.fixture(scope="module")
def loader(tmp_path_factory):
    """A griffe loader that finds the meshvis package in its installed layout."""
    tree = tmp_path_factory.mktemp("api")
    (tree / "meshvis").mkdir()
    for entry in (ROOT / "meshvis").iterdir():
        if entry.name != "__pycache__":
            os.symlink(entry, tree / "meshvis" / entry.name)
    for name, folder in MAPPED.items():
        os.symlink(folder, tree / "meshvis" / name)
    return griffe.GriffeLoader(docstring_parser=griffe.Parser.numpy, search_paths=[str(tree)])


def documented(obj, members: bool):
    """The object and, with ``members``, its public members as the reference shows them.

    Submodules are not shown (mkdocstrings' default); names a package re-exports in its
    ``__all__`` are shown where the package is.
    """
    yield obj
    if not members:
        return
    for name, member in obj.members.items():
        if name.startswith("_"):
            continue
        if member.is_alias:
            try:
                if not member.is_public:
                    continue
                member = member.final_target
            except griffe.AliasResolutionError:  # outside the package (``annotations``)
                continue
        if not member.is_module:
            yield from documented(member, member.is_class)


def looks_like_prose(annotation: str) -> bool:
    """A type column holding a sentence: ``(m,) bool, faces turned over``, ``the model``."""
    text = re.sub(r"`[^`]*`|\([^()]*\)|\[[^\]]*\]|\{[^}]*\}|\"[^\"]*\"|'[^']*'", "X", annotation)
    if ";" in text or ": " in text or re.search(r"\b(the|of the|to|when|for|per)\b", text):
        return True
    after_comma = re.search(r",\s+([a-z]\w*)\b(?!\.)", text)
    if after_comma and after_comma[1] not in TYPE_WORDS:
        return True
    first = re.match(r"([a-z][\w]*)\b(?!\.)", text)
    return bool(first and first[1] not in TYPE_WORDS)


def bad_entries(obj) -> list[str]:
    """Entries of the object's docstring whose description is missing (text in the type)."""
    if not obj.docstring:
        return []
    bad = []
    sections = obj.docstring.parse(griffe.Parser.numpy, warn_unknown_params=False)
    for section in sections:
        kind = section.kind.value
        if kind not in ENTRY_SECTIONS | RESULT_SECTIONS:
            continue
        for item in section.value:
            description = (getattr(item, "description", "") or "").strip()
            annotation = str(getattr(item, "annotation", "") or "")
            if description and not looks_like_prose(annotation):
                continue
            if kind in ENTRY_SECTIONS or looks_like_prose(annotation):
                bad.append(f"{obj.path}: {kind} {getattr(item, 'name', '') or annotation!r}: {annotation!r}")
    return bad


def test_the_reference_shows_modules():
    assert len(shown_modules()) >= 20


def test_every_entry_has_a_description(loader):
    loader.load("meshvis", try_relative_path=False)  # the package once, every submodule with it
    loaded = [(loader.modules_collection[module], members) for module, members in shown_modules()]
    loader.resolve_aliases(implicit=False, external=False)
    bad = []
    for module, members in loaded:
        for item in documented(module, members):
            bad.extend(bad_entries(item))
    assert not bad, f"{len(bad)} docstring entries render their text as a type:\n" + "\n".join(bad)
