"""Time of recorded motion: resets, gaps, a window, the uniform grid check, and resampling onto one.

The cueing needs samples on a uniform grid ``t_k = t_0 + k dt``. A recording is taken as on its grid
when every sample lies within :data:`GRID_TOL` of a step of it: a timing error that small (at 120 Hz,
8 us) shifts a signal by less than its own rounding and changes no metric measurably (the tests
measure it), while 3-decimal time stamps at 120 Hz (up to 0.5 ms = 6 % of a step off) or logger jitter
of 1 ms are not, and need :func:`resample`.

Resampling (``washbench cue --resample HZ``): every numeric column is interpolated linearly onto the
grid ``t_0 + k / HZ`` (integer and text columns hold their previous sample). When ``HZ`` is below the
recorded rate (1 / the median step) by more than 1 %, the motion and numeric columns are first low-pass filtered
against aliasing: the recording is interpolated onto a uniform grid at its own rate, then filtered
forward and backward (``scipy.signal.sosfiltfilt``, zero phase, so no delay) by a 4th-order
Butterworth low-pass at 0.4 x HZ (80 % of the new Nyquist frequency), then interpolated onto the new
grid. Gaps longer than ``max_gap_s`` are an error even when resampling (interpolating across them
would invent motion).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from washbench.errors import WashbenchError, located
from washbench.io.columns import F_COLUMNS, OMEGA_COLUMNS
from washbench.io.motion import DT_RANGE_S, F_MAX_MPS2, OMEGA_MAX_DEGPS, Motion
from washbench.io.readers import Samples

GRID_TOL = 1e-3
"""Samples may lie at most this fraction of a step off the uniform grid t_0 + k dt."""

DEFAULT_GAP_STEPS = 5.0
"""Default largest gap: this many typical (median) steps, i.e. up to four missing samples in a row."""

ANTIALIAS_ORDER = 4
ANTIALIAS_FRACTION = 0.4
"""Anti-alias cut-off as a fraction of the new sample rate (0.4 = 80 % of its Nyquist frequency)."""


def _err(s: Samples, i: int, problem: str) -> WashbenchError:
    line, row = s.where(i)
    return WashbenchError(located(s.path, f"{row}{problem}", line=line, field=s.time_column))


def split_resets(s: Samples, split: bool = True) -> list[Samples]:
    """The samples cut into segments where time jumps back (a simulator reset); ``split=False`` refuses one.

    Repeated time stamps are an error (the order of the samples is then unknown).
    """
    t = s.t_s
    steps = np.diff(t)
    same = steps == 0.0
    if same.any():
        i = int(np.argmax(same)) + 1
        raise _err(s, i, f"time does not increase ({t[i]:.9g} after {t[i - 1]:.9g})")
    back = np.flatnonzero(steps < 0.0) + 1
    if back.size and not split:
        i = int(back[0])
        raise _err(
            s,
            i,
            f"time jumps back from {t[i - 1]:.9g} to {t[i]:.9g} s (a reset?); without --no-split each part is "
            "cued separately",
        )
    bounds = [0, *back.tolist(), s.n]
    parts = [s.take(slice(a, b)) for a, b in itertools.pairwise(bounds)]
    for p, a in zip(parts, bounds[:-1], strict=True):
        if p.n < 2:
            raise _err(s, a, "a segment between two time resets has fewer than 2 samples")
    return parts


def check_gaps(s: Samples, max_gap_s: float | None) -> None:
    """Error at the first step longer than ``max_gap_s`` (default: :data:`DEFAULT_GAP_STEPS` median steps)."""
    steps = np.diff(s.t_s)
    typical = float(np.median(steps))
    limit = DEFAULT_GAP_STEPS * typical if max_gap_s is None else float(max_gap_s)
    big = steps > limit * (1.0 + 1e-9)
    if big.any():
        i = int(np.argmax(big)) + 1
        raise _err(
            s,
            i,
            f"gap of {steps[i - 1]:.6g} s from {s.t_s[i - 1]:.9g} to {s.t_s[i]:.9g} s, longer than the largest "
            f"allowed {limit:.6g} s (--max-gap-s; the typical step is {typical:.6g} s): cut around it with "
            "--start-s/--end-s",
        )


def window(s: Samples, start_s: float | None, end_s: float | None) -> Samples:
    """The samples with ``start_s <= t_s <= end_s`` (either bound optional)."""
    if start_s is None and end_s is None:
        return s
    lo = -math.inf if start_s is None else start_s
    hi = math.inf if end_s is None else end_s
    if hi <= lo:
        raise WashbenchError(f"--end-s {end_s:g} must be later than --start-s {start_s:g}")
    keep = (s.t_s >= lo) & (s.t_s <= hi)
    if keep.sum() < 2:
        raise WashbenchError(
            located(
                s.path,
                f"the window {lo:g}..{hi:g} s holds {int(keep.sum())} sample(s) of {s.t_s[0]:.6g}..{s.t_s[-1]:.6g} s: "
                "need at least 2",
            )
        )
    idx = np.flatnonzero(keep)
    return s.take(slice(int(idx[0]), int(idx[-1]) + 1), (f"window {lo:g}..{hi:g} s",))


def uniform_step(t: np.ndarray) -> tuple[float | None, float, int]:
    """(dt if ``t`` lies on a uniform grid within :data:`GRID_TOL`, else None; worst offset [steps]; its index).

    A grid written as ``t_0 + k dt`` gives back that dt exactly (so re-cueing a ``washbench fly`` trace
    reproduces it bit for bit); otherwise dt is the mean step.
    """
    n = t.size
    dt = float((t[-1] - t[0]) / (n - 1))
    k = np.arange(n, dtype=np.float64)
    first = float(t[1] - t[0])
    if np.array_equal(t[0] + k * first, t):
        return first, 0.0, 0
    off = np.abs(t - (t[0] + k * dt)) / dt
    i = int(np.argmax(off))
    worst = float(off[i])
    tol = GRID_TOL + 4.0 * float(np.spacing(max(abs(t[0]), abs(t[-1]), dt))) / dt
    return (dt if worst <= tol else None), worst, i


def suggest_rate(t: np.ndarray) -> float:
    """A round sample rate near the recording's own (1 / median step) for the --resample advice [Hz]."""
    hz = 1.0 / float(np.median(np.diff(t)))
    for nice in (1000, 500, 400, 250, 200, 120, 100, 60, 50, 40, 30, 25, 20, 10):
        if abs(hz - nice) <= 0.05 * nice:
            return float(nice)
    return float(f"{hz:.3g}")


def check_magnitudes(s: Samples) -> None:
    """Refuse samples beyond the accepted magnitudes (``F_MAX_MPS2``, ``OMEGA_MAX_DEGPS``), naming the first.

    Beyond them a recording is corrupt, not a flight (and such numbers only make the platform model slow).
    """
    for values, names, limit, unit in (
        (s.f_mps2, F_COLUMNS, F_MAX_MPS2, "m/s^2"),
        (s.omega_degps, OMEGA_COLUMNS, OMEGA_MAX_DEGPS, "deg/s"),
    ):
        big = np.abs(values) > limit
        if big.any():
            i, j = (int(x) for x in np.argwhere(big)[0])
            line, row = s.where(i)
            problem = f"{row}{values[i, j]:.6g} is beyond the accepted range +-{limit:g} {unit}"
            raise WashbenchError(located(s.path, problem, line=line, field=names[j]))


def check_step(s: Samples, dt: float) -> None:
    """Refuse a time step outside ``DT_RANGE_S`` (10 kHz to 1 Hz): the filters cannot be discretised sensibly."""
    lo, hi = DT_RANGE_S
    if not lo <= dt <= hi:
        problem = f"time step {dt:.6g} s is outside the accepted {lo:g}..{hi:g} s ({1 / hi:g} Hz to {1 / lo:g} Hz)"
        raise WashbenchError(located(s.path, problem, field=s.time_column))


def to_motion(s: Samples) -> Motion:
    """A :class:`Motion` of samples that lie on a uniform grid; else an error saying how far off, with advice.

    Magnitudes and the step must lie in the accepted ranges (:func:`check_magnitudes`, :func:`check_step`).
    """
    check_magnitudes(s)
    dt, worst, i = uniform_step(s.t_s)
    if dt is None:
        steps = np.diff(s.t_s)
        hz = suggest_rate(s.t_s)
        raise _err(
            s,
            i,
            f"time step is not uniform: steps from {steps.min():.6g} to {steps.max():.6g} s (median "
            f"{np.median(steps):.6g} s), samples up to {worst:.3g} of a step off a uniform grid (at most "
            f"{GRID_TOL:g} allowed); resample with --resample {hz:g}",
        )
    check_step(s, dt)
    w = s.omega_degps
    return Motion(t_s=s.t_s, dt_s=dt, f_mps2=s.f_mps2, omega_radps=np.radians(w), extra=s.extra, omega_degps=w)


def antialias(x: np.ndarray, rate_hz: float, fs_hz: float) -> np.ndarray:
    """Zero-phase Butterworth low-pass (order :data:`ANTIALIAS_ORDER`, forward and backward) at
    ``ANTIALIAS_FRACTION * rate_hz`` of ``x`` (N,) or (N, m) sampled uniformly at ``fs_hz``."""
    cutoff = ANTIALIAS_FRACTION * rate_hz
    import scipy.signal  # here, not at the top: a second of start-up that only --resample needs

    sos = scipy.signal.butter(ANTIALIAS_ORDER, cutoff, fs=fs_hz, output="sos")
    padlen = min(3 * (2 * len(sos) + 1), x.shape[0] - 1)
    return scipy.signal.sosfiltfilt(sos, x, axis=0, padlen=padlen)


def resample(s: Samples, rate_hz: float) -> tuple[Motion, str]:
    """``s`` onto the uniform grid ``t_0 + k / rate_hz`` (see the module notes); returns the motion and a note."""
    if not (math.isfinite(rate_hz) and rate_hz > 0.0 and DT_RANGE_S[0] <= 1.0 / rate_hz <= DT_RANGE_S[1]):
        lo, hi = (1.0 / DT_RANGE_S[1], 1.0 / DT_RANGE_S[0])
        raise WashbenchError(f"--resample: expected a rate of {lo:g}..{hi:g} Hz, got {rate_hz!r}")
    check_magnitudes(s)
    t = s.t_s
    dt = 1.0 / rate_hz
    n = math.floor((t[-1] - t[0]) * rate_hz + 1e-9) + 1
    if n < 2:
        raise WashbenchError(
            located(s.path, f"{t[-1] - t[0]:.6g} s of data give fewer than 2 samples at {rate_hz:g} Hz")
        )
    grid = t[0] + np.arange(n, dtype=np.float64) * dt
    fs = 1.0 / float(np.median(np.diff(t)))
    numeric = {k: v for k, v in s.extra.items() if v.dtype.kind == "f"}
    held = {k: v for k, v in s.extra.items() if v.dtype.kind != "f"}
    block = (
        np.column_stack([s.f_mps2, s.omega_degps, *numeric.values()])
        if numeric
        else np.column_stack([s.f_mps2, s.omega_degps])
    )
    if rate_hz < 0.99 * fs:  # a rate lower by under 1 % (clock drift, float32 time) needs no anti-alias
        m = math.floor((t[-1] - t[0]) * fs + 1e-9) + 1
        fine_t = t[0] + np.arange(m, dtype=np.float64) / fs
        fine = _interp(fine_t, t, block)
        block, t = antialias(fine, rate_hz, fs), fine_t
        note = (
            f"resampled to {rate_hz:g} Hz from {fs:.6g} Hz: anti-alias low-pass (Butterworth order {ANTIALIAS_ORDER}, "
            f"zero phase) at {ANTIALIAS_FRACTION * rate_hz:g} Hz, then linear interpolation"
        )
    else:
        note = f"resampled to {rate_hz:g} Hz from {fs:.6g} Hz by linear interpolation"
    out = _interp(grid, t, block)
    f, w = np.ascontiguousarray(out[:, :3]), np.ascontiguousarray(out[:, 3:6])
    extra = {k: np.ascontiguousarray(out[:, 6 + j]) for j, k in enumerate(numeric)}
    prev = np.clip(np.searchsorted(s.t_s, grid, side="right") - 1, 0, s.n - 1)
    extra |= {k: v[prev] for k, v in held.items()}
    extra = {k: extra[k] for k in s.extra}  # input order
    return Motion(t_s=grid, dt_s=dt, f_mps2=f, omega_radps=np.radians(w), extra=extra, omega_degps=w), note


def _interp(x_new: np.ndarray, x: np.ndarray, block: np.ndarray) -> np.ndarray:
    return np.column_stack([np.interp(x_new, x, block[:, j]) for j in range(block.shape[1])])
