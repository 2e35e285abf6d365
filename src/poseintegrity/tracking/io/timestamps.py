"""Timestamps of the tracking input: a clock reading is a finite number of seconds within +-MAX_ABS_TIME_S, in a
recording folder's frames.csv / gyro.csv as in a frame or gyro sample given to the trackers."""

from __future__ import annotations

from poseintegrity.errors import check_scalar

MAX_ABS_TIME_S = 1e12  # a timestamp beyond +-1e12 s (31 700 years) is not a clock reading


def check_timestamp(t: object, name: str = "t") -> float:
    """t as a float, or :class:`~poseintegrity.errors.ArgumentError` naming ``name`` if it is not a finite
    number of seconds within +-MAX_ABS_TIME_S (None, text, bool, NaN, 1e300 are refused)."""
    if type(t) is float and -MAX_ABS_TIME_S <= t <= MAX_ABS_TIME_S:  # the common case, without a call
        return t
    return check_scalar(name, t, low=-MAX_ABS_TIME_S, high=MAX_ABS_TIME_S)
