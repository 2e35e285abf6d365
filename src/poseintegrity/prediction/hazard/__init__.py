"""The failure hazard (ours, issue 50): the probability that the next stop fails, from evidence that needs no ground
truth, and the predictors that stop the robot on it.

    stop_evidence.py  per stop: levels and trends of what the robot sees (no ground truth)
    risk_sets.py      the discrete-time hazard's rows: which stops were at risk, which failed
    model.py          logistic regression + isotonic calibration on held-out worlds; Brier score, reliability
    stopping.py       hazard_next_step and hazard_long_range: theta_p for every operating point h
    applied.py        stage 04's rows from a trained model file (predict.hazard.model)
"""
