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


def prominences(x: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """Prominence of each of ``peaks`` (indices into the 1-D array ``x``), same units as ``x`` (module docstring)."""
    x = np.asarray(x, dtype=np.float64)
    out = np.empty(len(peaks), dtype=np.float64)
    for j, p in enumerate(np.asarray(peaks, dtype=np.int64)):
        height = x[p]
        higher_left = np.flatnonzero(x[:p] > height)
        left = higher_left[-1] + 1 if higher_left.size else 0
        higher_right = np.flatnonzero(x[p + 1 :] > height)
        right = p + higher_right[0] if higher_right.size else x.size - 1
        out[j] = height - max(float(np.min(x[left : p + 1])), float(np.min(x[p : right + 1])))
    return out


def find_peaks(x: np.ndarray, prominence: float) -> np.ndarray:
    """Indices of the local maxima of ``x`` whose prominence is at least ``prominence`` (same units as ``x``):
    the first value ``scipy.signal.find_peaks(x, prominence=prominence)`` returns."""
    peaks = local_maxima(x)
    return peaks[prominences(x, peaks) >= prominence]
