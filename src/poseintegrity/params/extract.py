"""Schema of the ``extract`` section of ``params.yaml`` (stages 02 and 05).

Windsor et al. published no SIFT, CLAHE or RANSAC settings (docs/references.md, "Camera of the Windsor et al.
experiments"): every value is our choice, set in ``params.yaml`` and documented there; no field has a default here,
so that the code can never run with a value that disagrees with the file. The bounds refuse what cannot be meant
(a ratio test of 1 keeps every match, a 50 px RANSAC threshold accepts any pose); the PnP method of the paper's
tables is ``protocol.pnp_method``, which stage 02 runs, and stage 05 runs ``pnp_methods`` beside it.
"""

from __future__ import annotations

from pydantic import Field, ValidationInfo, model_validator

from poseintegrity.params.protocol import PnPMethod
from poseintegrity.ransac import minimal_sample_size, ransac_iterations
from poseintegrity.schema import KeyRule, Section, Seed, distinct

MAX_PIXELS = 20.0  # a reprojection bound beyond this accepts wrong poses at 968 x 608 px: a setting gone astray
MAX_ITERATIONS = 1_000_000  # RANSAC iteration caps: 10^6 EPnP hypotheses are ~75 s per frame (bench_localization.py)


class ClaheParams(Section):
    """Contrast limited adaptive histogram equalization before SIFT (paper IV-C)."""

    clip_limit: float = Field(gt=0, le=255, description="cv2.createCLAHE clipLimit (a contrast factor per tile)")
    tile_grid: int = Field(ge=1, le=64, description="tiles per image side (tileGridSize = (n, n))")


class SiftParams(Section):
    """cv2.SIFT_create arguments (Lowe 2004's values in params.yaml)."""

    n_features: int = Field(ge=0, le=100_000, description="keep the n strongest keypoints; 0 keeps all (10^5 "
                                                          "descriptors are 51 MB per frame and worker)")
    n_octave_layers: int = Field(ge=1, le=8, description="layers per octave of the difference-of-Gaussian pyramid")
    contrast_threshold: float = Field(gt=0, lt=1, description="drops weak extrema (image intensities scaled to 0..1)")
    edge_threshold: float = Field(ge=1, le=100, description="drops edge-like extrema: ratio of principal curvatures")
    sigma: float = Field(gt=0, le=10, description="Gaussian blur of octave 0, px")


class RealismParams(Section):
    """The realism checks of the rendered world (:func:`poseintegrity.localization.realism.realism_metrics`); the
    stops they sample are ``protocol.sampled_stops``."""

    max_nfev: int = Field(ge=10, le=100_000, description="curve_fit evaluation budget of each R1 fit")


class GroundTruthParams(Section):
    """When a board pose may serve as ground truth (:mod:`poseintegrity.localization.ground_truth`): its groups must
    agree with each other, enough of them must remain, and its predicted uncertainty must be small beside the
    tolerances it judges."""

    consistency_factor: float = Field(
        ge=2, le=100, description="a group (a marker's 4 corners, a ChArUco corner) is dropped when its distance from "
        "the pose fitted to the others exceeds this times that fit's residual scale")
    noise_floor_px: float = Field(
        gt=0, le=5, description="floor of the residual scale: the check never calls a point off by less than "
        "consistency_factor times this, and the predicted uncertainty never assumes less noise")
    min_markers: int = Field(ge=2, le=1000, description="ArUco GridBoard: consistent markers a trusted pose needs")
    min_corners: int = Field(ge=4, le=1000, description="ChArUco board: consistent corners a trusted pose needs")
    max_sigma_t_mm: float = Field(gt=0, le=100, description="predicted RMS error of the board origin above which the "
                                                            "pose is no ground truth")
    max_sigma_r_deg: float = Field(gt=0, le=90, description="the same for the rotation")


class ConsensusParams(Section):
    """Per-frame evidence about a pose that needs no ground truth (issue 50,
    :mod:`poseintegrity.localization.consensus`): how its inliers' bootstrap and RANSAC re-runs with other seeds
    agree with it. A count of 0 turns its part off (its columns NaN)."""

    n_bootstrap: int = Field(ge=0, le=1000, description="resamples of a frame's inliers, each re-solved from its pose: "
                                                        "consensus_t_mm / consensus_r_deg are their RMS deviation "
                                                        "(1000 solves are ~0.2 s per frame and method)")
    n_reruns: int = Field(ge=0, le=100, description="RANSAC re-runs with other seeds: consensus_elsewhere is the "
                                                    "share landing elsewhere (100 USAC re-runs are ~0.6 s per frame)")
    elsewhere_mm: float = Field(gt=0, le=100, description="a re-run's pose is elsewhere beyond this translation "
                                                          "from the frame's")
    elsewhere_deg: float = Field(gt=0, le=90, description="... or beyond this rotation")


class ExtractParams(Section):
    """Target localization pipeline, artifact extraction and actual envelopes (stages 02 and 05)."""

    clahe: ClaheParams
    sift: SiftParams
    ratio_test: float = Field(gt=0, lt=1, description="Lowe ratio: best / second-best distance (III-B matching)")
    model_max_reprojection_px: float = Field(
        gt=0, le=MAX_PIXELS,
        description="III-B: drop triangulated model points reprojecting worse than this in either view")
    reprojection_threshold_px: float = Field(
        gt=0, le=MAX_PIXELS, description="RANSAC inlier threshold; also the recount threshold that defines n_i")
    ransac_confidence: float = Field(gt=0, lt=1)
    usac_max_iterations: int = Field(ge=1, le=MAX_ITERATIONS, description="USAC_MAGSAC iteration cap (paper path)")
    usac_refine_lm: bool = Field(
        description="polish the USAC pose by Levenberg-Marquardt on its inliers (pnp.solve_pnp_ransac)")
    ransac_budget_inlier_ratio: float = Field(
        gt=0, le=1,
        description="classic RANSAC (stage 05): the iteration cap of each method is sized to draw an all-inlier sample "
        "with ransac_confidence at this inlier ratio (ransac.ransac_iterations); OpenCV stops earlier once its best "
        "consensus makes the confidence reached. Frames below it may fail, with the reason said",
    )
    pnp_methods: distinct(PnPMethod) = Field(
        min_length=1, description="stage 05 (paper Fig. 6), beside protocol.pnp_method (which stage 02 runs)")
    seed: Seed = Field(description="seeds every RANSAC run (one derived seed per frame)")
    features_dir: str = Field(min_length=1, description="SIFT and per-frame caches, relative to data_dir")
    datasets: distinct(str) | None = Field(
        min_length=1, description="dataset ids to process (names of index.parquet); null: every dataset")
    realism: RealismParams
    ground_truth: GroundTruthParams
    consensus: ConsensusParams

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> ExtractParams:
        protocol = (info.context or {}).get("protocol")
        if protocol is not None and protocol.pnp_method in self.pnp_methods:
            raise KeyRule("pnp_methods", f"must not repeat protocol.pnp_method ({protocol.pnp_method}): stage 02 "
                                         f"runs it and stage 05 shows it beside these, got {self.pnp_methods}")
        s = max(minimal_sample_size(method) for method in self.pnp_methods)
        cap = ransac_iterations(self.ransac_confidence, self.ransac_budget_inlier_ratio, s)
        if cap > MAX_ITERATIONS:
            raise KeyRule("ransac_budget_inlier_ratio", f"classic RANSAC would draw up to {cap} samples of {s} per "
                                                        f"frame at ransac_confidence {self.ransac_confidence}, more "
                                                        f"than {MAX_ITERATIONS}: raise it")
        if self.datasets is not None and any(not name.strip() for name in self.datasets):
            raise KeyRule("datasets", f"dataset ids are non-empty names, got {self.datasets}")
        return self
