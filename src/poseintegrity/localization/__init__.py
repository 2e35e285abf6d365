"""Target localization of Windsor et al. (RA-L 2024), section III-B and IV-C.

dataset (stage-01 datasets, checked on read) -> features (CLAHE + SIFT, cached) -> matching (ratio test) ->
target_model (M_t, III-B) -> evidence (a frame's checked image, matches and ArUco pose, cached for stage 05) -> pnp
(PnP-RANSAC: USAC and classic variants, the classic iteration budget from poseintegrity.ransac; frame_pnp runs a frame's methods,
cached) -> poseintegrity.poses (E_t, E_r)
against the exact pose and the ground_truth (ArUco board) -> frame_artifacts (n_i and friends), realism checks ->
envelope (theta_a, IV-E). extract runs it over datasets on the workers of poseintegrity.parallel; envelope_figures
draws stage 02's figures of how each envelope ends and of how well the predicted error is calibrated.
"""

import lazy_loader

# Names resolve on first use, so that importing one module of the package (its params schema, say) does not
# import all of them: the stage runner and every worker process import only what they run.
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "dataset": ["DatasetError"],
        "envelope": ["actual_envelope", "envelopes"],
        "extract": ["DATA_FLAGS", "extract_all", "extract_dataset", "usable"],
        "pnp": ["METHODS", "solve_pnp_ransac"],
        "target_model": ["TargetModel", "build_target_model"],
    },
)
