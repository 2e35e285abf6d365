"""One error family for bad input, and the small checks public entry points run once at their boundary.

Every error the project raises on bad input derives from :class:`PoseIntegrityError` (a ``ValueError``), so a
user catches one type; each message names the argument, key or file (and line or row), what was expected and what
was found. The domain errors (``ParamsError``, ``DatasetError``, ``FrameError``, ...) live beside the code that
raises them and derive from it; :class:`ArgumentError` is the error of the checks below, which public functions
call once on what they are given (never inside a per-frame loop), in the spirit of scikit-learn's
``check_array``.
"""

from __future__ import annotations

import codecs
import math
from collections.abc import Iterable, Sequence, Sized
from numbers import Real
from pathlib import Path

import numpy as np


class PoseIntegrityError(ValueError):
    """Base of every error poseintegrity raises on bad input (a value, a file, a params key)."""


class ArgumentError(PoseIntegrityError):
    """An argument of a public function has the wrong type, shape, dtype or value."""


def _describe(value: object) -> str:
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape} and dtype {value.dtype}"
    return f"{type(value).__name__} {value!r:.60}"


def check_array(name: str, value: object, *, shape: Sequence[int | None] | None = None, min_rows: int = 0,
                dtype: str = "float", finite: bool = True, max_abs: float = 1e12, allow_nan: bool = False) -> np.ndarray:
    """``value`` as a numpy array, checked once: ``shape`` (``None`` for any length, e.g. ``(None, 3)``), at least
    ``min_rows`` rows, numeric ``dtype`` kind (``"float"`` converts any real numbers to float64, ``"int"`` needs
    integers), finite entries no larger than ``max_abs`` in magnitude (1e300 is not a coordinate); with
    ``allow_nan`` a NaN entry passes (where NaN is the documented "unknown", e.g. a flagged theta_p).

    Raises :class:`ArgumentError` naming ``name`` and what was found.
    """
    if value is None or isinstance(value, (str, bytes)):
        raise ArgumentError(f"{name}: expected an array, got {_describe(value)}")
    try:
        array = np.asarray(value)
    except (ValueError, TypeError) as error:
        raise ArgumentError(f"{name}: expected an array, got {_describe(value)} ({error})") from None
    if array.dtype.kind not in "iuf" or (dtype == "int" and array.dtype.kind not in "iu"):  # True is not a number
        raise ArgumentError(f"{name}: expected {'integers' if dtype == 'int' else 'real numbers'}, "
                            f"got {_describe(value) if array.dtype == object else 'dtype ' + str(array.dtype)}")
    if dtype == "float":
        array = array.astype(np.float64, copy=False)
    if shape is not None and (array.ndim != len(shape)
                              or any(want is not None and got != want for got, want in zip(array.shape, shape))):
        wanted = "(" + ", ".join("n" if want is None else str(want) for want in shape) + ")"
        raise ArgumentError(f"{name}: expected shape {wanted}, got {array.shape}")
    if array.ndim and len(array) < min_rows:
        raise ArgumentError(f"{name}: needs at least {min_rows} rows, got {len(array)}")
    if finite and array.size and array.dtype.kind == "f":
        bad = ~(np.abs(array) <= max_abs) & ~(allow_nan & np.isnan(array))
        if bad.any():
            index = tuple(int(i) for i in np.argwhere(bad)[0])
            raise ArgumentError(f"{name}: entries must be finite and at most {max_abs:g} in magnitude, "
                                f"got {float(array[index])!r} at index {index if len(index) > 1 else index[0]}")
    return array


def check_scalar(name: str, value: object, *, low: float = -math.inf, high: float = math.inf,
                 low_open: bool = False) -> float:
    """``value`` as a finite float within ``[low, high]`` (``(low, high]`` with ``low_open``); bools and text are
    refused (YAML's ``true`` is not a number)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (Real, np.integer, np.floating)):
        raise ArgumentError(f"{name}: expected a number, got {_describe(value)}")
    number = float(value)
    if not math.isfinite(number) or number < low or number > high or (low_open and number == low):
        interval = f"{'(' if low_open else '['}{low:g}, {high:g}]"
        raise ArgumentError(f"{name}: expected a finite number in {interval}, got {number!r}")
    return number


def check_rotation(name: str, R: object, atol: float = 1e-6) -> np.ndarray:
    """A (3, 3) rotation matrix: orthonormal (R^T R = I to ``atol``) with determinant +1."""
    R = check_array(name, R, shape=(3, 3))
    if not np.allclose(R.T @ R, np.eye(3), atol=atol) or np.linalg.det(R) < 0:
        raise ArgumentError(f"{name}: expected a rotation matrix (orthonormal, det +1), "
                            f"got det {np.linalg.det(R):.6g}, |R^T R - I| {np.abs(R.T @ R - np.eye(3)).max():.3g}")
    return R


def check_pose(name: str, T: object) -> np.ndarray:
    """A (4, 4) homogeneous rigid transform: rotation block orthonormal, last row [0, 0, 0, 1]."""
    T = check_array(name, T, shape=(4, 4))
    check_rotation(f"{name}[:3, :3]", T[:3, :3])
    if not np.allclose(T[3], [0.0, 0.0, 0.0, 1.0]):
        raise ArgumentError(f"{name}: last row must be [0, 0, 0, 1], got {T[3].tolist()}")
    return T


def check_intrinsics(name: str, K: object) -> np.ndarray:
    """A (3, 3) pinhole camera matrix [[fx, s, cx], [0, fy, cy], [0, 0, 1]] with positive focal lengths (pixels)."""
    K = check_array(name, K, shape=(3, 3))
    if K[0, 0] <= 0 or K[1, 1] <= 0:
        raise ArgumentError(f"{name}: focal lengths must be positive, got fx {float(K[0, 0])!r}, fy {float(K[1, 1])!r}")
    if not np.allclose(K[2], [0.0, 0.0, 1.0]) or K[1, 0] != 0:
        raise ArgumentError(f"{name}: expected [[fx, s, cx], [0, fy, cy], [0, 0, 1]], got {K.tolist()}")
    return K


def check_image(name: str, image: object, *, channels: Sequence[int] = (1,),
                dtypes: Sequence[str] = ("uint8",)) -> np.ndarray:
    """An image array: 2-D for one channel or (h, w, c) with ``c`` in ``channels``; dtype in ``dtypes``; not empty."""
    if not isinstance(image, np.ndarray):
        raise ArgumentError(f"{name}: expected an image array, got {_describe(image)}")
    n_channels = 1 if image.ndim == 2 else image.shape[2] if image.ndim == 3 else None
    if n_channels not in channels or image.size == 0:
        raise ArgumentError(f"{name}: expected a non-empty image with {' or '.join(map(str, channels))} "
                            f"channel(s), got shape {image.shape}")
    if str(image.dtype) not in dtypes:
        raise ArgumentError(f"{name}: expected dtype {' or '.join(dtypes)}, got {image.dtype}")
    return image


def check_increasing(name: str, values: object, *, strict: bool = True) -> np.ndarray:
    """A 1-D finite array that increases (strictly, or never decreases with ``strict=False``)."""
    values = check_array(name, values, shape=(None,))
    steps = np.diff(values)
    bad = steps <= 0 if strict else steps < 0
    if bad.any():
        i = int(np.argmax(bad))
        raise ArgumentError(f"{name}: must {'increase' if strict else 'not decrease'}, got {float(values[i])!r} "
                            f"then {float(values[i + 1])!r} at index {i + 1}")
    return values


def not_numbers(values: Iterable[object]) -> np.ndarray:
    """(n,) bool: the entries of a table column (a pandas Series, any sequence) that are neither a real number nor
    missing (None): text such as ``'20.0 mm'``, a bool, a list. Numeric columns have none."""
    if getattr(values, "dtype", np.dtype(object)).kind in "iuf":
        return np.zeros(len(values), dtype=bool)  # type: ignore[arg-type]
    return np.array([not (v is None or (isinstance(v, Real) and not isinstance(v, (bool, np.bool_)))) for v in values],
                    dtype=bool)


def read_text_file(path: Path, error: type[PoseIntegrityError], what: str = "file") -> str:
    """The UTF-8 text of a small input file (a table, a tool list) without the byte-order mark a spreadsheet may
    write first (Excel's "CSV UTF-8"; it would otherwise stick to the first column's name); ``error`` naming the file
    when it cannot be read, is empty, is not UTF-8 or holds NUL bytes (a binary file given by mistake)."""
    try:
        data = Path(path).read_bytes()
    except OSError as problem:
        raise error(f"{path}: cannot read the {what} ({problem.strerror or problem})") from None
    if not data.removeprefix(codecs.BOM_UTF8).strip():
        raise error(f"{path}: the {what} is empty")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as problem:
        raise error(f"{path}: not UTF-8 text (byte {problem.start}); is it a binary file?") from None
    if "\x00" in text:
        raise error(f"{path}: contains NUL bytes; is it a binary file?")
    return text.removeprefix("\ufeff")


def check_same_length(**arrays: Sized) -> int:
    """The common length of the named arrays; :class:`ArgumentError` naming each length if they differ."""
    lengths = {name: len(array) for name, array in arrays.items()}
    if len(set(lengths.values())) > 1:
        raise ArgumentError("lengths must agree: " + ", ".join(f"{name} {n}" for name, n in lengths.items()))
    return next(iter(lengths.values()))
