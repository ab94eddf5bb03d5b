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

``tilt_rate_radps`` (one field of a row): the tilt-coordination rate the washout commanded on the step, after its
tilt-rate limit, measured as that limit measures it (:func:`_tilt_measure`: the norm, or with
``rate_limit_mode: axis`` the largest axis), rad/s; so it is at most the limit, and equal to it on a step flagged
``sat_tilt_rate``. The small-angle washouts limit (and so measure) the Euler-angle rates, the quaternion washouts
the body rate. NaN for a washout computed outside the kernel (:func:`setpoint_step`): the bench knows no tilt rate
of it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from washbench.cueing.filters import filt_init, filt_step
from washbench.numerics.jit import njit, prange
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
from washbench.platform.hexapod_kinematics import NGEO, NWORK, hexapod_track
from washbench.platform.kinematics import track_axis, track_rotation, wheel_speeds
from washbench.platform.rig_kinematics import NRIG_STATE, rig_track

KIND_SMALL, KIND_LARGE, KIND_UNRESTRICTED = 0, 1, 2
KIND_SETPOINT = -1  # an algorithm outside the kernel gives the set points (:func:`setpoint_step`)

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
    "tilt_rate_radps",
    *(f"leg_{i}_m" for i in range(1, 7)),
)  # fmt: skip
NFIELDS = len(FIELDS)
O_POS, O_VEL, O_ACC, O_Q, O_OMEGA = 0, 3, 6, 9, 13
O_HEAD_F, O_HEAD_OMEGA, O_WHEEL, O_SP_POS, O_SP_Q, O_SAT = 16, 19, 22, 25, 28, 32
O_TILT = 39  # the tilt-coordination rate commanded (after its limit), rad/s; NaN outside the kernel
O_LEG = 40  # hexapod leg lengths (6), m; zero for other platforms

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
# the coordinated adaptive washout (:func:`_adapt`, docs/washouts.md): 1 to adapt, adaptation rates, cost weights,
# the translational gain's start and bounds, the tilt gain's bounds (its start is C_TILT_K)
C_ADAPT, C_GP, C_GK, C_WF, C_WW, C_WX, C_WV, C_WPG, C_WKG, C_P0, C_PLO, C_PHI, C_KLO, C_KHI = range(38, 52)
# the platform (docs/platforms.md): its kind, a hexapod's geometry (:mod:`washbench.platform.hexapod_kinematics`)
# and leg velocity and acceleration limits, a rig's limits (:meth:`washbench.platform.rig.RigModel.limits_array`)
C_PLAT = 52
PLAT_ATLAS, PLAT_HEXAPOD, PLAT_RIG, PLAT_IDEAL = 0, 1, 2, 3  # IDEAL: the pose is the set point (a plugin's pass)
C_GEO = 53
C_LV, C_LA = C_GEO + NGEO, C_GEO + NGEO + 1
C_RIG = C_LA + 1
NCFG = C_RIG + 12

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
S_AD = S_FX + 2 * NFILT  # adaptive washout: gains and sensitivities
S_GP = S_AD  # translational gains p (3), per inertial axis
S_GK = S_AD + 3  # tilt gains k (3), 1/s, per simulator body axis
S_SA = S_AD + 6  # d(a_sp)/dp per axis: the translational high-pass of the unscaled input (3 filters' outputs)
S_SV, S_SX = S_AD + 9, S_AD + 12  # d(v_sp)/dp, d(x_sp)/dp (3 each)
S_TH = S_AD + 15  # d(theta_sp)/dk: attitude sensitivity, body axes, 3x3 row-major [i, j] = component i of column j
S_SFX = S_AD + 24  # the sensitivity high-pass filters' states (3 filters x 2)
S_GRAD = S_AD + 30  # the last step's gradient dJ/dp (3), dJ/dk (3)
S_COST = S_AD + 36  # the last step's cost J
S_DW = S_AD + 37  # the last step's tilt-rate sensitivities d(w_t)/dk, 3x3 row-major [i, j] = component i of column j
# another platform than the Atlas: a hexapod's legs (6), leg velocities (6), leg set points (6), Newton scratch
# (NWORK); a rig's axes (NRIG_STATE, from S_LEG)
S_LEG = S_AD + 46
S_LEGV, S_LEGSP, S_WORK = S_LEG + 6, S_LEG + 12, S_LEG + 18
NSTATE = S_WORK + max(NWORK, NRIG_STATE)


_INLINE_INTO = ("bank_block",)


def _inline_per_sample(expr: object, caller: Any, callee: Any) -> bool:
    """numba's inlining decision for the per-sample step (:func:`step_one`, :func:`washout_classical`,
    :func:`platform_head`): inlined into :func:`bank_block` (which the streaming and whole-trace steps call),
    called elsewhere (set-point washouts; the study's :func:`washbench.analysis.evaluate.evaluate_batch` calls
    :func:`bank_block`).

    As calls, each passes its arrays by reference count: numba increments every array argument's count on entry
    and decrements it on exit, an atomic operation each, about 40 per washout and sample, which took half the
    kernel's time (perf: two instructions after the atomic adds held 54 % of the kernel's samples). Inlined, the
    counts are pruned: 2.1 -> 1.4 us a sample for the three washouts. The operations and their order are unchanged
    (no fast-math: same bits). Inlined into one function only, so it is compiled once (a parallel loop, as in
    :func:`bank_trace`, also fails to compile with it inlined).
    """
    return getattr(caller, "func_ir", caller).func_id.func_name in _INLINE_INTO


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


@njit(cache=True)
def _tilt_rate3(g_s, f, k, eps):
    """Tilt-coordination angular velocity with one gain per body axis: k_j (g_S/|g_S| x f/|f|)_j, rad/s; zero in free
    fall. With k_x = k_y = k_z = gain it is :func:`_tilt_rate` to the bit."""
    nf = norm3(f)
    ng = norm3(g_s)
    if nf < eps or ng == 0.0:
        return (0.0, 0.0, 0.0)
    c = cross(g_s, f)
    d = nf * ng
    return (c[0] * (k[0] / d), c[1] * (k[1] / d), c[2] * (k[2] / d))


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


@njit(cache=True, inline="always")
def _tilt_measure(v, per_axis):
    """The size of a tilt rate as its limit (:func:`_limit_tilt`) measures it: the norm, or the largest |axis|."""
    if per_axis == 0.0:
        return norm3(v)
    return max(abs(v[0]), max(abs(v[1]), abs(v[2])))


@njit(cache=True, inline="always")
def _fx(state, i):
    """View of filter i's two states."""
    return state[S_FX + 2 * i : S_FX + 2 * i + 2]


@njit(cache=True, inline="always")
def _sfx(state, j):
    """View of the translational sensitivity filter j's two states."""
    return state[S_SFX + 2 * j : S_SFX + 2 * j + 2]


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
    if c[C_ADAPT] != 0.0:
        for j in range(3):
            state[S_GP + j] = c[C_P0]
            state[S_GK + j] = c[C_TILT_K]
            state[S_SA + j] = 0.0
            state[S_SV + j] = 0.0
            state[S_SX + j] = 0.0
            filt_init(coef[F_TRANS_HP + j], _sfx(state, j), (a_i[0], a_i[1], a_i[2] + g)[j])
        for j in range(9):
            state[S_TH + j] = 0.0


@njit(cache=True)
def _adapt(c, coef, state, fs, ws, u, g_s, f_lp, wt_raw, wt, sat_tilt, a_hp, q_sp_prev, q_sp):
    """One step of the coordinated adaptive washout's steepest descent (docs/washouts.md, Eqs. A1-A9).

    Cost J = 1/2 [W_f |f_A - f_S|^2 + W_w |w_A - w_S|^2 + W_x |x|^2 + W_v |v|^2 + W_p |p - p0|^2 + W_k |k - k0|^2]
    with f_A, w_A the scaled aircraft motion (``fs``, ``ws``), f_S = R(q_sp)^T (a_sp - g_I) and w_S the set point's
    specific force and body rate, x, v the translational set point. The gains move by p -= G_p dJ/dp dt,
    k -= G_k dJ/dk dt, then are clipped to their bounds. Sensitivities (the past held at the current gains):
    d(a_sp)/dp_j = HP_j(u_j) exactly; d(theta)/dk_j integrates d(w_t)/dk_j = w_t,j / k_j e_j (plus, with the low-pass
    before the cross product, the attitude's effect through g_S) through the tilt-rate limit's Jacobian, with the
    rotation of the body frame (-w_S x theta dt).
    """
    dt = c[C_DT]
    g = c[C_G]
    # translational sensitivities: exact for the discrete channel
    for j in range(3):
        sa = filt_step(coef[F_TRANS_HP + j], _sfx(state, j), u[j])
        state[S_SA + j] = sa
        state[S_SV + j] += sa * dt
        state[S_SX + j] += state[S_SV + j] * dt
    # the set point's specific force (body) and body rate
    f_i = (a_hp[0], a_hp[1], a_hp[2] - g)
    f_s = qrot_inv(q_sp, f_i)
    w_s = qrate_body(q_sp, q_sp_prev, dt)
    e_f = (fs[0] - f_s[0], fs[1] - f_s[1], fs[2] - f_s[2])
    e_w = (ws[0] - w_s[0], ws[1] - w_s[1], ws[2] - w_s[2])
    e_fi = qrot(q_sp, e_f)  # the specific-force error in inertial axes
    # tilt-rate sensitivities dw_t/dk_j (before the limit): direct term, and the attitude's through g_S
    nf = norm3(f_lp)
    ng = norm3(g_s)
    before = c[C_LP_BEFORE] != 0.0 and nf >= c[C_FREEFALL] and ng > 0.0
    for m in range(9):  # [i, j] at S_DW + 3 i + j: component i of dw_t/dk_j (in the state: no allocation per step)
        state[S_DW + m] = 0.0
    for j in range(3):
        kj = state[S_GK + j]
        state[S_DW + 4 * j] = wt_raw[j] / kj if kj > 0.0 else 0.0
        if before:
            th = (state[S_TH + j], state[S_TH + 3 + j], state[S_TH + 6 + j])
            dc = cross(cross(g_s, th), f_lp)
            for i in range(3):
                state[S_DW + 3 * i + j] += state[S_GK + i] * dc[i] / (nf * ng)
    if sat_tilt:  # through the limit: the norm limit's Jacobian (vmax/|v|)(I - v v^T/|v|^2); the axis limit's zeros
        vmax = c[C_TILT_RATE]
        n = norm3(wt_raw)
        for j in range(3):
            col = (state[S_DW + j], state[S_DW + 3 + j], state[S_DW + 6 + j])
            if c[C_TILT_AXIS] != 0.0:
                for i in range(3):
                    if wt[i] != wt_raw[i]:
                        state[S_DW + 3 * i + j] = 0.0
            elif n > 0.0:
                d = (col[0] * wt_raw[0] + col[1] * wt_raw[1] + col[2] * wt_raw[2]) / (n * n)
                for i in range(3):
                    state[S_DW + 3 * i + j] = (vmax / n) * (col[i] - wt_raw[i] * d)
    # gradients
    for j in range(3):
        state[S_GRAD + j] = (
            -c[C_WF] * e_fi[j] * state[S_SA + j]
            + c[C_WX] * state[S_PSP + j] * state[S_SX + j]
            + c[C_WV] * state[S_VSP + j] * state[S_SV + j]
            + c[C_WPG] * (state[S_GP + j] - c[C_P0])
        )
        th = (state[S_TH + j], state[S_TH + 3 + j], state[S_TH + 6 + j])
        df = cross(f_s, th)  # d(f_S)/dk_j: f_S(theta + d) = f_S + f_S x d
        state[S_GRAD + 3 + j] = (
            -c[C_WF] * (e_f[0] * df[0] + e_f[1] * df[1] + e_f[2] * df[2])
            - c[C_WW] * (e_w[0] * state[S_DW + j] + e_w[1] * state[S_DW + 3 + j] + e_w[2] * state[S_DW + 6 + j])
            + c[C_WKG] * (state[S_GK + j] - c[C_TILT_K])
        )
    cost = 0.0
    for j in range(3):
        cost += c[C_WF] * e_f[j] * e_f[j] + c[C_WW] * e_w[j] * e_w[j]
        cost += c[C_WX] * state[S_PSP + j] ** 2 + c[C_WV] * state[S_VSP + j] ** 2
        cost += c[C_WPG] * (state[S_GP + j] - c[C_P0]) ** 2 + c[C_WKG] * (state[S_GK + j] - c[C_TILT_K]) ** 2
    state[S_COST] = 0.5 * cost
    # attitude sensitivity: body-frame perturbation carried by the set point's rotation, plus this step's rate
    for j in range(3):
        th = (state[S_TH + j], state[S_TH + 3 + j], state[S_TH + 6 + j])
        rot = cross(w_s, th)
        for i in range(3):
            state[S_TH + 3 * i + j] = th[i] - rot[i] * dt + state[S_DW + 3 * i + j] * dt
    # steepest descent, clipped to the bounds
    for j in range(3):
        state[S_GP + j] = min(c[C_PHI], max(c[C_PLO], state[S_GP + j] - c[C_GP] * state[S_GRAD + j] * dt))
        state[S_GK + j] = min(c[C_KHI], max(c[C_KLO], state[S_GK + j] - c[C_GK] * state[S_GRAD + 3 + j] * dt))


@njit(cache=True, inline=_inline_per_sample)
def washout_classical(f, om, c, coef, state, first, rest):
    """The classical-family washout (small-angle, large-angle, unrestricted) by one sample: scaling, the rotational
    saturation, tilt coordination, the rotational and translational channels. Updates the set points in
    ``state`` (S_PSP position, S_QSP attitude) and returns (sat_tilt, sat_rot): whether the tilt-rate and
    rotational-rate limits acted; the tilt rate commanded after its limit, as the limit measures it
    (:func:`_tilt_measure`, rad/s); and the set points before this sample (q_sp_prev, p_sp_prev), which on the first
    sample are the washout's start state."""
    kind = int(c[C_KIND])
    adapt = c[C_ADAPT] != 0.0
    dt = c[C_DT]
    g = c[C_G]
    fs = (c[C_SF] * f[0], c[C_SF] * f[1], c[C_SF] * f[2])
    ws, sat_rot = limit_norm((c[C_SW] * om[0], c[C_SW] * om[1], c[C_SW] * om[2]), c[C_ROT_SAT])
    if first:
        if rest:  # the simulator was at rest before the recording began: the first sample is a change
            _init_washout(kind, c, coef, state, (0.0, 0.0, -c[C_SF] * g), (0.0, 0.0, 0.0))
        else:
            _init_washout(kind, c, coef, state, fs, ws)
    g_i = (0.0, 0.0, g)
    q_sp_prev = (state[S_QSP], state[S_QSP + 1], state[S_QSP + 2], state[S_QSP + 3])
    p_sp_prev = (state[S_PSP], state[S_PSP + 1], state[S_PSP + 2])

    # ---- attitude set point and inertial acceleration of the translational channel
    if kind == KIND_SMALL:
        phi = state[S_BT] + state[S_BR]
        theta = state[S_BT + 1] + state[S_BR + 1]
        psi = state[S_BT + 2] + state[S_BR + 2]
        a_i = rot_euler(phi, theta, psi, fs)
        g_s = rot_euler_inv(phi, theta, psi, g_i)
        f_lp = fs
        if adapt:
            k = (state[S_GK], state[S_GK + 1], state[S_GK + 2])
            if c[C_LP_BEFORE] != 0.0:
                f_lp = _filt3(coef, state, F_TILT_LP, fs)
                wt = _tilt_rate3(g_s, f_lp, k, c[C_FREEFALL])
            else:
                wt = _filt3(coef, state, F_TILT_LP, _tilt_rate3(g_s, fs, k, c[C_FREEFALL]))
        elif c[C_LP_BEFORE] != 0.0:
            wt = _tilt_rate(g_s, _filt3(coef, state, F_TILT_LP, fs), c[C_TILT_K], c[C_FREEFALL])
        else:
            wt = _filt3(coef, state, F_TILT_LP, _tilt_rate(g_s, fs, c[C_TILT_K], c[C_FREEFALL]))
        wt_raw = wt
        bdot_t, sat_tilt = _limit_tilt(euler_rates(phi, theta, wt, c[C_COSMIN]), c[C_TILT_RATE], c[C_TILT_AXIS])
        tilt_rate = _tilt_measure(bdot_t, c[C_TILT_AXIS])
        if sat_tilt:  # the limited tilt rate in body axes (for the adaptation's sensitivities)
            wt = body_rates(phi, theta, bdot_t)
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
        f_lp = fs
        if adapt:
            k = (state[S_GK], state[S_GK + 1], state[S_GK + 2])
            if c[C_LP_BEFORE] != 0.0:
                f_lp = _filt3(coef, state, F_TILT_LP, fs)
                wt = _tilt_rate3(g_s, f_lp, k, c[C_FREEFALL])
            else:
                wt = _filt3(coef, state, F_TILT_LP, _tilt_rate3(g_s, fs, k, c[C_FREEFALL]))
        elif c[C_LP_BEFORE] != 0.0:
            wt = _tilt_rate(g_s, _filt3(coef, state, F_TILT_LP, fs), c[C_TILT_K], c[C_FREEFALL])
        else:
            wt = _filt3(coef, state, F_TILT_LP, _tilt_rate(g_s, fs, c[C_TILT_K], c[C_FREEFALL]))
        wt_raw = wt
        wt, sat_tilt = _limit_tilt(wt, c[C_TILT_RATE], c[C_TILT_AXIS])
        tilt_rate = _tilt_measure(wt, c[C_TILT_AXIS])
        wr = _filt3(coef, state, F_ROT_HP, ws)
        q_sp = qintegrate(q_sp_prev, (wt[0] + wr[0], wt[1] + wr[1], wt[2] + wr[2]), dt)
    for j in range(4):
        state[S_QSP + j] = q_sp[j]
    # translational channel: + g_I, high-pass, double integration (semi-implicit Euler)
    u = (a_i[0], a_i[1], a_i[2] + g)
    if adapt:
        a_hp = _filt3(coef, state, F_TRANS_HP, (state[S_GP] * u[0], state[S_GP + 1] * u[1], state[S_GP + 2] * u[2]))
    else:
        a_hp = _filt3(coef, state, F_TRANS_HP, u)
    for j in range(3):
        state[S_VSP + j] += a_hp[j] * dt
        state[S_PSP + j] += state[S_VSP + j] * dt
    if adapt:
        _adapt(c, coef, state, fs, ws, u, g_s, f_lp, wt_raw, wt, sat_tilt, a_hp, q_sp_prev, q_sp)
    return q_sp_prev, p_sp_prev, sat_tilt, sat_rot, tilt_rate


@njit(cache=True)
def _other_platform(p_sp_prev, p_sp, q_sp_prev, q_sp, first, rest, c, state, row):
    """A hexapod, a rig or the ideal follower of a plugin platform's pass (``c[C_PLAT]``) following the set points
    from (``p_sp_prev``, ``q_sp_prev``) to (``p_sp``, ``q_sp``) within its limits
    (:func:`washbench.platform.hexapod_kinematics.hexapod_track`, :func:`washbench.platform.rig_kinematics.rig_track`;
    the ideal follower's pose is the set point). On the ``first`` sample it starts at rest at the start set
    point (as near as it can reach). The MRP's velocity and acceleration are the pose's difference quotients
    (v_k = (p_k - p_{k-1}) / dt, a_k = (v_k - v_{k-1}) / dt) and the body rate the quaternion difference's (Eqs.
    18-19): (q, q_prev, omega, acc, sat_pos, sat_vel, sat_acc, sat_rate, sat_angacc); the leg lengths into ``row``."""
    dt = c[C_DT]
    catch = c[C_CATCH]
    hexapod = c[C_PLAT] == PLAT_HEXAPOD
    geo = c[C_GEO : C_GEO + NGEO]
    rig = c[C_RIG : C_RIG + 12]
    legs = state[S_LEG : S_LEG + 6]
    vels = state[S_LEGV : S_LEGV + 6]
    lsp = state[S_LEGSP : S_LEGSP + 6]
    work = state[S_WORK : S_WORK + NWORK]
    st = state[S_LEG : S_LEG + NRIG_STATE]
    ideal = c[C_PLAT] == PLAT_IDEAL
    if first:
        if ideal:
            p0 = p_sp_prev
            q0 = q_sp_prev
        elif hexapod:
            p0, q0, _, _, _ = hexapod_track(geo, c[C_LV], c[C_LA], catch, dt, p_sp_prev, q_sp_prev, p_sp_prev,
                                            q_sp_prev, legs, vels, lsp, work, True)  # fmt: skip
        else:
            p0, q0, _, _, _, _, _ = rig_track(rig, catch, dt, p_sp_prev, q_sp_prev, st, True)
        for j in range(3):
            state[S_P + j] = p0[j]
            state[S_V + j] = 0.0
            state[S_W + j] = 0.0
        for j in range(4):
            state[S_Q + j] = q0[j]
    p_prev = (state[S_P], state[S_P + 1], state[S_P + 2])
    v_prev = (state[S_V], state[S_V + 1], state[S_V + 2])
    q_prev = (state[S_Q], state[S_Q + 1], state[S_Q + 2], state[S_Q + 3])
    if ideal:
        p = p_sp
        q = q_sp
        sat_pos = 0
        sat_vel = 0
        sat_acc = 0
        sat_rate = 0
        sat_angacc = 0
        for i in range(6):
            row[O_LEG + i] = 0.0
    elif hexapod:
        p, q, sat_pos, sat_vel, sat_acc = hexapod_track(geo, c[C_LV], c[C_LA], catch, dt, p_prev, q_prev, p_sp, q_sp,
                                                        legs, vels, lsp, work, False)  # fmt: skip
        sat_rate = 0
        sat_angacc = 0
        for i in range(6):
            row[O_LEG + i] = legs[i]
    else:
        p, q, sat_pos, sat_vel, sat_acc, sat_rate, sat_angacc = rig_track(rig, catch, dt, p_sp, q_sp, st, False)
        for i in range(6):
            row[O_LEG + i] = 0.0
    v = ((p[0] - p_prev[0]) / dt, (p[1] - p_prev[1]) / dt, (p[2] - p_prev[2]) / dt)
    acc = ((v[0] - v_prev[0]) / dt, (v[1] - v_prev[1]) / dt, (v[2] - v_prev[2]) / dt)
    w = qrate_body(q, q_prev, dt)
    for j in range(3):
        state[S_P + j] = p[j]
        state[S_V + j] = v[j]
        state[S_W + j] = w[j]
        row[O_ACC + j] = acc[j]
    for j in range(4):
        state[S_Q + j] = q[j]
    return q, q_prev, w, acc, sat_pos, sat_vel, sat_acc, sat_rate, sat_angacc


@njit(cache=True, inline=_inline_per_sample)
def platform_head(p_sp_prev, p_sp, q_sp_prev, q_sp, first, rest, c, coef, state, counts, row, sat_tilt, sat_rot):
    """The Atlas platform tracking the set points (from ``p_sp_prev``, ``q_sp_prev`` to ``p_sp``, ``q_sp``) within
    its limits, and the simulator pilot-head motion from what the platform actually does; writes the output
    ``row`` (every field, the set points and the saturation flags, the washout's two given) and counts the flags.

    On the ``first`` sample the platform starts centred at attitude ``q_sp_prev``, at rest (``rest``) or turning
    at the set point's rate."""
    dt = c[C_DT]
    g_i = (0.0, 0.0, c[C_G])
    if c[C_PLAT] != PLAT_ATLAS:
        q, q_prev, w, acc, sat_pos, sat_vel, sat_acc, sat_rate, sat_angacc = _other_platform(
            p_sp_prev, p_sp, q_sp_prev, q_sp, first, rest, c, state, row
        )
    else:
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
                p_sp[j],
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
        q, w, sat_rate, sat_angacc = track_rotation(
            q_prev, w_prev, q_sp_prev, q_sp, c[C_WMAX], c[C_ALPHA], c[C_CATCH], dt
        )
        for j in range(4):
            state[S_Q + j] = q[j]
        for j in range(3):
            state[S_W + j] = w[j]
        for j in range(6):  # no legs: the row's leg fields defined all the same (every row's bits determined)
            row[O_LEG + j] = 0.0

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
        row[O_SP_POS + j] = p_sp[j]
    for j in range(4):
        row[O_Q + j] = q[j]
        row[O_SP_Q + j] = q_sp[j]
    flags = (sat_pos, sat_vel, sat_acc, sat_rate, sat_angacc, sat_tilt, sat_rot)
    for j in range(7):
        row[O_SAT + j] = float(flags[j])
        counts[j] += flags[j]


@njit(cache=True, inline=_inline_per_sample)
def step_one(f, om, c, coef, state, counts, row):
    """Advance one washout (+ platform + head motion) by one sample and write its output ``row``:
    washout -> set points -> platform -> head."""
    first = state[S_INIT] == 0.0
    rest = c[C_REST] != 0.0
    q_sp_prev, p_sp_prev, sat_tilt, sat_rot, tilt_rate = washout_classical(f, om, c, coef, state, first, rest)
    q_sp = (state[S_QSP], state[S_QSP + 1], state[S_QSP + 2], state[S_QSP + 3])
    p_sp = (state[S_PSP], state[S_PSP + 1], state[S_PSP + 2])
    platform_head(p_sp_prev, p_sp, q_sp_prev, q_sp, first, rest, c, coef, state, counts, row, sat_tilt, sat_rot)
    row[O_TILT] = tilt_rate
    state[S_INIT] = 1.0


@njit(cache=True)
def setpoint_step(p_sp, q_sp, sat_tilt, sat_rot, c, coef, state, counts, row):
    """One sample of a washout computed outside the kernel (a Python algorithm, :mod:`washbench.cueing.algorithm`):
    the platform tracks its new set point ``p_sp`` (3,) m and ``q_sp`` (4,) (unit quaternion) from the previous one,
    kept in ``state`` (S_PSP, S_QSP; before the first sample: the algorithm's start set point). ``sat_tilt``,
    ``sat_rot``: the algorithm's own limit flags (0 or 1). Its tilt rate is not known here: NaN in the row."""
    first = state[S_INIT] == 0.0
    rest = c[C_REST] != 0.0
    q_prev = (state[S_QSP], state[S_QSP + 1], state[S_QSP + 2], state[S_QSP + 3])
    p_prev = (state[S_PSP], state[S_PSP + 1], state[S_PSP + 2])
    pn = (p_sp[0], p_sp[1], p_sp[2])
    qn = (q_sp[0], q_sp[1], q_sp[2], q_sp[3])
    platform_head(p_prev, pn, q_prev, qn, first, rest, c, coef, state, counts, row, sat_tilt, sat_rot)
    row[O_TILT] = math.nan
    for j in range(3):
        state[S_PSP + j] = pn[j]
    for j in range(4):
        state[S_QSP + j] = qn[j]
    state[S_INIT] = 1.0


@njit(cache=True)
def setpoint_trace(sp_pos, sp_q, flags, c, coef, state, counts, out):
    """:func:`setpoint_step` over a whole trace: sp_pos (N, 3), sp_q (N, 4), flags (N, 2) int64; out (NFIELDS, N)."""
    row = np.zeros(NFIELDS)
    for k in range(sp_pos.shape[0]):
        setpoint_step(sp_pos[k], sp_q[k], flags[k, 0], flags[k, 1], c, coef, state, counts, row)
        for j in range(NFIELDS):
            out[j, k] = row[j]


@njit(cache=True)
def setpoint_block(sp_pos, sp_q, flags, c, coef, state, counts, out):
    """:func:`setpoint_step` over a block: sp_pos (M, 3), sp_q (M, 4), flags (M, 2) int64; out (M, NFIELDS)."""
    for k in range(sp_pos.shape[0]):
        setpoint_step(sp_pos[k], sp_q[k], flags[k, 0], flags[k, 1], c, coef, state, counts, out[k])


@njit(cache=True)
def _check_input(f, om):
    if f.shape[0] != 3 or om.shape[0] != 3:
        raise ValueError("cueing input: f and omega must have shape (3,)")
    for j in range(3):
        if not (math.isfinite(f[j]) and math.isfinite(om[j])):
            raise ValueError("cueing input: non-finite specific force or angular velocity")


@njit(cache=True, _nrt=False)
def bank_step(f, om, cfg, coef, state, counts, out):
    """Streaming form: advance every washout of the bank by one sample (f, om: (3,) float64): :func:`bank_block` on
    a block of one sample. Without reference counting, as :func:`bank_block` (the call from Python then makes no
    reference-count object for its seven arrays)."""
    _check_input(f, om)
    bank_block(f.reshape((1, 3)), om.reshape((1, 3)), cfg, coef, state, counts, out.reshape((out.shape[0], 1, NFIELDS)))


TRACE_CHUNK = 4096
"""Samples :func:`bank_trace` steps at a time through :func:`bank_block` (its rows then copied field-major)."""


@njit(cache=True, parallel=True)
def bank_trace(f, om, cfg, coef, state, counts, out):
    """Whole-trace form: f, om (N, 3), already checked finite; out (n_washouts, NFIELDS, N), field-major so that
    every output column is contiguous (no copy to split it into traces).

    Same per-washout step as bank_step (:func:`bank_block`, on chunks of :data:`TRACE_CHUNK` samples); the washouts
    are independent, so they run in parallel threads (one washout's samples in order on one thread: the same
    operations in the same order as streaming).
    """
    n = f.shape[0]
    for i in prange(cfg.shape[0]):
        if cfg[i, C_KIND] < 0.0:
            continue
        # the Atlas has no legs: its leg fields (zero in every row) are set at once, not copied sample by sample
        nf = O_LEG if cfg[i, C_PLAT] == PLAT_ATLAS else NFIELDS
        if nf < NFIELDS:
            out[i, nf:, :] = 0.0
        for k0 in range(0, n, TRACE_CHUNK):
            k1 = min(n, k0 + TRACE_CHUNK)
            rows = np.empty((1, k1 - k0, NFIELDS))
            bank_block(f[k0:k1], om[k0:k1], cfg[i : i + 1], coef[i : i + 1], state[i : i + 1], counts[i : i + 1], rows)
            for k in range(k0, k1):
                for j in range(nf):
                    out[i, j, k] = rows[0, k - k0, j]


@njit(cache=True, _nrt=False)
def bank_block(f, om, cfg, coef, state, counts, out):
    """Block form for a flight in progress (:meth:`CueingBank.steps`): f, om (M, 3) checked finite; out
    (n_washouts, M, NFIELDS). Serial: a short block does not pay for threads (nor starts OpenMP in a process
    that may fork). The one compiled loop every form runs (streaming: a block of one; whole trace: chunks): the
    per-sample step (:func:`step_one` and what it calls) is inlined here, see :func:`_inline_per_sample`.

    Compiled without numba's reference counting (``_nrt=False``): it allocates nothing, and the arrays it is given
    outlive the call, so counting the references of the views it takes (atomic operations, still about a quarter
    of its time once inlined) buys nothing: 1.4 -> 1.1-1.2 us a sample for the three washouts, same bits.
    """
    for i in range(cfg.shape[0]):  # the washouts are independent: each one's samples in order, as sample by sample
        if cfg[i, C_KIND] < 0.0:
            continue
        c, cf, st, ct, o = cfg[i], coef[i], state[i], counts[i], out[i]
        for k in range(f.shape[0]):
            step_one(f[k], om[k], c, cf, st, ct, o[k])


_HERE = Path(__file__).resolve().parent
drop_stale_cache(
    __file__,
    [
        _HERE.parent / "numerics" / "rotations.py",
        _HERE / "filters.py",
        _HERE.parent / "numerics" / "jitcache.py",
        _HERE.parent / "platform" / "kinematics.py",
        _HERE.parent / "platform" / "hexapod_kinematics.py",
        _HERE.parent / "platform" / "rig_kinematics.py",
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
    "O_TILT",
    "SAT_KINDS",
    "bank_block",
    "bank_step",
    "bank_trace",
    "platform_head",
    "setpoint_block",
    "setpoint_step",
    "setpoint_trace",
    "step_one",
    "washout_classical",
]
