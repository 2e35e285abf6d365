"""params.yaml validation: every bad value stops before any work, with the offending key named."""

import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from params_cases import refusal
from poseintegrity.config import ParamsError, load_params, load_section, parse_params, read_raw

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


# What reading a params file refuses, each a ParamsError naming the file (and the line, key or chain): before,
# non-UTF-8 bytes raised a raw UnicodeDecodeError, an extends cycle a RecursionError, and a key written twice was
# silently replaced by its last value.

@pytest.mark.parametrize("read", [load_params, read_raw, lambda path: load_section(path, "parallel")],
                         ids=["load_params", "read_raw", "load_section"])
def test_non_utf8_bytes_name_the_file_and_offset(tmp_path, read):
    latin = tmp_path / "params.yaml"
    latin.write_bytes("protocol:\n  note: caf\xe9\n".encode("latin-1"))
    with pytest.raises(ParamsError, match=r"params\.yaml is not UTF-8 text: byte 0xe9 at offset 21 \(line 2\)"):
        read(latin)


def test_non_utf8_bytes_in_an_extended_file_name_that_file(tmp_path):
    (tmp_path / "base.yaml").write_bytes(b"parallel: {n_jobs: 1}\n# \xff\n")
    (tmp_path / "overlay.yaml").write_text("extends: base.yaml\n")
    with pytest.raises(ParamsError, match=r"base\.yaml is not UTF-8 text: byte 0xff at offset 24 \(line 2\)"):
        load_section(tmp_path / "overlay.yaml", "parallel")


@pytest.mark.parametrize("files, chain", [
    ({"a.yaml": "extends: b.yaml\n", "b.yaml": "extends: a.yaml\n"}, r"a\.yaml -> \S*b\.yaml -> \S*a\.yaml"),
    ({"a.yaml": "extends: a.yaml\n"}, r"a\.yaml -> \S*a\.yaml"),
    ({"a.yaml": "extends: ./sub/../b.yaml\n", "b.yaml": "extends: c.yaml\n", "c.yaml": "extends: b.yaml\n"},
     r"b\.yaml -> \S*c\.yaml -> \S*b\.yaml"),
])
def test_extends_cycle_names_the_chain(tmp_path, files, chain):
    (tmp_path / "sub").mkdir()
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    with pytest.raises(ParamsError, match=f"extends makes a cycle: .*{chain}"):
        load_params(tmp_path / "a.yaml")


@pytest.mark.parametrize("value, message", [
    ("missing.yaml", r"a\.yaml: extends 'missing\.yaml': no such file"),
    ("[params.yaml]", r"a\.yaml: extends must be the path of a params file \(text\), got list"),
    ("3", r"a\.yaml: extends must be the path of a params file \(text\), got int"),
    ("''", r"a\.yaml: extends must be the path of a params file \(text\), got str"),
    ("list.yaml", r"a\.yaml: extends 'list\.yaml', which is not a mapping"),
])
def test_bad_extends_names_the_file(tmp_path, value, message):
    (tmp_path / "list.yaml").write_text("- 1\n")
    (tmp_path / "a.yaml").write_text(f"extends: {value}\nparallel: {{n_jobs: 1}}\n")
    with pytest.raises(ParamsError, match=message):
        load_params(tmp_path / "a.yaml")


def _with_line_after(text: str, anchor: str, line: str) -> str:
    assert anchor in text
    return text.replace(anchor, anchor + line, 1)


PARAMS_TEXT = (ROOT / "params.yaml").read_text()


@pytest.mark.parametrize("text, key", [
    (PARAMS_TEXT + "parallel: {n_jobs: 1}\n", "parallel"),  # a whole section twice
    (_with_line_after(PARAMS_TEXT, "  n_jobs: 2 ", "\n  n_jobs: 3 "), "parallel.n_jobs"),
    (PARAMS_TEXT.replace("{arc: 4, line: 5}", "{arc: 4, line: 5, arc: 3}"), "protocol.sampled_stops.arc"),  # flow
    (PARAMS_TEXT.replace("distance_mm: 300, elevation_deg: 50,", "distance_mm: 300, distance_mm: 310, "
                                                                  "elevation_deg: 50,", 1),
     "generate.scenes.0.distance_mm"),  # inside a list
])
def test_duplicate_key_names_the_dotted_key_and_lines(tmp_path, text, key):
    path = tmp_path / "params.yaml"
    path.write_text(text)
    with pytest.raises(ParamsError, match=rf"params\.yaml: line \d+: key '{re.escape(key)}' is written twice "
                                          rf"\(lines \d+ and \d+\)"):
        load_params(path)


def test_duplicate_key_in_an_overlay_names_the_overlay(tmp_path):
    overlay = tmp_path / "tiny.yaml"
    overlay.write_text(f"extends: {ROOT / 'params.yaml'}\nfit:\n  k_max: 5\n  k_max: 6\n")
    with pytest.raises(ParamsError, match=r"tiny\.yaml: line 4: key 'fit\.k_max' is written twice \(lines 3 and 4\)"):
        load_params(overlay)


def test_yaml_merge_keys_may_override_what_they_merge(tmp_path):
    path = tmp_path / "merge.yaml"
    path.write_text("base: &base {n_jobs: 1, backend: local}\nparallel:\n  <<: *base\n  n_jobs: 2\n")
    assert read_raw(path)[0]["parallel"] == {"n_jobs": 2, "backend": "local"}


def test_valid_files_still_load_unchanged():
    """params.yaml and its tiny overlay validate; a few values spot-checked, including an int written for a float
    (distance_mm: 300), tuples and paths from YAML lists and text, literals and null."""
    params = load_params(ROOT / "params.yaml")
    tiny = load_params(ROOT / "tests" / "params_tiny.yaml")
    scene = params.generate.scenes[0]
    assert scene.distance_mm == 300.0 and type(scene.distance_mm) is float
    assert scene.glenoid_tilt_deg == (0.0, 25.0)
    assert params.protocol.tolerances == [(2.0, 3.0), (4.0, 10.0)]
    assert params.generate.scapula.mesh == ROOT / "src" / "poseintegrity" / "assets" / "scapula_left.stl"
    assert params.generate.calibration.distance_mm == (250.0, 450.0)
    assert params.protocol.pnp_method == "usac_magsac" and params.fit.k_max is None
    assert params.track.filter.kappa is None and params.track.motion.occlusions == [(20.0, 2.0)]
    assert tiny.generate.camera.downscale == 4 and tiny.parallel.n_jobs == 1 and tiny.fit.k_max == 5
    assert tiny.track.evaluation.lag_max_ms == 300.0 and tiny.generate.lines.scene == "scene_b"
