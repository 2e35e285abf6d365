"""Camera paths of IV-D: the geometric facts the protocol states, checked on the poses."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poseintegrity.config import load_params
from poseintegrity.scenes import trajectories
from poseintegrity.scenes.camera import Intrinsics, look_at
from repository import ROOT

CAMERA = load_params(ROOT / "params.yaml").generate.camera

AIM = np.array([10.0, -20.0, 80.0])


def model_view():
    return trajectories.model_pair(AIM, np.array([0.2, -0.6, 0.77]) / np.linalg.norm([0.2, -0.6, 0.77]), 350.0,
                                   20.0)


def angle_between_deg(R_a, R_b) -> float:
    return float(np.degrees((Rotation.from_matrix(R_a).inv() * Rotation.from_matrix(R_b)).magnitude()))


def test_look_at_is_a_rotation_pointing_at_the_target():
    T = look_at(np.array([300.0, -200.0, 400.0]), AIM)
    R = T[:3, :3]
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)
    direction = (AIM - T[:3, 3]) / np.linalg.norm(AIM - T[:3, 3])
    np.testing.assert_allclose(R[:, 2], direction, atol=1e-12)
    assert R[2, 1] < 0  # image "down" (camera +y) points down in the world


def test_model_pair_is_a_pure_x_translation():
    T0, T1 = model_view()
    np.testing.assert_allclose(T0[:3, :3], T1[:3, :3])
    np.testing.assert_allclose(np.linalg.inv(T0) @ T1[:, 3], [20.0, 0, 0, 1], atol=1e-9)


@pytest.mark.parametrize("azimuth", [0.0, 90.0, 270.0])
def test_arc_stops_change_viewing_angle_by_theta_and_keep_the_target_centred(azimuth):
    T0, _ = model_view()
    stops = trajectories.arc(T0, AIM, azimuth, 45.0, 20)
    assert [s.theta_deg for s in stops] == pytest.approx(2.25 * np.arange(20))  # from the model view
    np.testing.assert_allclose(stops[0].T_world_cam, T0)
    K = Intrinsics.from_params(CAMERA).K
    for stop in stops:
        assert angle_between_deg(T0[:3, :3], stop.T_world_cam[:3, :3]) == pytest.approx(stop.theta_deg, abs=1e-9)
        assert np.linalg.norm(stop.T_world_cam[:3, 3] - AIM) == pytest.approx(350.0)
        aim_cam = np.linalg.inv(stop.T_world_cam) @ np.append(AIM, 1)
        uv = K @ aim_cam[:3] / aim_cam[2]
        np.testing.assert_allclose(uv[:2], K[:2, 2], atol=1e-6)  # the target stays at the principal point
    # the first step moves along the image direction given by the azimuth
    step = np.linalg.inv(T0) @ np.append(stops[1].T_world_cam[:3, 3], 1)
    direction = step[:2] / np.linalg.norm(step[:2])
    np.testing.assert_allclose(direction, [np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))], atol=0.02)


def test_arcs_of_different_azimuths_diverge():
    T0, _ = model_view()
    ends = [trajectories.arc(T0, AIM, az, 45.0, 20)[-1].T_world_cam[:3, 3] for az in (0.0, 90.0, 270.0)]
    assert min(np.linalg.norm(a - b) for i, a in enumerate(ends) for b in ends[i + 1:]) > 100.0


@pytest.mark.parametrize("offset", [0.0, 5.0, 15.0])
def test_line_moves_back_along_the_optical_axis(offset):
    T0, _ = model_view()
    stops = trajectories.line(T0, AIM, offset, 150.0, 15)
    start = stops[0].T_world_cam[:3, 3]
    for k, stop in enumerate(stops):
        assert stop.x_mm == pytest.approx(10.0 * k)
        assert np.linalg.norm(stop.T_world_cam[:3, 3] - start) == pytest.approx(10.0 * k)
        np.testing.assert_allclose(stop.T_world_cam[:3, :3], stops[0].T_world_cam[:3, :3])
        assert angle_between_deg(T0[:3, :3], stop.T_world_cam[:3, :3]) == pytest.approx(offset, abs=1e-9)
        assert stop.theta_deg == offset
