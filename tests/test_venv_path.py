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


# The toy stage of the README's study: the committed run's metrics, each number moved with the threshold (at the
# committed 0.6 they are the committed ones), with issue 38's keys added (a ceiling share for every predictor, the
# error predictors as copies of long range) so that the headline is as large as it will be; from them stage 07's
# headline (the only metrics file dvc.yaml declares) and one detailed file, an output DVC must not show as metrics.
TOY_STAGE = """import json, sys
from pathlib import Path
import yaml
from poseintegrity.report.headline_file import headline_metrics
from poseintegrity.report.metrics import write_metrics
from poseintegrity.report.summary import read_metrics

t = yaml.safe_load(open("params.yaml"))["extract"]["reprojection_threshold_px"]
def moved(value):
    if isinstance(value, dict):
        return {key: moved(item) for key, item in value.items()}
    if isinstance(value, list):  # an interval's ends
        return [moved(item) for item in value]
    return value * t / 0.6 if isinstance(value, float) else value
metrics = read_metrics(Path(sys.argv[1]))
for stage in ("predictors", "validation"):
    for predictor in ("long_range", "next_step", "mlp"):
        for entry in metrics[stage][predictor].values():
            if isinstance(entry, dict):
                entry["ceiling_share"] = 0.5
    for predictor in ("error_long_range", "error_next_step", "error_combined"):
        metrics[stage][predictor] = metrics[stage]["long_range"]
metrics = moved(metrics)
Path("reports/metrics").mkdir(parents=True, exist_ok=True)
write_metrics("reports/metrics/headline.json", headline_metrics(metrics))
write_metrics("reports/metrics/predictors.json", metrics["predictors"])
open("curve.csv", "w").write("theta,n_i\\n" + "".join(f"{k},{100 - k * t}\\n" for k in range(5)))
"""


@pytest.mark.pipeline
def test_the_readmes_experiment_commands_run_as_written(tmp_path):
    """README "Changing a parameter", on a one-stage project that writes the headline from the committed metrics
    (TOY_STAGE) and declares the metrics dvc.yaml declares, with a plot: named runs of three RANSAC thresholds (run
    directly here; the README queues them, whose workers are checked by hand, above), then `dvc exp show`, `dvc exp
    show --only-changed`, `dvc metrics diff` and `dvc plots diff` of them and `dvc exp apply` of one, each line as the
    README writes it (run from the project's folder, so `.venv/bin/dvc` is this venv's dvc), on a terminal of 200
    columns: what they print fits in it and names the headline, never a detailed metrics file."""
    import yaml

    from poseintegrity.report.headline_file import HEADLINE_FILE

    declared = yaml.safe_load((ROOT / "dvc.yaml").read_text())["metrics"]
    assert declared == [f"reports/metrics/{HEADLINE_FILE}"]  # the headline only (issue 41)
    (tmp_path / ".venv").symlink_to(Path(sys.executable).parents[1])
    (tmp_path / "dvc.yaml").write_text(yaml.safe_dump({
        "stages": {"fit": {"cmd": f"python fit.py {ROOT / 'reports' / 'metrics'}", "deps": ["fit.py"],
                           "params": ["extract.reprojection_threshold_px"],
                           "outs": [{path: {"cache": False}}
                                    for path in (*declared, "reports/metrics/predictors.json")],
                           "plots": [{"curve.csv": {"cache": False, "x": "theta", "y": "n_i"}}]}},
        "metrics": declared}))
    (tmp_path / "fit.py").write_text(TOY_STAGE)
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
    headline = json.loads((tmp_path / declared[0]).read_text())
    assert json.loads((ROOT / declared[0]).read_text()).keys() <= headline.keys()  # the committed one's worlds

    def readme(line: str) -> str:
        output = subprocess.run(line, shell=True, cwd=tmp_path, env=FOREIGN | {"COLUMNS": "200"},
                                capture_output=True, text=True, check=True).stdout
        assert "envelope_rules" not in output and "predictors.json" not in output  # no detailed file as metrics
        return output

    def fits(output: str) -> str:
        assert max(map(len, output.splitlines())) <= 200, f"wider than 200 columns:\n{output}"
        return output

    shown = readme(".venv/bin/dvc exp show")
    assert all(f"ransac-{t}" in shown for t in ("0.4", "0.6", "0.9"))
    # Without a terminal DVC prints the table its pager would scroll sideways; a terminal of 200 columns without the
    # pager shows the params and the headline's first columns, the paper's long range first, and folds the rest
    first = "main.2mm_3deg.long_range"
    changed = readme(".venv/bin/dvc exp show --only-changed")
    assert first in changed  # the headline's first columns; `metrics diff` below lists every one, ours too
    screen = fits(readme(".venv/bin/dvc exp show --only-changed --no-pager"))
    header = screen.splitlines()[1].split()
    assert header[2] == first and "…" in header  # the param beside it, its name cut short with ~110 metrics:
    assert any(name.startswith("extract.reprojection_th") for name in header[3:])
    diff = fits(readme(".venv/bin/dvc metrics diff ransac-0.4 ransac-0.9"))
    rows = [line.split() for line in diff.splitlines()[1:]]
    assert {row[0] for row in rows} == {declared[0]}

    def flat(block, prefix=""):
        return [key for name, value in block.items()
                for key in (flat(value, f"{prefix}{name}.") if isinstance(value, dict) else [f"{prefix}{name}"])]

    moved = {key for key in flat(headline) if not key.startswith(("tracking.", "main.r11", "validation.r11"))}
    missing = moved - {row[1] for row in rows}
    assert not missing and 40 <= len(flat(headline)) <= 120, (sorted(missing), len(flat(headline)))  # a hundred at most
    readme(".venv/bin/dvc plots diff ransac-0.4 ransac-0.6 ransac-0.9")
    page = (tmp_path / "dvc_plots" / "index.html").read_text()
    assert all(f"ransac-{t}" in page for t in ("0.4", "0.6", "0.9"))
    readme(".venv/bin/dvc exp apply ransac-0.9")
    assert "0.9" in (tmp_path / "params.yaml").read_text()
    applied = json.loads((tmp_path / declared[0]).read_text())["main"]["2mm_3deg"]["static"]
    committed = json.loads((ROOT / "reports" / "metrics" / "predictors.json").read_text())["static"]["2mm_3deg"]
    assert applied == pytest.approx(committed["max_mean_spl_zero_incursion"] * 0.9 / 0.6)
