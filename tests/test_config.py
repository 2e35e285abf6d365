"""params.yaml validation: every bad value stops before any work, with the offending key named."""

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

from params_cases import refusal
from poseintegrity.config import ParamsError, load_params, parse_params

ROOT = Path(__file__).resolve().parents[1]


def test_paper_scale_params_are_valid():
    params = load_params(ROOT / "params.yaml")
    assert len(params.generate.scenes) == 7
    assert params.protocol.range_end("arc") == 45.0 and params.protocol.range_end("line") == 150.0


def _error_for(raw: dict) -> str:
    with pytest.raises(ParamsError) as info:
        parse_params(raw)
    return str(info.value)


# Bad values of params.yaml, each refused before any work with its key named (``expected``: the key the error
# names). Rows for the protocol and the rules across sections; each section's own table sits beside its tests.
BAD_VALUES = [
    ("generate.images_per_stop", -3, "generate.images_per_stop"),
    ("generate.arcs.n_stops", 0, "generate.arcs.n_stops"),
    ("generate.arcs.n_stops", 4, "generate.arcs.n_stops"),  # no stop left after the 4 sampled ones
    ("generate.scenes.0.targets", ["femur"], "generate.scenes.0.targets"),
    ("generate.camera.downscale", 0, "generate.camera.downscale"),
    ("generate.sensor.flicker", -0.1, "generate.sensor.flicker"),
    ("generate.sensor.exposure", float("inf"), "generate.sensor.exposure"),
    ("generate.arcs.azimuths_deg", [0.0, float("nan")], "generate.arcs.azimuths_deg.1"),
    ("generate.arcs.colour", "red", "generate.arcs.colour"),
    ("protocol.pnp_method", "dls", "protocol.pnp_method"),
    ("protocol.tolerances", [[2.0, 3.0], [2.0, 3.0]], "protocol.tolerances"),
    ("protocol.tolerances", [[2.0, -3.0]], "protocol.tolerances"),
    ("protocol.arc_span_deg", float("nan"), "protocol.arc_span_deg"),
    ("protocol.sampled_stops.arc", 1, "protocol.sampled_stops.arc"),
    ("predict.tolerance_fig6_fig7", "2mm_3dg", "predict.tolerance_fig6_fig7"),
    ("predict.live_tolerance", "9mm_9deg", "predict.live_tolerance"),
    ("fit.k_max", 3, "fit.k_max"),  # the headline RMSE at 4 / 5 sampled stops would have no fits
    ("fit.k_min", 5, "fit.k_min"),
]


@pytest.mark.parametrize("key, value, expected", BAD_VALUES)
def test_bad_value_names_its_key(tiny_raw, key, value, expected):
    assert expected in refusal(tiny_raw, key, value)


def test_unknown_target_lists_known_names(tiny_raw):
    tiny_raw["generate"]["scenes"][1]["targets"] = ["scapula", "humerus"]
    message = _error_for(tiny_raw)
    assert "humerus" in message and "scapula_drilled" in message


def test_unreadable_texture_names_the_file(tiny_raw, tmp_path):
    bad = tmp_path / "not_an_image.png"
    bad.write_text("this is text")
    tiny_raw["generate"]["textures"] = {"block_print": str(bad)}
    message = _error_for(tiny_raw)
    assert "generate.textures" in message and str(bad) in message


def test_readable_texture_is_accepted(tiny_raw, tmp_path):
    import cv2

    good = tmp_path / "photo.png"
    cv2.imwrite(str(good), np.random.default_rng(0).integers(0, 255, (64, 64), dtype=np.uint8))
    tiny_raw["generate"]["textures"] = {"block_print": str(good)}
    assert parse_params(tiny_raw).generate.textures["block_print"].name == "photo.png"


def test_line_scene_must_exist(tiny_raw):
    tiny_raw["generate"]["lines"]["scene"] = "scene_z"
    assert "lines.scene" in _error_for(tiny_raw)


def test_missing_section_and_bad_yaml(tmp_path):
    assert "protocol" in _error_for({})
    assert "generate" in _error_for({"protocol": load_params(ROOT / "params.yaml").protocol.model_dump()})
    broken = tmp_path / "params.yaml"
    broken.write_text("generate: [unclosed")
    with pytest.raises(ParamsError, match="not valid YAML"):
        load_params(broken)
    with pytest.raises(ParamsError, match="cannot read"):
        load_params(tmp_path / "missing.yaml")
    (tmp_path / "list.yaml").write_text(yaml.safe_dump([1, 2]))
    with pytest.raises(ParamsError, match="expected a mapping"):
        load_params(tmp_path / "list.yaml")
