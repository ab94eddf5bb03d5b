"""Open-loop input shapes and the surface-travel map: pure functions of time, evaluated per step.

The shapes are the excitation signals of flight testing, of unit amplitude, as functions of
the time ``t`` (s) since the start of the phase (``t = (k - k0) * dt``, integer steps):

- ``step``: 0 before ``start_s``, 1 from it on.
- ``pulse``: 1 from ``start_s`` for ``duration_s``, else 0.
- ``doublet``: +1 for the first half of ``duration_s``, -1 for the second half.
- ``3211``: +1, -1, +1, -1 for 3, 2, 1 and 1 sevenths of ``duration_s`` (the 3-2-1-1 sequence).
- ``sine``: sin(2 pi (t - start_s) / period_s) from ``start_s``, for ``duration_s`` (default: to the phase end).
- ``chirp``: a frequency sweep sin(phase(t)) from ``start_hz`` to ``end_hz`` over ``duration_s``;
  ``linear`` (f = f0 + (f1 - f0) tau / T) or ``logarithmic`` (f = f0 (f1 / f0)^(tau / T)), the
  phase starting at 0 (the definitions of ``scipy.signal.chirp`` with ``phi=-90``).

Every window is half-open, [start, end): at ``t = start_s`` the signal is on, at the end off.

Surfaces: JSBSim's ``aerosurface_scale`` maps a command u in -1..1 onto the travel zero-centred
(u > 0 onto 0..max, u < 0 onto min..0), so a deflection in degrees maps back piecewise linearly.
The travel is read from the pilot profile's ``surfaces`` (taken from the model's flight-control
system), see :func:`surface_deg` and :func:`surface_norm`.
"""

from __future__ import annotations

import math

#: The input shapes, as the manoeuvre files name them.
SHAPES = ("step", "pulse", "doublet", "3211", "sine", "chirp")
SWEEPS = ("linear", "logarithmic")
TWO_PI = 2.0 * math.pi
_EPS = 1e-9  # s: step times are k * dt, so window edges are compared with a little slack


def step(t: float, start_s: float) -> float:
    """Unit step at ``start_s`` (s)."""
    return 1.0 if t >= start_s - _EPS else 0.0


def pulse(t: float, start_s: float, duration_s: float) -> float:
    """Unit pulse on [start_s, start_s + duration_s)."""
    return 1.0 if start_s - _EPS <= t < start_s + duration_s - _EPS else 0.0


def doublet(t: float, start_s: float, duration_s: float) -> float:
    """+1 for the first half of ``duration_s`` from ``start_s``, -1 for the second half, 0 outside."""
    tau = t - start_s
    if tau < -_EPS or tau >= duration_s - _EPS:
        return 0.0
    return 1.0 if tau < 0.5 * duration_s - _EPS else -1.0


def multistep_3211(t: float, start_s: float, duration_s: float) -> float:
    """The 3-2-1-1 sequence over ``duration_s`` (7 units): +1 for 3 units, -1 for 2, +1 for 1, -1 for 1."""
    tau = t - start_s
    if tau < -_EPS or tau >= duration_s - _EPS:
        return 0.0
    units = tau * 7.0 / duration_s
    if units < 3.0 - _EPS:
        return 1.0
    if units < 5.0 - _EPS:
        return -1.0
    if units < 6.0 - _EPS:
        return 1.0
    return -1.0


def sine(t: float, start_s: float, period_s: float, duration_s: float = math.inf) -> float:
    """sin(2 pi (t - start_s) / period_s) on [start_s, start_s + duration_s), else 0."""
    tau = t - start_s
    if tau < -_EPS or tau >= duration_s - _EPS:
        return 0.0
    return math.sin(TWO_PI * tau / period_s)


def chirp_phase(tau: float, duration_s: float, start_hz: float, end_hz: float, sweep: str = "linear") -> float:
    """Phase (rad) of a frequency sweep ``tau`` seconds after its start (the integral of 2 pi f)."""
    if sweep == "linear":
        return TWO_PI * (start_hz * tau + 0.5 * (end_hz - start_hz) * tau * tau / duration_s)
    if start_hz == end_hz:
        return TWO_PI * start_hz * tau
    ratio = end_hz / start_hz
    return TWO_PI * start_hz * duration_s / math.log(ratio) * (ratio ** (tau / duration_s) - 1.0)


def chirp(t: float, start_s: float, duration_s: float, start_hz: float, end_hz: float, sweep: str = "linear") -> float:
    """A sine sweep from ``start_hz`` to ``end_hz`` on [start_s, start_s + duration_s), else 0."""
    tau = t - start_s
    if tau < -_EPS or tau >= duration_s - _EPS:
        return 0.0
    return math.sin(chirp_phase(tau, duration_s, start_hz, end_hz, sweep))


def unit_shape(
    shape: str,
    t: float,
    start_s: float = 0.0,
    duration_s: float | None = None,
    period_s: float | None = None,
    start_hz: float | None = None,
    end_hz: float | None = None,
    sweep: str = "linear",
) -> float:
    """The unit-amplitude value of ``shape`` at ``t`` (s since the phase start); see the module docstring."""
    if shape == "step":
        return step(t, start_s)
    if shape == "pulse":
        return pulse(t, start_s, _need(duration_s))
    if shape == "doublet":
        return doublet(t, start_s, _need(duration_s))
    if shape == "3211":
        return multistep_3211(t, start_s, _need(duration_s))
    if shape == "sine":
        return sine(t, start_s, _need(period_s), math.inf if duration_s is None else duration_s)
    if shape == "chirp":
        return chirp(t, start_s, _need(duration_s), _need(start_hz), _need(end_hz), sweep)
    raise ValueError(f"unknown input shape {shape!r} (one of {', '.join(SHAPES)})")


def shape_extent(
    shape: str,
    start_s: float = 0.0,
    duration_s: float | None = None,
    period_s: float | None = None,
    start_hz: float | None = None,
    end_hz: float | None = None,
    sweep: str = "linear",
    phase_s: float | None = None,
) -> tuple[float, float]:
    """(lowest, highest) unit value of ``shape`` over its window (0 before it included), sampled every 1 ms.

    A sine without ``duration_s`` runs to the phase end ``phase_s`` (one period when that is not known). Sampling
    can only miss a peak by a little, never invent one: the extent is never wider than the signal's.
    """
    if shape in ("step", "pulse"):
        return 0.0, 1.0
    if shape in ("doublet", "3211"):
        return -1.0, 1.0
    length = duration_s
    if length is None:
        length = (phase_s - start_s) if phase_s is not None else _need(period_s)
    n = max(math.ceil(length / 1e-3), 1)
    lo = hi = 0.0
    for k in range(n):
        v = unit_shape(shape, start_s + k * 1e-3, start_s, duration_s, period_s, start_hz, end_hz, sweep)
        lo, hi = min(lo, v), max(hi, v)
    return lo, hi


def _need(x: float | None) -> float:
    if x is None:
        raise ValueError("missing parameter for the input shape")
    return x


def surface_deg(u: float, min_deg: float, max_deg: float) -> float:
    """Surface deflection (deg) of the normalised surface command ``u`` (-1..1, clipped), zero-centred map.

    ``min_deg`` (at u = -1, <= 0) and ``max_deg`` (at u = +1, >= 0) are the travel.
    """
    u = -1.0 if u < -1.0 else 1.0 if u > 1.0 else u
    return u * max_deg if u >= 0.0 else -u * min_deg


def surface_norm(deg: float, min_deg: float, max_deg: float) -> float:
    """The normalised command (-1..1) that deflects the surface ``deg`` degrees: the inverse of :func:`surface_deg`."""
    u = (deg / max_deg if max_deg > 0.0 else 0.0) if deg >= 0.0 else (-deg / min_deg if min_deg < 0.0 else 0.0)
    return -1.0 if u < -1.0 else 1.0 if u > 1.0 else u
