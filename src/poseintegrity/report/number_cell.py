"""A number as a table cell: a float rounded as the column shows it, any other value as written, and the table's own
word where there is none."""

from __future__ import annotations

import math


def number_cell(value, fmt: str = "{:.3g}", missing: str = "none") -> str:
    """``value`` as a cell: a float by ``fmt`` (three significant digits unless told), an int or a string as written
    (a count, a name); ``missing`` for None or NaN, where nothing was measured."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return missing
    return fmt.format(value) if isinstance(value, float) else str(value)
