"""The packages resolve their names on first use (lazy_loader): every exported name must resolve, and reading
params.yaml must not import the heavy modules a stage may not need."""

import importlib
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ["poseintegrity.artifact_models", "poseintegrity.localization", "poseintegrity.prediction",
            "poseintegrity.tracking"]


@pytest.mark.parametrize("name", PACKAGES)
def test_every_exported_name_resolves_to_its_module(name):
    package = importlib.import_module(name)
    for attribute in package.__all__:
        value = getattr(package, attribute)
        module = getattr(value, "__module__", None)
        assert module is None or module.startswith(name), f"{name}.{attribute} comes from {module}"
    assert set(package.__all__) <= set(dir(package))
    with pytest.raises(AttributeError):
        package.no_such_name


def test_loading_params_does_not_import_torch_or_the_stage_code():
    code = ("import sys; from poseintegrity.config import load_params; load_params('params.yaml'); "
            "print(sorted(m for m in ('torch', 'poseintegrity.tracking.filter.srukf', "
            "'poseintegrity.localization.extract', 'poseintegrity.prediction.sweeps') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=ROOT)
    assert out.stdout.strip() == "[]"


def test_the_stage_runner_skips_the_slow_iri_grammar():
    """papermill and nbconvert as run_stage imports them, after poseintegrity.stage."""
    out = subprocess.run([sys.executable, "-c", "import sys, poseintegrity.stage, papermill, nbconvert; print("
                          "'rfc3987_syntax' in sys.modules and sys.modules['rfc3987_syntax'] is not None)"],
                         capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
