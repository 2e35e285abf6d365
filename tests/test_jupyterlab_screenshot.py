"""tools/jupyterlab_screenshot.py without a browser: the options it gives JupyterLab exist, the settings it writes are
the ones JupyterLab reads (autosave off), Chromium starts headless with a new, empty profile, and a folder that is
no project is refused before anything starts. (Taking the screenshot needs Chromium and a project with data: the
script's docstring says how; the notebooks themselves run in JupyterLab in tests/test_notebooks.py.)"""

import importlib.util
import sys
from pathlib import Path

import pytest

from repository import ROOT

spec = importlib.util.spec_from_file_location("jupyterlab_screenshot", ROOT / "tools" / "jupyterlab_screenshot.py")
screenshot = importlib.util.module_from_spec(spec)
spec.loader.exec_module(screenshot)
LAB = Path(sys.prefix) / "share" / "jupyter" / "lab"  # JupyterLab's application folder in the venv


def test_every_option_given_to_jupyterlab_is_a_trait_it_has(tmp_path):
    # JupyterLab imported here, not at collection: 0.8 s of every test process, most of which never run this module
    from jupyter_server.auth.identity import IdentityProvider
    from jupyter_server.serverapp import ServerApp
    from jupyterlab.labapp import LabApp

    command = screenshot.lab_command(tmp_path, "t0ken")
    assert command[:3] == [str(Path(sys.executable).parent / "jupyter"), "lab", "--no-browser"]
    classes = {"ServerApp": ServerApp, "IdentityProvider": IdentityProvider, "LabApp": LabApp}
    options = [arg[2:].split("=", 1)[0] for arg in command if arg.startswith("--") and "." in arg.split("=")[0]]
    assert len(options) == 5
    for option in options:  # JupyterLab warns of an unknown option and goes on without it
        owner, trait = option.split(".")
        assert trait in classes[owner].class_trait_names(config=True), option
    assert "--ServerApp.ip=127.0.0.1" in command and "--LabApp.expose_app_in_browser=True" in command


def test_the_settings_written_are_the_ones_jupyterlab_reads(tmp_path):
    from jupyterlab_server.settings_utils import get_settings

    folder = screenshot.write_lab_settings(tmp_path)
    for plugin, values in screenshot.LAB_SETTINGS.items():
        found, problems = get_settings(str(LAB / "settings"), str(LAB / "schemas"), str(folder), schema_name=plugin)
        assert found["settings"] == values and not any(problems), (plugin, problems)  # valid against its schema
    assert screenshot.LAB_SETTINGS["@jupyterlab/docmanager-extension:plugin"] == {"autosave": False}


def test_chromium_starts_headless_with_a_new_empty_profile_and_a_devtools_port_of_its_choice(tmp_path):
    command = screenshot.chromium_command("chromium", tmp_path / "profile", 1440, 1000)
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--remote-debugging-port=0", f"--user-data-dir={tmp_path / 'profile'}"):
        assert flag in command
    assert not (tmp_path / "profile").exists()  # Chromium creates it: nothing of another profile in it
    assert screenshot.devtools_port(tmp_path / "profile") is None
    (tmp_path / "profile").mkdir()
    (tmp_path / "profile" / "DevToolsActivePort").write_text("40123\n/devtools/browser/abc\n")  # as Chromium writes
    assert screenshot.devtools_port(tmp_path / "profile") == 40123


def test_a_folder_that_is_no_project_is_refused_before_anything_starts(tmp_path):
    with pytest.raises(SystemExit, match="no dvc.yaml or no notebooks/03_fit_artifact_models.ipynb there"):
        screenshot.main([str(tmp_path), "--out", str(tmp_path / "lab.png")])
    assert not (tmp_path / "lab.png").exists()
