"""Peaks of a sampled signal by prominence, as ``scipy.signal.find_peaks(x, prominence=p)`` finds them, in numpy.

A manoeuvre's oscillation checks (:func:`washbench.flight.checks.oscillation`) need the extrema of one trace;
importing ``scipy.signal`` for them cost a run (or a suite worker) 0.8 s, more than the figures of that run
(issue 21). The definitions are scipy's (``scipy/signal/_peak_finding_utils.pyx``, ``_local_maxima_1d`` and
``_peak_prominences`` with no window), so the peaks are the same indices:

- a *local maximum* is a sample, or a flat run of equal samples, with a strictly lower neighbour on each side;
  a flat run gives its middle index, rounded down; the first and last samples are never peaks;
- its *prominence* is its height above the higher of its two bases, where the base on each side is the lowest
  sample between the peak and the nearest strictly higher sample on that side (or the signal's end);
- the peaks kept are those whose prominence is at least the given one.
"""

from __future__ import annotations

import numpy as np


def local_maxima(x: np.ndarray) -> np.ndarray:
    """Indices (int64, ascending) of the local maxima of the 1-D array ``x`` (module docstring)."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 1:
        raise ValueError(f"expected a 1-D array, got shape {x.shape}")
    if x.size < 3:
        return np.zeros(0, dtype=np.int64)
    starts = np.flatnonzero(np.concatenate(([True], x[1:] != x[:-1])))  # the first sample of each flat run
    ends = np.concatenate((starts[1:] - 1, [x.size - 1]))
    v = x[starts]
    inner = np.flatnonzero((v[1:-1] > v[:-2]) & (v[1:-1] > v[2:])) + 1
    return ((starts[inner] + ends[inner]) // 2).astype(np.int64)


def _nearest_higher(values: list[float], order: range) -> list[int]:
    """For each index, in ``order``'s direction, the index of the nearest earlier sample strictly higher than it
    (-1 where there is none): one pass with a stack of the samples still waiting for a higher one."""
    nearest = [-1] * len(values)
    stack: list[int] = []
    for i in order:
        v = values[i]
        while stack and values[stack[-1]] <= v:
            stack.pop()
        if stack:
            nearest[i] = stack[-1]
        stack.append(i)
    return nearest


def prominences(x: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """Prominence of each of ``peaks`` (indices into the 1-D array ``x``), same units as ``x`` (module docstring).

    The bases' ranges come from one pass each way over the samples (the nearest strictly higher sample on each
    side), their minima from ``np.minimum.reduceat``: linear in the samples, where searching from every peak was
    quadratic on a noisy trace (28,000 peaks in 100,000 samples: 3 s).
    """
    x = np.asarray(x, dtype=np.float64)
    peaks = np.asarray(peaks, dtype=np.int64)
    if peaks.size == 0:
        return np.zeros(0, dtype=np.float64)
    values = x.tolist()
    n = len(values)
    left_higher = np.array(_nearest_higher(values, range(n)), dtype=np.int64)[peaks]
    right_higher = np.array(_nearest_higher(values, range(n - 1, -1, -1)), dtype=np.int64)[peaks]
    right_higher[right_higher < 0] = n
    padded = np.append(x, 0.0)  # reduceat's indices may then be n (the end of the last range)

    def range_min(start: np.ndarray, stop: np.ndarray) -> np.ndarray:  # min of x[start:stop], each non-empty
        bounds = np.empty(2 * start.size, dtype=np.int64)
        bounds[0::2], bounds[1::2] = start, stop
        return np.minimum.reduceat(padded, bounds)[0::2]

    left_min = range_min(left_higher + 1, peaks + 1)
    right_min = range_min(peaks, right_higher)
    return x[peaks] - np.maximum(left_min, right_min)


def find_peaks(x: np.ndarray, prominence: float) -> np.ndarray:
    """Indices of the local maxima of ``x`` whose prominence is at least ``prominence`` (same units as ``x``):
    the first value ``scipy.signal.find_peaks(x, prominence=prominence)`` returns."""
    peaks = local_maxima(x)
    return peaks[prominences(x, peaks) >= prominence]
