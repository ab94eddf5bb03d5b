"""The built-in multimodal pilot model in discrete time, one sample per call (:class:`MultimodalPilot`).

The continuous model is that of :mod:`washbench.pilot.params`::

    u = H_nms [ K_v (T_L s + 1)/(T_I s + 1) e^(-tau_v s) (e + n_v) - K_m e^(-tau_m s) (w_hat + n_m)
                - K_a e^(-tau_m s) f_hat ]

Realised as: each delay a line of whole samples (``round(tau / dt)``; the vestibular line shortened by the
perceived motion's own lag, :attr:`washbench.pilot.model.PilotContext.motion_lag_samples`), then three linear
filters, one per modality, each with the neuromuscular dynamics in it (so every one is proper):
``G_v = K_v (T_L s + 1) / (T_I s + 1) H_nms``, ``G_m = K_m H_nms`` and ``G_a = K_a H_nms``, discretised with a
first-order hold (``scipy.signal.cont2discrete(..., method="foh")``: exact for an input linear between samples,
the input assumption of the project's vestibular models too). The noises ``n_v`` and ``n_m`` are white, drawn once
per run from ``numpy.random.default_rng(seed)`` with variance ``V / dt`` per sample (so their intensity matches the
continuous model's up to the Nyquist frequency). Plain Python floats per step: a few microseconds, beside the
JSBSim step.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from washbench.pilot.model import PilotContext
from washbench.pilot.params import MultimodalParams


class _Filter:
    """A discrete SISO state-space filter stepped on Python floats: ``y = C x + D u; x <- A x + B u``."""

    def __init__(self, num: list[float], den: list[float], dt_s: float) -> None:
        from scipy import signal  # deferred: scipy's signal module (a tenth of a second) for a run's set-up only

        if not any(num):  # a channel switched off (gain 0): no state, no output
            self.a, self.b, self.c, self.d, self.x, self.n = [], [], [], 0.0, [], 0
            return
        a, b, c, d, _ = signal.cont2discrete(signal.tf2ss(num, den), dt_s, method="foh")
        self.a = [[float(v) for v in row] for row in np.atleast_2d(a)]
        self.b = [float(v) for v in np.asarray(b).reshape(-1)]
        self.c = [float(v) for v in np.asarray(c).reshape(-1)]
        self.d = float(np.asarray(d).reshape(-1)[0])
        self.x = [0.0] * len(self.b)
        self.n = len(self.b)

    def step(self, u: float) -> float:
        x = self.x
        n = self.n
        y = self.d * u
        for i in range(n):
            y += self.c[i] * x[i]
        new = [0.0] * n
        for i in range(n):
            row = self.a[i]
            acc = self.b[i] * u
            for j in range(n):
                acc += row[j] * x[j]
            new[i] = acc
        self.x = new
        return y


class _Delay:
    """A delay line of ``n`` whole samples (0: none)."""

    def __init__(self, n: int) -> None:
        self.buf = [0.0] * (n + 1)
        self.i = 0
        self.n = n

    def step(self, v: float) -> float:
        if self.n == 0:
            return v
        self.buf[self.i] = v
        self.i = (self.i + 1) % (self.n + 1)
        return self.buf[self.i]


def realised_delays(p: MultimodalParams, dt_s: float) -> tuple[int, int]:
    """The (visual, vestibular) delays in whole samples, before the perceived motion's own lag is taken off."""
    return round(p.visual_delay_s / dt_s), round(p.vestibular_delay_s / dt_s)


def channel_polynomials(p: MultimodalParams) -> dict[str, tuple[list[float], list[float]]]:
    """Numerator and denominator (descending powers of s) of G_v, G_m and G_a (the module docstring)."""
    wn2 = p.nms_frequency_radps**2
    nms_den = [1.0, 2.0 * p.nms_damping * p.nms_frequency_radps, wn2]
    visual_num = [p.visual_gain * p.lead_s * wn2, p.visual_gain * wn2]
    visual_den = list(np.polymul([p.lag_s, 1.0], nms_den)) if p.lag_s > 0.0 else nms_den
    return {
        "visual": (visual_num, [float(v) for v in visual_den]),
        "vestibular": ([p.vestibular_gain * wn2], nms_den),
        "otolith": ([p.otolith_gain * wn2], nms_den),
    }


class MultimodalPilot:
    """The built-in pilot model (module docstring): ``MultimodalPilot(params, context)``, then :meth:`step`."""

    Params = MultimodalParams

    def __init__(self, params: MultimodalParams | None, context: PilotContext) -> None:
        p = params if params is not None else MultimodalParams()
        self.params = p
        dt = context.dt_s
        nv, nm = realised_delays(p, dt)
        lag = max(0, context.motion_lag_samples)
        self.visual_delay = _Delay(nv)
        self.motion_delay = _Delay(max(0, nm - lag))
        self.force_delay = _Delay(max(0, nm - lag))
        self.delays_s = (nv * dt, max(nm, lag) * dt)
        """The delays as realised, s (visual; vestibular, the perceived motion's lag included)."""
        polys = channel_polynomials(p)
        self.visual = _Filter(*polys["visual"], dt)
        self.canals = _Filter(*polys["vestibular"], dt)
        self.otoliths = _Filter(*polys["otolith"], dt)
        rng = np.random.default_rng(context.seed)
        n = max(1, context.steps)
        self.visual_noise = (rng.standard_normal(n) * math.sqrt(p.visual_noise_rad2s / dt)).tolist()
        self.rate_noise = (rng.standard_normal(n) * math.sqrt(p.vestibular_noise_rad2ps / dt)).tolist()
        self.k = 0
        self._last = (0.0, 0.0)

    def step(self, error_rad: float, rate_radps: float, force_mps2: float) -> float:
        """One sample: the displayed error (rad), the perceived rate (rad/s) and specific force (m/s^2); the
        control (task units)."""
        k = self.k
        nv = self.visual_noise[k] if k < len(self.visual_noise) else 0.0
        nm = self.rate_noise[k] if k < len(self.rate_noise) else 0.0
        self.k = k + 1
        seen = self.visual_delay.step(error_rad + nv)
        felt_rate = self.motion_delay.step(rate_radps + nm)
        felt_force = self.force_delay.step(force_mps2)
        u_visual = self.visual.step(seen)
        u_motion = -self.canals.step(felt_rate) - self.otoliths.step(felt_force)
        self._last = (u_visual, u_motion)
        return u_visual + u_motion

    def contributions(self) -> tuple[float, float]:
        """The visual and the vestibular parts of the last control."""
        return self._last

    def describe(self) -> dict[str, Any]:
        """The parameters, as flown (the delays as realised in samples)."""
        out: dict[str, Any] = dict(self.params.model_dump())
        out["visual_delay_realised_s"], out["vestibular_delay_realised_s"] = self.delays_s
        return out
