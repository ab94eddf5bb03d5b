"""Numbers in the CSV files washbench writes: full precision, so that reading them back is exact."""

from __future__ import annotations

import math


def csv_number(x: float) -> str:
    """A float for CSV: full precision (repr, so reading back is exact); NaN as an empty field."""
    return "" if math.isnan(x) else repr(float(x))
