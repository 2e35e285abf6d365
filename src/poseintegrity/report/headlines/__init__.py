"""HEADLINES: every row of the stage pages (``reports/stages/<stage>.md``), assembled from one module per stage's
results, in the order each page shows its section's rows and the summary lists the targets that fail.

A row (:class:`~poseintegrity.report.headlines.sections.Headline`) is a dotted key of ``reports/metrics/<stage>.json``
beside the papers' figure (:mod:`poseintegrity.paper_results`) and the project's target where there is one.
"""

from __future__ import annotations

from poseintegrity.report.headlines.ceiling import ceiling_rows
from poseintegrity.report.headlines.datasets import DATASET_ROWS
from poseintegrity.report.headlines.envelope_causes import cause_rows
from poseintegrity.report.headlines.envelope_rules import rule_rows
from poseintegrity.report.headlines.error_calibration import calibration_rows
from poseintegrity.report.headlines.error_predictors import error_predictor_rows
from poseintegrity.report.headlines.exact_pose import exact_pose_rows
from poseintegrity.report.headlines.fits import FIT_ROWS
from poseintegrity.report.headlines.free_width import free_width_rows
from poseintegrity.report.headlines.ground_truth import truth_rows
from poseintegrity.report.headlines.model_choice import model_choice_rows
from poseintegrity.report.headlines.paper_predictors import predictor_rows
from poseintegrity.report.headlines.pnp_variants import PNP_ROWS
from poseintegrity.report.headlines.realism import REALISM_ROWS, validation_world_rows
from poseintegrity.report.headlines.sections import SECTIONS, Headline, section_heading
from poseintegrity.report.headlines.tracking import TRACKING_ROWS
from poseintegrity.report.headlines.validation import validation_rows

__all__ = ["HEADLINES", "SECTIONS", "Headline", "section_heading"]

HEADLINES: list[Headline] = [
    *DATASET_ROWS,
    *REALISM_ROWS,
    *truth_rows("artifacts", "realism", "ground_truth"),
    *cause_rows("artifacts", "", "envelopes"),
    *PNP_ROWS,
    *FIT_ROWS,
    *predictor_rows(),
    *ceiling_rows("predictors"),
    *free_width_rows(),
    *model_choice_rows(),
    *rule_rows(),
    *error_predictor_rows(),
    *calibration_rows("main"),
    *calibration_rows("validation"),
    *exact_pose_rows("predictors"),
    *validation_world_rows(),
    *validation_rows(),
    *ceiling_rows("validation"),
    *exact_pose_rows("validation"),
    *TRACKING_ROWS,
]
