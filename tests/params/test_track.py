"""The track section of params.yaml: every bad value is refused before any work, naming its key."""

import copy
import re

import pytest

from poseintegrity.config import ParamsError, parse_params


def _set(raw: dict, dotted: str, value) -> dict:
    raw = copy.deepcopy(raw)
    *parents, last = dotted.split(".")
    node = raw
    for part in parents:
        node = node[int(part)] if isinstance(node, list) else node[part]
    node[int(last) if isinstance(node, list) else last] = value
    return raw


SAME = [0.02, 0.01, 0.0]
BAD = [
    ("track.seed", -1, "track.seed"),
    ("track.frames.phantom_radius_px", [4.0, 1.5], "track.frames.phantom_radius_px"),
    ("track.frames.phantom_radius_px", [0.0, 1.5], "track.frames.phantom_radius_px"),
    ("track.frames.phantom_depth_mm", [850.0, 150.0], "track.frames.phantom_depth_mm"),
    ("track.frames.phantom_elongation", [8.0, 3.0], "track.frames.phantom_elongation"),
    ("track.frames.phantom_elongation", [0.5, 3.0], "track.frames.phantom_elongation"),
    ("track.frames.supersampling", 0, "track.frames.supersampling"),
    ("track.hand.turn_s", [4.0, 2.0], "track.hand.turn_s"),
    ("track.hand.pause_s", [1.5, 0.3], "track.hand.pause_s"),
    ("track.hand.pause_s", [-0.3, 1.5], "track.hand.pause_s"),
    ("track.hand.occlusion_s", [0.3, 0.1], "track.hand.occlusion_s"),
    ("track.markers_body", [SAME, SAME, SAME, [0.05, -0.02, 0.01]], "track.markers_body"),  # three identical markers
    ("track.markers_body", [[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.03, 0.0, 0.0], [0.07, 0.0, 0.0]], "track.markers_body"),  # collinear
    ("track.markers_body", [[0.0, 0.0, 0.0], [0.03, 0.0, 0.0], [0.0, 0.03, 0.0], [0.03, 0.03, 0.0]], "track.markers_body"),  # a square: equal sides
    ("track.markers_body", [[0.0, 0.0, 0.0], [0.03, 0.0, 0.0], [0.0, 0.05, 0.0]], "track.markers_body"),  # none left to drop
    ("track.evaluation.second_tool", [SAME, SAME, SAME, [0.05, -0.02, 0.01]], "track.evaluation.second_tool"),
    ("track.evaluation.second_tool", [[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.03, 0.0, 0.0]], "track.evaluation.second_tool"),
    # a copy of the first tool, shifted: every distance equals one of markers_body
    ("track.evaluation.second_tool", [[0.13455, 0.01295, 0.01797], [0.11721, -0.01669, 0.00796], [0.08431, -0.01049, -0.01109]],
     "track.evaluation.second_tool"),
    ("track.evaluation.sigma_scales", [-1, 0], "track.evaluation.sigma_scales"),
    ("track.evaluation.sigma_scales", [], "track.evaluation.sigma_scales"),
    ("track.evaluation.sweep_distances_m", [-1], "track.evaluation.sweep_distances_m"),
    ("track.evaluation.sweep_distances_m", [0.5, 1.5], "track.evaluation.sweep_distances_m"),  # beyond depth_max_mm
    ("track.motion.occlusions", [[-1.0, 2.0]], "track.motion.occlusions.0"),
    ("track.motion.occlusions", [[1.0, 5.0]], "track.motion.occlusions.0"),  # ends after duration_s (3 s in the tiny params)
    ("track.motion.occlusions", [[1.0, 0.0]], "track.motion.occlusions.0"),
    ("track.motion.frame_interval_s", 0.002, "track.motion.frame_interval_s"),
    ("track.motion.home_m", [0.0, 0.0, -0.45], "track.motion.home_m"),  # behind the camera
    ("track.motion.p_occlusion", 1.5, "track.motion.p_occlusion"),
    ("track.drop_marker", 9, "track.drop_marker"),
    ("track.drop_marker", -1, "track.drop_marker"),
    ("track.detection.depth_typo", 1, "track.detection.depth_typo"),
    ("track.detection.max_area", 1.0, "track.detection.max_area"),  # below min_area
    ("track.detection.depth_max_mm", 50.0, "track.detection.depth_max_mm"),  # below depth_min_mm
    ("track.detection.threshold", 300, "track.detection.threshold"),
    ("track.filter.kappa", -30.0, "track.filter.kappa"),  # N + kappa <= 0
    ("track.filter.dt", 0.0, "track.filter.dt"),
    ("track.filter.alpha", 1.5, "track.filter.alpha"),
    ("track.matching.min_markers", 2, "track.matching.min_markers"),
    ("track.camera.focal_px", float("nan"), "track.camera.focal_px"),
    ("track.evaluation.success_frames", 0, "track.evaluation.success_frames"),
]


@pytest.mark.parametrize("dotted, value, key", BAD, ids=[f"{d}={v}" for d, v, _ in BAD])
def test_bad_track_value_names_its_key(tiny_raw, dotted, value, key):
    with pytest.raises(ParamsError) as info:
        parse_params(_set(tiny_raw, dotted, value))
    assert re.search(rf"^  {re.escape(key)}[.:]", str(info.value), re.MULTILINE), str(info.value)  # the key, or one of its entries


def test_the_tiny_and_paper_scale_track_sections_are_valid(tiny_params):
    assert tiny_params.track.evaluation.success_frames < 10_000


def test_every_track_value_comes_from_params_yaml(tiny_raw):
    """No field has a default: dropping any key of the section is refused, naming it."""
    for section, values in tiny_raw["track"].items():
        keys = [f"{section}.{k}" for k in values] if isinstance(values, dict) else [section]
        for dotted in keys:
            raw = copy.deepcopy(tiny_raw)
            *parents, last = ["track", *dotted.split(".")]
            node = raw
            for part in parents:
                node = node[part]
            del node[last]
            with pytest.raises(ParamsError, match=f"track.{dotted}: Field required"):
                parse_params(raw)
