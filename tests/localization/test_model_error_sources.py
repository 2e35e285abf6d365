"""studies/model_error_sources.py: its re-localization is stage 02's (same features, matches, seed and cap, so the same
poses), and where the reported model baseline is the exact one (the synthetic datasets) replacing it changes nothing."""

import importlib.util

import numpy as np
import pytest

from poseintegrity.errors import ArgumentError
from poseintegrity.localization import extract as E
from repository import ROOT

spec = importlib.util.spec_from_file_location("model_error_sources", ROOT / "studies" / "model_error_sources.py")
study = importlib.util.module_from_spec(spec)
spec.loader.exec_module(study)
pytestmark = pytest.mark.pipeline  # stage 02 on a synthetic dataset, then the study on it


@pytest.fixture(scope="module")
def params(extract_params):
    return extract_params.model_copy(update=dict(datasets=["arc_a"]))


def test_the_stage_02_variant_localizes_every_frame_as_stage_02_did(synthetic_data_dir, params, workers):
    rows = E.extract_all(synthetic_data_dir, params, [study.METHOD], workers, progress=False)
    table = study.study(synthetic_data_dir, "arc_a", range(0, 10), params, None)
    stage_02 = rows.groupby("stop")[["n_inliers", "E_t_exact_mm", "E_r_exact_deg", "sigma_t_pred_mm"]].mean()
    ours = table.loc["stage 02"]
    assert len(ours) == len(stage_02) >= 2
    np.testing.assert_array_equal(ours.n_inliers.to_numpy(), stage_02.n_inliers.to_numpy())
    np.testing.assert_allclose(ours.E_t_mm.to_numpy(), stage_02.E_t_exact_mm.to_numpy(), rtol=1e-9)
    np.testing.assert_allclose(ours.E_r_deg.to_numpy(), stage_02.E_r_exact_deg.to_numpy(), rtol=1e-9)
    np.testing.assert_allclose(ours.sigma_t_pred_mm.to_numpy(), stage_02.sigma_t_pred_mm.to_numpy(), rtol=1e-9)
    # the synthetic model pair's reported baseline is its exact one: the same M_t, the same poses
    np.testing.assert_allclose(table.loc["exact baseline"].E_t_mm.to_numpy(), ours.E_t_mm.to_numpy(), rtol=1e-9)
    assert set(table.index.get_level_values("variant")) == {"stage 02", "exact baseline", "exact baseline, anchor"}


def test_an_unknown_dataset_is_refused_by_name(synthetic_data_dir, params):
    with pytest.raises(ArgumentError, match="'nope'"):
        study.study(synthetic_data_dir, "nope", range(0, 2), params, None)
