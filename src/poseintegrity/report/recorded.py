"""The summary's section on recorded data (``generate.source`` a folder, docs/recorded-data.md): what was measured on
the user's datasets, from the metrics the stages wrote.

On recorded data the rendered world's checks do not apply (its realism bars and targets are properties of the
paper's data that a rendered world is held to): the section says what the datasets were (``generate.json``), what
stage 02 measured on each (``artifacts.json`` ``datasets``: frames localized, n_i at the first stop, theta_a per
tolerance), what the predictors reach on the first world's arcs and lines (``predictors.json``, Tables I-III, Fig. 7)
and, with a second world, the first world's operating points applied to it (``validation.json``).
"""

from __future__ import annotations

import math

from poseintegrity.report.number_cell import number_cell

UNITS = {"arc": "deg", "line": "mm"}
PREDICTORS = {"static": "static baseline", "long_range": "long range (eq. 1)", "next_step": "next step"}


def recorded_source(metrics: dict[str, dict]) -> str | None:
    """The recorded folder stage 01 brought in (``generate.json`` ``source``), or None for the rendered world."""
    source = metrics.get("generate", {}).get("source")
    return None if source in (None, "rendered") else str(source)


def _envelope(row: dict, tolerance: str) -> str:
    """theta_a of one dataset and tolerance, e.g. "12.3 deg", ">= 40 deg (censored)" or "none" (nothing measured)."""
    theta_a, unit = row.get(f"theta_a_{tolerance}"), UNITS.get(row["trajectory"], "")
    if theta_a is None or (isinstance(theta_a, float) and math.isnan(theta_a)):
        return "none"
    if row.get(f"censored_{tolerance}"):
        return f">= {theta_a:.3g} {unit} (censored: no failure up to the last stop)"
    return f"{theta_a:.3g} {unit}"


def dataset_rows(metrics: dict[str, dict]) -> list[dict]:
    """Stage 02's per-dataset records of every world (``artifacts.json`` ``datasets`` and ``worlds.*.datasets``)."""
    artifacts = metrics.get("artifacts", {})
    rows = list(artifacts.get("datasets", []))
    for world in artifacts.get("worlds", {}).values():
        rows += world.get("datasets", [])
    return rows


def _tolerances(rows: list[dict]) -> list[str]:
    return sorted({key[len("theta_a_"):] for row in rows for key in row if key.startswith("theta_a_")})


def _predictor_lines(predictors: dict, tolerances: list[str], n_arcs: int, n_lines: int) -> list[str]:
    """Tables I-III on the first world's arcs: per predictor and tolerance, max mean SPL at zero incursion and n_t;
    Fig. 7's figures on its straight lines. ``n_arcs``, ``n_lines``: the world's datasets of each kind."""
    if not n_arcs:
        lines = ["No arcs in this world: Tables I-III (viewing-angle datasets) have nothing to show."]
    else:
        lines = ["| predictor | " + " | ".join(f"{t}: max mean SPL at zero incursion (deg); n_t" for t in tolerances) + " |",
                 "| --- |" + " --- |" * len(tolerances)]
        for predictor, name in PREDICTORS.items():
            cells = []
            for tolerance in tolerances:
                entry = predictors.get(predictor, {}).get(tolerance, {})
                point = entry.get("best_size") if predictor == "static" else entry.get("best_n_t")
                label = "size" if predictor == "static" else "n_t"
                cells.append(f"{number_cell(entry.get('max_mean_spl_zero_incursion'))}; {label} {number_cell(point)}")
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
    line = predictors.get("straight_line", {})
    lines += ["", f"Straight lines ({line.get('tolerance', '-')}): long range "
                  f"{number_cell(line.get('long_range_max_mean_spl_zero_incursion'))} mm, static "
                  f"{number_cell(line.get('static_max_mean_spl_zero_incursion'))} mm of mean SPL at zero incursion "
                  "(none: no operating point without an incursion)." if n_lines else
              "No straight lines in this world: Fig. 7 has nothing to show."]
    return lines


def _transfer_lines(validation: dict, tolerances: list[str], kinds: list[str]) -> list[str]:
    """The first world's operating points on the held-out world (validation.json: arcs, and straight lines with the
    static baseline and the long range predictor), or its note. ``kinds``: the trajectories of the first world's
    datasets (an operating point exists only for those)."""
    if validation.get("world") is None:
        return [f"Held-out world: {validation.get('note', 'none')}."]
    lines = [f"Held-out world `{validation['world']}`: the operating points chosen on `{validation.get('chosen_on')}` "
             "applied unchanged (R_i: incursion rate, eq. 4; mean SPL, eq. 3, in deg on arcs and mm on lines):", ""]
    parts = (("arc", "transfer", PREDICTORS), ("line", "transfer_straight_line",
                                               {key: PREDICTORS[key] for key in ("static", "long_range")}))
    for trajectory, key, predictors in parts:
        if trajectory not in kinds:
            lines += [f"No {trajectory}s in `{validation.get('chosen_on')}`: no {trajectory} operating point to apply.",
                      ""]
            continue
        lines += [f"| {trajectory}s: predictor | " + " | ".join(f"{t}: R_i; mean SPL" for t in tolerances) + " |",
                  "| --- |" + " --- |" * len(tolerances)]
        for predictor, name in predictors.items():
            entry = validation.get(key, {}).get(predictor, {})
            cells = [f"{number_cell(entry.get(t, {}).get('incursion_rate'))}; "
                     f"{number_cell(entry.get(t, {}).get('mean_spl'))}" for t in tolerances]
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        lines.append("")
    return lines[:-1]


def recorded_section(metrics: dict[str, dict]) -> list[str]:
    """Markdown lines of the section on recorded data (empty for the rendered world)."""
    source = recorded_source(metrics)
    if source is None:
        return []
    generate = metrics["generate"]
    worlds = generate.get("worlds", {})
    lines = ["## Your recorded data: what was measured", "",
             f"Recorded datasets from `{source}` (`generate.source`): {generate.get('n_datasets')} datasets "
             f"({generate.get('n_viewing_angle_datasets')} arcs, {generate.get('n_straight_line_datasets')} straight "
             f"lines), {generate.get('n_images')} images with the model pairs; worlds "
             + ", ".join(f"`{world}` ({counts.get('n_datasets')} datasets)" for world, counts in worlds.items()) + ".",
             "Nothing was rendered, so the rendered world's checks do not apply: below, no realism bar or target is "
             "judged, and the papers' figures stand beside yours for orientation only. Stage 06 (marker tracking) runs "
             "on its own simulation whatever the source (a headset recording: `python -m poseintegrity.tracking.replay`, "
             "docs/recorded-data.md).", ""]
    rows = dataset_rows(metrics)
    tolerances = _tolerances(rows)
    if rows:
        lines += ["Per dataset, on the paper's PnP path (`protocol.pnp_method`), theta_a under the headline rule "
                  "(`protocol.envelope.failed_frames`):", "",
                  "| world | dataset | trajectory | frames | stops | last stop | localized | mean n_i, first stop | "
                  + " | ".join(f"theta_a {t}" for t in tolerances) + " |",
                  "| --- |" + " --- |" * (7 + len(tolerances))]
        for row in rows:
            unit = UNITS.get(row["trajectory"], "")
            lines.append(f"| {row['world']} | {row['dataset']} | {row['trajectory']} | {row['n_frames']} | "
                         f"{row['n_stops']} | {number_cell(row['last_stop'])} {unit} | "
                         f"{number_cell(row['localized_share'], '{:.0%}')} | "
                         f"{number_cell(row['first_stop_mean_n_inliers'])} | "
                         + " | ".join(_envelope(row, t) for t in tolerances) + " |")
        lines.append("")
    else:
        lines += ["Stage 02 has not run yet: no per-dataset measurement.", ""]
    chosen = metrics.get("validation", {}).get("chosen_on", next(iter(worlds), "-"))
    kinds = [row["trajectory"] for row in rows if row["world"] == chosen]
    if "predictors" in metrics:
        lines += [f"The predictors on world `{chosen}`, where their operating points are chosen:", "",
                  *_predictor_lines(metrics["predictors"], tolerances, kinds.count("arc"), kinds.count("line")), ""]
    if "validation" in metrics:
        lines += [*_transfer_lines(metrics["validation"], tolerances, kinds), ""]
    return lines
