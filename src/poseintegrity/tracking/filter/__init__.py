"""The filter (II-E, Alg. 5): state and process model, the unscented transform, the square-root UKF (and the plain
UKF it is checked against), the Cholesky updates, and the tracking loop of one tool or several.
"""
