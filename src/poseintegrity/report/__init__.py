"""What a run reports: the figures the notebooks share, each stage's metrics file, and stage 07's pages.

    figures.py           figures several stages draw (scene gallery, views, tails, population, hazard)
    metrics.py           write_metrics: a stage's reports/metrics/<stage>.json, NaN as null
    summary.py           reports/summary.md: the first screen, the papers' figures, ours, the failing targets, links
    claims.py            the first screen: each claim judged as the paper measured it, its caveat, our variants
    beyond_papers.py     the summary's section on our own predictors and the population
    population_table.py  the population's table (population.json)
    stage_pages.py       reports/stages/<stage>.md: every headline row beside the papers', every target judged
    headlines/           HEADLINES: which metrics keys are rows, the papers' figures and the targets beside them
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
