"""A stage's metrics file (report/metrics.py): JSON that every reader accepts."""

import json

import numpy as np

from poseintegrity.report.metrics import write_metrics


def test_metrics_file_is_valid_json_with_null_for_nan(tmp_path):
    """json.dumps alone writes NaN / Infinity, which no JSON reader (dvc metrics) accepts."""
    path = tmp_path / "stage.json"
    write_metrics(path, {"a": np.float64("nan"), "b": [np.int64(3), np.bool_(True), np.inf], "c": {"d": np.float32(0.5)}})
    assert json.loads(path.read_text()) == {"a": None, "b": [3, True, None], "c": {"d": 0.5}}
    assert [p.name for p in tmp_path.iterdir()] == ["stage.json"]  # the partial file was renamed
