"""Executing a pipeline notebook as dvc.yaml's stage does, on the tiny parameters, for the notebook tests."""

from pathlib import Path

import papermill

from repository import ROOT

TINY_PARAMS = ROOT / "tests" / "params_tiny.yaml"


def execute(name: str, work: Path, params_path: Path = TINY_PARAMS) -> Path:
    """notebooks/<name>.ipynb executed with its data in ``work / "data"`` and its reports in ``work / "reports"``
    (the executed copy in ``work / "executed"``); returns ``work``."""
    executed = work / "executed" / f"{name}.ipynb"
    executed.parent.mkdir(parents=True, exist_ok=True)
    papermill.execute_notebook(
        str(ROOT / "notebooks" / f"{name}.ipynb"), str(executed), kernel_name="python3", progress_bar=False,
        cwd=str(ROOT), parameters={"params_path": str(params_path), "data_dir": str(work / "data"),
                                   "reports_dir": str(work / "reports")},
    )
    return work

