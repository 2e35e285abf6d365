"""How well a recorded dataset's model pair can triangulate its target (Windsor et al. III-B), before any run.

The target model M_t is triangulated from the two model images and their relative pose. Two-view triangulation
with a baseline b across the line of sight, a focal length f (px) and a disparity error delta (px) measures depth
Z = f b / d (d: the disparity, px), so delta moves it by |dZ / dd| delta = Z^2 delta / (f b): the depth error of
every model point, which no later stage can remove (the stereo depth resolution; docs/references.md, "Depth error
of a model pair"). A pair a few mm apart at a few hundred mm gives errors of several mm, past the tolerances the
envelopes are measured at (IV-E).

Measured here, as stage 02 builds M_t (:func:`~poseintegrity.localization.target_model.build_target_model`, its
CLAHE + SIFT, ratio test and reprojection bound): Z, the median depth of the triangulated target points in camera 0;
b, the component of the model baseline across camera 0's optical axis (T_cam1_cam0); f, the mean of fx and fy
(camera.yaml); delta, ``extract.reprojection_threshold_px``, the pixel accuracy the pipeline works at.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from poseintegrity.localization.features import detect_features
from poseintegrity.localization.target_model import build_target_model
from poseintegrity.params.extract import ExtractParams
from poseintegrity.params.protocol import ProtocolParams
from poseintegrity.recorded.reader import Recorded, read_image

MIN_POINTS = 5  # fewer triangulated target points give no distance to speak of (and a model PnP cannot use)


@dataclass(frozen=True)
class PairGeometry:
    """The model pair of one dataset. baseline_mm: |camera 1's centre - camera 0's|; across_mm: its component
    across camera 0's optical axis; distance_mm: median depth of the target points in camera 0 (NaN with fewer
    than :data:`MIN_POINTS`); focal_px; disparity_px (delta); depth_error_mm: Z^2 delta / (f b) (NaN without a
    distance, inf for a baseline along the axis); n_points: target points triangulated."""

    baseline_mm: float
    across_mm: float
    distance_mm: float
    focal_px: float
    disparity_px: float
    depth_error_mm: float
    n_points: int


def pair_geometry(recorded: Recorded, extract: ExtractParams) -> PairGeometry:
    """The model pair of ``recorded`` measured as the module docstring says."""
    images = [read_image(recorded.folder / file)[0] for file in recorded.model_images]
    masks = [np.full_like(image, 255) if mask is None else read_image(recorded.folder / mask)[0]
             for image, mask in zip(images, recorded.model_masks)]
    features = tuple(detect_features(image, extract.clahe, extract.sift) for image in images)
    model = build_target_model(features, tuple(masks), recorded.T_cam1_cam0, np.eye(4), recorded.camera,
                               extract.ratio_test, extract.model_max_reprojection_px)  # points in camera 0
    R, t = recorded.T_cam1_cam0[:3, :3], recorded.T_cam1_cam0[:3, 3]
    centre = -R.T @ t  # camera 1's centre in camera 0's frame
    across = float(np.hypot(centre[0], centre[1]))
    focal = float(np.mean(np.diag(recorded.camera.K)[:2]))
    distance = float(np.median(model.points[:, 2])) if model.size >= MIN_POINTS else float("nan")
    delta = extract.reprojection_threshold_px
    with np.errstate(divide="ignore"):
        error = float(distance**2 * delta / (focal * across)) if across > 0 else float("inf")
    return PairGeometry(float(np.linalg.norm(centre)), across, distance, focal, delta, error, model.size)


def pair_warnings(recorded: Recorded, extract: ExtractParams, protocol: ProtocolParams) -> list[str]:
    """Warning lines about a weak model pair (empty when it is fine): a depth error at the target above the loosest
    E_t of ``protocol.tolerances`` (every envelope would then measure the model's error, not the viewpoint's), or
    too few target points to triangulate at all."""
    geometry = pair_geometry(recorded, extract)
    where = f"{recorded.folder / 'model.csv'}: the model pair"
    if geometry.n_points < MIN_POINTS:
        return [f"{where} triangulates {geometry.n_points} target point(s) (fewer than {MIN_POINTS}): stage 02 cannot "
                f"build a target model from it (a textured target inside both masks, seen from both images?)"]
    loosest = max(E_t for E_t, _ in protocol.tolerances)
    if geometry.depth_error_mm <= loosest:
        return []
    return [f"{where} is {geometry.baseline_mm:.3g} mm apart ({geometry.across_mm:.3g} mm across the line of sight) "
            f"at {geometry.distance_mm:.4g} mm from the target with f = {geometry.focal_px:.5g} px: a disparity error "
            f"of {geometry.disparity_px:g} px (extract.reprojection_threshold_px) gives a depth error of "
            f"{geometry.depth_error_mm:.3g} mm at the target (Z^2 delta / (f b)), more than the loosest tolerance, "
            f"{loosest:g} mm (protocol.tolerances): the envelopes would measure the target model's error; a baseline of "
            f"{geometry.distance_mm**2 * geometry.disparity_px / (geometry.focal_px * loosest):.3g} mm or more keeps it "
            f"within {loosest:g} mm"]
