"""The Objective Motion Cueing Test (OMCT): inputs, Fourier coefficients, gain and phase, linearity, boundaries.

Pure functions over traces, no files (the command is :mod:`washbench.runs.omct`). After Advani and Hosman
(ICAO 9625 Ed. 3, Attachment F): a sinusoid at the motion cueing algorithm's input, at twelve frequencies
``10^(k/5)`` rad/s (k = -5 .. 6), and the gain and phase of the simulator's motion at the pilot's head.

**The ten tests** (:data:`TESTS`) and what their gain compares (all gains are dimensionless):

====================  ======================================  =============================================
test                  output (simulator pilot's head)         reference (aircraft pilot's head)
====================  ======================================  =============================================
``pitch_to_pitch``    pitch rate ``omega_y``                  pitch rate (= attitude ratio for a sinusoid)
``roll_to_roll``      roll rate ``omega_x``                   roll rate
``yaw_to_yaw``        yaw rate ``omega_z``                    yaw rate
``f_x_to_f_x``        ``f_x``                                 ``f_x``
``f_y_to_f_y``        ``f_y``                                 ``f_y``
``f_z_to_f_z``        ``f_z``                                 ``f_z``
``pitch_to_f_x``      ``f_x``                                 ``f_x = g sin(theta)`` that the pitch causes
``roll_to_f_y``       ``f_y``                                 ``f_y = -g sin(phi)`` that the roll causes
``f_x_to_pitch``      ``g theta``: pitch attitude, as the     ``f_x``
                      specific force it tilts into the pilot
``f_y_to_roll``       ``-g phi`` (roll attitude, likewise)    ``f_y``
====================  ======================================  =============================================

The attitudes of the last two tests come from the head angular velocity: at the frequency ``w`` the attitude's
Fourier coefficient is the rate's divided by ``j w``. So a perfect static tilt coordination has gain 1, phase 0
(the OMCT literature also quotes these two gains in rad/(m/s^2): divide by g).

**Inputs** (:func:`input_spec`, via :mod:`washbench.analysis.signals`, the same generator as
``washbench signal sine``): rotational tests turn the aircraft about the pilot's head with the angular
velocity ``Theta w sin(w t)`` (the input amplitude is that rate; the attitude is ``-Theta cos(w t)``, about
level) and the specific force that gravity gives the changing attitude; translational tests add
``A sin(w t)`` to level flight at 1 g.
Amplitudes (:func:`amplitude`) are CHOSEN HERE, not ICAO 9625's (whose table is not reproduced in this
project): ``A`` = 0.5 m/s^2 for translation; ``Theta = min(2 deg, 50 deg/s^2 / w^2)`` for rotation (the input's
angular acceleration stays at half the Atlas sphere's 100 deg/s^2 limit). With CW1 and the Atlas limits these
bind no limit, and the geometric non-linearity of a 2 deg attitude changes a gain by ``Theta^2 / 8 = 1.5e-4``.

**Timing** (:func:`timing`): the run lasts ``settle_s + periods * 2 pi / w``. ``settle_s`` is
``SETTLE_TIME_CONSTANTS`` (10) time constants of the slowest decay of the washout's linearised dynamics
(:func:`slowest_decay_radps`: the tilt gain ``K`` -- a bound on the tilt loop's slowest pole for every washout
-- the rotational and translational high-passes, the tilt low-pass and the head derivative estimator), so a
transient has fallen to ``e^-10 = 4.5e-5`` of its start; for CW1 that is ``10 / 0.4 = 25 s``. The gain and
phase are then taken over the last ``periods`` whole periods, at least ``MIN_WINDOW_S`` (5 s) long.

**Fourier coefficient** (:func:`fourier_coefficient`): the least-squares fit of ``a0 + a cos(w t) + b sin(w t)``
over the window, returned as ``c = a - j b`` (so the fundamental is ``Re(c e^{j w t})``). Over an exact number
of periods this IS the Fourier coefficient ``(2/T) integral y e^{-j w t}``; the fit keeps it exact when the
window's whole periods do not end on a sample (up to half a step), where a plain sum would leak the mean.

**Linearity** (:func:`is_linear`): a point is linear when no platform limit, tilt-rate limit or rotational
saturation bound at any step of its run, and the output left over after the mean and the fundamental (its
RMS times sqrt(2), relative to the reference amplitude: harmonics, a leftover transient) is at most
``MAX_DISTORTION`` (1 %) of the input.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from washbench.analysis.signals import AXIS_INDEX, ROTATIONAL_AXES, SignalSpec, amplitude_unit

FREQUENCIES_RADPS: tuple[float, ...] = tuple(10.0 ** (k / 5.0) for k in range(-5, 7))
SETTLE_TIME_CONSTANTS = 10.0
MIN_WINDOW_S = 5.0
MAX_DISTORTION = 0.01
TRANSLATIONAL_AMPLITUDE_MPS2 = 0.5
ROTATIONAL_ATTITUDE_DEG = 2.0
ROTATIONAL_ANGACC_DEGPS2 = 50.0


@dataclass(frozen=True)
class OmctTest:
    """One OMCT test: the input axis, the output quantity at the simulator pilot's head and its reference.

    ``output_kind``/``reference_kind`` are ``"f"`` (specific force) or ``"omega"`` (angular velocity) with an
    axis index; ``tilt_sign`` is 0 for a direct output, else the output is ``tilt_sign * g * omega / (j w)``
    (the attitude as specific force: +1 for pitch, -1 for roll).
    """

    name: str
    input_axis: str
    output_axis: str
    output_kind: str
    output_index: int
    reference_kind: str
    reference_index: int
    tilt_sign: int = 0


TESTS: tuple[OmctTest, ...] = (
    OmctTest("pitch_to_pitch", "pitch", "pitch", "omega", 1, "omega", 1),
    OmctTest("roll_to_roll", "roll", "roll", "omega", 0, "omega", 0),
    OmctTest("yaw_to_yaw", "yaw", "yaw", "omega", 2, "omega", 2),
    OmctTest("f_x_to_f_x", "f_x", "f_x", "f", 0, "f", 0),
    OmctTest("f_y_to_f_y", "f_y", "f_y", "f", 1, "f", 1),
    OmctTest("f_z_to_f_z", "f_z", "f_z", "f", 2, "f", 2),
    OmctTest("pitch_to_f_x", "pitch", "f_x", "f", 0, "f", 0),
    OmctTest("roll_to_f_y", "roll", "f_y", "f", 1, "f", 1),
    OmctTest("f_x_to_pitch", "f_x", "pitch", "omega", 1, "f", 0, tilt_sign=1),
    OmctTest("f_y_to_roll", "f_y", "roll", "omega", 0, "f", 1, tilt_sign=-1),
)
TEST_NAMES: tuple[str, ...] = tuple(t.name for t in TESTS)
TESTS_BY_NAME: dict[str, OmctTest] = {t.name: t for t in TESTS}


def amplitude(axis: str, w_radps: float) -> tuple[float, str]:
    """The input amplitude (chosen here, see the module docstring) and its unit: m/s^2 or deg/s (the rate)."""
    if axis in ROTATIONAL_AXES:
        attitude_deg = min(ROTATIONAL_ATTITUDE_DEG, ROTATIONAL_ANGACC_DEGPS2 / (w_radps * w_radps))
        return attitude_deg * w_radps, amplitude_unit(axis)
    return TRANSLATIONAL_AMPLITUDE_MPS2, amplitude_unit(axis)


def slowest_decay_radps(
    kind: str,
    tilt_gain_per_s: float,
    rot_wn: Sequence[float],
    trans_wn: Sequence[float],
    tilt_lp_wn: Sequence[float],
    derivative_wn: float,
) -> float:
    """The slowest decay rate [1/s] of a washout's dynamics linearised about level flight (a lower bound).

    The tilt loop's slowest pole is at ``-K`` for the quaternion washouts (integrator with gain ``K``) and
    further left for the small-angle one (its characteristic polynomial ``s (s + 2 wn)^2 + K (2 wn)^2`` is
    positive on ``[-K, 0]``), so ``K`` bounds both. The unrestricted washout has no rotational high-pass; a
    zero break frequency is no filter.
    """
    rates = [tilt_gain_per_s, derivative_wn, *trans_wn, *(2.0 * w for w in tilt_lp_wn)]
    if kind != "unrestricted":
        rates += [w for w in rot_wn if w > 0.0]
    return min(rates)


@dataclass(frozen=True)
class Timing:
    """One run's timing: ``settle_s`` waited, then ``periods`` whole periods analysed; ``duration_s`` in all."""

    settle_s: float
    periods: int
    duration_s: float


def settle_time_s(slowest_decay: float) -> float:
    """SETTLE_TIME_CONSTANTS time constants of the slowest decay [1/s]: the wait before the analysis [s]."""
    return SETTLE_TIME_CONSTANTS / slowest_decay


def timing(w_radps: float, slowest_decay: float) -> Timing:
    """Settle for :func:`settle_time_s`, then whole periods lasting at least MIN_WINDOW_S."""
    period = 2.0 * math.pi / w_radps
    settle = settle_time_s(slowest_decay)
    periods = max(1, math.ceil(MIN_WINDOW_S / period))
    return Timing(settle_s=settle, periods=periods, duration_s=settle + periods * period)


def input_spec(test: OmctTest, w_radps: float, rate_hz: float, duration_s: float, scale: float = 1.0) -> SignalSpec:
    """The test's input, a ``sine`` of :mod:`washbench.analysis.signals` (what ``washbench signal`` writes).

    ``scale`` multiplies the amplitude of :func:`amplitude` (to probe the end of the linear range).
    """
    amp, _ = amplitude(test.input_axis, w_radps)
    return SignalSpec(
        kind="sine",
        axis=test.input_axis,
        amplitude=amp * scale,
        frequency_hz=w_radps / (2.0 * math.pi),
        duration_s=duration_s,
        rate_hz=rate_hz,
    )


def window_samples(w_radps: float, dt_s: float, periods: int) -> int:
    """Number of samples in ``periods`` whole periods at step ``dt_s`` (rounded to the nearest sample)."""
    return round(periods * 2.0 * math.pi / (w_radps * dt_s))


@dataclass(frozen=True)
class Fit:
    """Fourier fit of one signal at one frequency: mean ``a0``, coefficient ``c``, ``residual`` amplitude."""

    a0: float
    c: complex
    residual: float  # sqrt(2) * RMS of what is left after a0 and the fundamental (an amplitude)


def fourier_coefficient(y: np.ndarray, dt_s: float, w_radps: float, periods: int) -> Fit:
    """Fit ``a0 + Re(c e^{j w t})`` to the last ``periods`` whole periods of ``y`` (N,) sampled every ``dt_s``.

    Time is measured from sample 0 of ``y`` (t_k = k dt), so phases of signals from the same run compare.
    """
    y = np.asarray(y, dtype=np.float64)
    m = window_samples(w_radps, dt_s, periods)
    if m < 3 or m > y.shape[0]:
        raise ValueError(f"{periods} periods at {w_radps} rad/s need {m} samples; the signal has {y.shape[0]}")
    k = np.arange(y.shape[0] - m, y.shape[0], dtype=np.float64)
    wt = w_radps * dt_s * k
    basis = np.column_stack([np.ones(m), np.cos(wt), np.sin(wt)])
    seg = y[-m:]
    coef, *_ = np.linalg.lstsq(basis, seg, rcond=None)
    resid = seg - basis @ coef
    return Fit(a0=float(coef[0]), c=complex(coef[1], -coef[2]), residual=float(math.sqrt(2.0 * np.mean(resid**2))))


def _signal(kind: str, index: int, f_mps2: np.ndarray, omega_radps: np.ndarray) -> np.ndarray:
    return f_mps2[:, index] if kind == "f" else omega_radps[:, index]


@dataclass(frozen=True)
class Response:
    """One output's response relative to the test's reference: complex ``h`` (gain ``|h|``, phase ``arg h``).

    ``distortion``: the output's residual amplitude relative to the reference amplitude (scaled like ``h``).
    """

    h: complex
    distortion: float

    @property
    def gain(self) -> float:
        """|h| (dimensionless)."""
        return abs(self.h)

    @property
    def phase_deg(self) -> float:
        """arg h in degrees, (-180, 180]; NaN where the gain is 0 (no phase)."""
        return math.degrees(math.atan2(self.h.imag, self.h.real)) if self.h != 0 else math.nan


def reference_fit(
    test: OmctTest, f_mps2: np.ndarray, omega_radps: np.ndarray, dt_s: float, w_radps: float, periods: int
) -> Fit:
    """Fourier fit of the test's reference signal in the aircraft pilot's motion (N, 3) each."""
    return fourier_coefficient(
        _signal(test.reference_kind, test.reference_index, f_mps2, omega_radps), dt_s, w_radps, periods
    )


def response(
    test: OmctTest,
    reference: Fit,
    f_mps2: np.ndarray,
    omega_radps: np.ndarray,
    dt_s: float,
    w_radps: float,
    periods: int,
    gravity_mps2: float,
) -> Response:
    """The test's output in a motion (head f, omega (N, 3)) relative to the reference fit (the input's).

    Works for the simulator pilot's head and, with the aircraft's own motion, for the aircraft pilot (whose
    output is the reference itself in a direct test, and zero rotation in the tilt tests).
    """
    y = _signal(test.output_kind, test.output_index, f_mps2, omega_radps)
    fit = fourier_coefficient(y, dt_s, w_radps, periods)
    scale: complex = 1.0
    if test.tilt_sign:
        scale = test.tilt_sign * gravity_mps2 / (1j * w_radps)
    ref = reference.c
    return Response(h=fit.c * scale / ref, distortion=fit.residual * abs(scale) / abs(ref))


def is_linear(distortion: float, saturated_kinds: Sequence[str]) -> bool:
    """True when no limit bound during the run and the distortion is at most MAX_DISTORTION."""
    return not saturated_kinds and distortion <= MAX_DISTORTION


def discrete_frequency_response(
    b: Sequence[tuple[float, float]], phi: Sequence[float], w_radps: float, dt_s: float
) -> complex:
    """Frequency response at ``w`` of a sum of first-order sections ``(b1 + b0 z^-1) / (1 - phi z^-1)``.

    The form of :class:`washbench.perception.vestibular.DiscreteModel` (``b`` = (b1, b0) pairs): its exact
    steady-state response to a sampled sinusoid, so the perceived motion of a periodic head motion is this
    times the head motion's Fourier coefficient, with no start-up transient to wait for.
    """
    zinv = complex(math.cos(w_radps * dt_s), -math.sin(w_radps * dt_s))
    return sum(((b1 + b0 * zinv) / (1.0 - p * zinv) for (b1, b0), p in zip(b, phi, strict=True)), 0j)


# ---------------------------------------------------------------- boundaries


@dataclass(frozen=True)
class Bounds:
    """Gain (absolute) and phase (deg) bounds of one test at some frequencies (rad/s, ascending).

    Any of the four bound lists may be None (not bounded on that side).
    """

    frequency_radps: tuple[float, ...]
    gain_min: tuple[float, ...] | None = None
    gain_max: tuple[float, ...] | None = None
    phase_min_deg: tuple[float, ...] | None = None
    phase_max_deg: tuple[float, ...] | None = None


def _interp(w: float, freqs: tuple[float, ...], values: tuple[float, ...] | None, log_values: bool) -> float | None:
    """Bound at ``w`` by straight lines on the Bode plot (log frequency; log gain); None outside or unbounded."""
    if values is None or not (freqs[0] <= w <= freqs[-1]):
        return None
    x = np.log10(freqs)
    v = np.log10(values) if log_values else np.asarray(values)
    out = float(np.interp(math.log10(w), x, v))
    return 10.0**out if log_values else out


def bounds_at(b: Bounds, w_radps: float) -> tuple[float | None, float | None, float | None, float | None]:
    """(gain_min, gain_max, phase_min_deg, phase_max_deg) at ``w``; None where not bounded there."""
    f = b.frequency_radps
    return (
        _interp(w_radps, f, b.gain_min, True),
        _interp(w_radps, f, b.gain_max, True),
        _interp(w_radps, f, b.phase_min_deg, False),
        _interp(w_radps, f, b.phase_max_deg, False),
    )


def check_bounds(b: Bounds | None, w_radps: float, gain: float, phase_deg: float) -> tuple[bool | None, bool | None]:
    """(gain inside, phase inside) of one point; None where the boundary does not cover this frequency.

    The phase is compared as given (continuous along frequency, as on the Bode plot).
    """
    if b is None:
        return None, None
    gmin, gmax, pmin, pmax = bounds_at(b, w_radps)
    gain_in = (
        None if gmin is None and gmax is None else (gmin is None or gain >= gmin) and (gmax is None or gain <= gmax)
    )
    phase_in = (
        None
        if pmin is None and pmax is None
        else (pmin is None or phase_deg >= pmin) and (pmax is None or phase_deg <= pmax)
    )
    return gain_in, phase_in


def unwrap_phase_deg(phases_deg: Sequence[float]) -> list[float]:
    """Phases along ascending frequency made continuous (steps below 180 deg), the first kept in (-180, 180].

    NaN entries (no phase) are kept and skipped.
    """
    out: list[float] = []
    last: float | None = None
    for p in phases_deg:
        if math.isnan(p):
            out.append(p)
            continue
        if last is not None:
            p = p - 360.0 * round((p - last) / 360.0)
        out.append(p)
        last = p
    return out


def axis_index(axis: str) -> int:
    """Index 0..2 of an axis name in its (f or omega) vector."""
    return AXIS_INDEX[axis]


def saturated_kinds(counts: Mapping[str, int]) -> tuple[str, ...]:
    """The limit kinds with at least one saturated step, in the given order."""
    return tuple(k for k, v in counts.items() if v)


# ---------------------------------------------------------------- the platform's own motion at the pilot's head


def rotation_matrices(q: np.ndarray) -> np.ndarray:
    """Body->inertial rotation matrices (N, 3, 3) of unit quaternions (N, 4), scalar first."""
    w, x, y, z = (np.asarray(q, dtype=np.float64)[:, i] for i in range(4))
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


@dataclass(frozen=True)
class PlatformHead:
    """The simulator's actual motion at the pilot's head, from the platform's state, at samples 0..N-2.

    ``f_mps2`` specific force and ``omega_radps`` angular velocity (N-1, 3), cockpit body axes; ``roll_rad``,
    ``pitch_rad`` (N-1,): the platform's attitude (ZYX Euler angles of its quaternion).
    """

    f_mps2: np.ndarray
    omega_radps: np.ndarray
    roll_rad: np.ndarray
    pitch_rad: np.ndarray


def platform_head_motion(
    pos_m: np.ndarray, q: np.ndarray, omega_radps: np.ndarray, head_m: Sequence[float], dt_s: float, g_mps2: float
) -> PlatformHead:
    """The platform's own motion at the head (offset ``head_m`` from the cockpit centre, body axes, m).

    From the platform's state as the kinematic model moved it (not through any estimator): position ``pos_m``
    (N, 3) inertial NED, attitude ``q`` (N, 4) body->inertial, and body rates ``omega_radps`` (N, 3), where
    ``omega[k]`` is the constant rate the platform turned at over the step ``(t_{k-1}, t_k]`` (it moves ``q[k-1]``
    to ``q[k]``). At each sample ``t_k``, centred (no delay; a sinusoid's gain is off by at most
    ``(w dt)^2 / 6``, 0.3 % at 16 rad/s and 120 Hz):

    - angular velocity ``w_k = (omega[k] + omega[k+1]) / 2``, angular acceleration ``(omega[k+1] - omega[k]) / dt``;
    - inertial acceleration ``a_k = (p[k+1] - 2 p[k] + p[k-1]) / dt^2`` (``p[0]`` extended backwards at rest);
    - specific force ``f = R_k^T (a_k - [0, 0, g]) + alpha_k x r + w_k x (w_k x r)`` (Eq. 10 of the paper with the
      platform's own rates);
    - attitude: the roll and pitch angles of ``q[k]``.

    The last sample needs ``omega[N]`` and ``p[N]``: it is left out (N-1 samples returned, sample k at t_k).
    """
    p = np.asarray(pos_m, dtype=np.float64)
    om = np.asarray(omega_radps, dtype=np.float64)
    qq = np.asarray(q, dtype=np.float64)
    n = p.shape[0]
    if n < 3 or p.shape != (n, 3) or om.shape != (n, 3) or qq.shape != (n, 4):
        raise ValueError(f"need pos (N>=3, 3), q (N, 4), omega (N, 3); got {p.shape}, {qq.shape}, {om.shape}")
    w = 0.5 * (om[:-1] + om[1:])
    alpha = (om[1:] - om[:-1]) / dt_s
    prev = np.vstack([p[:1], p[:-2]])
    acc = (p[1:] - 2.0 * p[:-1] + prev) / (dt_s * dt_s)
    rot = rotation_matrices(qq[:-1])
    r = np.broadcast_to(np.asarray(head_m, dtype=np.float64), w.shape)
    a_rel = acc - np.array([0.0, 0.0, g_mps2])
    f = np.einsum("nji,nj->ni", rot, a_rel) + np.cross(alpha, r) + np.cross(w, np.cross(w, r))
    roll = np.arctan2(rot[:, 2, 1], rot[:, 2, 2])
    pitch = -np.arcsin(np.clip(rot[:, 2, 0], -1.0, 1.0))
    return PlatformHead(f_mps2=f, omega_radps=w, roll_rad=roll, pitch_rad=pitch)


def platform_response(
    test: OmctTest, reference: Fit, head: PlatformHead, dt_s: float, w_radps: float, periods: int, gravity_mps2: float
) -> Response:
    """The test's output in the platform's own head motion relative to the reference fit (the input's).

    Direct tests take the head's specific force or angular velocity; the tilt tests (``f_x_to_pitch``,
    ``f_y_to_roll``) the platform's attitude itself, as specific force: ``tilt_sign * g * angle``.
    """
    if test.tilt_sign:
        y = head.pitch_rad if test.output_index == 1 else head.roll_rad
        scale = test.tilt_sign * gravity_mps2
    else:
        y = _signal(test.output_kind, test.output_index, head.f_mps2, head.omega_radps)
        scale = 1.0
    fit = fourier_coefficient(y, dt_s, w_radps, periods)
    return Response(h=fit.c * scale / reference.c, distortion=fit.residual * abs(scale) / abs(reference.c))
