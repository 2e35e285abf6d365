"""The summary's table of the arcs that decide each headline, and why each of them ends (issue 30).

A headline of Tables I-III is the largest mean SPL at zero incursion; its operating point (n_t, or the static
envelope size) is held where it is by the arcs that would incur at the next bolder point (``predictors.json`` /
``validation.json`` ``<predictor>.<tolerance>.decided_by``, :func:`~poseintegrity.prediction.paper_tables.deciding_datasets`).
Beside each such arc: how its envelope ends (``artifacts.json`` ``envelope_causes``, of its world and tolerance,
:mod:`~poseintegrity.localization.envelope_causes`): theta_a against the ground truth and against the exact pose, the
limit, the cause, what the ground truth moved the criterion by, n_i at theta_a, and how many stops before it had no
trusted ground truth (theta_a was read across them); at its first failing stop, the measured mean E_t beside the
predicted RMS E_t (issue 38: how far the predicted error saw the end coming).
"""

from __future__ import annotations

from poseintegrity.report.number_cell import number_cell

HEADER = ["| world | tolerance | predictor | max mean SPL (deg) | operating point | decided by | theta_a (deg) | "
          "theta_a, exact pose (deg) | limit | ends on | ground truth moved it by | n_i at theta_a | "
          "stops unmeasured | E_t at its end (mm) | predicted E_t there (mm) |",
          "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]


def _cell(value, fmt: str = "{:.2f}") -> str:
    """A number of the table: a float by ``fmt`` (two decimals unless told), "-" where there is none."""
    return number_cell(value, fmt, "-")


def _causes(metrics: dict[str, dict], world: str | None) -> dict[tuple[str, str], dict]:
    """(dataset, tolerance) -> that envelope's row of ``artifacts.json``'s cause table: the first world's (top
    level) when ``world`` is None, else ``worlds.<world>``'s."""
    artifacts = metrics.get("artifacts", {})
    rows = artifacts.get("envelope_causes") if world is None else artifacts.get("worlds", {}).get(world, {}).get(
        "envelope_causes")
    return {(row["dataset"], row["tolerance"]): row for row in rows or []}


def deciding_section(metrics: dict[str, dict]) -> list[str]:
    """Markdown lines: the table of the module docstring for the main world (``predictors.json``) and the held-out
    one (``validation.json``); no lines when neither stage wrote ``decided_by``."""
    lines = []
    for stage in ("predictors", "validation"):
        table = metrics.get(stage, {})
        world = table.get("world") if stage == "validation" else None  # predictors.json: the first world's
        causes = _causes(metrics, world)
        for predictor, entries in table.items():
            for tolerance, entry in sorted(entries.items()) if isinstance(entries, dict) else ():
                if not isinstance(entry, dict) or "decided_by" not in entry:
                    continue
                point = next((entry[key] for key in ("best_n_t", "best_size", "best_k") if entry.get(key) is not None),
                             None)
                head = (f"| {world or 'main'} | {tolerance} | {predictor} | "
                        f"{_cell(entry['max_mean_spl_zero_incursion'])} | {_cell(point, '{:g}')} |")
                for dataset in entry["decided_by"] or [None]:
                    row = causes.get((dataset, tolerance), {})
                    lines.append(f"{head} {dataset or 'none'} | {_cell(row.get('theta_a'))} | "
                                 f"{_cell(row.get('theta_a_exact'))} | {row.get('limit', '-')} | "
                                 f"{row.get('cause', '-')} | {_cell(row.get('truth_shift'), '{:.3f}')} | "
                                 f"{_cell(row.get('n_inliers_at_theta_a'), '{:.1f}')} | "
                                 f"{_cell(row.get('unmeasured_stops'))} | "
                                 f"{_cell(row.get('E_t_at_end'))} | {_cell(row.get('sigma_t_pred_at_end'))} |")
    if not lines:
        return []
    return ["### Which arcs decide each headline, and why they end", "",
            "The arcs that hold each predictor's operating point where it is: at the next bolder point (a smaller n_t "
            "or k, a larger static size) they are the ones that incur. Beside each, how its envelope ends "
            "(`artifacts.json` `envelope_causes`): `estimate` (the estimate's error crosses the tolerance against the "
            "exact pose too), `resolution` (it stays within against the exact pose, and the ground truth, within "
            "R11's bar, moved it across by the amount shown: the estimate's error lies within the ground truth's "
            "resolution of the tolerance), `ground_truth` (moved across by more: a fault), `no_pose`.", "",
            *HEADER, *lines, ""]
