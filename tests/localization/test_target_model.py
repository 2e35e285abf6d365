import cv2
import numpy as np

import loc_synthetic as synthetic
from poseintegrity.localization.features import detect_features
from poseintegrity.localization.target_model import build_target_model, triangulate


def test_triangulation_recovers_known_points():
    rng = np.random.default_rng(0)
    X = rng.uniform([-50, -50, 200], [50, 50, 400], (40, 3))  # camera-0 frame, mm
    T_cam1_cam0 = np.eye(4)
    T_cam1_cam0[:3, 3] = [-20.0, 0.0, 0.0]  # camera 1 is 20 mm to the right of camera 0
    x0 = (X @ synthetic.K.T)[:, :2] / X[:, 2:]
    X1 = X + T_cam1_cam0[:3, 3]
    x1 = (X1 @ synthetic.K.T)[:, :2] / X1[:, 2:]
    np.testing.assert_allclose(triangulate(synthetic.K, T_cam1_cam0, x0, x1), X, atol=1e-6)


def model_views(rng, params, target_mask=True):
    plane, target = synthetic.canvas(rng)
    T0 = synthetic.arc_pose(0.0, 0.0)
    T1 = synthetic.shifted(T0, np.array([20.0, 0.0, 0.0]))
    features = tuple(detect_features(synthetic.render(plane, T), params.clahe, params.sift) for T in (T0, T1))
    masks = tuple(synthetic.render(target if target_mask else 0 * target, T, cv2.INTER_NEAREST) for T in (T0, T1))
    return features, masks, (T0, T1)


def test_model_points_lie_on_the_target_in_the_board_frame(extract_params):
    features, masks, poses = model_views(np.random.default_rng(1), extract_params)
    model = build_target_model(features, masks, poses[1] @ np.linalg.inv(poses[0]), poses[0], synthetic.CAMERA,
                               extract_params.ratio_test,
                               extract_params.model_max_reprojection_px)
    assert model.size > 200 and model.descriptors.shape == (model.size, 128)
    x_min, y_min, x_max, y_max = synthetic.TARGET_MM
    margin = 2.0
    assert np.all((model.points[:, 0] > x_min - margin) & (model.points[:, 0] < x_max + margin))
    assert np.all((model.points[:, 1] > y_min - margin) & (model.points[:, 1] < y_max + margin))
    assert np.median(np.abs(model.points[:, 2])) < 1.0  # the target is the plane z = 0


def test_empty_mask_gives_an_empty_model(extract_params):
    features, masks, poses = model_views(np.random.default_rng(2), extract_params, target_mask=False)
    model = build_target_model(features, masks, poses[1] @ np.linalg.inv(poses[0]), poses[0], synthetic.CAMERA,
                               extract_params.ratio_test,
                               extract_params.model_max_reprojection_px)
    assert model.size == 0 and model.points.shape == (0, 3) and model.descriptors.shape == (0, 128)
    assert model.covariances.shape == (0, 3, 3) and np.isnan(model.pixel_noise_px)


def test_model_points_carry_their_triangulation_covariance_along_the_model_rays(extract_params):
    """Each point's covariance (board frame) is symmetric positive definite, elongated along model camera 0's ray
    through it (the depth of a 20 mm pair), and its pixel noise is what the kept points' residuals say."""
    features, masks, poses = model_views(np.random.default_rng(1), extract_params)
    model = build_target_model(features, masks, poses[1] @ np.linalg.inv(poses[0]), poses[0], synthetic.CAMERA,
                               extract_params.ratio_test, extract_params.model_max_reprojection_px)
    assert 0.0 < model.pixel_noise_px < extract_params.model_max_reprojection_px
    cov = model.covariances
    assert cov.shape == (model.size, 3, 3)
    np.testing.assert_allclose(cov, np.swapaxes(cov, 1, 2), atol=1e-12)
    values, vectors = np.linalg.eigh(cov)
    assert np.all(values > 0)
    centre = np.linalg.inv(poses[0])[:3, 3]  # camera 0 in the board frame
    rays = model.points - centre
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    assert np.all(np.abs(np.sum(vectors[:, :, 2] * rays, axis=1)) > 0.99)
    assert np.all(values[:, 2] > 10 * values[:, 1])
