"""The metrics the report tests render: the committed paper-scale run's, the same as runs before issues 49 and 38
wrote them and with the keys issue 38 adds, and a run on recorded data (two worlds, an arc and a line)."""

import copy

from poseintegrity import paper_results as paper
from poseintegrity.report.summary import read_metrics
from repository import ROOT

COMMITTED = read_metrics(ROOT / "reports" / "metrics")  # the paper-scale run
TOLERANCES = paper.TOLERANCES
WORLDS = (("predictors", ""), ("validation", "worlds.validation."))  # (stage, prefix in artifacts.json / pnp.json)
OURS = ("error_long_range", "error_next_step", "error_next_step_observed", "error_combined")


def with_issue_38(metrics: dict) -> dict:
    """The committed metrics with the keys issue 38 adds (CONTRACTS.md), each value distinct."""
    metrics = copy.deepcopy(metrics)
    for w, stage in enumerate(("predictors", "validation")):
        table = metrics[stage]
        table["ceiling"] = {t: {"n_arcs": 17 - w - i, "mean_theta_a": 21.3 + i, "min_theta_a": 14.6 - w,
                                "static_spl": table["static"][t]["max_mean_spl_zero_incursion"],
                                "gain": 0.471 + 0.2 * i + w} for i, t in enumerate(TOLERANCES)}
        for j, predictor in enumerate(("long_range", "next_step", "mlp")):
            for i, t in enumerate(TOLERANCES):
                table[predictor][t]["ceiling_share"] = 0.2 + 0.1 * j + 0.03 * i - 0.5 * w
        for j, predictor in enumerate(OURS):
            table[predictor] = {t: {"max_mean_spl_zero_incursion": 17.0 + j + i + w, "best_k": 2.5 + j,
                                    "best_n_t": None, "decided_by": [], "ceiling_share": 0.55 + 0.01 * j - 0.1 * i}
                                for i, t in enumerate(TOLERANCES)}
    return metrics

def before_issue_49(metrics: dict) -> dict:
    """The metrics as a run before issue 49 wrote them: no interval anywhere (every verdict then undecided)."""
    metrics = copy.deepcopy(metrics)
    for stage in ("predictors", "validation", "tracking"):
        table = metrics[stage]
        table.pop("intervals", None)
        for entry in table.values():
            if isinstance(entry, dict):
                entry.pop("interval", None)
                for value in entry.values():
                    if isinstance(value, dict) and "max_mean_spl_zero_incursion" in value:  # a predictor's entry
                        for key in ("interval", "gain", "relative_gain"):
                            value.pop(key, None)
    return metrics

def before_issue_38(metrics: dict) -> dict:
    """The metrics as a run before issue 38 wrote them: no ceiling, no shares, no error predictors (no intervals), and
    none of what came later (issue 50's hazard)."""
    metrics = before_issue_49(metrics)
    for stage in ("predictors", "validation"):
        table = metrics[stage]
        for key in ("ceiling", *OURS, "hazard", "hazard_next_step", "hazard_long_range"):
            table.pop(key, None)
        for entry in table.values():
            for value in entry.values() if isinstance(entry, dict) else ():
                if isinstance(value, dict):
                    value.pop("ceiling_share", None)
    return metrics


OLD = before_issue_38(COMMITTED)
FIXTURES = {"committed": COMMITTED, "before issue 49": before_issue_49(COMMITTED), "before issue 38": OLD,
            "issue 38": with_issue_38(OLD)}

# a run on recorded data: stage 02's record of one dataset, then the metrics of two worlds
DATASET = {"world": "lab_a", "trajectory": "arc", "dataset": "knee_01", "n_frames": 40, "n_stops": 20,
           "last_stop": 88.0, "localized_share": 0.75, "first_stop_mean_n_inliers": 143.5,
           "theta_a_2mm_3deg": 31.25, "censored_2mm_3deg": False, "theta_a_4mm_10deg": 88.0, "censored_4mm_10deg": True}
RECORDED = {
    "generate": {"source": "/data/mine", "n_datasets": 2, "n_viewing_angle_datasets": 1, "n_straight_line_datasets": 1,
                 "n_images": 70, "worlds": {"lab_a": {"n_datasets": 1}, "lab_b": {"n_datasets": 1}}},
    "artifacts": {"datasets": [DATASET], "realism": {"min_abs_spearman": 0.9, "description_only": "recorded data"},
                  "worlds": {"lab_b": {"datasets": [DATASET | {"world": "lab_b", "trajectory": "line",
                                                              "dataset": "shaft_01", "last_stop": 140.0}]}}},
    "predictors": {"static": {"2mm_3deg": {"max_mean_spl_zero_incursion": 20.5, "best_size": 21.0}},
                   "long_range": {"2mm_3deg": {"max_mean_spl_zero_incursion": 25.0, "best_n_t": 23.0}},
                   "straight_line": {"tolerance": "2mm_3deg"}},
    "validation": {"world": "lab_b", "chosen_on": "lab_a",
                   "transfer": {"long_range": {"2mm_3deg": {"incursion_rate": 0.0, "mean_spl": 12.5}}}},
}
