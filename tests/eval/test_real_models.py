"""The benchmarks read real models from an explicit folder (``--models DIR``)."""

from __future__ import annotations

import pytest

from meshvis.errors import ParameterError
from meshvis.eval.bench import cases as C
from meshvis.eval.bench import labeling_sweep
from meshvis.eval.bench.real_models import DEFAULT_MODELS, models_folder


def test_default_is_relative_to_the_current_folder():
    assert DEFAULT_MODELS.replace("\\", "/") == "../shared/models/real"


def test_missing_folder_is_a_one_line_error(tmp_path):
    missing = tmp_path / "nowhere"
    with pytest.raises(ParameterError, match="nowhere: folder of real models not found") as info:
        models_folder(missing)
    assert "\n" not in str(info.value)
    with pytest.raises(ParameterError):
        labeling_sweep.default_models(missing)
    with pytest.raises(ParameterError):
        list(C.built_cases([C.CASES["sphere_pair"], C.CASES["cow"]], [], lambda *a: None, missing))


def test_missing_file_in_a_folder_skips_its_case(tmp_path):
    skipped: list[str] = []
    assert list(C.built_cases([C.CASES["cow"]], skipped, lambda *a: None, tmp_path)) == []
    assert skipped and skipped[0].startswith("cow: skipped")


def test_cli_names_the_missing_folder(tmp_path, capsys):
    from meshvis.cli.main import main

    assert main(["bench", "labeling-sweep", "--models", str(tmp_path / "nowhere")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("meshvis: error:") and "nowhere" in err and len(err.splitlines()) == 1


def test_labeling_default_model_is_the_repository_assembly():
    import os

    from meshvis.eval.bench.labeling import default_model

    soup, name = default_model()
    assert name.endswith(os.path.join("models", "assembly.obj")) and soup.n_parts == 36
