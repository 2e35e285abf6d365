"""The error family and the boundary checks of poseintegrity.errors, against known answers."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import poseintegrity
from poseintegrity.errors import (ArgumentError, PoseIntegrityError, check_array, check_image, check_increasing,
                                  check_intrinsics, check_pose, check_rotation, check_same_length, check_scalar)


def test_every_project_error_class_derives_from_the_family():
    """A user catches one type: every public exception class defined in the package derives from it (a private one,
    such as config's duplicate-key signal inside the YAML loader, is caught where it is raised)."""
    import importlib
    import inspect
    import pkgutil

    found = []
    for module_info in pkgutil.walk_packages(poseintegrity.__path__, "poseintegrity."):
        module = importlib.import_module(module_info.name)
        for name, cls in inspect.getmembers(module, inspect.isclass):
            if issubclass(cls, BaseException) and cls.__module__ == module.__name__ and not name.startswith("_"):
                found.append(cls)
                assert issubclass(cls, PoseIntegrityError), f"{module.__name__}.{name} is outside the family"
    assert len(found) >= 10
    assert issubclass(PoseIntegrityError, ValueError) and poseintegrity.PoseIntegrityError is PoseIntegrityError


def test_check_array_converts_and_names_what_is_wrong():
    assert check_array("points", [[1, 2, 3]], shape=(None, 3)).dtype == np.float64
    cases = [(None, "expected an array"), ("abc", "expected an array"), ([[1, 2]], r"expected shape \(n, 3\)"),
             ([[np.nan, 0, 0]], "entries must be finite"), ([[1e300, 0, 0]], "entries must be finite"), ([[True, False, True]], "expected real numbers"),
             ([["a", 1, 2]], "expected real numbers"), ([[1, 2], [3]], "expected an array")]
    for value, message in cases:
        if message is None:
            check_array("points", value, shape=(None, 3))
            continue
        with pytest.raises(ArgumentError, match=f"^points: {message}"):
            check_array("points", value, shape=(None, 3))
    with pytest.raises(ArgumentError, match="at least 3 rows, got 2"):
        check_array("points", np.zeros((2, 3)), shape=(None, 3), min_rows=3)
    with pytest.raises(ArgumentError, match="integers"):
        check_array("ids", [1.5], dtype="int")


def test_check_scalar_refuses_booleans_text_and_out_of_range():
    assert check_scalar("dt", 3, low=0.0, low_open=True) == 3.0
    for value in (True, "1", None, np.nan, 1e400, -1.0, 0.0):
        with pytest.raises(ArgumentError, match="^dt: expected"):
            check_scalar("dt", value, low=0.0, low_open=True)


def test_rotation_and_pose_checks_agree_with_scipy():
    R = Rotation.from_rotvec([0.3, -0.2, 0.1]).as_matrix()
    assert np.array_equal(check_rotation("R", R), R)
    with pytest.raises(ArgumentError, match="rotation matrix"):
        check_rotation("R", R * 1.01)
    with pytest.raises(ArgumentError, match="rotation matrix"):
        check_rotation("R", -R)  # a reflection: det -1
    T = np.eye(4)
    T[:3, :3] = R
    check_pose("T_cam_board", T)
    T[3, 0] = 1.0
    with pytest.raises(ArgumentError, match=r"T_cam_board: last row"):
        check_pose("T_cam_board", T)


def test_intrinsics_need_positive_focal_lengths():
    K = np.array([[600.0, 0, 320], [0, 600, 240], [0, 0, 1]])
    check_intrinsics("K", K)
    for bad, message in ((np.diag([0.0, 600, 1]), "focal lengths"), (K * 2, r"\[\[fx"), (np.zeros((3, 3)), "focal")):
        with pytest.raises(ArgumentError, match=message):
            check_intrinsics("K", bad)


def test_image_check_names_channels_and_dtype():
    check_image("image", np.zeros((4, 5), np.uint8))
    with pytest.raises(ArgumentError, match="1 channel"):
        check_image("image", np.zeros((4, 5, 3), np.uint8))
    with pytest.raises(ArgumentError, match="dtype uint8, got float32"):
        check_image("image", np.zeros((4, 5), np.float32))
    with pytest.raises(ArgumentError, match="non-empty"):
        check_image("image", np.zeros((0, 5), np.uint8))


def test_increasing_and_lengths():
    check_increasing("theta_deg", [0, 1, 2])
    check_increasing("t", [0, 1, 1], strict=False)
    with pytest.raises(ArgumentError, match="theta_deg: must increase, got 1.0 then 1.0 at index 2"):
        check_increasing("theta_deg", [0, 1, 1])
    assert check_same_length(theta=[1, 2], n=[3, 4]) == 2
    with pytest.raises(ArgumentError, match="theta 2, n 3"):
        check_same_length(theta=[1, 2], n=[3, 4, 5])
