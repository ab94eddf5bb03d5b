"""Test signals on one axis of the aircraft pilot's head motion: the input of ``washbench cue`` without a flight.

A signal is a shape ``s(t)`` scaled by an amplitude on one of six axes, sampled at ``t_k = k / rate_hz``:

- translational axes ``f_x``, ``f_y``, ``f_z``: the specific force ``A s(t)`` [m/s^2] is added to level flight
  at 1 g, ``f = [0, 0, -g] + A s(t) e_axis``, with no rotation;
- rotational axes ``roll``, ``pitch``, ``yaw``: the body angular velocity about that axis is ``A s(t)``
  (``A`` in deg/s at this edge, rad/s inside), and the specific force is the one gravity gives the changing
  attitude, ``f = -R^T g_I`` with ``R`` the rotation about that body axis by the angle ``theta(t)`` (a physically
  consistent rotation about the pilot's head): roll ``[0, -g sin(phi), -g cos(phi)]``, pitch
  ``[g sin(theta), 0, -g cos(theta)]``, yaw ``[0, 0, -g]``. ``theta`` is the integral of the rate: from level
  (``theta(0) = 0``) for step, pulse, doublet and chirp; for the periodic kinds (sine, multisine) the zero-mean
  one, so the aircraft oscillates about level and starts at rest in rotation at the bottom of its swing (sine:
  ``theta = -(A / w) cos(w t)``). Starting at rest matters: the washouts start every filter in the steady state
  of the first sample, and a first rate of ``A`` would leave the rotational high-pass a transient that the
  tilt coordination then has to undo at its rate limit.

Kinds (``F`` = ``frequency_hz``, ``t0`` = ``start_s``, ``w = 2 pi F``):

- ``sine``: ``sin(w t)``. This is the OMCT input (:mod:`washbench.analysis.omct`).
- ``step``: 0 before ``t0``, 1 from ``t0`` on (a rotational step is a constant rate: the aircraft keeps turning).
- ``pulse``: 1 on ``[t0, t0 + 1/F)``, else 0.
- ``doublet``: +1 on ``[t0, t0 + 1/(2F))``, -1 on ``[t0 + 1/(2F), t0 + 1/F)``, else 0 (one square-wave period).
- ``chirp``: ``sin(phase(t))`` with the frequency swept exponentially from ``F/100`` at ``t0`` to ``F`` at the
  end (two decades, equal time per decade); 0 before ``t0``.
- ``multisine``: the mean of six sines at ``F * 10^(k/5)``, k = 0..5 (the OMCT spacing, one decade up from
  ``F``), with Schroeder phases ``-pi k (k - 1) / 6`` (low crest factor); peak at most ``A``.

Attitudes are integrated in closed form, except the chirp's, which uses the cumulative Simpson rule on a grid
eight times finer than the samples (error below 1e-12 rad for any rate this module accepts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from washbench.errors import WashbenchError
from washbench.io.budget import check_samples

G0_MPS2 = 9.80665  # standard gravity: the level-flight specific force of the signals
AXES: tuple[str, ...] = ("f_x", "f_y", "f_z", "roll", "pitch", "yaw")
TRANSLATIONAL_AXES: tuple[str, ...] = ("f_x", "f_y", "f_z")
ROTATIONAL_AXES: tuple[str, ...] = ("roll", "pitch", "yaw")
KINDS: tuple[str, ...] = ("sine", "step", "pulse", "doublet", "chirp", "multisine")
NEEDS_FREQUENCY: frozenset[str] = frozenset({"sine", "pulse", "doublet", "chirp", "multisine"})
AXIS_INDEX = {"f_x": 0, "f_y": 1, "f_z": 2, "roll": 0, "pitch": 1, "yaw": 2}
AXIS_ALIASES = {"surge": "f_x", "sway": "f_y", "heave": "f_z", "x": "f_x", "y": "f_y", "z": "f_z",
                "p": "roll", "q": "pitch", "r": "yaw"}  # fmt: skip
"""The metrics' DOF names (surge, sway, heave) and the body-axis letters, accepted for the signal axes."""


def canonical_axis(name: str) -> str:
    """The axis ``name`` as :data:`AXES` spells it (``heave`` -> ``f_z``; case and ``-``/``_`` ignored); an unknown
    name is a WashbenchError listing both namings."""
    key = name.strip().lower().replace("-", "_")
    key = AXIS_ALIASES.get(key, key)
    if key not in AXES:
        raise WashbenchError(
            f"unknown axis {name!r} (valid: {', '.join(AXES)}, or surge, sway, heave for f_x, f_y, f_z)"
        )
    return key
MULTISINE_N = 6
CHIRP_DECADES = 2.0
_REFINE = 8  # chirp attitude: Simpson sub-steps per sample


def amplitude_unit(axis: str) -> str:
    """The unit of ``--amplitude`` on ``axis``: m/s^2 (specific force) or deg/s (angular velocity)."""
    return "m/s^2" if axis in TRANSLATIONAL_AXES else "deg/s"


@dataclass(frozen=True)
class SignalSpec:
    """One test signal. ``amplitude`` in m/s^2 (translational axes) or deg/s (rotational axes).

    ``frequency_hz`` is required by every kind but ``step``; ``start_s`` is the onset of step, pulse, doublet
    and chirp (sine and multisine start at t = 0). Samples ``t_k = k / rate_hz``, k = 0 .. round(duration_s *
    rate_hz). Checked by :func:`check_spec`.
    """

    kind: str
    axis: str
    amplitude: float
    frequency_hz: float | None = None
    duration_s: float = 20.0
    rate_hz: float = 120.0
    start_s: float = 1.0


@dataclass(frozen=True)
class Signal:
    """Sampled head motion: ``t_s`` (N,) [s], ``f_mps2`` (N, 3) body specific force, ``omega_radps`` (N, 3)."""

    t_s: np.ndarray
    f_mps2: np.ndarray
    omega_radps: np.ndarray

    @property
    def dt_s(self) -> float:
        """The sample step [s]."""
        return float(self.t_s[1] - self.t_s[0])


def _positive(name: str, value: float | None) -> float:
    if value is None or not (math.isfinite(value) and value > 0.0):
        raise WashbenchError(f"{name} must be a positive number, got {value!r}")
    return float(value)


def check_spec(spec: SignalSpec) -> SignalSpec:
    """The spec if it is valid; otherwise WashbenchError naming the option and the problem (one line)."""
    if spec.kind not in KINDS:
        raise WashbenchError(f"unknown signal kind {spec.kind!r} (valid: {', '.join(KINDS)})")
    if spec.axis not in AXES:
        canonical_axis(spec.axis)  # the error naming both namings
        raise WashbenchError(f"axis {spec.axis!r}: give it as {canonical_axis(spec.axis)!r} in a SignalSpec")
    if not math.isfinite(spec.amplitude):
        raise WashbenchError(f"--amplitude must be a finite number, got {spec.amplitude!r}")
    rate = _positive("--rate-hz", spec.rate_hz)
    duration = _positive("--duration-s", spec.duration_s)
    if duration * rate < 1.0:
        raise WashbenchError(f"--duration-s {duration} s is shorter than one sample at {rate} Hz")

    check_samples(duration * rate + 1.0, f"--duration-s {duration:g} at --rate-hz {rate:g}")
    if not (math.isfinite(spec.start_s) and spec.start_s >= 0.0):
        raise WashbenchError(f"--start-s must be a number >= 0, got {spec.start_s!r}")
    if spec.kind in NEEDS_FREQUENCY:
        f = _positive("--frequency-hz", spec.frequency_hz)
        top = f * 10.0 ** ((MULTISINE_N - 1) / 5.0) if spec.kind == "multisine" else f
        if top >= 0.5 * rate:
            raise WashbenchError(
                f"--frequency-hz: {spec.kind} reaches {top:.6g} Hz, "
                f"at or above the Nyquist frequency {0.5 * rate:.6g} Hz"
            )
    return spec


def _chirp_phase(t: np.ndarray, f1_hz: float, t0: float, t1: float) -> np.ndarray:
    """Phase [rad] of an exponential sweep from f1/100 Hz at t0 to f1 Hz at t1 (0 before t0)."""
    f0 = f1_hz / 10.0**CHIRP_DECADES
    span = max(t1 - t0, 1e-12)
    beta = math.log(f1_hz / f0) / span
    tau = np.clip(t - t0, 0.0, None)
    return 2.0 * math.pi * f0 * np.expm1(beta * tau) / beta


def _shape(spec: SignalSpec, t: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """The dimensionless shape s(t) and, where known in closed form, its integral from 0 [s]."""
    kind, t0 = spec.kind, spec.start_s
    if kind == "step":
        return (t >= t0).astype(np.float64), np.clip(t - t0, 0.0, None)
    f = float(spec.frequency_hz)  # type: ignore[arg-type]  # checked by check_spec
    w = 2.0 * math.pi * f
    if kind == "sine":
        return np.sin(w * t), -np.cos(w * t) / w
    if kind == "pulse":
        width = 1.0 / f
        return ((t >= t0) & (t < t0 + width)).astype(np.float64), np.clip(t - t0, 0.0, width)
    if kind == "doublet":
        h = 0.5 / f
        s = ((t >= t0) & (t < t0 + h)).astype(np.float64) - ((t >= t0 + h) & (t < t0 + 2 * h)).astype(np.float64)
        return s, np.clip(t - t0, 0.0, h) - np.clip(t - t0 - h, 0.0, h)
    if kind == "multisine":
        s = np.zeros_like(t)
        integral = np.zeros_like(t)
        for k in range(MULTISINE_N):
            wk = w * 10.0 ** (k / 5.0)
            ph = -math.pi * k * (k - 1) / MULTISINE_N
            s += np.sin(wk * t + ph)
            integral -= np.cos(wk * t + ph) / wk
        return s / MULTISINE_N, integral / MULTISINE_N
    # chirp
    s = np.where(t >= t0, np.sin(_chirp_phase(t, f, t0, float(t[-1]))), 0.0)
    return s, None


def _chirp_integral(spec: SignalSpec, n: int, dt: float) -> np.ndarray:
    """Integral from 0 of the rotational chirp shape at the samples, cumulative Simpson on a finer grid [s]."""
    from scipy.integrate import cumulative_simpson

    k = np.arange((n - 1) * _REFINE + 1, dtype=np.float64)
    tf = k * (dt / _REFINE)
    t_end = (n - 1) * dt
    f = float(spec.frequency_hz)  # type: ignore[arg-type]
    sf = np.where(tf >= spec.start_s, np.sin(_chirp_phase(tf, f, spec.start_s, t_end)), 0.0)
    cum = cumulative_simpson(sf, dx=dt / _REFINE, initial=0.0)
    return cum[::_REFINE]


def generate(spec: SignalSpec, gravity_mps2: float = G0_MPS2) -> Signal:
    """Sample the signal: t_s (N,), f_mps2 (N, 3), omega_radps (N, 3); see the module docstring."""
    spec = check_spec(spec)
    dt = 1.0 / spec.rate_hz
    n = round(spec.duration_s * spec.rate_hz) + 1
    t = np.arange(n, dtype=np.float64) * dt
    rotational = spec.axis in ROTATIONAL_AXES
    s, integral = _shape(spec, t)
    f = np.zeros((n, 3))
    f[:, 2] = -gravity_mps2
    omega = np.zeros((n, 3))
    j = AXIS_INDEX[spec.axis]
    if not rotational:
        f[:, j] += spec.amplitude * s
        return Signal(t_s=t, f_mps2=f, omega_radps=omega)
    a = math.radians(spec.amplitude)
    omega[:, j] = a * s
    if integral is None:
        integral = _chirp_integral(spec, n, dt)
    angle = a * integral
    if spec.axis == "roll":
        f[:, 1] = -gravity_mps2 * np.sin(angle)
        f[:, 2] = -gravity_mps2 * np.cos(angle)
    elif spec.axis == "pitch":
        f[:, 0] = gravity_mps2 * np.sin(angle)
        f[:, 2] = -gravity_mps2 * np.cos(angle)
    return Signal(t_s=t, f_mps2=f, omega_radps=omega)
