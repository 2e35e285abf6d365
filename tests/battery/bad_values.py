"""The bad values of the battery, by kind of argument: each a label and a function of the valid value (and a
scratch folder for files) that returns the bad one. ``BENIGN`` labels are conversions a public function may simply
perform (an int32 point array is a valid point array); every other label is an input that must be refused with a
:class:`~poseintegrity.PoseIntegrityError` naming the argument, flagged in the result, or declared correct by the
entry point (``EntryPoint.accepts``).
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

BadValue = Callable[[Any, Path], Any]


def _set(value: Any, index: tuple, x: float) -> np.ndarray:
    array = np.array(value, dtype=float)
    array[index] = x
    return array


def _first(array: np.ndarray) -> tuple:
    return (0,) * np.ndim(array)


def _first_number(mapping: dict) -> str:
    return next(key for key, value in mapping.items() if not isinstance(value, str))


COMMON: dict[str, BadValue] = {
    "None": lambda v, _: None,
    "text": lambda v, _: "text",
}

ARRAY: dict[str, BadValue] = {  # (n, ...) arrays whose first axis counts items (points, samples, stops)
    **COMMON,
    "empty": lambda v, _: np.asarray(v)[:0],
    "one_element": lambda v, _: np.asarray(v)[:1],
    "one_fewer": lambda v, _: np.asarray(v)[:-1],  # lengths that no longer agree with the other arguments
    "wrong_ndim": lambda v, _: np.asarray(v)[None],
    "nan": lambda v, _: _set(v, _first(v), np.nan),
    "inf": lambda v, _: _set(v, _first(v), np.inf),
    "huge": lambda v, _: _set(v, _first(v), 1e300),
    "bool": lambda v, _: np.ones(np.shape(v), bool),
    "text_entries": lambda v, _: np.full(np.shape(v), "x"),
    "int32": lambda v, _: np.round(np.asarray(v)).astype(np.int32),
}
POINTS: dict[str, BadValue] = {  # (n, k) arrays: also a wrong trailing size
    **ARRAY,
    "wrong_trailing": lambda v, _: np.asarray(v)[:, :-1],
    "one_dim": lambda v, _: np.asarray(v).ravel(),
}
MATRIX: dict[str, BadValue] = {  # fixed-shape matrices: K, poses
    **COMMON,
    "wrong_shape": lambda v, _: np.asarray(v)[:-1],
    "nan": lambda v, _: _set(v, _first(v), np.nan),
    "inf": lambda v, _: _set(v, _first(v), np.inf),
    "huge": lambda v, _: _set(v, _first(v), 1e300),
    "zeros": lambda v, _: np.zeros(np.shape(v)),
    "one_size_smaller": lambda v, _: np.asarray(v)[:-1, :-1],  # a 3 x 3 rotation where a 4 x 4 pose is wanted
    "text_entries": lambda v, _: np.full(np.shape(v), "x"),
}
MAPPING: dict[str, BadValue] = {  # a dict of named values (a board spec)
    **COMMON,
    "empty": lambda v, _: {},
    "missing_key": lambda v, _: dict(list(v.items())[1:]),  # the first: a required key
    "text_value": lambda v, _: {**v, _first_number(v): "x"},
    "nan_value": lambda v, _: {**v, _first_number(v): float("nan")},
}
IMAGE: dict[str, BadValue] = {
    **COMMON,
    "empty": lambda v, _: np.asarray(v)[:0],
    "float32": lambda v, _: np.asarray(v).astype(np.float32),
    "float_nan": lambda v, _: _set(v, _first(v), np.nan).astype(np.float32),
    "int32": lambda v, _: np.asarray(v).astype(np.int32),
    "bool": lambda v, _: np.asarray(v) > 0,
    "uint16": lambda v, _: np.asarray(v).astype(np.uint16) * 257,
    "three_channel": lambda v, _: np.repeat(np.asarray(v)[..., None], 3, axis=2),
    "four_channel": lambda v, _: np.repeat(np.asarray(v)[..., None], 4, axis=2),
    "one_dim": lambda v, _: np.asarray(v).ravel(),
}
SCALAR: dict[str, BadValue] = {
    **COMMON,
    "nan": lambda v, _: float("nan"),
    "inf": lambda v, _: float("inf"),
    "huge": lambda v, _: 1e300,
    "negative_huge": lambda v, _: -1e300,
    "bool": lambda v, _: True,
    "array": lambda v, _: np.array([v, v]),
}
TIMESTAMP = {**SCALAR, "negative": lambda v, _: -1.0}


def _bad_copy(value: Any, folder: Path) -> Path:
    """Where the bad version of file ``value`` goes: inside a copy of the scratch folder's top folder
    that holds it (so its siblings are still there) when it lies in the scratch folder, else alone."""
    path = Path(value)
    if folder in path.parents:
        relative = path.relative_to(folder)
        top = folder / "bad" / relative.parts[0]
        if len(relative.parts) > 1 and not top.exists():
            shutil.copytree(folder / relative.parts[0], top)
        top.parent.mkdir(parents=True, exist_ok=True)
        return folder / "bad" / relative
    (folder / "bad").mkdir(parents=True, exist_ok=True)
    return folder / "bad" / path.name


def _file(content: bytes) -> BadValue:
    def write(value: Any, folder: Path) -> Path:
        path = _bad_copy(value, folder)
        path.unlink(missing_ok=True)
        path.write_bytes(content)
        return path
    return write


def _truncated(value: Any, folder: Path) -> Path:
    data = Path(value).read_bytes()
    path = _bad_copy(value, folder)
    path.unlink(missing_ok=True)
    path.write_bytes(data[: len(data) // 2])
    return path


def _missing(value: Any, folder: Path) -> Path:
    path = _bad_copy(value, folder)
    path.unlink(missing_ok=True)
    return path


FILE: dict[str, BadValue] = {  # a file argument: the valid file's name, bad content
    "missing": _missing,
    "zero_bytes": _file(b""),
    "binary_garbage": _file(bytes(range(256)) * 4),
    "non_utf8": _file("caf\u00e9: 1\n".encode("latin-1")),
    "truncated": _truncated,
}


def _with_bom(value: Any, folder: Path) -> Path:
    data = Path(value).read_bytes()
    path = _bad_copy(value, folder)
    path.unlink(missing_ok=True)
    path.write_bytes(b"\xef\xbb\xbf" + data)
    return path


TEXT_FILE: dict[str, BadValue] = {  # a text file a person may have written (a CSV table, YAML, JSON)
    **FILE,
    "bom_only": _file(b"\xef\xbb\xbf"),  # empty, whatever the mark says
    "utf8_bom": _with_bom,  # Excel's "CSV UTF-8" starts with a byte-order mark: the same text (VALID)
}


def _retyped(table: pd.DataFrame) -> pd.DataFrame:
    bad = table.copy()
    column = next(c for c in bad.columns if pd.api.types.is_numeric_dtype(bad[c]) and not pd.api.types.is_bool_dtype(bad[c]))
    bad[column] = bad[column].astype(object)
    bad.loc[bad.index[0], column] = "x"
    return bad


TABLE: dict[str, BadValue] = {  # a table passed between stages
    "empty": lambda v, _: v.iloc[:0],
    "missing_column": lambda v, _: v.drop(columns=v.columns[0]),
    "renamed_column": lambda v, _: v.rename(columns={v.columns[0]: f"{v.columns[0]}_renamed"}),
    "text_in_numeric": lambda v, _: _retyped(v),
    "duplicated_row": lambda v, _: pd.concat([v, v.iloc[:1]], ignore_index=True),
}


def stored(spoil: BadValue) -> BadValue:
    """A parquet file's bad version: its table spoiled by a TABLE value, written where :func:`_bad_copy` puts it."""
    def write(value: Any, folder: Path) -> Path:
        table = spoil(pd.read_parquet(value), folder)
        path = _bad_copy(value, folder)
        path.unlink(missing_ok=True)
        table.to_parquet(path)
        return path
    return write


PARQUET: dict[str, BadValue] = {**FILE, **{label: stored(spoil) for label, spoil in TABLE.items()}}  # a table file

KINDS = {"array": ARRAY, "points": POINTS, "matrix": MATRIX, "image": IMAGE, "scalar": SCALAR,
         "timestamp": TIMESTAMP, "file": FILE, "text_file": TEXT_FILE, "parquet": PARQUET, "table": TABLE,
         "mapping": MAPPING}
FILE_KINDS = {"file", "text_file", "parquet"}  # arguments that are a file, named in errors by the file's name
BENIGN = {"int32"}  # a lossless conversion any numeric entry point may perform
VALID = {"utf8_bom"}  # the valid input in another spelling: must give the valid result (neither refused nor flagged)
