"""One battery of bad inputs through every registered public entry point (registry.py), as scikit-learn's
``check_estimator`` does for estimators.

For every entry point, argument and bad value of that argument's kind (bad_values.py) the outcome must be one of:
a :class:`~poseintegrity.PoseIntegrityError` whose message names the argument (or file), a result the entry point
flags as failed, or the correct result (a lossless conversion, or a label the entry point declares correct). Any
other exception type, or a plain result for a bad value, fails. ``python tests/battery/census.py`` prints the
outcomes counted by class.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from poseintegrity import PoseIntegrityError

from bad_values import BENIGN, FILE_KINDS, KINDS, VALID
from registry import entry_points

CASES = [(name, argument, label) for name, entry in entry_points().items()
         for argument, kind in entry.arguments.items() for label in [*KINDS[kind], *entry.cases.get(argument, {})]]


def outcome(name: str, argument: str, label: str, tmp_path: Path) -> str:
    """``"refused"``, ``"flagged"``, ``"accepted"`` (correct by declaration or conversion) or a failure:
    ``"raw <ExceptionType>"``, ``"unnamed"`` (a family error that does not name the argument) or ``"silent"``;
    for a VALID label (the valid input spelled otherwise) anything but ``"accepted"`` is ``"not accepted: ..."``."""
    entry = entry_points()[name]
    arguments = dict(entry.valid(tmp_path))
    bad_value = {**KINDS[entry.arguments[argument]], **entry.cases.get(argument, {})}[label]
    arguments[argument] = bad_value(arguments[argument], tmp_path)
    word = entry.names.get(argument, argument)
    if entry.arguments[argument] in FILE_KINDS:  # a file is named by its name (its folder for a recording)
        word = entry.names.get(argument, Path(arguments[argument]).name)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with np.errstate(all="ignore"):
                result = entry.call(arguments)
    except PoseIntegrityError as error:
        return f"not accepted: {error}" if label in VALID else "refused" if word.lower() in str(error).lower() else "unnamed"
    except Exception as error:  # noqa: BLE001 - the battery classifies every other exception as a failure
        return f"raw {type(error).__name__}"
    if entry.flagged(result):
        return "not accepted: flagged" if label in VALID else "flagged"
    if label in BENIGN or label in VALID or label in entry.accepts.get(argument, set()):
        return "accepted"
    return "silent"


def test_every_entry_point_gives_a_valid_result_on_valid_input(tmp_path):
    for name, entry in entry_points().items():
        folder = tmp_path / name.replace(" ", "_").replace(":", "_")
        folder.mkdir()
        result = entry.call(entry.valid(folder))
        assert not entry.flagged(result), f"{name} flags its valid input"


@pytest.mark.parametrize(("name", "argument", "label"), CASES, ids=[f"{n}:{a}:{l}" for n, a, l in CASES])
def test_bad_input_is_refused_by_name_or_flagged(name, argument, label, tmp_path):
    assert outcome(name, argument, label, tmp_path) in {"refused", "flagged", "accepted"}
