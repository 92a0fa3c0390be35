"""Tuples, lists and dictionaries of named constants read from a module's source."""

from __future__ import annotations

import sys

from meshvis._defaults import UNRESOLVED, module_constant


def test_containers_of_names_are_read_without_importing(tmp_path, monkeypatch):
    (tmp_path / "meshvis_probe_box.py").write_text(
        "import math\nWEST, EAST = 0, 1\nPAIR = (WEST, EAST)\nNAMES = ['a', WEST]\n"
        "TABLE = {'left': (WEST,), 'both': PAIR}\nLOOSE = {'x': math.pi}\n"
        "SPREAD = {**TABLE}\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    read = {name: module_constant(f"meshvis_probe_box:{name}") for name in ("EAST", "PAIR", "NAMES", "TABLE")}
    assert read == {"EAST": 1, "PAIR": (0, 1), "NAMES": ["a", 0], "TABLE": {"left": (0,), "both": (0, 1)}}
    assert type(read["PAIR"]) is tuple and type(read["NAMES"]) is list
    assert "meshvis_probe_box" not in sys.modules  # all of it from the source
    from meshvis import _defaults

    for name in ("LOOSE", "SPREAD"):  # another package's constant, a ``**`` entry
        assert _defaults._constant("meshvis_probe_box", name, _defaults.MAX_HOPS) is UNRESOLVED


def test_the_layouts_table_is_the_librarys():
    from meshvis._defaults import _constant

    layouts = _constant("meshvis.labeling.candidates", "LAYOUTS", 8)
    from meshvis.labeling.candidates import LAYOUTS

    assert layouts == LAYOUTS
