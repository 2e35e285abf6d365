"""The workflow's contracts: output-free notebooks with stable ids and a parameters cell, dvc stages run by the
stage runner that depend on data (never on executed notebooks), params sections validated by config, the two
README commands."""

import json
import tomllib
from pathlib import Path

import pytest
import yaml

from poseintegrity.config import Params, load_params
from repository import outside_references

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
DVC = yaml.safe_load((ROOT / "dvc.yaml").read_text())
POPULATION = yaml.safe_load((ROOT / "population" / "dvc.yaml").read_text())  # issue 49: `make population`


def notebook_stages() -> list[tuple[Path, str, dict]]:
    """(notebook, stage name, stage) of every stage that runs a notebook: the paper-scale pipeline's (named after its
    notebook) and the population's (a foreach stage's body; its commands name the notebooks they run)."""
    found = [(notebook, notebook.stem, DVC["stages"][notebook.stem]) for notebook in NOTEBOOKS
             if notebook.stem in DVC["stages"]]
    for name, stage in POPULATION["stages"].items():
        body = stage.get("do", stage)
        commands = body["cmd"] if isinstance(body["cmd"], list) else [body["cmd"]]
        found += [(notebook, f"population/dvc.yaml:{name}", body) for notebook in NOTEBOOKS
                  if any(f"notebooks/{notebook.name}" in command for command in commands)]
    return found


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_source_notebook_is_output_free_with_parameters_cell(notebook):
    nb = json.loads(notebook.read_text())
    cells = nb["cells"]
    for cell in cells:
        assert cell.get("outputs", []) == [], f"{notebook.name}: cell {cell.get('id')} carries outputs"
        assert cell.get("execution_count") is None, f"{notebook.name}: cell {cell.get('id')} has an execution count"
    ids = [cell.get("id") for cell in cells]
    assert all(ids) and len(set(ids)) == len(ids), "every cell needs a unique, stable id"
    assert not any(i.count("-") == 4 and len(i) == 36 for i in ids), "ids look random (uuid): keep readable ids"
    code = [c for c in cells if c["cell_type"] == "code"]
    assert "parameters" in code[0].get("metadata", {}).get("tags", [])
    source = "".join(code[0]["source"])
    for name in ("params_path", "data_dir", "reports_dir"):
        assert name in source
    assert nb["metadata"]["kernelspec"]["name"] == "python3"


def test_every_notebook_has_a_stage_running_it_through_the_stage_runner():
    """poseintegrity.stage writes the executed notebook, its HTML and a timing file, and reads `parallel`."""
    stages = DVC["stages"]
    for notebook in NOTEBOOKS:
        if notebook.stem not in stages:  # the population's (population/dvc.yaml)
            stage = next(stage for nb, name, stage in notebook_stages() if nb == notebook)
        else:
            stage = stages[notebook.stem]
        assert stage["cmd"].endswith(f"python -m poseintegrity.stage notebooks/{notebook.name}")
        assert f"notebooks/{notebook.name}" in stage["deps"]
        assert "parallel" in stage["params"]
        outs = [next(iter(out)) if isinstance(out, dict) else out for out in stage["outs"]]
        assert f"reports/notebooks/{notebook.name}" in outs and f"reports/notebooks/{notebook.stem}.html" in outs
        assert {f"reports/metrics/timing/{notebook.stem}.json": {"cache": False}} in stage["outs"]


def test_the_population_runs_the_paper_s_notebooks_on_each_world():
    """population/dvc.yaml: per world, stages 01, 02 and 04's notebooks on the world's params file, in its folder."""
    for name, notebook in (("generate", "01_generate_datasets"), ("extract", "02_extract_artifacts"),
                           ("predict", "04_predictor_sweeps")):
        stage = POPULATION["stages"][name]
        assert stage["foreach"] == "${population.worlds}" and stage["do"]["wdir"] == ".."
        command = " ".join(stage["do"]["cmd"]).split()
        at = command.index(f"notebooks/{notebook}.ipynb")
        assert command[at + 1:at + 7] == ["--params", "data/population/${item}/params.yaml", "--data",
                                          "data/population/${item}", "--reports", f"data/population/${{item}}/{name}"]
        assert "parallel" in stage["do"]["params"] and "population.worlds" not in stage["do"]["params"]


def _imported_modules(source: str, package: str = "") -> set[str]:
    """Modules of poseintegrity that ``source`` imports (absolute, or relative to ``package``), at any depth."""
    import ast

    def nodes(tree):  # every node, without the bodies of `if TYPE_CHECKING:` (annotations only, never run)
        for child in ast.iter_child_nodes(tree):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                yield from (n for orelse in child.orelse for n in [orelse, *nodes(orelse)])
                continue
            yield child
            yield from nodes(child)

    found = set()
    for node in nodes(ast.parse(source)):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names if alias.name.startswith("poseintegrity")}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1] + ([base] if base else []))
            if base.startswith("poseintegrity"):
                found |= {base} | {f"{base}.{alias.name}" for alias in node.names}
    return found


def _module_file(module: str) -> Path | None:
    path = ROOT / "src" / Path(*module.split("."))
    return path / "__init__.py" if path.is_dir() else path.with_suffix(".py") if path.with_suffix(".py").exists() else None


NOT_FOLLOWED = ("config.py", "__init__.py")  # config imports every section's schema; a package __init__ re-exports


def _import_closure(notebook: Path) -> set[Path]:
    """The source files of poseintegrity whose code a notebook runs: the modules it imports and theirs (a static
    walk of import statements, function-level ones included). Not followed: a package's ``__init__`` (its
    re-exports load code a stage need not run) and ``config`` (it imports every section's schema; a stage depends
    on the schemas of the sections it reads, :func:`test_every_stage_depends_on_the_schema_of_each_section_it_reads`)."""
    cells = json.loads(notebook.read_text())["cells"]
    todo = _imported_modules("\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code"))
    files: set[Path] = set()
    while todo:
        path = _module_file(todo.pop())
        if path is None or path in files:
            continue
        files.add(path)
        if path.name not in NOT_FOLLOWED:
            package = ".".join(path.relative_to(ROOT / "src").with_suffix("").parts[:-1])
            todo |= _imported_modules(path.read_text(), package)
    return {path for path in files if path.name != "__init__.py"}


def test_every_stage_depends_on_every_source_file_its_notebook_runs():
    """A change to a module a stage runs re-runs the stage: the import closure of each notebook (static) lies
    inside the stage's source deps, so dvc.lock cannot call results current that another version of the code made."""
    missing = {}
    for notebook, name, stage in notebook_stages():
        deps = [ROOT / d for d in stage["deps"] if str(d).startswith("src/")]
        closure = _import_closure(notebook)
        assert len(closure) > 5, notebook.name  # the walk found the package
        if lost := sorted(str(f.relative_to(ROOT)) for f in closure if not any(f == d or d in f.parents for d in deps)):
            missing[name] = lost
    assert not missing, f"stages run source files they do not depend on in dvc.yaml: {missing}"


def test_every_stage_depends_on_the_schema_of_each_section_it_reads():
    """A change to the rules of a section re-runs the stages that read it, whether or not their code imports it."""
    schemas = {path.stem for path in (ROOT / "src/poseintegrity/params").glob("*.py")} - {"__init__"}
    for name, stage in DVC["stages"].items():
        read = {key.split(".")[0] for key in stage.get("params", [])} & schemas
        assert read or name == "07_report", name
        missing = {section for section in read if f"src/poseintegrity/params/{section}.py" not in stage["deps"]}
        assert not missing, f"{name} reads params sections whose schema it does not depend on: {missing}"


def test_no_stage_depends_on_an_executed_notebook():
    for name, stage in DVC["stages"].items():
        assert not any(str(d).startswith("reports/notebooks") for d in stage.get("deps", [])), name


def test_stage_params_are_validated_sections():
    params = yaml.safe_load((ROOT / "params.yaml").read_text())
    sections = set(Params.model_fields)
    assert set(params) == sections
    for name, stage in DVC["stages"].items():
        for key in stage.get("params", []):  # a section, or a dotted key inside one
            section, *inner = key.split(".")
            assert section in sections, f"{name} tracks unknown params section {section}"
            node = params[section]
            for part in inner:
                assert part in node, f"{name} tracks {key}, which params.yaml does not have"
                node = node[part]


def test_tiny_params_are_an_overlay_that_only_shrinks_params_yaml():
    """Every key of the overlay exists in params.yaml (a typo would silently add a key) and the merge validates."""
    tiny = yaml.safe_load((ROOT / "tests" / "params_tiny.yaml").read_text())
    assert tiny.pop("extends") == "../params.yaml"
    full = yaml.safe_load((ROOT / "params.yaml").read_text())

    def keys_exist(overlay, base, path=""):
        for key, value in overlay.items():
            assert isinstance(base, dict) and key in base, f"tests/params_tiny.yaml: {path}{key} is not in params.yaml"
            if isinstance(value, dict):
                keys_exist(value, base[key], f"{path}{key}.")

    keys_exist(tiny, full)
    load_params(ROOT / "tests" / "params_tiny.yaml")


def test_declared_metrics_are_stage_outputs_kept_in_git():
    outs = {}
    for stage in DVC["stages"].values():
        for out in stage.get("outs", []):
            if isinstance(out, dict):
                outs.update(out)
    for metric in DVC["metrics"]:
        assert outs.get(metric) == {"cache": False}, metric


def test_the_fast_tier_is_the_suite_without_its_pipeline_runs():
    """README "Development": `make test-fast` runs pytest on both cores, leaving out the tests marked `pipeline`, a
    marker pyproject.toml registers."""
    import subprocess

    dry = subprocess.run(["make", "--no-print-directory", "-n", "test-fast"], cwd=ROOT, capture_output=True, text=True,
                         check=True).stdout  # the commands it would run (under `make test`, a sub-make's)
    assert 'pytest -n 2 -m "not pipeline"' in dry.splitlines()[-1]
    markers = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]["markers"]
    assert any(marker.startswith("pipeline:") for marker in markers)
    assert "make test-fast" in (ROOT / "README.md").read_text().split("## Development", 1)[1]


def test_readme_and_ci_use_the_two_commands():
    readme = (ROOT / "README.md").read_text()
    assert "make repro" in readme and "make test" in readme
    assert "make test" in (ROOT / ".ci" / "run").read_text()


def test_dvc_lock_matches_committed_notebooks_and_params():
    """On a fresh clone `dvc status` may miss outputs, but never sees a changed notebook or changed params."""
    import hashlib

    from ruamel.yaml import YAML  # YAML 1.2 as DVC reads it (PyYAML would take the lock's 1e-12 for a string)

    params = YAML(typ="safe").load((ROOT / "params.yaml").read_text())
    stages = {}
    for lock_path, run_by in ((ROOT / "dvc.lock", "make repro"), (ROOT / "population" / "dvc.lock", "make population")):
        assert lock_path.exists(), f"{lock_path.name} is committed with every run ({run_by} writes it)"
        stages |= YAML(typ="safe").load(lock_path.read_text())["stages"]
    for name, stage in stages.items():
        for dep in stage.get("deps", []):
            if dep["path"].startswith("notebooks/"):
                digest = hashlib.md5((ROOT / dep["path"]).read_bytes()).hexdigest()
                assert digest == dep["md5"], f"{dep['path']} differs from the one {name} ran (re-run the stage)"
        for key, value in stage.get("params", {}).get("params.yaml", {}).items():  # a section or a dotted key
            current = params
            for part in key.split("."):
                current = current[part]
            assert current == value, f"params.yaml {key} changed since {name} ran"


def test_dvc_lock_was_written_by_the_committed_sources():
    """The committed results come from this code: DVC sees no changed source dependency (caches that running
    leaves beside the sources, __pycache__ with numba's, are in .dvcignore). Data may be missing, as on a clone."""
    from dvc.repo import Repo

    with Repo(str(ROOT)) as repo:
        status = repo.status()
    changed = {(stage, path): state for stage, entries in status.items() for entry in entries if isinstance(entry, dict)
               for path, state in entry.get("changed deps", {}).items() if not path.startswith("data/")}
    assert not changed, f"sources changed since dvc.lock was written (re-run make repro): {changed}"


def test_the_pnp_cache_stage_05_adds_to_stage_02s_output_is_ignored_by_dvc():
    """Stage 05 caches its PnP results beside the SIFT features in data/features, an output of stage 02: DVC must
    not count them (.dvcignore), or stage 02 would be out of date after every stage 05 and re-run."""
    from types import SimpleNamespace

    from dvc.repo import Repo

    from poseintegrity.localization.frame_rows import FrameTask

    evidence = ROOT / "data" / "features" / "main_arc_0" / "images" / "s00_i00.evidence.npz"
    pnp = FrameTask.pnp_path.fget(SimpleNamespace(evidence_path=evidence))
    assert pnp.parent == evidence.parent and pnp != evidence
    with Repo(str(ROOT)) as repo:
        assert repo.dvcignore.is_ignored_file(str(pnp))
        assert not any(repo.dvcignore.is_ignored_file(str(evidence.with_name(name)))
                       for name in (evidence.name, "s00_i00.npz"))  # what stage 02 computes stays its output


SHIPPED = ["src", "notebooks", "benchmarks", "docs", "README.md", "params.yaml", "dvc.yaml", "Makefile"]
def test_outside_references_finds_what_a_clone_cannot_follow():
    text = "see NOTES_ELSEWHERE.md, ../../elsewhere/papers and /home/someone/data; README.md and ../params.yaml are fine"
    assert outside_references(text, ROOT / "tests") == ["NOTES_ELSEWHERE.md", "../../elsewhere", "/home/someone"]


def test_the_repository_points_nowhere_outside_itself():
    """Facts the code relies on are cited from docs/references.md, which travels with every clone."""
    files = [p for entry in SHIPPED for p in ([ROOT / entry] if (ROOT / entry).is_file()
                                               else sorted((ROOT / entry).rglob("*"))) if p.is_file()]
    text_files = [p for p in files if p.suffix in {".py", ".ipynb", ".md", ".yaml", ""}]
    assert len(text_files) > 50
    offenders = {str(p.relative_to(ROOT)): found for p in text_files
                 if (found := outside_references(p.read_text(errors="ignore"), p.parent))}
    assert not offenders
