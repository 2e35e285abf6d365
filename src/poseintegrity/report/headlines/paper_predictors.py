"""The paper's predictors on the main world (``predictors.json``, stage 04, Windsor et al. V, Tables I-III): per
tolerance each one's max mean SPL at zero incursion (deg) and threshold n_t beside the paper's, the relative
improvements, the simulated live trials, n_t relative to the first stop and held out by scene (LOSO), long range on
each PnP variant, and the share of rows resting on a flagged fit."""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.headlines.fits import FIT_STATUS_LABELS
from poseintegrity.report.headlines.sections import Headline


def predictor_rows() -> list[Headline]:
    """Tables I-III per tolerance, each row beside the paper's own value for that tolerance (paper_results.py)."""
    names = {"static": "static baseline", "mlp": "MLP", "long_range": "long range (EMG, eq. 1)",
             "next_step": "next step"}
    rows = []
    for tolerance in paper.TOLERANCES:
        label = paper.TOLERANCE_LABELS[tolerance]
        for predictor, name in names.items():
            rows.append(Headline("predictors", f"{predictor}.{tolerance}.max_mean_spl_zero_incursion",
                                 f"{name}, {label}: max mean SPL at zero incursion (deg)",
                                 f"{paper.WINDSOR_SPL_ZERO_INCURSION[predictor][tolerance]:g}"))
        for predictor in paper.WINDSOR_THRESHOLDS:
            rows.append(Headline("predictors", f"{predictor}.{tolerance}.best_n_t",
                                 f"{names[predictor]}, {label}: its threshold n_t",
                                 f"{paper.WINDSOR_THRESHOLDS[predictor][tolerance]}"))
    improvement = paper.WINDSOR_IMPROVEMENTS
    rows += [
        Headline("predictors", "long_range.relative_improvement", "long range over static (mean of both tolerances)",
                 f"+{improvement['long_range_vs_static']:.1%}", fmt="{:+.1%}"),
        Headline("predictors", "long_range.relative_improvement_vs_mlp", "long range over MLP",
                 f"+{improvement['long_range_vs_mlp']:.1%}", fmt="{:+.1%}"),
        Headline("predictors", "next_step.relative_improvement", "next step over static",
                 f"+{improvement['next_step_vs_static']:.1%}", fmt="{:+.1%}"),
        Headline("predictors", "next_step.relative_improvement_vs_long_range", "next step over long range",
                 f"+{improvement['next_step_vs_long_range']:.1%}", fmt="{:+.1%}"),
        Headline("predictors", "straight_line.relative_improvement", "straight lines (2 mm/3 deg): long range over static",
                 f"+{improvement['straight_line_vs_static']:.1%}", fmt="{:+.1%}"),
        Headline("predictors", "live.incursions", "simulated live trials: incursions (next step, fixed n_t)",
                 f"{paper.WINDSOR_LIVE['incursions']} of {paper.WINDSOR_LIVE['n_trials']}"),
        Headline("predictors", "live.envelope_share", "simulated live trials: share of the actual envelope used",
                 f"{paper.WINDSOR_LIVE['envelope_share']:.1%}", fmt="{:.1%}"),
        Headline("predictors", "live.static_envelope_share", "... static baseline",
                 f"{paper.WINDSOR_LIVE['static_envelope_share']:.1%}", fmt="{:.1%}"),
    ]
    for tolerance in paper.TOLERANCES:
        label = paper.TOLERANCE_LABELS[tolerance]
        for predictor, name in (("long_range_relative", "long range"), ("next_step_relative", "next step")):
            rows += [
                Headline("predictors", f"{predictor}.{tolerance}.max_mean_spl_zero_incursion",
                         f"beyond the paper: {name}, n_t relative to the first stop, {label}: max mean SPL at zero "
                         "incursion (deg)"),
                Headline("predictors", f"{predictor}.{tolerance}.best_fraction", "... its n_t / first-stop mean n_i"),
            ]
        for predictor in ("long_range", "long_range_relative", "next_step", "next_step_relative"):
            rows += [
                Headline("predictors", f"loso.{predictor}.{tolerance}.heldout_incursion_rate",
                         f"beyond the paper, LOSO: {predictor}, {label}, operating point chosen for 0 incursions on "
                         "the other scenes: held-out R_i"),
                Headline("predictors", f"loso.{predictor}.{tolerance}.heldout_mean_spl", "... held-out mean SPL (deg)"),
            ]
    rows += [Headline("predictors", f"pnp.{method}.max_mean_spl_zero_incursion", f"long range on {name}, 2 mm/3 deg "
                      "(deg)", "similar to USAC (Fig. 6)" if method == "epnp" else "-", section="pnp")
             for method, name in (("epnp", "EPnP"), ("p3p", "P3P"), ("ap3p", "AP3P"), ("sqpnp", "SQPnP"))]
    # every row of a predictor rests on a fit: the share resting on a flagged one (still counted, as the robot acted)
    for predictor in ("long_range", "mlp", "next_step"):
        rows += [Headline("predictors", f"fit_status.{predictor}.{status}",
                          f"{names[predictor]}: share of rows (dataset x n_t) on a fit {label}" if status == "ok"
                          else f"... {label}", fmt="{:.1%}")
                 for status, label in FIT_STATUS_LABELS.items()]
    rows.append(Headline("predictors", "live.n_flagged_fits", "simulated live trials that went by a flagged fit"))
    return rows
