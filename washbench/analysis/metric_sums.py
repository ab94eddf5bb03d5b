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

F_N, F_SUM, F_FIRST, F_LAST, F_FSUM, F_FFIRST, F_FLAST = range(7)
NFELT = 7
"""One DOF's accumulator of the felt error (:mod:`washbench.analysis.felt`): the count, the sum, first and last of
the dead-banded error, and the same of the false part (for the trapezoid rule)."""

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


@njit(cache=True, inline="always")
def felt_update(acc, x, y, band, sign, x0):
    """Add one sample to a felt-error accumulator ``acc`` (NFELT,): ``max(|x - y| - band, 0)`` and the false part,
    ``max(-sign (y - x0) - band, 0)`` where ``sign`` (the aircraft pilot's cue beyond the band) is not 0, else
    ``max(|y - x0| - band, 0)`` (x aircraft, y simulator, x0 the aircraft's first sample; the DOF's units)."""
    n = acc[F_N] + 1.0
    acc[F_N] = n
    g = max(abs(x - y) - band, 0.0)
    h = max(-sign * (y - x0) - band, 0.0) if sign != 0.0 else max(abs(y - x0) - band, 0.0)
    if n == 1.0:
        acc[F_FIRST] = g
        acc[F_FFIRST] = h
    acc[F_SUM] += g
    acc[F_LAST] = g
    acc[F_FSUM] += h
    acc[F_FLAST] = h


@njit(cache=True)
def felt_finish(acc, dt):
    """(felt error, false part): the trapezoid integrals over dt of a felt-error accumulator."""
    e = dt * (acc[F_SUM] - 0.5 * (acc[F_FIRST] + acc[F_LAST]))
    f = dt * (acc[F_FSUM] - 0.5 * (acc[F_FFIRST] + acc[F_FLAST]))
    return e, f


@njit(cache=True, inline="always")
def cue_sign(x, x0, band):
    """The sign of the aircraft pilot's cue ``x - x0`` where it is beyond ``band``, else 0."""
    d = x - x0
    if abs(d) > band:
        return 1.0 if d > 0.0 else -1.0
    return 0.0


@njit(cache=True)
def felt_sums(x, y, band, dt, out):
    """The felt error and its false part per column (``out`` (2, C)) of the aircraft's ``x`` and the simulator's
    ``y`` (N, C) in the DOFs' units, with dead bands ``band`` (C,)."""
    acc = np.zeros(NFELT)
    for j in range(x.shape[1]):
        acc[:] = 0.0
        for k in range(x.shape[0]):
            felt_update(acc, x[k, j], y[k, j], band[j], cue_sign(x[k, j], x[0, j], band[j]), x[0, j])
        e, f = felt_finish(acc, dt)
        out[0, j] = e
        out[1, j] = f


@njit(cache=True, inline="always")
def jolt_step(f_now, f_before, a_now, a_before, allow):
    """One sample's jolt: ``max(|f_now - f_before| - |a_now - a_before| - allow, 0)`` (simulator f, aircraft a;
    ``allow`` the jerk dead band times dt)."""
    return max(abs(f_now - f_before) - abs(a_now - a_before) - allow, 0.0)


@njit(cache=True)
def jolt_sums(f, a, allow, out):
    """The jolt per column (``out`` (C,)) of the simulator's head specific force ``f`` against the aircraft's ``a``
    (N, C), m/s^2; ``allow`` = J_T dt (m/s^2)."""
    for j in range(f.shape[1]):
        total = 0.0
        for k in range(1, f.shape[0]):
            total += jolt_step(f[k, j], f[k - 1, j], a[k, j], a[k - 1, j], allow)
        out[j] = total


@njit(cache=True)
def signal_metrics(x, y, dt):
    """(PC or nan, integral of |x - y| dt, max |x - y|) of two equal-length 1-D signals sampled every dt."""
    acc = np.zeros(NACC)
    for k in range(x.shape[0]):
        acc_update(acc, x[k], y[k])
    return finish(acc, dt)
