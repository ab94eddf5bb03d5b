"""Kinematic Atlas platform: set-point tracking under limits, omni-wheel speeds (numba-compiled).

Translational stage, per inertial axis (NED, m, m/s, m/s^2), discrete semi-implicit Euler:
``v_k = v_{k-1} + a_k dt``, ``p_k = p_{k-1} + v_k dt``. Inside its limits the stage reaches each new
set point exactly (the paper's perfect-response assumption). Otherwise the velocity is the commanded
one clipped to the intersection of three bounds, so no limit is ever exceeded:

- acceleration: |v_k - v_{k-1}| <= a_max dt;
- velocity: |v_k| <= v_max;
- position: the stage must still be able to stop inside +-p_max braking at a_max afterwards
  (:func:`brake_speed`, exact for the discrete integrator). This is feasible whenever the previous
  step was, so the position limit is never overrun (a final clamp only removes rounding).

After a saturation the remaining lag is closed with a speed that can itself be braked at
``catch_up_fraction * a_max`` (no overshoot past the set point).

Sphere: attitude unlimited (body->inertial quaternion, scalar first), body angular velocity in rad/s
with |omega| <= rate_max and |omega_k - omega_{k-1}| <= alpha_max dt (norms, direction kept; a radial
projection onto a ball never breaks the other bound). Flags returned per step name the limit that bound.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from washbench.numerics.jit import njit
from washbench.numerics.jitcache import drop_stale_cache
from washbench.numerics.rotations import limit_norm, norm3, qconj, qintegrate, qmul, qrotvec

drop_stale_cache(__file__, [Path(__file__).resolve().parent.parent / "numerics" / "rotations.py"])


#: Beyond this many braking steps (r / (a_max dt^2)) the discrete braking sum is inverted in its continuous form.
_BRAKE_STEPS_EXACT = 2.0**50


@njit(cache=True)
def brake_speed(r: float, a_max: float, dt: float) -> float:
    """Largest speed (m/s or rad/s) that, taken this step, still lets the motion stop within distance r.

    Discrete: moving at v for one step and then braking at a_max (semi-implicit Euler) covers
    S(v) = v dt + dt sum_{i>=1} max(v - i a_max dt, 0). S is increasing and piecewise linear with knots
    S(j a_max dt) = a_max dt^2 j (j + 1) / 2; the function inverts it exactly in closed form (at most two
    corrections of the knot index, for rounding). Past 2^50 braking steps (absurd limits or time steps) the
    continuous form v = sqrt(2 a r + (a dt / 2)^2) - a dt / 2 is used: it never loops and never overflows
    an integer, whatever the finite or infinite inputs.
    """
    if not r > 0.0:  # also NaN
        return 0.0
    h = a_max * dt * dt
    x = r / h if h > 0.0 else math.inf
    if not x <= _BRAKE_STEPS_EXACT:
        ad = a_max * dt
        return math.sqrt(2.0 * a_max * r + 0.25 * ad * ad) - 0.5 * ad
    j = math.floor(0.5 * (math.sqrt(1.0 + 8.0 * x) - 1.0))
    for _ in range(2):
        if j > 0 and 0.5 * h * j * (j + 1) > r:
            j -= 1
    for _ in range(2):
        if 0.5 * h * (j + 1) * (j + 2) <= r:
            j += 1
    if j == 0:  # also where h overflowed (a huge time step): one step covers r
        return r / dt
    s_j = 0.5 * h * j * (j + 1)
    return j * a_max * dt + (r - s_j) / (dt * (j + 1))


@njit(cache=True, inline="always")
def catch_up_speed(lag: float, a_max: float, dt: float) -> tuple[float, bool]:
    """Speed that closes a lag > 0 (m or rad) this step, capped to one that can still be braked at ``a_max``.

    Returns (speed, True if the whole lag is closed this step).
    """
    speed = lag / dt
    cap = brake_speed(lag, a_max, dt)
    if cap < speed:
        return cap, False
    return speed, True


@njit(cache=True)
def track_axis(
    p_prev: float,
    v_prev: float,
    sp_prev: float,
    sp: float,
    p_max: float,
    v_max: float,
    a_max: float,
    catch_up: float,
    dt: float,
) -> tuple[float, float, int, int, int]:
    """One step of one translational axis towards set point ``sp``.

    Returns (p, v, sat_pos, sat_vel, sat_acc) with flags 0/1. ``sp_prev`` is the previous set point:
    ``p_prev - sp_prev`` is the lag left by earlier saturations.
    """
    e = sp_prev - p_prev
    v_des = (sp - sp_prev) / dt
    full = True
    if e != 0.0:
        corr, full = catch_up_speed(abs(e), catch_up * a_max, dt)
        v_des += corr if e > 0.0 else -corr
    hi_a = v_prev + a_max * dt
    lo_a = v_prev - a_max * dt
    hi_p = brake_speed(p_max - p_prev, a_max, dt)
    lo_p = -brake_speed(p_max + p_prev, a_max, dt)
    hi = min(hi_a, v_max, hi_p)
    lo = max(lo_a, -v_max, lo_p)
    if lo > hi:  # only by rounding: the braking sequence of the previous step is always feasible
        lo = hi
    sat_pos = 0
    sat_vel = 0
    sat_acc = 0
    if v_des > hi:
        v = hi
        if hi == hi_p:
            sat_pos = 1
        elif hi == v_max:
            sat_vel = 1
        else:
            sat_acc = 1
    elif v_des < lo:
        v = lo
        if lo == lo_p:
            sat_pos = 1
        elif lo == -v_max:
            sat_vel = 1
        else:
            sat_acc = 1
    else:
        v = v_des
    # inside the limits the set point is reached exactly (not just to rounding)
    p = sp if full and sat_pos + sat_vel + sat_acc == 0 else p_prev + v * dt
    if p > p_max:
        p = p_max
        v = (p - p_prev) / dt
    elif p < -p_max:
        p = -p_max
        v = (p - p_prev) / dt
    # rounding (in the lines above, or in the caller's (v - v_prev) / dt) must not push a value past its limit
    if v > v_max:
        v = v_max
    elif v < -v_max:
        v = -v_max
    return p, v, sat_pos, sat_vel, sat_acc


@njit(cache=True)
def track_rotation(
    q_prev: tuple[float, float, float, float],
    w_prev: tuple[float, float, float],
    q_sp_prev: tuple[float, float, float, float],
    q_sp: tuple[float, float, float, float],
    w_max: float,
    alpha_max: float,
    catch_up: float,
    dt: float,
) -> tuple[tuple[float, float, float, float], tuple[float, float, float], int, int]:
    """One step of the sphere towards attitude set point ``q_sp`` (body rates, rad/s).

    Returns (q, omega_body, sat_rate, sat_angacc). The feed-forward rate is the set point's own rate
    (rotation from ``q_sp_prev`` to ``q_sp``); a lag (``q_prev`` vs ``q_sp_prev``) is closed at a rate
    that can be braked at ``catch_up * alpha_max``.
    """
    ff = qrotvec(qmul(qconj(q_sp_prev), q_sp))
    wx = ff[0] / dt
    wy = ff[1] / dt
    wz = ff[2] / dt
    err = qrotvec(qmul(qconj(q_prev), q_sp_prev))
    ne = norm3(err)
    full = True
    if ne > 0.0:
        corr, full = catch_up_speed(ne, catch_up * alpha_max, dt)
        k = corr / ne
        wx += err[0] * k
        wy += err[1] * k
        wz += err[2] * k
    w = (wx, wy, wz)
    d, sat_angacc = limit_norm((wx - w_prev[0], wy - w_prev[1], wz - w_prev[2]), alpha_max * dt)
    if sat_angacc:
        w = (w_prev[0] + d[0], w_prev[1] + d[1], w_prev[2] + d[2])
    w, sat_rate = limit_norm(w, w_max)
    # inside the limits the set point is reached exactly (not just to rounding)
    q = q_sp if full and sat_rate + sat_angacc == 0 else qintegrate(q_prev, w, dt)
    return q, w, sat_rate, sat_angacc


@njit(cache=True)
def wheel_speeds(jac: np.ndarray, w_inertial: tuple[float, float, float]) -> tuple[float, float, float]:
    """Omni-wheel angular speeds (rad/s) = J @ omega_I; ``jac`` is ``wheel_jacobian(...)`` flattened (9,), row-major."""
    return (
        jac[0] * w_inertial[0] + jac[1] * w_inertial[1] + jac[2] * w_inertial[2],
        jac[3] * w_inertial[0] + jac[4] * w_inertial[1] + jac[5] * w_inertial[2],
        jac[6] * w_inertial[0] + jac[7] * w_inertial[1] + jac[8] * w_inertial[2],
    )
