"""Target localization of Windsor et al. (RA-L 2024), section III-B and IV-C.

dataset (stage-01 datasets, checked on read) -> features (CLAHE + SIFT, cached) -> matching (ratio test) ->
target_model (M_t, III-B) -> evidence (a frame's checked image, matches and ArUco pose, cached for stage 05) -> pnp
(PnP-RANSAC: USAC and classic variants) -> poseintegrity.poses (E_t, E_r) against the exact pose and the ground_truth (ArUco
board) -> frame_artifacts (n_i and friends), realism checks -> envelope (theta_a, IV-E). extract runs it over
datasets on the workers of poseintegrity.parallel.
"""

from poseintegrity.localization.dataset import DatasetError
from poseintegrity.localization.envelope import actual_envelope, envelopes
from poseintegrity.localization.extract import DATA_FLAGS, extract_all, extract_dataset, usable
from poseintegrity.localization.params import ExtractParams
from poseintegrity.localization.pnp import METHODS, solve_pnp_ransac
from poseintegrity.localization.target_model import TargetModel, build_target_model

__all__ = [
    "DATA_FLAGS", "DatasetError", "ExtractParams", "METHODS", "TargetModel", "actual_envelope", "build_target_model",
    "envelopes", "extract_all", "extract_dataset", "solve_pnp_ransac", "usable",
]
