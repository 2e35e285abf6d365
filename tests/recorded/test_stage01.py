"""``generate.source``: a folder of recorded datasets, which stage 01 materializes instead of rendering
(tests/recorded/test_dvc_repro.py runs it end to end); a source that is not a folder is refused naming the key."""

from __future__ import annotations

import pytest

from poseintegrity.config import ParamsError, load_params
from repository import ROOT


def overlay(tmp_path, source) -> str:
    path = tmp_path / "params.yaml"
    path.write_text(f"extends: {ROOT / 'tests' / 'params_tiny.yaml'}\ngenerate:\n  source: {source}\n")
    return str(path)


def test_a_source_that_is_not_a_folder_is_refused_naming_the_key(tmp_path):
    with pytest.raises(ParamsError, match="generate.source"):
        load_params(overlay(tmp_path, tmp_path / "no_such_folder"))
    assert load_params(overlay(tmp_path, tmp_path)).generate.source == tmp_path
