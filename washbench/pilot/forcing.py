"""Multisine forcing functions: sines at integer multiples of the measurement window's base frequency.

As in the cybernetic experiments this follows (Zaal et al. 2009; Pool et al. 2011; docs/pilot-model.md, "Forcing
functions"): a forcing function is a sum of sines

    f(t) = sum_k A_k sin(n_k w_b t + phi_k),     w_b = 2 pi / T_m

with whole numbers ``n_k`` of periods in the measurement window ``T_m`` (81.92 s: 8192 samples at 100 Hz), so
each sine falls on one bin of the window's discrete Fourier transform and leaks into none. The target and the
disturbance use disjoint ``n_k``, so at each forcing frequency one of them alone excites the loop: the
identification of the pilot's two responses from one run (:mod:`washbench.pilot.identify`). The amplitudes follow
the magnitude of a shaping filter ``|(1 + T_1 j w)^2 / (1 + T_2 j w)^2|`` (the designs' low-pass: power at the
high frequencies without making the task impossible), scaled to the RMS asked. The phases are given, or chosen
from the task's seed: of :data:`PHASE_TRIES` random sets, the one with the lowest crest factor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

PHASE_TRIES = 256
"""Random phase sets tried for the lowest crest factor."""


def base_frequency(window_s: float) -> float:
    """w_b = 2 pi / T_m, rad/s."""
    return 2.0 * math.pi / window_s


def shaped_amplitudes(w_radps: np.ndarray, rms: float, lead_s: float, lag_s: float) -> np.ndarray:
    """Amplitudes ``A_k`` proportional to ``|(1 + lead j w)^2 / (1 + lag j w)^2|`` with ``sqrt(sum A_k^2 / 2)``
    equal to ``rms``."""
    s = 1j * np.asarray(w_radps, dtype=float)
    a = np.abs((1.0 + lead_s * s) ** 2 / (1.0 + lag_s * s) ** 2)
    return a * (rms / math.sqrt(float(np.sum(a * a)) / 2.0))


def crest_factor(signal: np.ndarray) -> float:
    """Peak over RMS."""
    return float(np.max(np.abs(signal)) / math.sqrt(float(np.mean(signal * signal))))


def lowest_crest_phases(w_radps: np.ndarray, amplitudes: np.ndarray, window_s: float, seed: int) -> np.ndarray:
    """Of :data:`PHASE_TRIES` phase sets drawn from ``numpy.random.default_rng(seed)`` (uniform in [0, 2 pi)),
    the one whose multisine has the lowest crest factor over the window (sampled at 2048 points)."""
    rng = np.random.default_rng(seed)
    t = np.arange(2048) * (window_s / 2048)
    arg = np.outer(t, w_radps)
    best = rng.uniform(0.0, 2.0 * math.pi, len(w_radps))
    best_cf = crest_factor(np.sin(arg + best) @ amplitudes)
    for _ in range(PHASE_TRIES - 1):
        phases = rng.uniform(0.0, 2.0 * math.pi, len(w_radps))
        cf = crest_factor(np.sin(arg + phases) @ amplitudes)
        if cf < best_cf:
            best, best_cf = phases, cf
    return best


@dataclass(frozen=True)
class Multisine:
    """``f(t) = sum A_k sin(n_k w_b t + phi_k)`` (module docstring); amplitudes in the signal's unit."""

    multiples: np.ndarray
    amplitudes: np.ndarray
    phases_rad: np.ndarray
    window_s: float

    @property
    def frequencies_radps(self) -> np.ndarray:
        return self.multiples * base_frequency(self.window_s)

    def at(self, t_s: np.ndarray) -> np.ndarray:
        """The signal at times ``t_s`` (s)."""
        t = np.asarray(t_s, dtype=float)
        return np.sin(np.multiply.outer(t, self.frequencies_radps) + self.phases_rad) @ self.amplitudes

    def scaled(self, factors: np.ndarray) -> Multisine:
        """The same sines with each amplitude multiplied by ``factors[k]``."""
        return Multisine(self.multiples, self.amplitudes * np.asarray(factors), self.phases_rad, self.window_s)

    @property
    def rms(self) -> float:
        return math.sqrt(float(np.sum(self.amplitudes**2)) / 2.0)
