"""The pilot-vehicle loop in the frequency domain: responses, variances, stability, crossover (pure functions).

The loop of a compensatory tracking task (docs/pilot-model.md, "The loop"), at each frequency w [rad/s]::

    x = G (u + f_d)                                     attitude [rad]: plant G, disturbance f_d on the control
    e = f_t - x                                         displayed error [rad], target f_t
    u = A (e + n_v) - B x - C n_m                       the pilot (:mod:`washbench.pilot.params`):
        A = H_nms H_v,   C = H_nms H_m,   B = C P       visual channel, vestibular channel, vestibular path P

``P`` is what the canals report per unit attitude: ``P = H_scc(jw) H_mf(jw) jw`` with the canal model ``H_scc``
and the motion condition ``H_mf`` (1: the aircraft's own motion; 0: no motion; a washout's describing function).
With ``L = (A + B) G`` (the disturbance open loop) and ``S = 1 / (1 + L)``::

    u = S [A f_t - L f_d + A n_v - C n_m]
    e = S (1 + B G) f_t - S G f_d - S G (A n_v - C n_m)

and the target open loop is ``x / e = A G / (1 + B G)``. A multisine's variance is ``sum |H(jw_k)|^2 a_k^2 / 2``;
a white noise of two-sided intensity V gives ``(1/pi) int_0^{w_N} |H(jw)|^2 V dw`` (up to the Nyquist frequency of
the sampled loop).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from washbench.pilot.params import MultimodalParams


def nms_frf(w_radps: np.ndarray, p: MultimodalParams) -> np.ndarray:
    """H_nms(jw) = w_n^2 / ((jw)^2 + 2 zeta w_n jw + w_n^2)."""
    s = 1j * np.asarray(w_radps, dtype=float)
    wn, z = p.nms_frequency_radps, p.nms_damping
    return wn * wn / (s * s + 2.0 * z * wn * s + wn * wn)


def visual_frf(w_radps: np.ndarray, p: MultimodalParams, delay_s: float | None = None) -> np.ndarray:
    """H_v(jw) = K_v (T_L jw + 1) / (T_I jw + 1) exp(-jw tau_v) (``delay_s``: the delay realised, else tau_v)."""
    s = 1j * np.asarray(w_radps, dtype=float)
    tau = p.visual_delay_s if delay_s is None else delay_s
    return p.visual_gain * (p.lead_s * s + 1.0) / (p.lag_s * s + 1.0) * np.exp(-s * tau)


def vestibular_frf(w_radps: np.ndarray, p: MultimodalParams, delay_s: float | None = None) -> np.ndarray:
    """H_m(jw) = K_m exp(-jw tau_m) (``delay_s``: the delay realised, else tau_m)."""
    s = 1j * np.asarray(w_radps, dtype=float)
    tau = p.vestibular_delay_s if delay_s is None else delay_s
    return p.vestibular_gain * np.exp(-s * tau)


@dataclass(frozen=True)
class Loop:
    """The loop's transfer functions on a frequency grid ``w`` (module docstring): each a complex array like ``w``.

    ``A``, ``B``, ``C``: the pilot's visual channel, vestibular feedback and vestibular channel; ``G`` the plant.
    """

    w: np.ndarray
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    G: np.ndarray

    @property
    def disturbance_open_loop(self) -> np.ndarray:
        """L = (A + B) G: the loop the disturbance sees."""
        return (self.A + self.B) * self.G

    @property
    def target_open_loop(self) -> np.ndarray:
        """A G / (1 + B G): attitude over error at the target's frequencies."""
        return self.A * self.G / (1.0 + self.B * self.G)

    @property
    def sensitivity(self) -> np.ndarray:
        return 1.0 / (1.0 + self.disturbance_open_loop)

    def error_from_target(self) -> np.ndarray:
        return self.sensitivity * (1.0 + self.B * self.G)

    def error_from_disturbance(self) -> np.ndarray:
        return -self.sensitivity * self.G

    def control_from_target(self) -> np.ndarray:
        return self.sensitivity * self.A

    def control_from_disturbance(self) -> np.ndarray:
        return -self.sensitivity * self.disturbance_open_loop

    def error_from_visual_noise(self) -> np.ndarray:
        return -self.sensitivity * self.G * self.A

    def error_from_vestibular_noise(self) -> np.ndarray:
        return self.sensitivity * self.G * self.C

    def control_from_visual_noise(self) -> np.ndarray:
        return self.sensitivity * self.A

    def control_from_vestibular_noise(self) -> np.ndarray:
        return -self.sensitivity * self.C


def loop(
    w_radps: np.ndarray,
    p: MultimodalParams,
    plant: np.ndarray,
    path: np.ndarray,
    delays_s: tuple[float, float] | None = None,
) -> Loop:
    """The :class:`Loop` of pilot ``p`` on plant ``G = plant`` with vestibular path ``P = path`` (module docstring),
    all on ``w_radps``. ``delays_s``: the (visual, vestibular) delays as realised in discrete time, else the
    parameters'."""
    w = np.asarray(w_radps, dtype=float)
    tv, tm = delays_s if delays_s is not None else (None, None)
    hn = nms_frf(w, p)
    a = hn * visual_frf(w, p, tv)
    c = hn * vestibular_frf(w, p, tm)
    return Loop(w=w, A=a, B=c * np.asarray(path), C=c, G=np.asarray(plant, dtype=complex))


def sine_variance(h: np.ndarray, amplitudes: np.ndarray) -> float:
    """Variance of the response to a multisine: ``sum |h_k|^2 a_k^2 / 2`` (``h`` at its frequencies)."""
    return float(np.sum(np.abs(h) ** 2 * np.asarray(amplitudes) ** 2) / 2.0)


def noise_variance(w_radps: np.ndarray, h: np.ndarray, intensity: float) -> float:
    """Variance of the response ``h`` (on the grid ``w``, ascending) to white noise of two-sided intensity V:
    ``(1/pi) int |h|^2 V dw`` by the trapezoidal rule over the grid."""
    if intensity == 0.0:
        return 0.0
    return float(np.trapezoid(np.abs(h) ** 2, w_radps) * intensity / math.pi)


def noise_grid(dt_s: float, n: int = 1500, w_min: float = 0.01) -> np.ndarray:
    """A log-spaced grid from ``w_min`` to the Nyquist frequency pi/dt, rad/s (for :func:`noise_variance`)."""
    return np.geomspace(w_min, math.pi / dt_s, n)


def loop_type(w_radps: np.ndarray, open_loop: np.ndarray) -> int:
    """Number of integrators of an open loop, from the slope of its magnitude over the grid's first decade."""
    w = np.asarray(w_radps)
    i = int(np.searchsorted(w, w[0] * 10.0))
    slope = (np.log10(abs(open_loop[i])) - np.log10(abs(open_loop[0]))) / (np.log10(w[i]) - np.log10(w[0]))
    return max(0, round(float(-slope)))


def stable(w_radps: np.ndarray, open_loop: np.ndarray) -> bool:
    """Nyquist's criterion for ``1 / (1 + L)``, L with no pole in the right half plane and ``n`` integrators.

    Along the imaginary axis indented to the right of the origin, the net turn of ``1 + L`` is twice its turn over
    ``w`` in (0, inf) minus ``n pi`` (the indentation); the closed loop has no right-half-plane pole when that is
    zero: the turn from the grid's first frequency (where ``1 + L ~ L``, ``arg = -n pi/2`` for a positive gain) to
    its last (where ``1 + L ~ 1``) is ``n pi / 2``. The grid must start where ``|L|`` is large and end where it is
    small (:func:`stability_grid`), and be fine enough that the phase moves less than pi between points.
    """
    g = 1.0 + np.asarray(open_loop)
    if not np.all(np.isfinite(g)) or np.any(g == 0.0):
        return False
    n = loop_type(w_radps, open_loop)
    turn = float(np.unwrap(np.angle(g))[-1] - np.angle(g[0]))
    if abs(g[-1] - 1.0) > 0.2:  # the grid does not reach the frequencies where the loop has died out
        return False
    return abs(turn - n * math.pi / 2.0) < 0.5


def stability_grid() -> np.ndarray:
    """The frequency grid :func:`stable` is used on: 1e-3 to 1e3 rad/s, 12 000 points."""
    return np.geomspace(1e-3, 1e3, 12000)


@dataclass(frozen=True)
class Crossover:
    """Where an open loop's magnitude crosses 1: frequency (rad/s) and phase margin (deg); NaN when it does not."""

    frequency_radps: float
    phase_margin_deg: float


def crossover(w_radps: np.ndarray, open_loop: np.ndarray) -> Crossover:
    """The first crossing of ``|H| = 1`` from above along the ascending frequencies ``w`` (the forcing
    frequencies in the cited papers), log-magnitude and unwrapped phase interpolated linearly in log frequency;
    phase margin ``180 + phase(w_c)``, deg."""
    w = np.asarray(w_radps, dtype=float)
    h = np.asarray(open_loop)
    mag = np.log(np.abs(h))
    phase = np.unwrap(np.angle(h))
    if phase[0] > 0.5:  # an open loop starts near -90 deg (one integrator) or -180 deg: the branch below zero
        phase = phase - 2.0 * math.pi * math.ceil((phase[0] - 0.5) / (2.0 * math.pi))
    for i in range(len(w) - 1):
        if mag[i] >= 0.0 > mag[i + 1]:
            f = mag[i] / (mag[i] - mag[i + 1])
            lw = math.log(w[i]) + f * (math.log(w[i + 1]) - math.log(w[i]))
            ph = phase[i] + f * (phase[i + 1] - phase[i])
            return Crossover(math.exp(lw), 180.0 + math.degrees(ph))
    return Crossover(math.nan, math.nan)
