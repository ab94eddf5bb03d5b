"""The compiled cueing step: one washout + Atlas platform + simulator head motion, per sample.

Everything here is numba-compiled and allocation-free per step. One call of :func:`bank_step` advances
every washout of a bank by one sample; :func:`bank_trace` loops the SAME per-washout step
(:func:`step_one`) over a whole recording, so streaming and whole-trace results are identical bit for bit.

Inputs per sample: ``f`` specific force at the aircraft pilot's head, aircraft body axes, m/s^2 (at rest
[0, 0, -g]); ``om`` aircraft body angular velocity, rad/s. Outputs: one row of ``FIELDS`` per washout.

Arrays (built by :mod:`washbench.cueing.bank`):

- ``cfg`` (n_washouts, NCFG) float64: kind, dt, g, gains and platform limits in SI (``C_*`` offsets);
- ``coef`` (n_washouts, NFILT, 9): packed discrete filters (``F_*`` indices, see :mod:`.filters`);
- ``state`` (n_washouts, NSTATE): integrators, platform and filter states (``S_*`` offsets);
- ``counts`` (n_washouts, 7) int64: saturation step counts in ``SAT_KINDS`` order;
- ``out`` (n_washouts, NFIELDS): the latest output row of each washout.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit, prange

from washbench.cueing.filters import filt_init, filt_step
from washbench.numerics.jitcache import drop_stale_cache
from washbench.numerics.rotations import (
    body_rates,
    cross,
    euler_from_quat,
    euler_rates,
    limit_norm,
    norm3,
    qintegrate,
    qrate_body,
    qrot,
    qrot_inv,
    quat_from_euler,
    rot_euler,
    rot_euler_inv,
    wrap_near,
)
from washbench.platform.kinematics import track_axis, track_rotation, wheel_speeds

KIND_SMALL, KIND_LARGE, KIND_UNRESTRICTED = 0, 1, 2

SAT_KINDS: tuple[str, ...] = ("pos", "vel", "acc", "rate", "angacc", "tilt_rate", "rot_rate")

FIELDS: tuple[str, ...] = (
    "pos_x_m", "pos_y_m", "pos_z_m",
    "vel_x_mps", "vel_y_mps", "vel_z_mps",
    "acc_x_mps2", "acc_y_mps2", "acc_z_mps2",
    "q_w", "q_x", "q_y", "q_z",
    "omega_x_radps", "omega_y_radps", "omega_z_radps",
    "head_f_x_mps2", "head_f_y_mps2", "head_f_z_mps2",
    "head_omega_x_radps", "head_omega_y_radps", "head_omega_z_radps",
    "wheel_1_radps", "wheel_2_radps", "wheel_3_radps",
    "sp_pos_x_m", "sp_pos_y_m", "sp_pos_z_m",
    "sp_q_w", "sp_q_x", "sp_q_y", "sp_q_z",
    *(f"sat_{k}" for k in SAT_KINDS),
)  # fmt: skip
NFIELDS = len(FIELDS)
O_POS, O_VEL, O_ACC, O_Q, O_OMEGA = 0, 3, 6, 9, 13
O_HEAD_F, O_HEAD_OMEGA, O_WHEEL, O_SP_POS, O_SP_Q, O_SAT = 16, 19, 22, 25, 28, 32

# cfg offsets
C_KIND, C_DT, C_G, C_SF, C_SW, C_TILT_K, C_TILT_RATE, C_ROT_SAT, C_COSMIN, C_FREEFALL = range(10)
C_R = 10  # head offset R_SS (3)
C_PMAX, C_VMAX, C_AMAX = 13, 16, 19  # per axis (3 each)
C_WMAX, C_ALPHA, C_CATCH = 22, 23, 24
C_JAC = 25  # wheel Jacobian, row-major (9)
C_TILT_AXIS = 34  # 1: the tilt-rate limit clips each axis; 0: it limits the norm (direction kept)
C_LP_BEFORE = 35  # 1: tilt low-pass on f before the cross product; 0: on the tilt rate after it
C_HEAD_EULER = 36  # 1: head rate by the Eq. 8 estimator on Euler angles; 0: quaternion difference (Eqs. 18-19)
C_REST = 37  # 1: start from rest (level, f = [0, 0, -g], no rotation) instead of the first sample's steady state
NCFG = 38

# filter indices (each 3 consecutive axes)
F_TRANS_HP, F_TILT_LP, F_ROT_HP, F_EULER_D, F_OMEGA_D = 0, 3, 6, 9, 12
NFILT = 15

# state offsets
S_INIT = 0
S_VSP, S_PSP = 1, 4  # translational set point velocity / position (inertial)
S_BT, S_BR = 7, 10  # small-angle: tilt and rotational Euler angles
S_QSP = 13  # attitude set point (4)
S_P, S_V, S_Q, S_W = 17, 20, 23, 27  # platform position, velocity, quaternion, body rate
S_EUL = 30  # small-angle head: previous (unwrapped) platform Euler angles
S_FX = 33  # filter states, 2 per filter
NSTATE = S_FX + 2 * NFILT


@njit(cache=True)
def _tilt_rate(g_s, f, gain, eps):
    """Tilt-coordination angular velocity gain * (g_S/|g_S| x f/|f|), rad/s; zero in free fall."""
    nf = norm3(f)
    ng = norm3(g_s)
    if nf < eps or ng == 0.0:
        return (0.0, 0.0, 0.0)
    c = cross(g_s, f)
    k = gain / (nf * ng)
    return (c[0] * k, c[1] * k, c[2] * k)


@njit(cache=True, inline="always")
def _limit_tilt(v, vmax, per_axis):
    """The tilt-rate limit: on the norm (direction kept) or on each axis; returns (v, 1 if it limited)."""
    if per_axis == 0.0:
        return limit_norm(v, vmax)
    out0 = min(vmax, max(-vmax, v[0]))
    out1 = min(vmax, max(-vmax, v[1]))
    out2 = min(vmax, max(-vmax, v[2]))
    hit = 1 if (out0 != v[0] or out1 != v[1] or out2 != v[2]) else 0
    return (out0, out1, out2), hit


@njit(cache=True)
def _fx(state, i):
    """View of filter i's two states."""
    return state[S_FX + 2 * i : S_FX + 2 * i + 2]


@njit(cache=True, inline="always")
def _filt3(coef, state, i, u):
    """Step filters i, i + 1, i + 2 (one per axis) with the components of ``u``; return their outputs.

    Inlined into the step (``inline="always"``): as a call it made the streaming step about 7% slower.
    """
    return (
        filt_step(coef[i], _fx(state, i), u[0]),
        filt_step(coef[i + 1], _fx(state, i + 1), u[1]),
        filt_step(coef[i + 2], _fx(state, i + 2), u[2]),
    )


@njit(cache=True)
def _init3(coef, state, i, u):
    """Start filters i, i + 1, i + 2 in the steady state of the components of ``u``."""
    for j in range(3):
        filt_init(coef[i + j], _fx(state, i + j), u[j])


@njit(cache=True)
def _init_washout(kind, c, coef, state, fs, ws):
    """Start every washout filter and integrator in the steady state of the first sample.

    The simulator starts centred with the tilt that aligns -g_S with the first specific force (level for a
    level start, none in free fall), yaw 0, translational set point at rest at the centre.
    """
    g = c[C_G]
    nf = norm3(fs)
    phi0 = 0.0
    theta0 = 0.0
    if nf >= c[C_FREEFALL]:
        phi0 = math.atan2(-fs[1] / nf, -fs[2] / nf)
        theta0 = math.asin(min(1.0, max(-1.0, fs[0] / nf)))
    q0 = quat_from_euler(phi0, theta0, 0.0)
    for j in range(3):
        state[S_VSP + j] = 0.0
        state[S_PSP + j] = 0.0
        state[S_BT + j] = 0.0
        state[S_BR + j] = 0.0
    state[S_BT] = phi0
    state[S_BT + 1] = theta0
    for j in range(4):
        state[S_QSP + j] = q0[j]
    g_i = (0.0, 0.0, g)
    if kind == KIND_SMALL:
        a_i = rot_euler(phi0, theta0, 0.0, fs)
        g_s = rot_euler_inv(phi0, theta0, 0.0, g_i)
        rot_in = euler_rates(phi0, theta0, ws, c[C_COSMIN])
    else:
        a_i = qrot(q0, fs)
        g_s = qrot_inv(q0, g_i)
        rot_in = ws
    tilt_in = fs if c[C_LP_BEFORE] != 0.0 else _tilt_rate(g_s, fs, c[C_TILT_K], c[C_FREEFALL])
    _init3(coef, state, F_TRANS_HP, (a_i[0], a_i[1], a_i[2] + g))
    _init3(coef, state, F_TILT_LP, tilt_in)
    _init3(coef, state, F_ROT_HP, rot_in)


@njit(cache=True)
def step_one(f, om, c, coef, state, counts, row):
    """Advance one washout (+ platform + head motion) by one sample and write its output ``row``."""
    kind = int(c[C_KIND])
    dt = c[C_DT]
    g = c[C_G]
    fs = (c[C_SF] * f[0], c[C_SF] * f[1], c[C_SF] * f[2])
    ws, sat_rot = limit_norm((c[C_SW] * om[0], c[C_SW] * om[1], c[C_SW] * om[2]), c[C_ROT_SAT])
    first = state[S_INIT] == 0.0
    rest = c[C_REST] != 0.0
    if first:
        if rest:  # the simulator was at rest before the recording began: the first sample is a change
            _init_washout(kind, c, coef, state, (0.0, 0.0, -c[C_SF] * g), (0.0, 0.0, 0.0))
        else:
            _init_washout(kind, c, coef, state, fs, ws)
    g_i = (0.0, 0.0, g)
    q_sp_prev = (state[S_QSP], state[S_QSP + 1], state[S_QSP + 2], state[S_QSP + 3])
    p_sp_prev = (state[S_PSP], state[S_PSP + 1], state[S_PSP + 2])

    # ---- washout: attitude set point and inertial acceleration of the translational channel
    if kind == KIND_SMALL:
        phi = state[S_BT] + state[S_BR]
        theta = state[S_BT + 1] + state[S_BR + 1]
        psi = state[S_BT + 2] + state[S_BR + 2]
        a_i = rot_euler(phi, theta, psi, fs)
        g_s = rot_euler_inv(phi, theta, psi, g_i)
        if c[C_LP_BEFORE] != 0.0:
            wt = _tilt_rate(g_s, _filt3(coef, state, F_TILT_LP, fs), c[C_TILT_K], c[C_FREEFALL])
        else:
            wt = _filt3(coef, state, F_TILT_LP, _tilt_rate(g_s, fs, c[C_TILT_K], c[C_FREEFALL]))
        bdot_t, sat_tilt = _limit_tilt(euler_rates(phi, theta, wt, c[C_COSMIN]), c[C_TILT_RATE], c[C_TILT_AXIS])
        bdot_r = _filt3(coef, state, F_ROT_HP, euler_rates(phi, theta, ws, c[C_COSMIN]))
        for j in range(3):
            state[S_BT + j] += bdot_t[j] * dt
            state[S_BR + j] += bdot_r[j] * dt
        q_sp = quat_from_euler(
            state[S_BT] + state[S_BR], state[S_BT + 1] + state[S_BR + 1], state[S_BT + 2] + state[S_BR + 2]
        )
    else:
        a_i = qrot(q_sp_prev, fs)
        g_s = qrot_inv(q_sp_prev, g_i)
        if c[C_LP_BEFORE] != 0.0:
            wt = _tilt_rate(g_s, _filt3(coef, state, F_TILT_LP, fs), c[C_TILT_K], c[C_FREEFALL])
        else:
            wt = _filt3(coef, state, F_TILT_LP, _tilt_rate(g_s, fs, c[C_TILT_K], c[C_FREEFALL]))
        wt, sat_tilt = _limit_tilt(wt, c[C_TILT_RATE], c[C_TILT_AXIS])
        wr = _filt3(coef, state, F_ROT_HP, ws)
        q_sp = qintegrate(q_sp_prev, (wt[0] + wr[0], wt[1] + wr[1], wt[2] + wr[2]), dt)
    for j in range(4):
        state[S_QSP + j] = q_sp[j]
    # translational channel: + g_I, high-pass, double integration (semi-implicit Euler)
    a_hp = _filt3(coef, state, F_TRANS_HP, (a_i[0], a_i[1], a_i[2] + g))
    for j in range(3):
        state[S_VSP + j] += a_hp[j] * dt
        state[S_PSP + j] += state[S_VSP + j] * dt

    # ---- platform
    if first:
        for j in range(3):
            state[S_P + j] = 0.0
            state[S_V + j] = 0.0
        for j in range(4):
            state[S_Q + j] = q_sp_prev[j]
        w0 = qrate_body(q_sp, q_sp_prev, dt)  # already moving at the set point's rate: no start jolt
        for j in range(3):
            state[S_W + j] = 0.0 if rest else w0[j]
    sat_pos = 0
    sat_vel = 0
    sat_acc = 0
    for j in range(3):
        v_prev = state[S_V + j]
        p, v, s_p, s_v, s_a = track_axis(
            state[S_P + j],
            v_prev,
            p_sp_prev[j],
            state[S_PSP + j],
            c[C_PMAX + j],
            c[C_VMAX + j],
            c[C_AMAX + j],
            c[C_CATCH],
            dt,
        )
        state[S_P + j] = p
        state[S_V + j] = v
        # the acceleration the stage made, within its limit exactly (the difference quotient rounds)
        row[O_ACC + j] = min(max((v - v_prev) / dt, -c[C_AMAX + j]), c[C_AMAX + j])
        sat_pos |= s_p
        sat_vel |= s_v
        sat_acc |= s_a
    acc = (row[O_ACC], row[O_ACC + 1], row[O_ACC + 2])
    q_prev = (state[S_Q], state[S_Q + 1], state[S_Q + 2], state[S_Q + 3])
    w_prev = (state[S_W], state[S_W + 1], state[S_W + 2])
    q, w, sat_rate, sat_angacc = track_rotation(q_prev, w_prev, q_sp_prev, q_sp, c[C_WMAX], c[C_ALPHA], c[C_CATCH], dt)
    for j in range(4):
        state[S_Q + j] = q[j]
    for j in range(3):
        state[S_W + j] = w[j]

    # ---- simulator pilot-head motion from what the platform actually does
    if c[C_HEAD_EULER] != 0.0:
        e = euler_from_quat(q)
        if first:
            ephi, etheta, epsi = e
        else:
            ephi = wrap_near(e[0], state[S_EUL])
            etheta = e[1]
            epsi = wrap_near(e[2], state[S_EUL + 2])
        state[S_EUL] = ephi
        state[S_EUL + 1] = etheta
        state[S_EUL + 2] = epsi
        beta = (ephi, etheta, epsi)
        if first:
            _init3(coef, state, F_EULER_D, euler_from_quat(q_prev) if rest else beta)
        bdot = _filt3(coef, state, F_EULER_D, beta)
        wh = body_rates(ephi, etheta, bdot)
        a_s = rot_euler_inv(ephi, etheta, epsi, acc)
        g_sh = rot_euler_inv(ephi, etheta, epsi, g_i)
    else:
        wh = qrate_body(q, q_prev, dt)
        a_s = qrot_inv(q, acc)
        g_sh = qrot_inv(q, g_i)
    if first:
        _init3(coef, state, F_OMEGA_D, (0.0, 0.0, 0.0) if rest else wh)
    wdot = _filt3(coef, state, F_OMEGA_D, wh)
    r = (c[C_R], c[C_R + 1], c[C_R + 2])
    t1 = cross(wdot, r)
    t2 = cross(wh, cross(wh, r))
    w_i = qrot(q, w)
    wheels = wheel_speeds(c[C_JAC : C_JAC + 9], w_i)

    # ---- output row
    for j in range(3):
        row[O_POS + j] = state[S_P + j]
        row[O_VEL + j] = state[S_V + j]
        row[O_OMEGA + j] = w[j]
        row[O_HEAD_F + j] = a_s[j] - g_sh[j] + t1[j] + t2[j]
        row[O_HEAD_OMEGA + j] = wh[j]
        row[O_WHEEL + j] = wheels[j]
        row[O_SP_POS + j] = state[S_PSP + j]
    for j in range(4):
        row[O_Q + j] = q[j]
        row[O_SP_Q + j] = q_sp[j]
    flags = (sat_pos, sat_vel, sat_acc, sat_rate, sat_angacc, sat_tilt, sat_rot)
    for j in range(7):
        row[O_SAT + j] = float(flags[j])
        counts[j] += flags[j]
    state[S_INIT] = 1.0


@njit(cache=True)
def _check_input(f, om):
    if f.shape[0] != 3 or om.shape[0] != 3:
        raise ValueError("cueing input: f and omega must have shape (3,)")
    for j in range(3):
        if not (math.isfinite(f[j]) and math.isfinite(om[j])):
            raise ValueError("cueing input: non-finite specific force or angular velocity")


@njit(cache=True)
def bank_step(f, om, cfg, coef, state, counts, out):
    """Streaming form: advance every washout of the bank by one sample (f, om: (3,) float64)."""
    _check_input(f, om)
    for i in range(cfg.shape[0]):
        step_one(f, om, cfg[i], coef[i], state[i], counts[i], out[i])


@njit(cache=True, parallel=True)
def bank_trace(f, om, cfg, coef, state, counts, out):
    """Whole-trace form: f, om (N, 3), already checked finite; out (n_washouts, NFIELDS, N), field-major so that
    every output column is contiguous (no copy to split it into traces).

    Same per-washout step as bank_step; the washouts are independent, so they run in parallel threads (one
    washout's samples in order on one thread: the same operations in the same order as streaming).
    """
    for i in prange(cfg.shape[0]):
        row = np.zeros(NFIELDS)
        for k in range(f.shape[0]):
            step_one(f[k], om[k], cfg[i], coef[i], state[i], counts[i], row)
            for j in range(NFIELDS):
                out[i, j, k] = row[j]


@njit(cache=True)
def bank_block(f, om, cfg, coef, state, counts, out):
    """Block form for a flight in progress (:meth:`CueingBank.steps`): f, om (M, 3) checked finite; out
    (n_washouts, M, NFIELDS). Serial: a short block does not pay for threads (nor starts OpenMP in a process
    that may fork); the same per-washout step as bank_step, sample by sample.
    """
    for k in range(f.shape[0]):
        for i in range(cfg.shape[0]):
            step_one(f[k], om[k], cfg[i], coef[i], state[i], counts[i], out[i, k])


_HERE = Path(__file__).resolve().parent
drop_stale_cache(
    __file__,
    [
        _HERE.parent / "numerics" / "rotations.py",
        _HERE / "filters.py",
        _HERE.parent / "numerics" / "jitcache.py",
        _HERE.parent / "platform" / "kinematics.py",
    ],
)

__all__ = [
    "C_HEAD_EULER",
    "C_LP_BEFORE",
    "C_TILT_AXIS",
    "FIELDS",
    "NCFG",
    "NFIELDS",
    "NFILT",
    "NSTATE",
    "SAT_KINDS",
    "bank_block",
    "bank_step",
    "bank_trace",
    "step_one",
]
