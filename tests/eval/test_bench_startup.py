"""``meshvis bench startup``: the start-up cost of ``meshvis info`` next to ``python -c pass``."""

from __future__ import annotations

import json

import pytest
from helpers import real_model

from meshvis.cli.main import main
from meshvis.eval.bench import startup


def test_the_table_says_met_or_missed():
    r = {
        "model": "m.stl",
        "load": 0.5,
        "repeat": 5,
        "median": {"python -c pass": 0.02, "meshvis --version": 0.03, "meshvis info MODEL": 0.62},
        "best": {"python -c pass": 0.02, "meshvis --version": 0.03, "meshvis info MODEL": 0.6},
        "over_python": {"python -c pass": 0.0, "meshvis --version": 0.01, "meshvis info MODEL": 0.6},
        "cpu_median": {"python -c pass": 0.02, "meshvis --version": 0.03, "meshvis info MODEL": 0.5},
        "steps_cpu": {"numpy": 0.08},
        "target": 0.5,
    }
    assert "0.600 s (target <= 0.5 s: missed)" in startup.format(r)
    r["over_python"]["meshvis info MODEL"] = 0.4
    assert "(target <= 0.5 s: met)" in startup.format(r)


@pytest.mark.slow
def test_bench_startup_runs(tmp_path, capsys):
    model = real_model("soup.stl")
    out = tmp_path / "s.json"
    assert main(["bench", "startup", model, "--repeat", "1", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "meshvis info MODEL" in text and "numba, first compiled kernel called" in text
    r = json.loads(out.read_text())
    assert r["median"]["meshvis info MODEL"] > r["median"]["python -c pass"] > 0
    assert main(["bench", "startup", "--kernels", model, "--repeat", "1", "--json", str(out)]) == 0
    assert "numba wall s" in capsys.readouterr().out
    row = json.loads(out.read_text())["rows"][0]
    assert row["faces"] == 100 and row["numba"]["cpu"] > 0 and row["numpy"]["cpu"] > 0
