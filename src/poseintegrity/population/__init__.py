"""A population of rendered worlds to judge the predictors on (ours, issue 49; ``population/dvc.yaml``).

Windsor et al. judge a predictor on one lab's 21 arcs; there one arc sets the static baseline and often the operating
point, and a headline moves by tens of points with it. Here the worlds are drawn from a declared distribution (the
``population`` section of params.yaml) and each one goes through the paper's protocol (stages 01, 02 and 04 of the
main pipeline, on its own params file): a predictor is then judged by how its share of the ceiling spreads over the
worlds, at its own operating point and at points chosen on other worlds, as a held-out test set judges a model.

    draw.py      a world's params from the declared distribution
    judge.py     every predictor across the worlds: own and transferred operating points, paired comparisons
    hazard.py    the failure hazard trained on the other worlds and judged on each held-out one
    __main__.py  ``python -m poseintegrity.population draw``: a world of the population as a params file
"""
