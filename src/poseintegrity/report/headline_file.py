"""``reports/metrics/headline.json``: the few dozen numbers DVC shows (`dvc metrics show` / `diff`, `dvc exp show`),
written by stage 07 from the detailed metrics files, which stay stage outputs (git-tracked, read by the summary).

Per world (:func:`~poseintegrity.report.claims.metric_worlds`) and tolerance: the max mean SPL at zero incursion of
static, long range, next step and the MLP and each one's share of the ceiling with its interval (issue 49: two values,
``_low`` and ``_high``); issue 38's error predictors' shares and intervals, where the metrics hold them, in the world's
``ours`` block (the paper's stay the headline: DVC shows the file's columns in key order, and folds the last ones
first on a narrow terminal; their SPLs stay in the detailed files, so that the file keeps to ~110 values); per world
R11 (what the board's ground truth adds to E_t and E_r, 99th percentile); the tracking success rates. A key the detailed metrics lack is left out, never invented.
"""

from __future__ import annotations

from poseintegrity import paper_results as paper
from poseintegrity.report.beyond_papers import ERROR as OURS
from poseintegrity.report.claims import metric_worlds
from poseintegrity.report.lookup import MISSING, lookup

HEADLINE_FILE = "headline.json"
PAPERS = ("static", "long_range", "next_step", "mlp")  # the paper's predictors (Tables I-II)
TRUTH = {"r11_p99_E_t_mm": "p99_E_t_truth_mm", "r11_p99_E_r_deg": "p99_E_r_truth_deg"}  # headline key: truth_accuracy's
SUCCESS_RATES = ("a_markers4", "a_markers3", "b_markers4", "b_markers3")  # tracking.json success_rates: motion, markers


def _present(pairs) -> dict:
    """The (key, value) pairs whose value the metrics hold."""
    return {key: value for key, value in pairs if value is not MISSING}


def _per_tolerance(metrics: dict[str, dict], stage: str, predictors: tuple[str, ...], with_spl: bool = True) -> dict:
    """``{<tolerance>: {<predictor>: SPL, <predictor>_ceiling_share: share, <predictor>_ceiling_share_low / _high: its
    interval}}`` of the predictors in ``stage``'s metrics (static's share is 0 by definition: not shown; without
    ``with_spl`` the shares alone)."""
    block = {}
    for tolerance in paper.TOLERANCES:
        entry = {predictor: f"{predictor}.{tolerance}" for predictor in predictors}
        values = _present((p, lookup(metrics, stage, f"{key}.max_mean_spl_zero_incursion"))
                          for p, key in entry.items()) if with_spl else {}
        for p, key in entry.items():
            if p == "static":
                continue
            values |= _present([(f"{p}_ceiling_share", lookup(metrics, stage, f"{key}.ceiling_share"))])
            interval = lookup(metrics, stage, f"{key}.interval.ceiling_share")
            if isinstance(interval, list) and len(interval) == 2:
                values |= {f"{p}_ceiling_share_low": interval[0], f"{p}_ceiling_share_high": interval[1]}
        if values:
            block[tolerance] = values
    return block


def headline_metrics(metrics: dict[str, dict]) -> dict:
    """``{<world>: {<tolerance>: {...}, "ours": {<tolerance>: {...}}, "r11_...": ...}, "tracking": {<motion>_markers<n>:
    rate}}`` (:func:`_per_tolerance`) from the detailed metrics (stage name -> dict, as the summary reads them)."""
    headline = {}
    for world in metric_worlds(metrics):
        block = _per_tolerance(metrics, world.stage, PAPERS)
        if ours := _per_tolerance(metrics, world.stage, OURS, with_spl=False):
            block["ours"] = ours
        block |= _present((key, lookup(metrics, "artifacts", f"{world.prefix}realism.truth_accuracy.{name}"))
                          for key, name in TRUTH.items())
        if block:
            headline[world.name] = block
    rates = _present((key, lookup(metrics, "tracking", f"success_rates.{key}")) for key in SUCCESS_RATES)
    return headline | ({"tracking": rates} if rates else {})
