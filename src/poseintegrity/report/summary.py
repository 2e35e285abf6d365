"""``reports/summary.md``: what held of the two papers' claims, in at most 200 lines, and the links to the rest.

It opens with one screen (:func:`~poseintegrity.report.claims.claims_section`): what the data are, five words, each
claim judged as the paper measured it on each world, and our named variants. Then the papers' figures we reproduce,
each group under the claims it shows; our own predictors and the population (report/beyond_papers.py); the targets
that fail; and a link to each stage's page (:mod:`~poseintegrity.report.stage_pages`), which holds every headline
figure beside the papers' and every target judged. Wall times and speed-ups are on their own page
(:mod:`~poseintegrity.report.timing_page`), so that two runs write the same summary on any machine.
"""

from __future__ import annotations

import json
from pathlib import Path

from poseintegrity.report.beyond_papers import beyond_section
from poseintegrity.report.claims import claims_section, metric_worlds
from poseintegrity.report.headline_file import HEADLINE_FILE
from poseintegrity.report.headlines import HEADLINES
from poseintegrity.report.lookup import absent
from poseintegrity.report.recorded import recorded_section, recorded_source
from poseintegrity.report.stage_pages import PAGES, page_path, row_judgement, section_page, shown
from poseintegrity.report.timing_page import TIMING_PAGE


def read_metrics(metrics_dir: Path) -> dict[str, dict]:
    """Every stage's ``<stage>.json`` of ``metrics_dir`` by stage name (not the headline file stage 07 writes from
    them)."""
    return {p.stem: json.loads(p.read_text()) for p in sorted(Path(metrics_dir).glob("*.json"))
            if p.name != HEADLINE_FILE}


# The papers' figures we reproduce, beside the claims they show: (heading, the stage whose metrics say it ran, its
# figures as (path under reports/, what it shows))
PAPER_FIGURES = [
    ("Long range and next step over static (Windsor et al. Tables I-III, Figs. 5 and 8)", "predictors",
     [("figures/04_fig5_long_range.png", "Fig. 5: mean SPL vs R_i of long range, the MLP and static"),
      ("figures/04_fig8_next_step.png", "Fig. 8: mean SPL vs R_i of next step and static")]),
    ("The MLP and the artifact model (Windsor et al. Table I, Fig. 2)", "fits",
     [("figures/03_fig2_mean_rmse.png", "Fig. 2: mean RMSE of each artifact model from the first 4 stops")]),
    ("Straight lines and PnP variants (Windsor et al. Figs. 7 and 6)", "predictors",
     [("figures/04_fig7_straight_line.png", "Fig. 7: mean SPL vs R_i on the straight lines (mm)"),
      ("figures/04_fig6_pnp.png", "Fig. 6: long range and static on each PnP variant")]),
    ("Marker tracking (Black and Salcudean III, Figs. 5-9)", "tracking",
     [("figures/06_errors.png", "Figs. 4-5: errors without and with the UKF against ground truth"),
      ("figures/06_noise_vs_lag.png", "Figs. 6, 9: noise against lag as the sigmas scale"),
      ("figures/06_success_rate.png", "Fig. 7: the share of frames with the correct pose"),
      ("figures/06_occlusion.png", "Fig. 8: orientation through an occlusion, with and without the gyroscope")]),
]


def figure_lines(metrics: dict[str, dict]) -> list[str]:
    """The papers' figures, each group under the claims it shows; "not run" for a stage without metrics."""
    lines = ["## The papers' figures, ours", ""]
    for heading, stage, figures in PAPER_FIGURES:
        lines += [f"### {heading}", ""]
        if stage not in metrics:
            lines += [f"{absent(metrics, stage)}.", ""]
            continue
        lines += [f"![{text}]({path})" for path, text in figures] + [""]
    return lines


def target_lines(metrics: dict[str, dict]) -> list[str]:
    """How many of the report's targets pass, and each that fails, with its value and where it is explained."""
    judged = [(h, row_judgement(metrics, h)) for h in HEADLINES if h.target != "-"]
    failing = [h for h, passed in judged if passed is False]
    passing = sum(passed is True for _, passed in judged)
    lines = ["## Targets", "", f"Of {len(judged)} targets on the stage pages, {passing} pass, {len(failing)} fail and "
             f"{len(judged) - passing - len(failing)} have no value yet. Those failing, each with its reason on its "
             "page:", ""]
    lines += [f"- [{h.label.lstrip('. ')}]({page_path(section_page(h.shown_in))}): {shown(metrics, h)} against "
              f"{h.target}" for h in failing]
    return [*lines, ""]


def render_summary(metrics: dict[str, dict]) -> str:
    """Markdown: the first screen (report/claims.py), the section on recorded data when the run had any, the papers'
    figures beside their claims, our own predictors, the targets that fail, and the links to each stage's page
    (report/stage_pages.py) and to the machine-dependent figures, which the summary never holds, so that two runs
    write the same summary on any machine."""
    worlds = metric_worlds(metrics)
    recorded = recorded_source(metrics) is not None
    lines = ["# What held of the two papers: the latest run", "",
             "Generated by stage 07 from `reports/metrics/*.json`. The papers: Windsor et al., IEEE RA-L 9(5), 2024 "
             "(localization envelopes); Black and Salcudean, IEEE TIM 2024, DOI 10.1109/TIM.2024.3398108 (marker "
             "tracking); see `docs/references.md`. \"not run\": no metrics yet.", "",
             *claims_section(metrics), *recorded_section(metrics), *figure_lines(metrics),
             *beyond_section(metrics, worlds), *([] if recorded else target_lines(metrics)),
             "## Every stage in detail", ""]
    lines += [f"- [{title}]({page_path(page)})" for page, (title, _) in PAGES.items()]
    lines += [f"- [Wall times and speed-ups]({TIMING_PAGE}): they change with the machine and its load, so they are "
              "there, not here.", "", "## Same numbers on another machine", "", MACHINE_NOTE, ""]
    return "\n".join(lines)


# What README "Same numbers on any x86-64 machine" measured of the figures above
MACHINE_NOTE = ("OpenCV, numpy, OpenBLAS, torch and numba run capped at AVX2 on every x86-64 machine "
                "(`poseintegrity/kernel_pin`), so SIFT and every figure that follows from it are the same on an AVX-512 "
                "machine, and a stage run again with the same params writes the same bytes into every data and metrics "
                "file.")
