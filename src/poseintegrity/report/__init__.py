"""What a run reports: the figures the notebooks share, each stage's metrics file, and stage 07's pages.

    figures.py           figures several stages draw (scene gallery, views, tails, population, hazard)
    metrics.py           write_metrics: a stage's reports/metrics/<stage>.json, NaN as null
    summary.py           reports/summary.md: the first screen, the papers' figures, ours, the failing targets, links
    claims.py            the first screen: each claim judged as the paper measured it, its caveat, our variants
    beyond_papers.py     the summary's section on our own predictors and the population
    population_table.py  the population's table (population.json)
    stage_pages.py       reports/stages/<stage>.md: every headline row beside the papers', every target judged
    headlines/           HEADLINES: which metrics keys are rows, the papers' figures and the targets beside them
      __init__.py          HEADLINES assembled from the modules below, in the pages' order
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
    targets.py           a target judged pass or fail: by its stage, or read off its bar
    deciding.py          the arcs that decide each headline, and how each ends
    recorded.py          the summary's section on the user's recorded datasets
    headline_file.py     reports/metrics/headline.json, the few numbers DVC compares
    timing_page.py       reports/timing.md, the machine-dependent figures
    reader.py            Reader: a metrics value as shown, its interval, "not run" / "not measured"
    lookup.py            a dotted key of a stage's metrics, MISSING when absent
    number_cell.py       a number as a table cell: a float rounded, None / NaN as the table's word
    names.py             the predictors' names as the report writes them
"""
