"""The public cueing API: :class:`CueingBank` (streaming), :func:`cue_trace` (whole trace), :class:`WashoutTrace`.

A bank runs one or more washouts side by side on the same aircraft motion, each with its own kinematic
Atlas platform and simulator head motion. Both ways in call the same compiled step
(:mod:`washbench.cueing.kernel`), so they give identical results bit for bit.

Units and frames: inputs are the specific force at the aircraft pilot's head (aircraft body axes, m/s^2,
[0, 0, -g] at rest) and the aircraft body angular velocity (rad/s). Outputs are listed in
:data:`CueingBank.FIELDS`: platform position/velocity/acceleration (inertial NED, m, m/s, m/s^2),
attitude (body->inertial quaternion, scalar first), body angular velocity (rad/s), specific force (m/s^2)
and angular velocity (rad/s) at the simulator pilot's head in simulator body axes, omni-wheel speeds
(rad/s), the washout's set points, and 0/1 saturation flags per limit kind for the step.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from washbench.cueing import filters
from washbench.cueing.kernel import (
    C_ALPHA,
    C_AMAX,
    C_CATCH,
    C_COSMIN,
    C_DT,
    C_FREEFALL,
    C_G,
    C_JAC,
    C_KIND,
    C_PMAX,
    C_R,
    C_ROT_SAT,
    C_SF,
    C_SW,
    C_TILT_K,
    C_TILT_RATE,
    C_VMAX,
    C_WMAX,
    F_EULER_D,
    F_OMEGA_D,
    F_ROT_HP,
    F_TILT_LP,
    F_TRANS_HP,
    FIELDS,
    KIND_LARGE,
    KIND_SMALL,
    KIND_UNRESTRICTED,
    NCFG,
    NFIELDS,
    NFILT,
    NSTATE,
    O_ACC,
    O_HEAD_F,
    O_HEAD_OMEGA,
    O_OMEGA,
    O_POS,
    O_Q,
    O_SAT,
    O_SP_POS,
    O_SP_Q,
    O_VEL,
    O_WHEEL,
    SAT_KINDS,
    bank_step,
    bank_trace,
)
from washbench.cueing.params import WashoutParams, check_washouts
from washbench.errors import WashbenchError
from washbench.io.results import DT_RANGE_S
from washbench.platform.limits import PlatformLimits, wheel_jacobian

_KINDS = {"small-angle": KIND_SMALL, "large-angle": KIND_LARGE, "unrestricted": KIND_UNRESTRICTED}


def _check_dt(dt_s: float) -> float:
    dt = float(dt_s)
    lo, hi = DT_RANGE_S
    if not (math.isfinite(dt) and lo <= dt <= hi):
        raise WashbenchError(f"time step must be a positive number of seconds, {lo:g}..{hi:g} s, got {dt_s!r}")
    return dt


def _build_arrays(
    names: tuple[str, ...], params: WashoutParams, limits: PlatformLimits, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """The compiled bank's configuration (n, NCFG) and discretised filters (n, NFILT, 9), all SI.

    ``names`` (:func:`check_washouts`) and ``dt`` (s, :func:`_check_dt`) are already checked. Only the kind,
    the tilt low-pass and the rotational high-pass differ between washouts.
    """
    lim = limits.translation
    common = np.zeros(NCFG)
    common[C_DT] = dt
    common[C_G] = params.gravity_mps2
    common[C_SF] = params.scale.specific_force
    common[C_SW] = params.scale.angular_velocity
    common[C_TILT_K] = params.tilt.gain_per_s
    common[C_TILT_RATE] = math.radians(params.tilt.rate_limit_degps)
    common[C_ROT_SAT] = math.radians(params.rotational.saturation_degps)
    common[C_COSMIN] = params.small_angle.min_cos_pitch
    common[C_FREEFALL] = params.free_fall_threshold_mps2
    common[C_R : C_R + 3] = params.head.offset_m
    common[C_PMAX : C_PMAX + 3] = lim.position_limit_m.xyz
    common[C_VMAX : C_VMAX + 3] = lim.velocity_limit_mps.xyz
    common[C_AMAX : C_AMAX + 3] = lim.acceleration_limit_mps2.xyz
    common[C_WMAX] = math.radians(limits.rotation.rate_limit_degps)
    common[C_ALPHA] = math.radians(limits.rotation.acceleration_limit_degps2)
    common[C_CATCH] = limits.rotation.catch_up_fraction
    common[C_JAC : C_JAC + 9] = wheel_jacobian(limits).ravel()
    cfg = np.tile(common, (len(names), 1))

    coef = np.zeros((len(names), NFILT, filters.NCOEF))
    for j, wn in enumerate(params.translational_highpass_wn_radps.xyz):
        coef[:, F_TRANS_HP + j] = filters.discretise(filters.translational_highpass(wn), dt)
    derivative = filters.discretise(filters.derivative_estimator(params.head.derivative_wn_radps), dt)
    coef[:, F_EULER_D : F_EULER_D + 3] = derivative
    coef[:, F_OMEGA_D : F_OMEGA_D + 3] = derivative
    lp = params.tilt.lowpass_wn_radps
    rot = params.rotational.highpass_wn_radps
    for i, name in enumerate(names):
        kind = _KINDS[name]
        cfg[i, C_KIND] = kind
        # small-angle: the tilt low-pass filters the roll, pitch, yaw tilt rates; roll is made by f_y
        # (sway wn), pitch by f_x (surge wn), yaw by the z wn. Large-angle: it filters f_x, f_y, f_z.
        tilt_wn = (lp.y, lp.x, lp.z) if kind == KIND_SMALL else (lp.x, lp.y, lp.z)
        rot_wn = (0.0, 0.0, 0.0) if kind == KIND_UNRESTRICTED else (rot.roll, rot.pitch, rot.yaw)
        for j in range(3):
            coef[i, F_TILT_LP + j] = filters.discretise(filters.tilt_lowpass(tilt_wn[j]), dt)
            coef[i, F_ROT_HP + j] = filters.discretise(filters.rotational_highpass(rot_wn[j]), dt)
    return cfg, coef


@dataclass(frozen=True)
class WashoutTrace:
    """Everything one washout did over a recording (N samples), float64 arrays.

    pos_m, vel_mps, acc_mps2 (N, 3): platform translation, inertial NED. q (N, 4): platform attitude,
    body->inertial, scalar first. omega_radps (N, 3): platform body angular velocity. head_f_mps2,
    head_omega_radps (N, 3): simulator pilot-head specific force and angular velocity, simulator body axes.
    wheel_radps (N, 3): omni-wheel speeds. sp_pos_m (N, 3), sp_q (N, 4): the washout's set points.
    saturated: limit kind -> bool (N,) (kinds in ``SAT_KINDS``); saturation_counts: kind -> steps at it.
    """

    pos_m: np.ndarray
    vel_mps: np.ndarray
    acc_mps2: np.ndarray
    q: np.ndarray
    omega_radps: np.ndarray
    head_f_mps2: np.ndarray
    head_omega_radps: np.ndarray
    wheel_radps: np.ndarray
    sp_pos_m: np.ndarray
    sp_q: np.ndarray
    saturated: dict[str, np.ndarray]
    saturation_counts: dict[str, int]

    @classmethod
    def from_rows(cls, rows: np.ndarray) -> WashoutTrace:
        """Build from output rows (N, N_FIELDS) of :meth:`CueingBank.step` for one washout (columns copied)."""
        rows = np.asarray(rows, dtype=np.float64)
        if rows.ndim != 2 or rows.shape[1] != NFIELDS:
            raise ValueError(f"rows must have shape (N, {NFIELDS}), got {rows.shape}")

        def cols(start: int, n: int) -> np.ndarray:
            return np.ascontiguousarray(rows[:, start : start + n])

        saturated = {k: rows[:, O_SAT + j] != 0.0 for j, k in enumerate(SAT_KINDS)}
        return cls(
            pos_m=cols(O_POS, 3),
            vel_mps=cols(O_VEL, 3),
            acc_mps2=cols(O_ACC, 3),
            q=cols(O_Q, 4),
            omega_radps=cols(O_OMEGA, 3),
            head_f_mps2=cols(O_HEAD_F, 3),
            head_omega_radps=cols(O_HEAD_OMEGA, 3),
            wheel_radps=cols(O_WHEEL, 3),
            sp_pos_m=cols(O_SP_POS, 3),
            sp_q=cols(O_SP_Q, 4),
            saturated=saturated,
            saturation_counts={k: int(v.sum()) for k, v in saturated.items()},
        )


def _warm_up() -> None:
    """Compile (or load from the numba cache) the streaming step once, then forbid other signatures.

    With compilation disabled, a call with an unexpected argument type raises TypeError at once instead
    of compiling a new specialisation; :meth:`CueingBank.step` then converts the inputs and retries.
    """
    if bank_step.signatures:
        return
    cfg = np.zeros((0, NCFG))
    bank_step(
        np.zeros(3),
        np.zeros(3),
        cfg,
        np.zeros((0, NFILT, filters.NCOEF)),
        np.zeros((0, NSTATE)),
        np.zeros((0, len(SAT_KINDS)), dtype=np.int64),
        np.zeros((0, NFIELDS)),
    )
    bank_step.disable_compile()


class CueingBank:
    """Washouts + Atlas platform + head motion, one sample in, one row per washout out (streaming).

    ``step`` returns a (n_washouts, N_FIELDS) float64 array that is REUSED: the next call overwrites it,
    so copy it (e.g. into a preallocated buffer) if you keep it. The first call initialises every filter
    to the steady state of that sample. ``f_mps2`` and ``omega_radps`` are best given as float64 arrays
    of shape (3,) (anything else is converted, more slowly). Non-finite input raises ValueError.
    """

    FIELDS: tuple[str, ...] = FIELDS
    SAT_KINDS: tuple[str, ...] = SAT_KINDS

    def __init__(self, washouts: Sequence[str], params: WashoutParams, limits: PlatformLimits, dt_s: float) -> None:
        self.washouts = check_washouts(washouts)
        self.dt_s = _check_dt(dt_s)
        self._cfg, self._coef = _build_arrays(self.washouts, params, limits, self.dt_s)
        n = len(self.washouts)
        self._state = np.zeros((n, NSTATE))
        self._counts = np.zeros((n, len(SAT_KINDS)), dtype=np.int64)
        self._out = np.zeros((n, NFIELDS))
        _warm_up()

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> np.ndarray:
        """Advance all washouts by one sample; return the reused (n_washouts, N_FIELDS) output array."""
        try:
            bank_step(f_mps2, omega_radps, self._cfg, self._coef, self._state, self._counts, self._out)
        except TypeError:
            f = np.ascontiguousarray(f_mps2, dtype=np.float64).reshape(-1)
            w = np.ascontiguousarray(omega_radps, dtype=np.float64).reshape(-1)
            bank_step(f, w, self._cfg, self._coef, self._state, self._counts, self._out)
        return self._out

    def saturation_counts(self) -> dict[str, dict[str, int]]:
        """washout -> limit kind -> number of steps at that limit so far."""
        return {
            name: {k: int(self._counts[i, j]) for j, k in enumerate(SAT_KINDS)} for i, name in enumerate(self.washouts)
        }


def cue_trace(
    f_mps2: np.ndarray,
    omega_radps: np.ndarray,
    dt_s: float,
    washouts: Sequence[str],
    params: WashoutParams,
    limits: PlatformLimits,
) -> dict[str, WashoutTrace]:
    """Whole-trace form: run the washouts over arrays f (N, 3) m/s^2 and omega (N, 3) rad/s sampled every dt_s.

    Uses the same compiled step as :class:`CueingBank` and gives identical results. Raises WashbenchError
    for wrong shapes or non-finite samples (naming the first bad sample) and for a step outside
    ``washbench.io.results.DT_RANGE_S``. Magnitudes are not limited here (the platform stays within its
    limits whatever the input); ``read_motion`` refuses physically absurd recordings at the file edge.
    """
    names = check_washouts(washouts)
    dt = _check_dt(dt_s)
    f = np.ascontiguousarray(f_mps2, dtype=np.float64)
    w = np.ascontiguousarray(omega_radps, dtype=np.float64)
    if f.ndim != 2 or f.shape[1] != 3 or w.shape != f.shape:
        raise WashbenchError(f"specific force and angular velocity must both be (N, 3), got {f.shape} and {w.shape}")
    bad = ~(np.isfinite(f).all(axis=1) & np.isfinite(w).all(axis=1))
    if bad.any():
        raise WashbenchError(f"non-finite specific force or angular velocity at sample {int(np.argmax(bad))}")
    cfg, coef = _build_arrays(names, params, limits, dt)
    state = np.zeros((len(names), NSTATE))
    counts = np.zeros((len(names), len(SAT_KINDS)), dtype=np.int64)
    out = np.zeros((len(names), f.shape[0], NFIELDS))
    bank_trace(f, w, cfg, coef, state, counts, out)
    return {name: WashoutTrace.from_rows(out[i]) for i, name in enumerate(names)}
