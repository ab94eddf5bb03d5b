"""The metrics' compiled core: running sums of one DOF's error, fed one sample at a time.

One accumulator (``NACC`` float64) per DOF collects, for the aircraft pilot's signal x and a simulator pilot's
y: the sample count, the sum of |x - y| and its first and last terms (for the trapezoid rule), max |x - y|,
Welford's running means, squared deviations and co-deviation (for the Pearson correlation, numerically stable in
one pass) and the peaks of |x| and |y| (for the flat-signal test). :func:`finish` turns it into
(PC or nan, integral of |error|, max |error|). The whole-trace metrics (:mod:`washbench.analysis.metrics`) and the
studies' evaluation kernel (:mod:`washbench.analysis.evaluate`) both call :func:`acc_update` per sample, so they
give the same bits.
"""

from __future__ import annotations

import math

import numpy as np

from washbench.numerics.jit import njit

A_N, A_SUM, A_FIRST, A_LAST, A_MAX, A_MX, A_MY, A_M2X, A_M2Y, A_CXY, A_PX, A_PY = range(12)
NACC = 12

FLAT_RTOL = 1e-9
"""A signal whose standard deviation is at most this fraction of its peak |value| is flat."""
MIN_PC_SAMPLES = 3
"""Fewer samples leave PC undefined (nan): two points always correlate by +1 or -1 (a 2-sample input wrote an NPC
of ``inf`` into metrics.csv)."""


@njit(cache=True, inline="always")
def acc_update(acc, x, y):
    """Add one sample (x aircraft, y simulator) to accumulator ``acc`` (NACC,)."""
    n = acc[A_N] + 1.0
    acc[A_N] = n
    e = abs(x - y)
    if n == 1.0:
        acc[A_FIRST] = e
    acc[A_SUM] += e
    acc[A_LAST] = e
    if e > acc[A_MAX]:
        acc[A_MAX] = e
    dx = x - acc[A_MX]
    acc[A_MX] += dx / n
    dy = y - acc[A_MY]
    acc[A_MY] += dy / n
    acc[A_M2X] += dx * (x - acc[A_MX])
    acc[A_M2Y] += dy * (y - acc[A_MY])
    acc[A_CXY] += dx * (y - acc[A_MY])
    if abs(x) > acc[A_PX]:
        acc[A_PX] = abs(x)
    if abs(y) > acc[A_PY]:
        acc[A_PY] = abs(y)


@njit(cache=True)
def _flat(m2, n, peak):
    std = math.sqrt(m2 / n)
    return std == 0.0 or std <= FLAT_RTOL * peak


@njit(cache=True)
def finish(acc, dt):
    """(Pearson PC in [-1, 1], or nan if a signal is flat or there are fewer than 3 samples; trapezoid integral of
    |x - y| over dt; max |x - y|)."""
    n = acc[A_N]
    integral = dt * (acc[A_SUM] - 0.5 * (acc[A_FIRST] + acc[A_LAST]))
    if n < MIN_PC_SAMPLES or _flat(acc[A_M2X], n, acc[A_PX]) or _flat(acc[A_M2Y], n, acc[A_PY]):
        pc = math.nan
    else:
        pc = acc[A_CXY] / (math.sqrt(acc[A_M2X]) * math.sqrt(acc[A_M2Y]))
        pc = min(1.0, max(-1.0, pc))
    return pc, integral, acc[A_MAX]


@njit(cache=True)
def signal_metrics(x, y, dt):
    """(PC or nan, integral of |x - y| dt, max |x - y|) of two equal-length 1-D signals sampled every dt."""
    acc = np.zeros(NACC)
    for k in range(x.shape[0]):
        acc_update(acc, x[k], y[k])
    return finish(acc, dt)
