"""Stage 06's experiments (III), one module each, and the peers they are compared with (filterpy, pykalman).

    study.py             run_study: every experiment below, on workers
    accuracy.py          III-A/B: accuracy and occlusion, noise against lag, the published sigmas
    success.py           III-C: success rates of motions (a) and (b), 4 or 3 markers, two tools (ours)
    paper_pace.py        III-A at the paper's pace (motion (c))
    filter_runs.py       the filter runs, each made once over the recordings that need it
    lag.py               II-F: the filter's lag behind the unfiltered chain
    intervals.py         ours: block-resampled intervals of the success rates and the accuracy
    compute_time.py      Table I: the computation times of the pipeline's subroutines
    robustness.py        ours: a 10 m jump, a recording written to disk and replayed
    small_blobs.py       ours: 8-20 px markers, detected or not
    peers.py             filterpy's and pykalman's UKFs on our model, for agreement and speed
"""
