from poseintegrity.tracking.experiments.filter_runs import experiment_rng
from poseintegrity.tracking.experiments.small_blobs import small_blob_sweep, sweep_summary

from tracking.track_section import TINY


def test_small_blob_sweep_on_tiny_params():
    sweep = small_blob_sweep(TINY, experiment_rng(TINY, "small_blobs"))
    summary = sweep_summary(sweep)
    assert summary["marker_keep_rate"]["pixel"] >= summary["marker_keep_rate"]["contour"]
    assert set(sweep.measure) == {"contour", "pixel"} and set(sweep.kind) == {"marker", "phantom"}
