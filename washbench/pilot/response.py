"""A frequency response measured at the forcing frequencies, extended to any frequency (:class:`Measured`).

The adaptation (:mod:`washbench.pilot.adapt`) needs the controlled element and the motion filter between and
beyond the forcing frequencies (the noise integrals, Nyquist's criterion). Between two measured points the
log-magnitude and the unwrapped phase are linear in log frequency; beyond the lowest point the response continues
with ``low_slope`` decades of magnitude per decade of frequency and the phase ``low_phase_rad`` (an attitude
integrator: -1 and -pi/2), beyond the highest with ``high_slope`` and the phase falling on as a pure delay fitted
to the last two points (the controlled element's high-frequency lags). At the measured points it is exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Measured:
    """A response known at ascending frequencies ``w`` (rad/s), complex ``h``; call it at any frequencies."""

    w: np.ndarray
    h: np.ndarray
    low_slope: float = -1.0
    low_phase_rad: float | None = -math.pi / 2.0
    high_slope: float = -2.0
    high_delay: bool = True

    def __call__(self, w_query: np.ndarray) -> np.ndarray:
        wq = np.asarray(w_query, dtype=float)
        w = np.asarray(self.w, dtype=float)
        h = np.asarray(self.h, dtype=complex)
        lw, lq = np.log(w), np.log(wq)
        mag = np.log(np.maximum(np.abs(h), 1e-12))
        phase = np.unwrap(np.angle(h))
        if self.low_phase_rad is not None:  # the branch of the phase that meets the low-frequency asymptote
            phase = phase - 2.0 * math.pi * round((phase[0] - self.low_phase_rad) / (2.0 * math.pi))
        out_mag = np.interp(lq, lw, mag)
        out_phase = np.interp(lq, lw, phase)
        low = wq < w[0]
        high = wq > w[-1]
        out_mag[low] = mag[0] + self.low_slope * (lq[low] - lw[0])
        if self.low_phase_rad is not None:
            # from the lowest point's phase to the asymptote's over the decade below it
            f = np.clip((lw[0] - lq[low]) / math.log(10.0), 0.0, 1.0)
            out_phase[low] = phase[0] + f * (self.low_phase_rad - phase[0])
        else:
            out_phase[low] = phase[0]
        out_mag[high] = mag[-1] + self.high_slope * (lq[high] - lw[-1])
        rate = (phase[-1] - phase[-2]) / (w[-1] - w[-2]) if self.high_delay and len(w) > 1 else 0.0
        out_phase[high] = phase[-1] + min(rate, 0.0) * (wq[high] - w[-1])
        return np.exp(out_mag) * np.exp(1j * out_phase)


@dataclass(frozen=True)
class Constant:
    """A response equal to ``value`` at every frequency (the aircraft's own motion: 1; no motion: 0)."""

    value: complex

    def __call__(self, w_query: np.ndarray) -> np.ndarray:
        return np.full(np.shape(w_query), self.value, dtype=complex)


def motion_response(w: np.ndarray, h: np.ndarray) -> Measured:
    """A motion filter measured at ``w``: constant magnitude and phase beyond the measured points."""
    return Measured(w=w, h=h, low_slope=0.0, low_phase_rad=None, high_slope=0.0, high_delay=False)
