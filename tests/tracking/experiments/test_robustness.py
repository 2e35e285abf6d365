from poseintegrity.tracking.experiments.filter_runs import experiment_rng
from poseintegrity.tracking.experiments.robustness import recording_replay, ten_metre_jump
from poseintegrity.tracking.simulation.simulate import simulate

from tracking.track_section import TINY


def test_replay_from_disk_gives_the_in_memory_poses(tmp_path):
    table, agreement = recording_replay(TINY, tmp_path / "rec")
    assert agreement["same_flags"] and agreement["max_position_diff_mm"] < 1e-4
    assert (table.flag == "ok").mean() > 0.8
    assert {"t_s", "tool", "flag", "x_mm", "qw"} <= set(table.columns)


def test_ten_metre_jump_on_tiny_params():
    [sim] = simulate(TINY, experiment_rng(TINY, "accuracy"))
    jump = ten_metre_jump(sim, TINY, jump_at_s=1.0, jump_m=10.0)
    assert jump["ok_while_off"] == 0 and jump["frames_to_restart"] == TINY.filter.restart_after_rejections - 1
