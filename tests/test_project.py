"""The project's root, against which the notebooks' relative paths resolve wherever their kernel starts: the
project's own folder (the stage runner), notebooks/ (JupyterLab), a folder outside any project (a clear error); the
stage runner's paths, given relative to the current folder, reach the notebook as the same files."""

import json

import pytest

from poseintegrity import ArgumentError, PoseIntegrityError
from poseintegrity.project import ProjectError, project_paths, project_root
from poseintegrity.stage import notebook_parameter
from repository import ROOT

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
FIRST_LINE = "params_path, data_dir, reports_dir = stage_paths(params_path, data_dir, reports_dir)"


@pytest.fixture
def project(tmp_path):
    """A project (dvc.yaml at its root) with a notebooks/ folder, and a folder outside it."""
    (tmp_path / "project" / "notebooks").mkdir(parents=True)
    (tmp_path / "project" / "dvc.yaml").write_text("stages: {}\n")
    (tmp_path / "outside").mkdir()
    return tmp_path / "project"


def test_the_root_is_found_from_the_root_and_from_notebooks(project, monkeypatch):
    assert project_root(project) == project_root(project / "notebooks") == project
    for start in (project, project / "notebooks"):
        monkeypatch.chdir(start)  # where the stage runner, and JupyterLab, start the kernel
        assert project_paths("params.yaml", "data", "reports") == (project / "params.yaml", project / "data",
                                                                   project / "reports")
    assert project_root(ROOT / "notebooks") == ROOT  # the repository's own layout


def test_the_nearest_project_wins(project):
    inner = project / "studies" / "copy"
    (inner / "notebooks").mkdir(parents=True)
    (inner / "dvc.yaml").write_text("stages: {}\n")
    assert project_root(inner / "notebooks") == inner


def test_outside_any_project_the_error_names_the_folder_and_the_file_looked_for(project, monkeypatch):
    outside = project.parent / "outside"
    monkeypatch.chdir(outside)
    with pytest.raises(ProjectError) as error:
        project_paths("params.yaml", "data", "reports")
    assert isinstance(error.value, PoseIntegrityError)
    assert f"no dvc.yaml in {outside} or any folder above it" in str(error.value)
    assert "absolute paths" in str(error.value)  # what to do instead


def test_absolute_paths_need_no_project(project, monkeypatch):
    monkeypatch.chdir(project.parent / "outside")
    paths = (project / "params.yaml", project / "data", project / "reports")
    assert project_paths(*map(str, paths)) == paths  # papermill's injected absolute paths, as given


@pytest.mark.parametrize("bad", [None, 3, ["data"]])
def test_a_path_that_is_no_path_is_refused_naming_it(bad):
    with pytest.raises(ArgumentError, match=r"paths\[1\]: expected a path"):
        project_paths("params.yaml", bad)


def test_the_stage_runner_passes_what_the_notebook_resolves_to_the_same_file(project, monkeypatch):
    """Its command line's paths are relative to the current folder, the notebook's to the project's root."""
    monkeypatch.chdir(project)  # dvc repro: the injected parameters read as they did before the root was looked for
    assert [notebook_parameter(p) for p in ("params.yaml", "data", "reports")] == ["params.yaml", "data", "reports"]
    monkeypatch.chdir(project / "notebooks")
    assert notebook_parameter("../params.yaml") == "params.yaml"
    assert notebook_parameter("../../outside/data") == str(project.parent / "outside" / "data")
    monkeypatch.chdir(project.parent / "outside")  # no project: absolute, which the notebook takes as it is
    assert notebook_parameter("data") == str(project.parent / "outside" / "data")


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_every_notebook_imports_poseintegrity_first_and_resolves_its_parameters_before_using_them(notebook):
    """The first cell after the parameters (and papermill's injected ones) imports poseintegrity before anything
    else, so that it pins the CPU dispatch of numpy and the others before they load in a kernel JupyterLab started
    (dispatch.py; the stage runner's kernel inherits it), and resolves the three paths before any other line reads
    them."""
    code = [cell for cell in json.loads(notebook.read_text())["cells"] if cell["cell_type"] == "code"]
    lines = "".join(code[1]["source"]).splitlines()
    assert lines[0].startswith("from poseintegrity."), f"{notebook.name}: the first import is {lines[0]}"
    names = ("params_path", "data_dir", "reports_dir")
    uses = [i for i, line in enumerate(lines) if any(name in line for name in names)]
    assert uses and lines[uses[0]].startswith(FIRST_LINE), f"{notebook.name}: {lines[uses[0]] if uses else 'no use'}"


def test_a_notebook_run_outside_any_project_stops_at_its_first_cell_saying_why(project, monkeypatch):
    """Stage 07's first two cells, run as a kernel outside any project would run them: the ProjectError above, not
    a FileNotFoundError or a NameError further down."""
    code = [cell for cell in json.loads((ROOT / "notebooks" / "07_report.ipynb").read_text())["cells"]
            if cell["cell_type"] == "code"]
    monkeypatch.chdir(project.parent / "outside")
    namespace = {}
    exec("".join(code[0]["source"]), namespace)
    with pytest.raises(ProjectError, match="no dvc.yaml in .*outside or any folder above it"):
        exec("".join(code[1]["source"]), namespace)
