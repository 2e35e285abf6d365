"""Schema of the ``extract`` section of ``params.yaml`` (stages 02 and 05).

Windsor et al. published no SIFT, CLAHE or RANSAC settings (docs/references.md, "Camera of the Windsor et al.
experiments"): every value here is our choice and is documented next to its field.
"""

from __future__ import annotations

from pydantic import Field

from poseintegrity.protocol import PnPMethod
from poseintegrity.schema import Section, WorkerCount


class ClaheParams(Section):
    """Contrast limited adaptive histogram equalization before SIFT (paper IV-C)."""

    clip_limit: float = Field(2.0, gt=0, description="cv2.createCLAHE clipLimit")
    tile_grid: int = Field(8, ge=1, le=64, description="tiles per image side (tileGridSize = (n, n))")


class SiftParams(Section):
    """cv2.SIFT_create arguments (Lowe 2004 defaults unless changed)."""

    n_features: int = Field(0, ge=0, description="keep the n strongest keypoints; 0 keeps all")
    n_octave_layers: int = Field(3, ge=1, le=8)
    contrast_threshold: float = Field(0.04, gt=0)
    edge_threshold: float = Field(10.0, gt=0)
    sigma: float = Field(1.6, gt=0)


class RealismParams(Section):
    """The realism checks of the rendered world (:func:`poseintegrity.localization.realism.realism_metrics`); the
    stops they sample are ``protocol.sampled_stops``."""

    max_nfev: int = Field(ge=10, description="curve_fit evaluation budget of each R1 fit")


class ExtractParams(Section):
    """Target localization pipeline, artifact extraction and actual envelopes (stages 02 and 05)."""

    clahe: ClaheParams = ClaheParams()
    sift: SiftParams = SiftParams()
    ratio_test: float = Field(0.8, gt=0, lt=1, description="Lowe ratio: best / second-best distance")
    model_max_reprojection_px: float = Field(
        2.0, gt=0, description="III-B: drop triangulated model points reprojecting worse than this in either view"
    )
    reprojection_threshold_px: float = Field(
        4.0, gt=0, description="RANSAC inlier threshold; also the recount threshold that defines n_i"
    )
    ransac_confidence: float = Field(0.999, gt=0, lt=1)
    usac_max_iterations: int = Field(1000, ge=1, description="USAC_MAGSAC iteration cap (paper path)")
    usac_refine_lm: bool = Field(
        True, description="polish the USAC pose by Levenberg-Marquardt on its inliers (pnp.solve_pnp_ransac)")
    ransac_max_iterations: int = Field(
        100, ge=1,
        description="classic RANSAC iteration cap (stage 05); 100 is OpenCV's default iterationsCount."
        " docs/references.md, 'OpenCV 5': EPnP needed ~10 000 at 80 % outliers, so the classic solvers give up earlier than USAC on low-inlier"
        " frames (where each 5-point EPnP iteration costs ~0.1-0.2 ms)",
    )
    pnp_methods: list[PnPMethod] = Field(
        ["epnp", "p3p", "ap3p", "sqpnp", "iterative"], min_length=1, description="stage 05 (paper Fig. 6)"
    )
    seed: int = Field(0, ge=0, description="seeds every RANSAC run (one derived seed per frame)")
    n_jobs: WorkerCount = Field(2, description="joblib workers over images (-1: all cores)")
    features_dir: str = Field("features", min_length=1, description="SIFT cache, relative to data_dir")
    datasets: list[str] | None = Field(None, description="dataset ids to process; null: every dataset")
    realism: RealismParams
