"""Target localization of Windsor et al. (RA-L 2024), section III-B and IV-C.

dataset (stage-01 datasets, checked on read) -> features (CLAHE + SIFT, cached) -> matching (ratio test) ->
target_model (M_t, III-B) -> evidence (a frame's checked image, matches and ArUco pose, cached for stage 05) -> pnp
(PnP-RANSAC: USAC and classic variants, the classic iteration budget from poseintegrity.ransac; frame_pnp runs a
frame's methods, cached) -> poseintegrity.poses (E_t, E_r) against the exact pose and the ground_truth (ArUco board)
-> frame_artifacts (n_i and friends), realism checks -> envelope (theta_a, IV-E). extract runs it over datasets on the
workers of poseintegrity.workers; envelope_figures draws stage 02's figures.

    dataset.py                the stage-01 datasets (frames, camera, meta.json), checked on read
    features.py               CLAHE + SIFT keypoints of an image (IV-C), cached on disk
    matching.py               Lowe's ratio test by exact L2 nearest neighbours
    target_model.py           M_t: the target's static sparse feature model, triangulated from the model pair (III-B)
    evidence.py               what a frame gives before any PnP runs (matches, board poses), cached
    pnp.py                    PnP-RANSAC: USAC and the classic variants of Fig. 6 (III-B, IV-C, V-A)
    frame_pnp.py              the PnP results of a frame for every method, cached beside its evidence
    pose_covariance.py        the error a PnP pose is expected to have, propagated to first order (ours)
    consensus.py              how firmly a frame's own data hold its pose, without ground truth (ours)
    ground_truth.py           the ArUco / ChArUco board's pose (IV-C), checked before it judges anything
    kinematic_consistency.py  how far a pose estimate disagrees with the robot's kinematics (ours)
    frame_artifacts.py        a frame's pose estimation artifacts (III-C): the columns of artifacts.parquet
    model_store.py            M_t of each dataset built once on a worker, stored for the frame tasks
    frame_rows.py             one frame's rows: PnP per method, artifacts, E_t / E_r against its ground truth
    extract.py                stage 02/05: every frame of the datasets through the pipeline, one row per PnP method
    envelope.py               the actual envelope theta_a (IV-E), each tolerance judged by poses fine enough for it
    envelope_causes.py        why each envelope ends: the limit that ends theta_a and what caused it
    truth_accuracy.py         R11: the ground truth's own accuracy against the tolerances it judges
    board_warnings.py         the datasets whose board cannot judge the tolerance, named with why
    error_calibration.py      how well the predicted localization error says what the measured one is
    realism.py                the realism bars: properties the paper's datasets had, checked on a rendered world
    summaries.py              per-method and ground-truth summaries of an artifacts table (artifacts.json, pnp.json)
    envelope_figures.py       stage 02's figures: why each envelope ends, how well the predicted error is calibrated
"""

import lazy_loader

# Names resolve on first use, so that importing one module of the package (its params schema, say) does not
# import all of them: the stage runner and every worker process import only what they run.
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "envelope": ["actual_envelope", "envelopes"],
        "extract": ["extract_all", "extract_dataset"],
        "frame_rows": ["DATA_FLAGS", "usable"],
        "pnp": ["METHODS", "solve_pnp_ransac"],
        "target_model": ["TargetModel", "build_target_model"],
    },
)
