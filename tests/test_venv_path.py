"""The `python` of every dvc.yaml cmd is the interpreter of the venv that runs dvc, whatever PATH holds
(venv-on-path.pth, installed by `make install`), and the stage runner's kernel is this venv's even when the user has
a `python3` kernel of their own. tests/recorded/test_dvc_repro.py runs `dvc repro` itself with a foreign PATH."""

import json
import os
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

from repository import ROOT

FOREIGN = {**{k: v for k, v in os.environ.items() if k not in ("JUPYTER_PATH", "VIRTUAL_ENV")}, "PATH": "/usr/bin:/bin"}


def test_the_venv_holds_the_repositorys_path_hook():
    installed = Path(sysconfig.get_path("purelib")) / "venv-on-path.pth"
    assert installed.read_text() == (ROOT / "venv-on-path.pth").read_text(), "run make install"


def test_a_child_of_the_venvs_interpreter_finds_the_venvs_python_first():
    """What DVC does: a shell started from the interpreter with its environment resolves `python`."""
    script = "import subprocess; subprocess.run(['sh', '-c', 'command -v python'])"
    done = subprocess.run([sys.executable, "-c", script], env=FOREIGN, capture_output=True, text=True, check=True)
    assert done.stdout.strip() == str(Path(sys.executable).parent / "python")
    plain = subprocess.run(["sh", "-c", "command -v python || true"], env=FOREIGN, capture_output=True, text=True)
    assert plain.stdout.strip() != done.stdout.strip()  # the foreign PATH alone finds another python, or none


def test_the_stage_runner_prefers_the_venvs_kernel_to_the_users(tmp_path, monkeypatch):
    """jupyter_core (>= 5) searches the venv's share/jupyter before the user's data folder, but JUPYTER_PATH before
    both: a user's JUPYTER_PATH holding a `python3` kernel (another environment's) would run the notebooks."""
    from jupyter_client.kernelspec import KernelSpecManager

    from poseintegrity.stage import kernel_search_path

    user_kernel = tmp_path / "kernels" / "python3"
    user_kernel.mkdir(parents=True)
    (user_kernel / "kernel.json").write_text(json.dumps({"argv": ["/usr/bin/python3", "-m", "ipykernel_launcher", "-f",
                                                                  "{connection_file}"], "display_name": "mine",
                                                         "language": "python"}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path))  # restored after the test, whatever kernel_search_path sets
    assert KernelSpecManager().get_kernel_spec("python3").argv[0] == "/usr/bin/python3"
    kernel_search_path()
    assert KernelSpecManager().get_kernel_spec("python3").argv[0] == sys.executable


@pytest.mark.pipeline
def test_dvc_exp_run_gives_its_stage_the_venvs_python(tmp_path):
    """A one-stage project under git: `dvc exp run` (the README's parameter change) runs the cmd's `python` as the
    venv's with a PATH that has none. (Queued runs start their workers with dvc's own interpreter, dvc/daemon.py;
    checked by hand, docs/references.md.)"""
    dvc = str(Path(sys.executable).parent / "dvc")
    (tmp_path / "dvc.yaml").write_text('stages:\n  which:\n    cmd: python -c "import sys; print(sys.executable)" > '
                                       'out.txt\n    params: [x]\n    outs: [out.txt]\n')
    (tmp_path / "params.yaml").write_text("x: 1\n")
    for argv in (["git", "init", "-q"], ["git", "config", "user.email", "test@example.org"],
                 ["git", "config", "user.name", "test"], [dvc, "init", "-q"], ["git", "add", "-A"],
                 ["git", "commit", "-qm", "toy"], [dvc, "exp", "run", "-S", "x=2"]):
        subprocess.run(argv, cwd=tmp_path, env=FOREIGN, capture_output=True, text=True, check=True)
    assert (tmp_path / "out.txt").read_text().strip() == sys.executable


@pytest.mark.pipeline
def test_the_readmes_experiment_commands_run_as_written(tmp_path):
    """README "Changing a parameter", on a one-stage project with a metric and a plot: named runs of three RANSAC
    thresholds (run directly here; the README queues them, whose workers are checked by hand, above), then
    `dvc exp show`, `dvc exp show --only-changed`, `dvc plots diff` of the three and `dvc exp apply` of one, each
    line as the README writes it (run from the project's folder, so `.venv/bin/dvc` is this venv's dvc)."""
    (tmp_path / ".venv").symlink_to(Path(sys.executable).parents[1])
    (tmp_path / "dvc.yaml").write_text(
        "stages:\n  fit:\n    cmd: python fit.py\n    deps: [fit.py]\n    params: [extract.reprojection_threshold_px]\n"
        "    metrics: [{metrics.json: {cache: false}}]\n    plots: [{curve.csv: {cache: false, x: theta, y: n_i}}]\n")
    (tmp_path / "fit.py").write_text(
        "import json, yaml\nt = yaml.safe_load(open('params.yaml'))['extract']['reprojection_threshold_px']\n"
        "json.dump({'theta_a': 10 * t}, open('metrics.json', 'w'))\n"
        "open('curve.csv', 'w').write('theta,n_i\\n' + ''.join(f'{k},{100 - k * t}\\n' for k in range(5)))\n")
    (tmp_path / "params.yaml").write_text("extract:\n  reprojection_threshold_px: 0.6\n")
    (tmp_path / ".gitignore").write_text(".venv\n")
    dvc = ".venv/bin/dvc"
    setup = (["git", "init", "-q"], ["git", "config", "user.email", "test@example.org"],
             ["git", "config", "user.name", "test"], [dvc, "init", "-q"], [dvc, "repro", "-q"], ["git", "add", "-A"],
             ["git", "commit", "-qm", "toy"])
    for t in ("0.4", "0.6", "0.9"):
        setup += ([dvc, "exp", "run", "-n", f"ransac-{t}", "-S", f"extract.reprojection_threshold_px={t}"],)
    for argv in setup:
        subprocess.run(argv, cwd=tmp_path, env=FOREIGN, capture_output=True, text=True, check=True)

    def readme(line: str) -> str:
        return subprocess.run(line, shell=True, cwd=tmp_path, env=FOREIGN, capture_output=True, text=True,
                              check=True).stdout

    shown = readme(".venv/bin/dvc exp show")
    assert all(f"ransac-{t}" in shown for t in ("0.4", "0.6", "0.9"))
    changed = readme(".venv/bin/dvc exp show --only-changed")
    assert "theta_a" in changed and "reprojection_threshold_px" in changed
    readme(".venv/bin/dvc plots diff ransac-0.4 ransac-0.6 ransac-0.9")
    page = (tmp_path / "dvc_plots" / "index.html").read_text()
    assert all(f"ransac-{t}" in page for t in ("0.4", "0.6", "0.9"))
    readme(".venv/bin/dvc exp apply ransac-0.9")
    assert "0.9" in (tmp_path / "params.yaml").read_text()
    assert json.loads((tmp_path / "metrics.json").read_text()) == {"theta_a": 9.0}
