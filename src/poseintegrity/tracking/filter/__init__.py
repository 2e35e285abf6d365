"""The filter (II-E, Alg. 5): state and process model, the unscented transform, the square-root UKF (and the plain
UKF it is checked against), the Cholesky updates, and the tracking loop of one tool, of several, and of a recording.

    model.py             eqs. 3-30: state, process model, P_proc, P_mes
    unscented.py         what both unscented filters share: sigma points, weights, the model calls
    srukf.py             Alg. 5: the square-root UKF
    cholesky.py          Alg. 5's triangular factors: QR-based factor, rank-1 update and downdate
    ukf.py               the plain UKF the SR-UKF is checked against
    tracker.py           one tool: correspondence, partial updates, gyro, innovation gate (ours), restarts
    multi_tool.py        ours: several tools fed by the same frames
    recording_replay.py  a recording folder through detection and the trackers, into a pose table
"""
