"""Evaluate a manoeuvre's checks on the recorded flight.

Headings (``psi_deg``) wrap at north: their statistics are taken on the unwrapped heading and
wrapped back into [0, 360), and their limits are an arc, from ``min`` clockwise to ``max``
(``min: 350, max: 10`` passes 355 and 5). Oscillation statistics describe a free response (an
excitation's aftermath): see :func:`oscillation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from washbench.flight.manoeuvre_schema import HEADING_SIGNALS, HEADING_VALUE_STATS, OSCILLATION_STATS, Check
from washbench.numerics.peaks import find_peaks

#: Extrema smaller than this fraction of the largest swing are noise, not an oscillation's peaks.
PEAK_PROMINENCE = 0.05


@dataclass(frozen=True)
class Oscillation:
    """A decaying oscillation measured from its extrema (NaN where fewer than the needed peaks)."""

    period_s: float  # mean time between alternate extrema (one full cycle), s
    damping_ratio: float  # from the decay of the half peak-to-peak amplitudes, exp(-zeta omega_n t)
    amplitude: float  # largest half peak-to-peak swing between successive extrema, in the signal's unit
    peaks: int  # number of extrema used


def _heading_arc(value: float, lo: float, hi: float) -> bool:
    """Whether heading ``value`` (deg) lies on the arc from ``lo`` clockwise to ``hi``."""
    return (value - lo) % 360.0 <= (hi - lo) % 360.0 + 1e-9


def oscillation(x: np.ndarray, dt_s: float) -> Oscillation:
    """Period, damping ratio and amplitude of an oscillation sampled every ``dt_s`` seconds.

    The extrema (maxima and minima alternating, each with a prominence of at least
    ``PEAK_PROMINENCE`` of the signal's range) give the half-cycle swings
    a_i = |x_i+1 - x_i| / 2, which a slowly drifting mean leaves unchanged. The period is twice the
    mean spacing of the extrema; the decay rate sigma is the least-squares slope of ln a_i over the
    swing mid-times, and the damping ratio zeta = sigma / sqrt(sigma^2 + omega_d^2) with
    omega_d = 2 pi / period (a growing oscillation gives a negative ratio).
    """
    nan = math.nan
    x = np.asarray(x, dtype=float)
    if x.size < 5 or not np.all(np.isfinite(x)):
        return Oscillation(nan, nan, nan, 0)
    span = float(np.max(x) - np.min(x))
    if span <= 0.0:
        return Oscillation(nan, nan, nan, 0)
    prom = PEAK_PROMINENCE * span
    hi = find_peaks(x, prom)  # scipy.signal.find_peaks's peaks, without its import (0.8 s)
    lo = find_peaks(-x, prom)
    idx = np.sort(np.concatenate([hi, lo]))
    is_max = np.isin(idx, hi)
    keep: list[int] = []  # alternate maxima and minima: of a run of the same kind keep the extreme one
    for j, i in enumerate(idx):
        if keep and is_max[j] == (keep[-1] in hi):
            better = x[i] > x[keep[-1]] if is_max[j] else x[i] < x[keep[-1]]
            if better:
                keep[-1] = int(i)
            continue
        keep.append(int(i))
    k = np.array(keep)
    if k.size < 2:
        return Oscillation(nan, nan, nan, int(k.size))
    swings = 0.5 * np.abs(np.diff(x[k]))
    amplitude = float(np.max(swings))
    if k.size < 3:
        return Oscillation(nan, nan, amplitude, int(k.size))
    period = 2.0 * float(np.mean(np.diff(k))) * dt_s
    t_mid = 0.5 * (k[:-1] + k[1:]) * dt_s
    slope = float(np.polyfit(t_mid, np.log(swings), 1)[0])
    sigma = -slope
    omega_d = 2.0 * math.pi / period
    return Oscillation(period, sigma / math.hypot(sigma, omega_d), amplitude, int(k.size))


@dataclass(frozen=True)
class CheckResult:
    name: str
    measured: float  # NaN when it could not be measured (e.g. no touchdown)
    limit: str  # e.g. "<= 5", "30..60"
    passed: bool


def limit_text(check: Check) -> str:
    if check.min is not None and check.max is not None and check.min > check.max:
        return f"{check.min:g}..360..{check.max:g}"  # a heading arc through north
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
    if stat in OSCILLATION_STATS:
        osc = oscillation(x, dt_s)
        return osc.period_s if stat == "oscillation_period" else (
            osc.damping_ratio if stat == "damping_ratio" else osc.amplitude)  # fmt: skip
    if check.signal in HEADING_SIGNALS and stat != "turned":
        # unwrapped about the first sample: statistics of a heading crossing north are continuous
        x = np.degrees(np.unwrap(np.radians(x)))
        if stat in HEADING_VALUE_STATS:
            return _plain_stat(stat, x, columns[check.signal], mask, dt_s) % 360.0
    return _plain_stat(stat, x, columns[check.signal], mask, dt_s)


def _plain_stat(stat: str, x: np.ndarray, full: np.ndarray, mask: np.ndarray, dt_s: float) -> float:
    """A statistic of the selected samples ``x`` (``full`` and ``mask``: the whole signal, for ``rotated``)."""
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
        arc = check.signal in HEADING_SIGNALS and check.stat in HEADING_VALUE_STATS
        if ok and arc and check.min is not None and check.max is not None:
            ok = _heading_arc(value, check.min, check.max)
        else:
            if ok and check.min is not None and value < check.min:
                ok = False
            if ok and check.max is not None and value > check.max:
                ok = False
        out.append(CheckResult(check.name, value, limit_text(check), ok))
    return out
