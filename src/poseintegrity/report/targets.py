"""Every target of the report judged: pass or fail, and why.

A target is the project's own bar on a measured value (a row of :data:`~poseintegrity.report.headlines.HEADLINES`).
Where the stage that measured the value judged it itself (the realism bars of ``artifacts.json`` ``realism.passed``),
the row names that judgement (``judged_by``) and the report shows it, so that the count of bars passed and the rows
agree; every other target is a comparison the report reads off the target's text: "<= 3", ">= 90 %", "10-35", "0",
each optionally followed by words ("<= 0.5 (generate.calibration.max_rms_px)"). A value shown as a percentage is
compared with a bar written in percent.
"""

from __future__ import annotations

import operator
import re

from poseintegrity.errors import PoseIntegrityError
from poseintegrity.report.lookup import lookup

_NUMBER = r"[-+]?\d+(?:\.\d+)?"
_COMPARISON = re.compile(rf"^(<=|>=|<|>)\s*({_NUMBER})\s*(%?)")
_RANGE = re.compile(rf"^({_NUMBER})\s*-\s*({_NUMBER})\s*(%?)")
_EQUAL = re.compile(rf"^({_NUMBER})\s*(%?)(?:\s|$)")
_OPERATORS = {"<=": operator.le, ">=": operator.ge, "<": operator.lt, ">": operator.gt}


class UnjudgeableTarget(PoseIntegrityError):
    """A target whose text is no comparison and that names no stage judgement."""


def bar_holds(target: str, value: float) -> bool:
    """Whether ``value`` meets the bar written in ``target`` ("<= 3", ">= 90 %", "10-35", "0", ...); a bar in percent
    reads ``value`` as a share (0.05 is 5 %). Raises :class:`UnjudgeableTarget` for any other text."""
    if match := _COMPARISON.match(target):
        symbol, bar, percent = match.groups()
        return _OPERATORS[symbol](value * (100 if percent else 1), float(bar))
    if match := _RANGE.match(target):
        low, high, percent = match.groups()
        return float(low) <= value * (100 if percent else 1) <= float(high)
    if match := _EQUAL.match(target):
        bar, percent = match.groups()
        return value * (100 if percent else 1) == float(bar)
    raise UnjudgeableTarget(f"target {target!r}: neither a comparison (<=, >=, <, >, a range low-high or a number) nor "
                            "judged by its stage (Headline.judged_by)")


def judgeable(target: str, judged_by: str | None) -> bool:
    """Whether a row's target can be judged: it names its stage's judgement, or its text is a comparison."""
    if target == "-" or judged_by:
        return True
    try:
        bar_holds(target, 0.0)
    except UnjudgeableTarget:
        return False
    return True


def judged(metrics: dict[str, dict], stage: str, target: str, judged_by: str | None, value) -> bool | None:
    """Whether a row meets its target: the stage's own judgement at ``judged_by`` of its metrics, or :func:`bar_holds`
    on ``value``; None without a target or without a value to judge."""
    if target == "-":
        return None
    if judged_by:
        passed = lookup(metrics, stage, judged_by)
        return passed if isinstance(passed, bool) else None
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return bar_holds(target, float(value))
    return None


def target_cell(passed: bool | None, target: str, why: str) -> str:
    """The target column of a row: "-" without a target; else the target, "pass" or "fail" (:func:`judged`) and
    ``why`` when given ("not judged (no value)" when there is nothing to judge)."""
    if target == "-":
        return "-"
    word = "not judged (no value)" if passed is None else ("pass" if passed else "fail")
    return f"{target}: {word}" + (f"; {why}" if why else "")
