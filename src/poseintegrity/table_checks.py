"""The tables stages hand each other, checked where they are read: one small check (and reader) per table.

    artifacts.parquet, pnp_variants.parquet   one row per (dataset, stop, image, method): :func:`check_artifacts`
    envelopes.parquet, pnp_envelopes.parquet  one row per (dataset, trajectory, method, tolerance, rule):
                                              :func:`check_envelopes`
    fits/fig2_rmse.parquet                    one row per (trajectory, dataset, k, model): :func:`check_fig2_rmse`

Each check raises :class:`TableError` naming the table, the column and the first offending row (its key) when a
required column is missing, the table is empty, a key repeats (a duplicated row would count a dataset twice in
Fig. 2 and every SPL curve), a column has the wrong dtype or a value outside its range, or an expected dataset is
absent. The package functions that take these tables (envelopes, dataset_series, attach_envelopes,
with_pnp_variants, mean_rmse) call them once on what they are given; the ``read_*`` functions read a file and
check it, and the notebooks read every table through them. Hand-written with pandas (no new dependency): checking a
75 600-row artifacts table takes ~80 ms.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow

from poseintegrity.errors import PoseIntegrityError, not_numbers

TRAJECTORIES = ("arc", "line")
ARTIFACT_KEYS = ("dataset", "stop", "image", "method")
ARTIFACT_COLUMNS = ("world", "dataset", "trajectory", "stop", "image", "theta_deg", "x_mm", "method", "status",
                    "n_inliers", "E_t_mm", "E_r_deg")
# stage 02's evidence without ground truth (localization/consensus.py, which names them from here): not required
# (older tables lack them), checked where present
CONSENSUS_COLUMNS = ("consensus_t_mm", "consensus_r_deg", "consensus_elsewhere", "consensus_rerun_t_mm")
STOP_SPREAD_COLUMNS = ("stop_spread_t_mm", "stop_spread_r_deg")
ENVELOPE_KEYS = ("dataset", "trajectory", "method", "tolerance")  # and "rule" when the table has one
ENVELOPE_COLUMNS = ("world", "dataset", "trajectory", "method", "tolerance", "theta_a", "censored")
NOT_MEASURED = "not_measured"  # an envelope row's status when its theta_a could not be read (localization.envelope)
FIG2_KEYS = ("trajectory", "dataset", "k", "model")
FIG2_COLUMNS = ("trajectory", "dataset", "k", "model", "rmse", "status", "reason", "n_samples")
FIT_STATUSES = ("ok", "at_bound", "non_physical", "fallback")  # a fit's status, least to most severe (fitted.py)


class TableError(PoseIntegrityError):
    """A table handed between stages is missing columns or rows, repeats a key, or holds a value of the wrong type
    or range (the message names the table, the column and the first offending row)."""


def _row(table: pd.DataFrame, mask: np.ndarray, keys: Iterable[str]) -> str:
    first = table[mask].iloc[0]
    parts = [f"{key} {first[key]}" for key in keys if key in table.columns]
    return f"{parts[0]} ({', '.join(parts[1:])})" if len(parts) > 1 else "".join(parts)


def _structure(table: object, name: str, columns: Iterable[str], keys: tuple[str, ...]) -> pd.DataFrame:
    if not isinstance(table, pd.DataFrame):
        raise TableError(f"{name}: expected a pandas DataFrame, got {type(table).__name__}")
    if missing := [column for column in columns if column not in table.columns]:
        raise TableError(f"{name}: lacks columns {missing}")
    if table.empty:
        raise TableError(f"{name}: has no rows (was its stage run on no data?)")
    present = [key for key in keys if key in table.columns]
    repeated = table.duplicated(present, keep=False).to_numpy()
    if repeated.any():
        raise TableError(f"{name}: {int(repeated.sum())} rows repeat a key ({', '.join(present)}), first: "
                         f"{_row(table, repeated, present)}")
    return table


def _numeric(table: pd.DataFrame, name: str, column: str, keys: Iterable[str], *, integer: bool = False,
             low: float = -np.inf, nan: bool = False) -> None:
    if column not in table.columns:
        return
    kind = table[column].dtype.kind
    if kind not in ("iu" if integer else "iuf"):
        text = not_numbers(table[column])
        example = f": {table[column][text].iloc[0]!r} in {_row(table, text, keys)}" if text.any() else ""
        raise TableError(f"{name}: column {column} must hold {'integers' if integer else 'numbers'}, "
                         f"got dtype {table[column].dtype}{example}")
    values = table[column].to_numpy(dtype=np.float64)
    bad = np.isinf(values) | (values < low) | (np.zeros_like(values, dtype=bool) if nan else np.isnan(values))
    if bad.any():
        value = float(values[bad][0])
        what = "non-finite" if not np.isfinite(value) else f"below {low:g}"
        allowed = "finite numbers" + (f" >= {low:g}" if np.isfinite(low) else "") + (" or NaN" if nan else "")
        raise TableError(f"{name}: {_row(table, bad, keys)}: {what} {column} {value!r} (expected {allowed})")


def _expected(table: pd.DataFrame, name: str, datasets: Iterable[str] | None) -> None:
    if datasets is not None and (absent := sorted(set(datasets) - set(table["dataset"].astype(str)))):
        raise TableError(f"{name}: dataset(s) {absent[:10]}{' ...' if len(absent) > 10 else ''} missing")


def check_artifacts(table: pd.DataFrame, name: str = "the artifacts table", *,
                    columns: Iterable[str] = ARTIFACT_COLUMNS, datasets: Iterable[str] | None = None) -> pd.DataFrame:
    """An artifacts table (stage 02 / 05), checked: ``columns`` present, rows, one row per (dataset, stop, image,
    method), stop and image integers >= 0, a known trajectory, theta_deg / x_mm finite, n_inliers a count >= 0 (or NaN: a missing count, which the predictors flag),
    E_t_mm / E_r_deg >= 0 or NaN (no pose, no board), the consensus columns, where present, >= 0 or NaN
    (:data:`CONSENSUS_COLUMNS`, :data:`STOP_SPREAD_COLUMNS`), every dataset of ``datasets`` present. Returns it
    unchanged."""
    _structure(table, name, columns, ARTIFACT_KEYS)
    for column in ("stop", "image"):
        _numeric(table, name, column, ARTIFACT_KEYS, integer=True, low=0)
    for column in ("theta_deg", "x_mm"):
        _numeric(table, name, column, ARTIFACT_KEYS)
    _numeric(table, name, "n_inliers", ARTIFACT_KEYS, low=0, nan=True)  # NaN: a missing count, flagged downstream
    for column in ("E_t_mm", "E_r_deg", *CONSENSUS_COLUMNS, *STOP_SPREAD_COLUMNS):
        _numeric(table, name, column, ARTIFACT_KEYS, low=0, nan=True)
    if "trajectory" in table.columns and (unknown := sorted(set(table["trajectory"].astype(str)) - set(TRAJECTORIES))):
        raise TableError(f"{name}: unknown trajectory type(s) {unknown} in column trajectory, expected one of "
                         f"{list(TRAJECTORIES)}")
    _expected(table, name, datasets)
    return table


def check_envelopes(table: pd.DataFrame, name: str = "the envelopes table", *,
                    datasets: Iterable[str] | None = None) -> pd.DataFrame:
    """An envelopes table (stage 02 / 05, or one rule's rows of it), checked: its columns, rows, one row per
    (dataset, trajectory, method, tolerance, and rule when it has that column), a known trajectory, theta_a a
    finite number >= 0, censored booleans, every dataset of ``datasets`` present. NaN theta_a is an envelope stage
    02 could not read: allowed only on a row whose ``status`` says so (``not_measured``: no trusted ground truth
    before the envelope ends; such rows are left out of the scoring, prediction.sweeps.attach_envelopes), refused
    naming the dataset otherwise. Returns it unchanged."""
    keys = (*ENVELOPE_KEYS, *(["rule"] if "rule" in getattr(table, "columns", ()) else []))
    _structure(table, name, ENVELOPE_COLUMNS, keys)
    unread = table["status"].eq(NOT_MEASURED) if "status" in table.columns else pd.Series(False, index=table.index)
    _numeric(table[~unread], name, "theta_a", keys, low=0)
    _numeric(table[unread], name, "theta_a", keys, low=0, nan=True)
    if table["censored"].dtype.kind != "b":
        raise TableError(f"{name}: column censored must hold booleans, got dtype {table['censored'].dtype}")
    if unknown := sorted(set(table["trajectory"].astype(str)) - set(TRAJECTORIES)):
        raise TableError(f"{name}: unknown trajectory type(s) {unknown} in column trajectory, expected one of "
                         f"{list(TRAJECTORIES)}")
    _expected(table, name, datasets)
    return table


def check_fig2_rmse(table: pd.DataFrame, name: str = "the Fig. 2 RMSE table") -> pd.DataFrame:
    """The Fig. 2 table of stage 03 (artifact_models.fig2_rmse), checked: its columns, rows, one row per
    (trajectory, dataset, k, model), k an integer >= 1, rmse >= 0 or NaN, a known fit status. Returns it."""
    _structure(table, name, FIG2_COLUMNS, FIG2_KEYS)
    _numeric(table, name, "k", FIG2_KEYS, integer=True, low=1)
    _numeric(table, name, "rmse", FIG2_KEYS, low=0, nan=True)
    if unknown := sorted(set(table["status"].astype(str)) - set(FIT_STATUSES)):
        raise TableError(f"{name}: column status holds {unknown}, expected one of {list(FIT_STATUSES)}")
    return table


def read_table(path: str | Path) -> pd.DataFrame:
    """A parquet table; :class:`TableError` naming the file when it is missing or unreadable."""
    path = Path(path)
    if not path.is_file():
        raise TableError(f"{path}: missing (run the stage that writes it first)")
    try:
        return pd.read_parquet(path)
    except (OSError, ValueError, pyarrow.ArrowException) as error:
        raise TableError(f"{path}: cannot read: {error}") from None


def read_artifacts(path: str | Path, datasets: Iterable[str] | None = None,
                   columns: Iterable[str] = ARTIFACT_COLUMNS) -> pd.DataFrame:
    """``artifacts.parquet`` / ``pnp_variants.parquet``, checked (:func:`check_artifacts`) for the ``columns`` its
    reader uses (the fits read ``artifact_models.series.REQUIRED_COLUMNS``)."""
    return check_artifacts(read_table(path), str(path), columns=columns, datasets=datasets)


def read_envelopes(path: str | Path, datasets: Iterable[str] | None = None) -> pd.DataFrame:
    """``envelopes.parquet`` / ``pnp_envelopes.parquet``, checked (:func:`check_envelopes`)."""
    return check_envelopes(read_table(path), str(path), datasets=datasets)


def read_fig2_rmse(path: str | Path) -> pd.DataFrame:
    """``fits/fig2_rmse.parquet``, checked (:func:`check_fig2_rmse`)."""
    return check_fig2_rmse(read_table(path), str(path))
