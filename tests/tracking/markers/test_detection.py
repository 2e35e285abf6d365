import warnings

import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.errors import ArgumentError
from poseintegrity.tracking.markers.blob_shape import blob_pixels
from poseintegrity.tracking.markers.blob_split import split_by_depth
from poseintegrity.tracking.markers.depth_readings import valid_depth_range
from poseintegrity.tracking.markers.detection import (
    detect_markers, detect_markers_each, points_along_rays, raw_threshold, validate_frame,
)
from poseintegrity.tracking.markers.geometry import MARKER_DIAMETER_M
from poseintegrity.tracking.simulation.frames import Phantom, intrinsics, render_frame, unit_plane_lut

from tracking.track_section import GEOMETRY, TRACK

CAMERA, FRAMES, DETECTION = TRACK.camera, TRACK.frames, TRACK.detection
K = intrinsics(CAMERA)


def _frame(seed=0, phantoms=()):
    rng = np.random.default_rng(seed)
    markers = GEOMETRY @ Rotation.from_rotvec([0.3, 0.2, 0.1]).as_matrix().T + [0.02, -0.01, 0.45]
    ir, depth = render_frame(markers, list(phantoms), CAMERA, FRAMES, MARKER_DIAMETER_M / 2, rng)
    return markers, ir, depth


def _nearest(points, markers):
    return np.linalg.norm(points[:, None] - markers[None], axis=-1).min(axis=0)


def test_detects_every_marker_within_a_few_millimetres():
    markers, ir, depth = _frame()
    assert ir.dtype == np.uint16 and depth.dtype == np.uint16 and ir.shape == (512, 512)
    points = detect_markers(ir, depth, K, DETECTION)
    assert len(points) == 4
    assert _nearest(points, markers).max() < 0.012  # frame-level depth bias (3 mm std) included


def test_lut_and_pinhole_give_the_same_points_and_extrinsics_apply():
    markers, ir, depth = _frame(1)
    by_k = detect_markers(ir, depth, K, DETECTION)
    by_lut = detect_markers(ir, depth, unit_plane_lut(K, 512, 512), DETECTION)
    np.testing.assert_allclose(by_lut, by_k, atol=1e-9)
    T = np.eye(4)
    T[:3, 3] = [1.0, 2.0, 3.0]
    np.testing.assert_allclose(detect_markers(ir, depth, K, DETECTION, T_world_cam=T), by_k + [1.0, 2.0, 3.0])


def test_uint8_input_is_thresholded_directly():
    markers, ir, depth = _frame(2)
    ir8 = (np.clip(ir, 0, 1000) * 255.0 / 1000.0).astype(np.uint8)
    points = detect_markers(ir8, depth, K, DETECTION)
    assert len(points) == 4 and _nearest(points, markers).max() < 0.012


def test_round_phantoms_pass_and_elongated_ones_are_rejected():
    round_ph = Phantom(u=60, v=60, radius_px=3.0, elongation=1.0, angle=0.0, depth_mm=500.0)
    long_ph = Phantom(u=450, v=450, radius_px=2.0, elongation=6.0, angle=0.7, depth_mm=500.0)
    _, ir, depth = _frame(3, [round_ph, long_ph])
    points = detect_markers(ir, depth, K, DETECTION)
    assert len(points) == 5  # the 4 markers and the round phantom


def test_invalid_depth_drops_the_blob_and_bad_frames_do_not_crash():
    markers, ir, depth = _frame(4)
    zeroed = depth.copy()
    zeroed[:, :] = 0
    assert detect_markers(ir, zeroed, K, DETECTION).shape == (0, 3)
    nan_depth = depth.astype(float)
    nan_depth[:] = np.nan
    assert detect_markers(ir, nan_depth, K, DETECTION).shape == (0, 3)
    with pytest.warns(RuntimeWarning, match="lookup table"):
        assert detect_markers(ir, depth, np.zeros((10, 10, 2)), DETECTION).shape == (0, 3)
    with pytest.warns(RuntimeWarning, match="differs"):
        assert detect_markers(ir, depth[:10], K, DETECTION).shape == (0, 3)
    assert validate_frame(ir, depth, K) == ""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert detect_markers(np.zeros((512, 512), np.uint16), depth, K, DETECTION).shape == (0, 3)


def test_bad_units_lut_and_dtype_are_named_not_turned_into_points():
    markers, ir, depth = _frame(5)
    cases = {
        "metres": (ir, depth / 1000.0, K),
        "all zero": (ir, depth, np.zeros((512, 512, 2))),
        "numeric": (ir.astype(bool), depth, K),
    }
    for words, (a, b, c) in cases.items():
        with pytest.warns(RuntimeWarning, match=words):
            assert detect_markers(a, b, c, DETECTION).shape == (0, 3)


@pytest.mark.parametrize(("K_bad", "words"), [
    (np.zeros((3, 3)), r"unproject \(a 3x3 K\): focal lengths must be positive, got fx 0.0"),
    (np.where(np.eye(3, dtype=bool), np.nan, K), "entries must be finite"),
    (K * [[1e-9], [1e-9], [1.0]], "put the image corners beyond 20 on the unit plane"),
])
def test_a_k_that_cannot_unproject_is_named_not_turned_into_nan_points(K_bad, words):
    """A K of zeros gave inf/NaN points (a division by fx = 0), a NaN K NaN points, without a word."""
    _, ir, depth = _frame(6)
    with pytest.warns(RuntimeWarning, match=words):
        assert detect_markers(ir, depth, K_bad, DETECTION).shape == (0, 3)


@pytest.mark.parametrize(("T", "words"), [
    (np.eye(3), r"T_world_cam: expected shape \(4, 4\), got \(3, 3\)"),  # was an IndexError
    (np.full((4, 4), np.nan), "T_world_cam: entries must be finite"),  # was NaN points
    (np.diag([2.0, 2.0, 2.0, 1.0]), r"T_world_cam\[:3, :3\]: expected a rotation matrix"),
])
def test_extrinsics_that_are_not_a_rigid_pose_are_refused_naming_them(T, words):
    _, ir, depth = _frame(6)
    with pytest.raises(ArgumentError, match=words):
        detect_markers(ir, depth, K, DETECTION, T_world_cam=T)


def _small_marker_frame(distance_m, seed):
    """One marker at distance_m seen with a focal length of 250 px: a blob of about 8-20 px."""
    camera = CAMERA.model_copy(update={"focal_px": 250.0})
    rng = np.random.default_rng(seed)
    centre = np.array([[rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), distance_m]])
    ir, depth = render_frame(centre, [], camera, FRAMES, MARKER_DIAMETER_M / 2, rng)
    return centre, ir, depth, intrinsics(camera)


def test_pixel_shape_measure_keeps_small_blobs_the_contour_form_drops():
    kept = {"contour": 0, "pixel": 0}
    for seed in range(40):
        centre, ir, depth, K250 = _small_marker_frame(0.85, seed)
        for measure in kept:
            points = detect_markers(ir, depth, K250, DETECTION.model_copy(update={"shape_measure": measure}))
            kept[measure] += int(len(points) == 1 and np.linalg.norm(points[0] - centre[0]) < 0.015)
    assert kept["pixel"] == 40  # every blob of 8-10 px area
    assert kept["contour"] < 35  # the published polygon form loses a share of them to pixelisation


def test_touching_markers_are_split_into_two_points_near_their_centres():
    rng = np.random.default_rng(7)
    # two markers 9 mm apart side by side at 0.45 m: blobs of radius ~2.9 px whose centres are 4.8 px apart
    markers = np.array([[0.0, 0.0, 0.45], [0.009, 0.0, 0.452]])
    ir, depth = render_frame(markers, [], CAMERA, FRAMES, MARKER_DIAMETER_M / 2, rng)
    merged = detect_markers(ir, depth, K, DETECTION.model_copy(update={"split_touching": False}))
    split = detect_markers(ir, depth, K, DETECTION)
    assert len(merged) == 0  # one non-round blob: dropped by the published tests
    assert len(split) == 2
    assert _nearest(split, markers).max() < 0.006


def test_elongated_reflections_are_not_split_into_markers():
    rng = np.random.default_rng(8)
    found = 0
    for _ in range(30):
        phantom = Phantom(u=rng.uniform(60, 450), v=rng.uniform(60, 450), radius_px=rng.uniform(1.5, 4.0),
                          elongation=rng.uniform(3.0, 8.0), angle=rng.uniform(0, np.pi), depth_mm=500.0)
        ir, depth = render_frame(np.zeros((0, 3)), [phantom], CAMERA, FRAMES, MARKER_DIAMETER_M / 2, rng)
        found += len(detect_markers(ir, depth, K, DETECTION))
    assert found <= 1


def test_a_marker_partly_behind_another_is_found_at_the_depth_jump():
    rng = np.random.default_rng(9)
    # the second marker 40 mm further along nearly the same ray: its image is half hidden by the first, or all
    # but a sliver (centres 1.6 px apart)
    for lateral in ([0.006, 0.002], [0.0035, 0.0]):
        markers = np.array([[0.0, 0.0, 0.45], [*lateral, 0.49]])
        ir, depth = render_frame(markers, [], CAMERA, FRAMES, MARKER_DIAMETER_M / 2, rng)
        merged = detect_markers(ir, depth, K, DETECTION.model_copy(update={"split_touching": False}))
        split = detect_markers(ir, depth, K, DETECTION)
        assert len(merged) == 1 and _nearest(merged, markers).max() > 0.02  # one blob read as one marker: one is lost
        assert len(split) == 2 and _nearest(split, markers).max() < 0.008


def _crowded_frames(n_frames=40):
    """Frames where blobs touch, overlap in depth and meet phantoms: every branch of the blob analysis runs."""
    rng = np.random.default_rng(21)
    for _ in range(n_frames):
        first = np.array([rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rng.uniform(0.4, 0.7)])
        markers = np.vstack([first, first + [rng.uniform(0.002, 0.012), rng.uniform(-0.004, 0.004), rng.uniform(-0.05, 0.05)],
                             GEOMETRY @ Rotation.random(random_state=rng).as_matrix().T + [0.1, 0.1, rng.uniform(0.4, 0.9)]])
        phantoms = [Phantom(u=rng.uniform(20, 490), v=rng.uniform(20, 490), radius_px=rng.uniform(1.5, 4.0),
                            elongation=rng.choice([1.0, rng.uniform(1.0, 8.0)]), angle=rng.uniform(0, np.pi),
                            depth_mm=rng.uniform(150, 850)) for _ in range(3)]
        yield render_frame(markers, phantoms, CAMERA, FRAMES, MARKER_DIAMETER_M / 2, rng)


def test_several_detectors_on_one_frame_find_what_each_finds_alone():
    detectors = [DETECTION, DETECTION.model_copy(update={"split_touching": False}), DETECTION.model_copy(update={"threshold": 180}),
                 DETECTION.model_copy(update={"shape_measure": "contour"}), DETECTION]
    for ir, depth in _crowded_frames():
        together = detect_markers_each(ir, depth, K, detectors)
        assert len(together) == len(detectors)
        for detector, points in zip(detectors, together):
            np.testing.assert_array_equal(points, detect_markers(ir, depth, K, detector))


def test_a_blob_whose_box_spans_less_than_a_depth_cut_has_no_depth_split():
    """The shortcut of the blob analysis: where the valid readings of a blob's bounding box span less than
    depth_split_mm, split_by_depth on its pixels finds no split (and both cases occur here)."""
    cases = {True: 0, False: 0}
    for ir, depth in _crowded_frames():
        mask = cv2.compare(ir, raw_threshold(DETECTION, ir.dtype), cv2.CMP_GT)
        for contour in cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[0]:
            spread = valid_depth_range(depth, *cv2.boundingRect(contour), DETECTION.depth_min_mm, DETECTION.depth_max_mm)
            centres, _ = split_by_depth(blob_pixels(contour), depth, DETECTION)
            cases[spread < DETECTION.depth_split_mm] += 1
            if spread < DETECTION.depth_split_mm:
                assert len(centres) == 0
            elif len(centres):
                cases["split"] = cases.get("split", 0) + 1
    assert cases[True] > 50 and cases[False] > 10 and cases.get("split", 0) > 5


def test_points_along_rays_round_as_numpy_does():
    rng = np.random.default_rng(4)
    xy = rng.uniform(-1.2, 1.2, (500, 2))
    distance_mm = rng.uniform(100.0, 1000.0, 500)
    rays = np.column_stack([xy, np.ones(len(xy))])
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    np.testing.assert_array_equal(points_along_rays(xy, distance_mm), rays * (distance_mm / 1000.0)[:, None])
    assert points_along_rays(np.zeros((0, 2)), np.zeros(0)).shape == (0, 3)
