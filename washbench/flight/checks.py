"""Evaluate a manoeuvre's checks on the recorded flight."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from washbench.flight.manoeuvre import Check


@dataclass(frozen=True)
class CheckResult:
    name: str
    measured: float  # NaN when it could not be measured (e.g. no touchdown)
    limit: str  # e.g. "<= 5", "30..60"
    passed: bool


def limit_text(check: Check) -> str:
    if check.min is not None and check.max is not None:
        return f"{check.min:g}..{check.max:g}"
    if check.min is not None:
        return f">= {check.min:g}"
    return f"<= {check.max:g}"


def measure(
    check: Check,
    columns: dict[str, np.ndarray],
    phases: list[tuple[str, float, float]],
    events: dict[str, list[float]],
    dt_s: float,
) -> float:
    """The value of ``check.stat`` of ``check.signal`` over the selected phases (NaN if none).

    A phase covers its start and end samples (t_start <= t <= t_end), so the sample at which
    an end condition was met (say, the stall) belongs to the phase it ends as well.
    """
    t = columns["t_s"]
    if check.phases:
        mask = np.zeros(t.shape, dtype=bool)
        half = 0.5 * dt_s
        for name, t0, t1 in phases:
            if name in check.phases:
                mask |= (t >= t0 - half) & (t <= t1 + half)
    else:
        mask = np.ones(t.shape, dtype=bool)
    if check.stat in ("at_touchdown", "at_liftoff"):
        event = "touchdown" if check.stat == "at_touchdown" else "liftoff"
        times = [t for t in events.get(f"{event}_times_s", []) if mask[min(round(t / dt_s), len(mask) - 1)]]
        if not times:
            return math.nan
        k = round(times[0] / dt_s)
        if check.signal == "sink_fps":
            return float(-columns["climb_fpm"][k] / 60.0)
        return float(columns[check.signal][k])
    x = columns[check.signal][mask]
    if x.size == 0:
        return math.nan
    stat = check.stat
    if stat == "min":
        return float(np.min(x))
    if stat == "max":
        return float(np.max(x))
    if stat == "mean":
        return float(np.mean(x))
    if stat == "max_abs":
        return float(np.max(np.abs(x)))
    if stat == "initial":
        return float(x[0])
    if stat == "final":
        return float(x[-1])
    if stat == "max_rise":
        return float(np.max(x) - x[0])
    if stat == "max_drop":
        return float(x[0] - np.min(x))
    if stat == "max_deviation":
        return float(np.max(np.abs(x - x[0])))
    if stat == "rotated":
        # trapezoidal integral over the intervals whose both ends are selected
        full = columns[check.signal]
        both = mask[:-1] & mask[1:]
        return float(abs(np.sum((full[:-1][both] + full[1:][both]) * (0.5 * dt_s))))
    # turned: net heading change over the selection, from the unwrapped heading
    unwrapped = np.unwrap(np.radians(x))
    return float(np.degrees(abs(unwrapped[-1] - unwrapped[0])))


def evaluate(
    checks: list[Check],
    columns: dict[str, np.ndarray],
    phases: list[tuple[str, float, float]],
    events: dict[str, list[float]],
    dt_s: float,
) -> list[CheckResult]:
    """Measure every check; a check that cannot be measured fails."""
    out = []
    for check in checks:
        value = measure(check, columns, phases, events, dt_s)
        ok = not math.isnan(value)
        if ok and check.min is not None and value < check.min:
            ok = False
        if ok and check.max is not None and value > check.max:
            ok = False
        out.append(CheckResult(check.name, value, limit_text(check), ok))
    return out
