"""Which samples of a trace a recording needs: linear interpolation between the kept ones within a tolerance.

A viewer draws a time series as straight lines between its samples. Where a signal moves slowly, most of the steps
of a 120 Hz or 1 kHz trace lie on those lines to far below a pixel; :func:`keep_samples` keeps the fewest it can so
that linear interpolation (in time) between the kept samples reproduces every step within a per-column tolerance.
The kept samples are the original values (not a fit), so a reader gets the exact value at every kept step and an
interpolation within the tolerance at every other; where the signal moves fast every step is kept.

The algorithm is the "swinging door" of process historians: from the last kept sample (the anchor), the slope to
each later sample must stay inside the band of slopes that pass within the tolerance of every sample in between;
the first sample that leaves it makes its predecessor the next anchor. One pass, O(rows x columns), compiled.

Data a viewer holds rather than interpolates (3D poses: the view shows the latest pose at or before the time cursor)
is thinned by :func:`keep_changes` instead: a sample is kept where it differs from the last kept one by more than
the tolerance.
"""

from __future__ import annotations

import numpy as np

from washbench.numerics.jit import njit
from washbench.numerics.jitcache import announce_compile

__all__ = ["keep_changes", "keep_samples"]


def _float_array(a: np.ndarray) -> np.ndarray:
    """C-contiguous, writable float64 (the compiled kernels take no read-only arrays, e.g. Arrow's zero-copy views)."""
    out = np.ascontiguousarray(a, dtype=np.float64)
    return out if out.flags.writeable else out.copy()


@njit(cache=True)  # compiled on first use (announced), for the float64 arrays the wrapper passes
def _keep(t: np.ndarray, values: np.ndarray, tolerance: np.ndarray, max_gap: float) -> np.ndarray:  # pragma: no cover
    n, k = values.shape
    keep = np.zeros(n, dtype=np.bool_)
    if n == 0:
        return keep
    keep[0] = True
    keep[n - 1] = True
    lo = np.empty(k)
    hi = np.empty(k)
    a = 0
    lo[:] = -np.inf
    hi[:] = np.inf
    i = 1
    while i < n:
        finite = True
        for j in range(k):
            if not (np.isfinite(values[i, j]) and np.isfinite(values[a, j])):
                finite = False
        if not finite:  # gaps and their ends are kept as they are
            keep[i - 1] = True
            keep[i] = True
            a = i
            lo[:] = -np.inf
            hi[:] = np.inf
            i += 1
            continue
        d = t[i] - t[a]
        ok = i == a + 1 or d <= max_gap  # the line to the neighbour always passes
        if ok:
            for j in range(k):
                slope = (values[i, j] - values[a, j]) / d
                if slope < lo[j] or slope > hi[j]:
                    ok = False
                    break
        if ok:
            for j in range(k):
                lo[j] = max(lo[j], (values[i, j] - tolerance[j] - values[a, j]) / d)
                hi[j] = min(hi[j], (values[i, j] + tolerance[j] - values[a, j]) / d)
            i += 1
        else:  # the predecessor (after the anchor: i > a + 1 here) becomes the anchor
            a = i - 1
            keep[a] = True
            lo[:] = -np.inf
            hi[:] = np.inf
    return keep


def keep_samples(t: np.ndarray, values: np.ndarray, tolerance: np.ndarray | float, max_gap: float) -> np.ndarray:
    """Indices of the rows of ``values`` (N, k) at the times ``t`` (N,) to record, sorted, always with the first and
    the last.

    Linear interpolation in ``t`` (strictly increasing, any spacing) between the kept rows reproduces every row within
    ``tolerance`` (a number or one per column, in the values' unit, >= 0) in every column; kept rows are at most
    ``max_gap`` apart in ``t`` (> 0) unless they are neighbours; rows with a non-finite value are kept with their
    neighbours. Tolerance 0 keeps every row that is not exactly on the line between its neighbours (up to rounding).
    """
    v = _float_array(values)
    if v.ndim == 1:
        v = v.reshape(-1, 1)
    x = _float_array(t)
    tol = np.array(np.broadcast_to(np.asarray(tolerance, dtype=np.float64), (v.shape[1],)))
    if not np.all(tol >= 0) or not max_gap > 0 or x.shape != (v.shape[0],):
        raise ValueError(f"tolerance must be >= 0, max_gap > 0 and t (N,), got {tol.tolist()}, {max_gap}, {x.shape}")
    announce_compile(_keep)
    return np.flatnonzero(_keep(x, v, tol, float(max_gap)))


@njit(cache=True)  # compiled on first use (announced)
def _changes(values: np.ndarray, tolerance: np.ndarray, max_gap: int) -> np.ndarray:  # pragma: no cover - compiled
    n, k = values.shape
    keep = np.zeros(n, dtype=np.bool_)
    if n == 0:
        return keep
    keep[0] = True
    keep[n - 1] = True
    a = 0
    for i in range(1, n):
        moved = i - a >= max_gap
        for j in range(k):
            if not (abs(values[i, j] - values[a, j]) <= tolerance[j]):  # also where either is not finite
                moved = True
        if moved:
            keep[i] = True
            a = i
    return keep


def keep_changes(values: np.ndarray, tolerance: np.ndarray | float, max_gap: int) -> np.ndarray:
    """Indices of the rows of ``values`` (N, k) to record for a viewer that holds the latest row (zero-order hold):
    a row is kept where some column differs from the last kept row by more than ``tolerance`` (a number or one per
    column, >= 0), or ``max_gap`` rows after it; always the first and the last. Holding the kept rows reproduces every
    row within the tolerance."""
    v = _float_array(values)
    if v.ndim == 1:
        v = v.reshape(-1, 1)
    tol = np.array(np.broadcast_to(np.asarray(tolerance, dtype=np.float64), (v.shape[1],)))
    if not np.all(tol >= 0) or max_gap < 1:
        raise ValueError(f"tolerance must be >= 0 and max_gap >= 1, got {tol.tolist()}, {max_gap}")
    announce_compile(_changes)
    return np.flatnonzero(_changes(v, tol, int(max_gap)))
