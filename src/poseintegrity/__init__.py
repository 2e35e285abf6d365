"""poseintegrity: when can a pose estimate be trusted?

Reproductions of Windsor et al., "Forward Prediction of Target Localization Failure Through Pose
Estimation Artifact Modelling" (IEEE RA-L 9(5), 2024) and Black & Salcudean, "Robust Object Pose Tracking for
Augmented Reality Guidance and Teleoperation" (IEEE Transactions on Instrumentation and Measurement, 2024,
DOI 10.1109/TIM.2024.3398108), as a DVC pipeline of papermill notebooks (docs/references.md).

Packages, one per stage of the pipeline (and the papers' sections they implement):

    scenes/              stage 01: the rendered world of Windsor et al. IV (scenes, boards, robot, camera, datasets)
    recorded/            stage 01 on real data: a user's recorded localization datasets, checked and brought in
    localization/        stages 02, 05: target model, SIFT + PnP-RANSAC per frame, ground truth, envelopes (III, IV)
    artifact_models/     stage 03: models of n_i(theta), EMG and other base functions, the MLP (III-C, Fig. 2)
    prediction/          stage 04: the predictors, SPL and R_i, Tables I-III, intervals (III-E, V)
    tracking/            stage 06: Black and Salcudean's detection, correspondence, Kabsch, SR-UKF, section III
    report/              stage 07: the summary, a page per stage, the figures the notebooks share
    population/          a population of rendered worlds to judge the predictors on (population/dvc.yaml)
    params/              the schema of params.yaml, one module per section
    kernel_pin/          every library's CPU kernels pinned to AVX2, before anything loads

Modules every stage shares, each importing only modules of this list:

    config.py                 read and validate params.yaml; the published values as defaults (``published``)
    schema.py                 the params schemas' building blocks
    errors.py                 the one error family, and the checks entry points run at their boundary
    stage.py                  run one stage: its notebook through papermill, then HTML, timing, the lock
    stage_timing.py           each stage's wall time file, and the lines ``make repro`` ends with
    workers.py                map tasks over local processes or a Dask cluster, single-threaded each
    workspace_lock.py         one writer per data folder: the stage runner against open notebooks
    project.py                the project's root, against which notebooks resolve their paths
    atomic_write.py           write a folder or a file atomically; a full disk said in one line
    cache_entry.py            one cache file that proves it is whole and says what it was computed from
    table_checks.py           the parquet tables stages hand each other, checked where they are read
    seeding.py                named random generators from one seed
    resampling.py             clusters resampled with replacement, and percentile intervals
    world_order.py            which world heads a stage's metrics, and which is held out
    paper_results.py          the papers' published figures
    poses.py                  4 x 4 rigid poses T_a_b, E_t and E_r
    lens.py                   Brown-Conrady distortion, the calibrated camera and its YAML file
    calibration.py            Zhang's calibration from ChArUco images
    boards.py                 the ground-truth boards as a dataset describes them
    dataset_meta.py           a dataset's meta.json as its types, checked on read (stage 01 writes, 02 reads)
    grayscale.py              the one conversion of an image to OpenCV's 8-bit grey
    mesh_file.py              a closed triangle mesh read from a file, and its check
    ransac.py                 how many samples classic RANSAC draws
    pose_correspondences.py   how many 2D-3D correspondences a camera pose needs
    denavit_hartenberg.py     a 6R arm's DH parameters and the UR5e's published table
    kinematics.py             forward and inverse kinematics, the Jacobian, manipulability
"""

from poseintegrity.kernel_pin import check_dispatch, pin_dispatch

check_dispatch(pin_dispatch())  # before numpy, OpenBLAS, OpenCV, torch or numba load: they read it once (dispatch)

from poseintegrity.errors import ArgumentError, PoseIntegrityError  # noqa: E402

__all__ = ["ArgumentError", "PoseIntegrityError"]
__version__ = "0.1.0"
