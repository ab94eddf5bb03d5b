"""What a condition's runs say, from the responses at the forcing frequencies (pure functions over arrays).

As in the cited experiments (Zaal et al. 2009, 2011; Pool et al. 2011; docs/pilot-model.md, "Measures"): each run's
measurement window (``N`` samples, the forcing functions' period) is Fourier transformed, ``X[n] = sum_k x_k
exp(-2 pi j n k / N)``, and the Fourier coefficients of the runs are averaged (the forcing functions repeat
identically, the remnant does not). At the disturbance's frequencies (``n`` in its multiples) and the target's:

    H_c(w)     = X / (U + F_d)          the controlled element, at both sets (attitude over control input)
    H_ol,d(w_d) = -U / (U + F_d)        the disturbance open loop, (H_v + H_m P) H_nms H_c
    H_ol,t(w_t) = X / E                 the target open loop, H_v H_nms H_c / (1 + H_m P H_nms H_c)
    H_mf(w)    = W_sim / W_ac            the motion filter: the simulator over the aircraft pilot's rate

and the crossover frequencies and phase margins of the two open loops (:func:`washbench.pilot.frequency.
crossover`). Variances (Parseval over the window: ``var = (2 / N^2) sum_{n=1}^{N/2-1} |X[n]|^2`` plus the Nyquist
bin once, the mean over the runs) are split into what lies at the target's frequencies and at the disturbance's
(the power of the averaged coefficients there) and the rest, the remnant.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from washbench.pilot.frequency import Crossover, crossover


def window_spectrum(x: np.ndarray, window: int) -> np.ndarray:
    """The one-sided DFT of the last ``window`` samples of ``x`` (``numpy.fft.rfft``)."""
    return np.fft.rfft(np.asarray(x, dtype=float)[-window:])


@dataclass(frozen=True)
class Decomposition:
    """A signal's variance (over the window, mean of the runs) split by frequency: at the target's sines, at the
    disturbance's, and the remnant (every other frequency but 0)."""

    target: float
    disturbance: float
    remnant: float

    @property
    def total(self) -> float:
        return self.target + self.disturbance + self.remnant


def decompose(spectra: Sequence[np.ndarray], window: int, target: np.ndarray, disturbance: np.ndarray) -> Decomposition:
    """:class:`Decomposition` of runs' window spectra (:func:`window_spectrum`); ``target`` and ``disturbance``:
    the bins (the multiples). The parts at the forcing frequencies are the power of the runs' averaged Fourier
    coefficients (what repeats from run to run; the remnant's share of those bins averages out), the remnant is
    the rest of the runs' mean variance."""

    def power(spec: np.ndarray) -> np.ndarray:
        p = np.abs(spec) ** 2 * (2.0 / window**2)
        p[0] = 0.0  # the mean is not variance
        if window % 2 == 0:
            p[-1] /= 2.0  # the Nyquist bin is counted once
        return p

    mean_power = power(np.mean(spectra, axis=0))
    total = float(np.mean([power(s).sum() for s in spectra]))
    t = float(mean_power[target].sum())
    d = float(mean_power[disturbance].sum())
    return Decomposition(t, d, total - t - d)


@dataclass(frozen=True)
class Identified:
    """The frequency responses of one condition at the forcing frequencies (module docstring), complex arrays."""

    w_target: np.ndarray
    w_disturbance: np.ndarray
    plant_target: np.ndarray
    plant_disturbance: np.ndarray
    open_loop_target: np.ndarray
    open_loop_disturbance: np.ndarray
    motion_target: np.ndarray
    motion_disturbance: np.ndarray

    @property
    def target_crossover(self) -> Crossover:
        return crossover(self.w_target, self.open_loop_target)

    @property
    def disturbance_crossover(self) -> Crossover:
        return crossover(self.w_disturbance, self.open_loop_disturbance)

    def plant(self) -> tuple[np.ndarray, np.ndarray]:
        """(w, H_c) at every forcing frequency, ascending."""
        w = np.concatenate([self.w_target, self.w_disturbance])
        h = np.concatenate([self.plant_target, self.plant_disturbance])
        order = np.argsort(w)
        return w[order], h[order]

    def motion(self) -> tuple[np.ndarray, np.ndarray]:
        """(w, H_mf) at every forcing frequency, ascending."""
        w = np.concatenate([self.w_target, self.w_disturbance])
        h = np.concatenate([self.motion_target, self.motion_disturbance])
        order = np.argsort(w)
        return w[order], h[order]


def identify(
    runs: Sequence[dict[str, np.ndarray]],
    window: int,
    base_frequency_radps: float,
    target: np.ndarray,
    disturbance: np.ndarray,
) -> Identified:
    """:class:`Identified` from runs, each a mapping of full-length signals: ``error``, ``control``, ``attitude``,
    ``disturbance``, ``aircraft_rate``, ``head_rate``; ``target`` and ``disturbance`` the multiples (bins)."""

    def mean(key: str) -> np.ndarray:
        return np.mean([window_spectrum(r[key], window) for r in runs], axis=0)

    e, u, x, fd = mean("error"), mean("control"), mean("attitude"), mean("disturbance")
    w_ac, w_sim = mean("aircraft_rate"), mean("head_rate")
    t, d = np.asarray(target), np.asarray(disturbance)
    with np.errstate(divide="ignore", invalid="ignore"):
        plant = x / (u + fd)
        motion = w_sim / w_ac
        return Identified(
            w_target=t * base_frequency_radps,
            w_disturbance=d * base_frequency_radps,
            plant_target=plant[t],
            plant_disturbance=plant[d],
            open_loop_target=x[t] / e[t],
            open_loop_disturbance=-u[d] / (u[d] + fd[d]),
            motion_target=motion[t],
            motion_disturbance=motion[d],
        )
