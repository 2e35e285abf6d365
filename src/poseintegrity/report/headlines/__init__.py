"""HEADLINES: every row of the stage pages (``reports/stages/<stage>.md``), assembled from one module per stage's
results, in the order each page shows its section's rows and the summary lists the targets that fail.

A row (:class:`~poseintegrity.report.headlines.sections.Headline`) is a dotted key of ``reports/metrics/<stage>.json``
beside the papers' figure (:mod:`poseintegrity.paper_results`) and the project's target where there is one.

    sections.py          Headline (one row) and the sections rows are shown in, rendered and recorded
    datasets.py          generate.json: the rendered datasets, calibration, robot, board, disk
    realism.py           artifacts.json: the realism bars R1-R10, and the validation world's bars
    ground_truth.py      artifacts.json: R11, what the board's ground truth adds to E_t and E_r
    envelope_causes.py   artifacts.json: how each envelope ends, counted per ending and tolerance
    error_calibration.py artifacts.json: how well the predicted error is calibrated, per world
    pnp_variants.py      pnp.json: n_i, failures, iteration caps and theta_a per PnP variant
    fits.py              fits.json: each artifact model's RMSE and fit statuses; the models' names
    paper_predictors.py  predictors.json: Tables I-III, improvements, live trials, LOSO, flagged fits
    ceiling.py           predictors.json, validation.json: the ceiling and each predictor's share of it
    free_width.py        predictors.json: ours on the free-width EMG, and the tail diagnosis
    model_choice.py      predictors.json: every base function as the long range model, per world
    envelope_rules.py    predictors.json: Tables I-II under each rule for frames without a pose
    error_predictors.py  predictors.json, validation.json: the predictors on the predicted error
    exact_pose.py        predictors.json, validation.json: Tables I-II against the exact pose
    validation.py        validation.json: the main world's operating points applied, and its own sweep
    tracking.py          tracking.json: errors, success rates, marker removals, the paper's pace, lag
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
