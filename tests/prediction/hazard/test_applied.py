"""Stage 04's hazard rows from a model file (prediction/hazard/applied.py): the file round-trips, and a dataset the
models were trained on gets no rows."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from poseintegrity.errors import ArgumentError
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.prediction.hazard.applied import HazardSet, hazard_rows, read_hazard, write_hazard
from poseintegrity.prediction.hazard.model import fit_hazard
from prediction.hazard.hazard_synthetic import arc_frames, load_protocol, synthetic_rows


def test_the_model_file_round_trips_and_a_dataset_it_was_trained_on_gets_no_rows(tmp_path):
    protocol = ProtocolParams.model_validate(load_protocol())
    frames = pd.concat([arc_frames("main", f"s{i}_arc", [100, 90, 70, 50, 30, 15, 8, 0]) for i in range(3)])
    evidence_rows = synthetic_rows(3, 100, 5)
    models = {(name, predictor): fit_hazard(evidence_rows.rename(columns={"a": "log_inliers"}), ("log_inliers",), 1.0, 2)
              for name in protocol.tolerance_names for predictor in ("hazard_next_step", "hazard_long_range")}
    hazard = HazardSet(("s0_arc",), models, {key: 0.1 for key in models})
    write_hazard(tmp_path / "model.json", hazard)
    back = read_hazard(tmp_path / "model.json")
    assert back.trained_on == ("s0_arc",) and back.chosen == hazard.chosen
    levels = np.array([0.01, 0.1, 0.5])
    rows = hazard_rows(frames, back, protocol, levels)
    assert set(rows["dataset"]) == {"s1_arc", "s2_arc"}  # never a prediction for a dataset the model was trained on
    assert len(rows) == 2 * 2 * len(protocol.tolerance_names) * len(levels)
    pd.testing.assert_frame_equal(rows, hazard_rows(frames, hazard, protocol, levels))
    (tmp_path / "bad.json").write_text('{"format": 1, "tolerances": {"2mm_3deg": {"hazard_next_step": {"coef": 1}}}}')
    with pytest.raises(ArgumentError, match="bad.json, 2mm_3deg.hazard_next_step: not a hazard model"):
        read_hazard(tmp_path / "bad.json")
    with pytest.raises(ArgumentError, match="predict.hazard.model: cannot read"):
        read_hazard(tmp_path / "absent.json")
