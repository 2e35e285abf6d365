import numpy as np
import pandas as pd

from poseintegrity.tracking.experiments.filter_runs import experiment_rng
from poseintegrity.tracking.experiments.success import success_rates, success_recording, success_runs, two_tools_success
from poseintegrity.tracking.simulation.simulate import simulate

from tracking.track_section import TINY


def success_tables(params):
    return {name: table for run in success_runs(params) for name, (table, _) in success_recording(params, run).items()}


def test_success_rates_cover_both_motions_and_the_split_variant():
    table, frames = success_rates(TINY, success_tables(TINY))
    assert len(table) == 9 and set(table.motion) == {"a", "b"}  # (a): 4 markers, 3 with each marker dropped; (b): 4, 3, split or not
    assert set(table.dropped[table.motion == "a"]) == {0, 1, 2, 3, 4}
    assert (table.frames == TINY.evaluation.success_frames).all()
    assert ((table.rate >= 0) & (table.rate <= table.possible)).all()  # a hidden marker cannot be found
    again, _ = success_rates(TINY, success_tables(TINY))
    pd.testing.assert_frame_equal(table, again)


def test_the_stress_recording_is_rendered_once_for_both_detectors():
    """With and without splitting touching blobs, (b) runs on the same frames: the same rendering and a detector
    run alone on it (simulate with one detector) gives the same points as with two."""
    run = next(r for r in success_runs(TINY) if r.motion == "b")
    both = success_recording(TINY, run, keep=True)
    split, unsplit = both[f"b_{run.label}"][1], both[f"b_{run.label}_no_split"][1]
    np.testing.assert_array_equal(split.T_true, unsplit.T_true)
    duration = split.trajectory.t[-1]
    [alone] = simulate(TINY, experiment_rng(TINY, f"stress_{run.label}"), np.array(TINY.markers_body), TINY.evaluation.success_omega_std,
                       duration, [TINY.detection.model_copy(update={"split_touching": False})], n_frames=TINY.evaluation.success_frames)
    assert all(np.array_equal(a, b) for a, b in zip(alone.points, unsplit.points)) and len(alone.points) == len(unsplit.points)


def test_two_tools_among_phantoms_on_tiny_params():
    tools = two_tools_success(TINY, 6, "phantom_rich")
    assert set(tools.tool) == {"tool1", "tool2"} and tools.correct.mean() > 0.8
