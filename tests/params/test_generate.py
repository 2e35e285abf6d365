"""The ``generate`` section: every bad value refused before any work, its key named; params.yaml the only source."""

import pytest

from params_cases import refusal
from poseintegrity.params.generate import GenerateParams
from poseintegrity.scenes import trips
from poseintegrity.scenes.optics import defocus_sigma_px

NO_LIGHT = {"ambient": 0.0, "ring": 0.0, "room": 0.0, "background": 0.5}

# (key under generate, bad value, the key the error names); after each, what it did before it was refused.
# The tiny parameters' scenes: scene_a (a printed block), scene_b (the drilled scapula, the lines' scene).
BAD_VALUES = [
    ("arcs.azimuths_deg", [0, 0.4], "arcs.azimuths_deg"),  # both wrote scene_a_arc000: 3 folders, 9 index rows
    ("arcs.azimuths_deg", [90, 90], "arcs.azimuths_deg"),  # the same arc rendered twice into one folder
    ("arcs.azimuths_deg", [0, 360], "arcs.azimuths_deg.1"),  # the arc at 0 again, as scene_a_arc360
    ("arcs.azimuths_deg", [-90], "arcs.azimuths_deg.0"),  # scene_a_arc-90: the arc at 270 under another name
    ("arcs.azimuths_deg", [], "arcs.azimuths_deg"),  # no arc at all
    ("arcs.n_stops", 1000, "arcs.n_stops"),  # accepted: hours of rendering
    ("lines.offsets_deg", [0, 0], "lines.offsets_deg"),  # two datasets in scene_b_line00
    ("lines.offsets_deg", [5, 5.2], "lines.offsets_deg"),  # both named scene_b_line05
    ("lines.offsets_deg", [], "lines.offsets_deg"),
    ("lines.n_stops", 1000, "lines.n_stops"),
    ("lines.distance_mm", 60, "lines.distance_mm"),
    ("images_per_stop", 100000, "images_per_stop"),  # accepted: a million images
    ("model_baseline_mm", 1000, "model_baseline_mm"),  # stopped at rendering, blaming scenes.0.distance_mm
    ("seed", 2**70, "seed"),
    ("n_jobs", 2, "n_jobs"),  # gone: parallel.n_jobs is the only worker count
    ("camera.downscale", 5000, "camera.downscale"),  # a 0 x 0 image: stopped at rendering, blaming distance_mm
    ("camera.sensor_width_px", 100000, "camera.sensor_width_px"),  # accepted: GBs of z-buffer per worker
    ("camera.lens_mm", 400, "camera.lens_mm"),  # focus behind the lens; stopped at rendering, blaming distance_mm
    ("camera.f_number", 0.001, "camera.f_number"),  # accepted: a defocus blur of hundreds of pixels
    ("camera.distortion", [-0.6, 0.0, 0.0, 0.0, 0.0], "camera.distortion"),  # folds: the corners see no ray, or two
    ("camera.distortion", [0.0, 0.0, 0.6, 0.0, 0.0], "camera.distortion"),  # folds the top rows (tangential)
    ("camera.distortion", [-0.06, 0.02, 0.0, 0.0], "camera.distortion"),  # 4 coefficients
    ("camera.principal_point_offset_px", [500.0, 0.0], "camera.principal_point_offset_px.0"),
    ("calibration.board.marker_mm", 25.0, "calibration.board.marker_mm"),  # a marker larger than its square
    ("calibration.board.dictionary", "DICT_4X4_NOPE", "calibration.board.dictionary"),
    ("calibration.board.squares_x", 40, "calibration.board.dictionary"),  # 120 markers, DICT_5X5_100 has 100
    ("calibration.n_views", 2, "calibration.n_views"),  # fewer than a calibration can use
    ("board.marker_mm", 30.0, "board.marker_mm"),  # a ChArUco marker larger than its square
    ("board.markers_x", 3, "board.markers_x"),  # an ArUco grid's key on a ChArUco board
    ("board.squares_x", None, "board.squares_x"),  # a ChArUco board without its size
    ("board.squares_x", 30, "board.dictionary"),  # 60 markers on 30 x 4 squares, DICT_4X4_50 has 50
    ("board.placement", "hanging", "board.placement"),
    ("board.placement", "planned", "board.sizes_mm"),  # a plan without the sizes it chooses from
    ("board.sizes_mm", [15.0, 18.0], "board.sizes_mm"),  # a key of the plan on a board placed by the old rule
    ("board.max_boards", 3, "board.max_boards"),
    ("printed_boards.caliper_std_mm", -0.1, "printed_boards.caliper_std_mm"),
    ("capture.model_settle_ms", -5.0, "capture.model_settle_ms"),
    ("calibration.distance_mm", [450.0, 250.0], "calibration.distance_mm"),
    ("calibration.distance_mm", [50.0, 300.0], "calibration.distance_mm"),  # nearer than the lens focuses
    ("calibration.max_tilt_deg", 85.0, "calibration.max_tilt_deg"),  # the board seen edge-on
    ("calibration.max_tilt_deg", 0.0, "calibration.max_tilt_deg"),  # every view fronto-parallel: f undetermined
    ("calibration.max_tilt_deg", 19.0, "calibration.max_tilt_deg"),  # too little tilt for an accurate focal length
    ("calibration.max_rms_px", 0.0, "calibration.max_rms_px"),  # no calibration passes
    ("camera.distortion", [-3.0, 0.0, 0.0, 0.0, 0.0], "camera.distortion.0"),  # a fisheye: plumb_bob cannot model it
    ("printed_boards.scale_std", 0.05, "printed_boards.scale_std"),  # 5 %: seen with a ruler
    ("capture.exposure_ms", 50.0, "capture.exposure_ms"),  # longer than the 33.3 ms frame period
    ("validation.scenes.0.name", "scene_a", "validation.scenes"),  # names the main world's datasets
    ("validation.lines", {"scene": "scene_a", "distance_mm": 240, "offsets_deg": [0], "n_stops": 6, "focus": "range"},
     "validation.lines.scene"),  # a scene of the other world
    ("validation.images_per_stop", 0, "validation.images_per_stop"),
    ("validation.seed", -1, "validation.seed"),
    ("sensor.exposure", 1e6, "sensor.exposure"),  # accepted: every image white
    ("sensor.flicker", 0.45, "sensor.flicker"),  # accepted: ~1 % of the images black (gain <= 0)
    ("sensor.blur_sigma_px", 500, "sensor.blur_sigma_px"),
    ("lights", NO_LIGHT, "lights"),  # accepted: every object black
    ("bone_foam.pore_radius_mm", 0.001, "bone_foam.pore_radius_mm"),  # MemoryError: 219 GiB of pore centres
    ("bone_foam.shininess", 1e9, "bone_foam.shininess"),
    ("scapula.length_mm", 2000, "scapula.length_mm"),
    ("scenes.0.name", "a/b", "scenes.0.name"),  # accepted: folders a/b_arc000 inside a folder a
    ("scenes.0.name", ".hidden", "scenes.0.name"),  # accepted: hidden folders like the unfinished .partial ones
    ("scenes.1.name", "scene_a", "scenes"),
    ("scenes.0.distance_mm", 5000, "scenes.0.distance_mm"),
    ("scenes.0.glenoid_tilt_deg", [0, 10], "scenes.0.glenoid_tilt_deg"),  # a block: accepted and ignored
    ("scenes.1.glenoid_tilt_deg", None, "scenes.1.glenoid_tilt_deg"),  # a scapula needs one (was 0, 0 by default)
    ("scenes.1.glenoid_tilt_deg", [0, 170], "scenes.1.glenoid_tilt_deg.1"),  # accepted: the back of the bone
    ("scenes.1.n_clutter", 50, "scenes.1.n_clutter"),
]


@pytest.mark.parametrize("key, value, expected", BAD_VALUES)
def test_bad_value_names_its_key(tiny_raw, key, value, expected):
    assert f"generate.{expected}" in refusal(tiny_raw, f"generate.{key}", value)


def test_every_key_is_set_by_params_yaml():
    """No field has a default that could disagree with params.yaml: leaving any key out is refused (the optional
    keys are required exactly where they mean something: glenoid_tilt_deg with a scapula, a board's sizes with its
    type, the plan's keys with placement planned, and refused elsewhere)."""
    optional = {("SceneSpec", "glenoid_tilt_deg")} | {
        ("GroundTruthBoardParams", key) for key in ("markers_x", "markers_y", "marker_length_mm", "separation_mm",
                                                    "squares_x", "squares_y", "square_mm", "marker_mm", "sizes_mm",
                                                    "max_boards", "plan_sigma_t_mm")}

    def defaults(model):
        for name, field in model.model_fields.items():
            assert field.is_required() or (model.__name__, name) in optional, f"{model.__name__}.{name} has a default"
            for sub in getattr(field.annotation, "__args__", (field.annotation,)):
                if isinstance(sub, type) and hasattr(sub, "model_fields"):
                    defaults(sub)

    defaults(GenerateParams)


def test_dataset_ids_are_the_plan_and_distinct(tiny_params):
    ids = tiny_params.generate.dataset_ids()
    assert ids == [plan.dataset for plan in trips.plan_datasets(tiny_params.generate)]
    assert len(set(ids)) == len(ids)



@pytest.mark.parametrize("distance_mm", [220.0, 300.0])
def test_lines_focused_for_their_range_blur_both_ends_alike(tiny_params, distance_mm):
    """``lines.focus: range`` puts the focus where the thin lens blurs the lines' near end (the model view) and far
    end (the 0-deg line's last stop) alike, between the two and nearer the near end (the circle of confusion grows as
    |d - d_f| / d); ``model_view`` keeps the near end sharp and blurs the far end twice as much."""
    generate, length = tiny_params.generate, tiny_params.protocol.line_length_mm
    lines = generate.lines.model_copy(update={"distance_mm": distance_mm, "focus": "range"})
    near, far = distance_mm, distance_mm + length * (lines.n_stops - 1) / lines.n_stops
    focus = lines.focus_mm(length)
    assert near < focus < (near + far) / 2
    blur = [float(defocus_sigma_px(d, focus, generate.camera)) for d in (near, far)]
    assert blur[0] == pytest.approx(blur[1], rel=1e-9) and blur[0] > 0
    at_model = lines.model_copy(update={"focus": "model_view"})
    assert at_model.focus_mm(length) == near
    assert float(defocus_sigma_px(far, near, generate.camera)) == pytest.approx(2 * blur[1], rel=0.05)
