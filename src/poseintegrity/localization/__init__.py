"""Target localization of Windsor et al. (RA-L 2024), section III-B and IV-C.

features (CLAHE + SIFT, cached) -> matching (ratio test) -> target_model (M_t, III-B) -> pnp (PnP-RANSAC:
USAC and classic variants) -> errors (E_t, E_r) against the exact pose and the ground_truth (ArUco board) ->
artifacts (n_i and friends, realism checks) -> envelope (theta_a, IV-E). extract runs it over datasets.
"""

from poseintegrity.localization.envelope import actual_envelope, envelopes
from poseintegrity.localization.errors import pose_errors
from poseintegrity.localization.extract import extract_all, extract_dataset
from poseintegrity.localization.params import ExtractParams
from poseintegrity.localization.pnp import METHODS, solve_pnp_ransac
from poseintegrity.localization.target_model import TargetModel, build_target_model

__all__ = [
    "ExtractParams", "METHODS", "TargetModel", "actual_envelope", "build_target_model", "envelopes",
    "extract_all", "extract_dataset", "pose_errors", "solve_pnp_ransac",
]
