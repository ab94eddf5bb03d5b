"""One number format for the report: a fixed count of significant digits, positional notation, no exponents.

``sig(0.00005058)`` is ``0.0000506``, ``sig(83.88)`` is ``83.9``, ``sig(12345)`` is ``12300`` (3 digits). Undefined
values (NaN) are ``-``, infinities ``inf`` / ``-inf``. Full precision is in the CSV files, not here.
"""

from __future__ import annotations

import math

SIG_DIGITS = 3

SCORE_FLAG = "⚠"
"""The mark of a ranking score above 1 (worse than a simulator standing still), in the report and its figures."""


def sig(x: float, digits: int = SIG_DIGITS, signed: bool = False) -> str:
    """``x`` rounded to ``digits`` significant digits, written without an exponent (``signed``: always a sign)."""
    if math.isnan(x):
        return "-"
    if math.isinf(x):
        return ("+inf" if signed else "inf") if x > 0 else "-inf"
    sign = "+" if signed and x >= 0 else ""
    if x == 0.0:
        return f"{sign}0"
    exponent = math.floor(math.log10(abs(x)))
    rounded = round(x, digits - 1 - exponent)
    if rounded != 0.0:  # rounding can carry into the next decade (9.996 -> 10.0)
        exponent = math.floor(math.log10(abs(rounded)))
    decimals = max(digits - 1 - exponent, 0)
    return f"{sign}{rounded:.{decimals}f}" if decimals else f"{sign}{round(rounded):d}"


def pct(x: float, signed: bool = True) -> str:
    """A percentage with 2 significant digits (at least one decimal below 10 %), e.g. ``+12 %``, ``-0.4 %``."""
    if not math.isfinite(x):
        return "-" if math.isnan(x) else sig(x, signed=signed)
    text = sig(x, 2, signed=signed)
    return f"{text} %"
