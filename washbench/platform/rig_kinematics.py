"""A 2- or 3-DOF rig's step (numba-compiled): each axis tracks its set point within its limits.

The attitude set point (body -> inertial quaternion) is split into ZYX Euler angles (roll phi, pitch theta, yaw psi,
rad); each present axis tracks its angle with the Atlas stage's per-axis tracker
(:func:`washbench.platform.kinematics.track_axis`: angle, rate and acceleration limits, braking-aware, so an axis
never passes its angle limit), an absent one stays at zero; heave tracks the set point's down position likewise
(the rig has no surge or sway). ``rig`` is :meth:`washbench.platform.rig.RigModel.limits_array`; ``st`` (12,)
holds angle, rate and angle set point per axis, then heave's position, velocity and set point.
"""

from __future__ import annotations

from pathlib import Path

from washbench.numerics.jit import njit
from washbench.numerics.jitcache import drop_stale_cache
from washbench.numerics.rotations import euler_from_quat, quat_from_euler, wrap_near
from washbench.platform.kinematics import track_axis

drop_stale_cache(
    __file__,
    [
        Path(__file__).resolve().parent.parent / "numerics" / "rotations.py",
        Path(__file__).resolve().parent / "kinematics.py",
    ],
)

NRIG_STATE = 12


@njit(cache=True)
def rig_track(rig, catch_up, dt, p_sp, q_sp, st, first):
    """One step of the rig towards set point (p_sp, q_sp); returns (p, q, sat_angle_or_heave, sat_heave_vel,
    sat_heave_acc, sat_rate, sat_angacc), flags 0/1."""
    e = euler_from_quat(q_sp)
    sat_pos = 0
    sat_vel = 0
    sat_acc = 0
    sat_rate = 0
    sat_angacc = 0
    a0 = 0.0
    a1 = 0.0
    a2 = 0.0
    for j in range(3):
        lim = rig[3 * j]
        if lim <= 0.0:
            continue
        target = e[j]
        if j == 2 and not first:
            target = wrap_near(target, st[3 * j + 2])
        if not -lim <= target <= lim:  # a set point beyond the stop: track the stop
            target = min(lim, max(-lim, target))
            sat_pos = 1
        if first:
            st[3 * j] = target
            st[3 * j + 1] = 0.0
            st[3 * j + 2] = target
        else:
            a, w, s_p, s_v, s_a = track_axis(st[3 * j], st[3 * j + 1], st[3 * j + 2], target, lim, rig[3 * j + 1],
                                             rig[3 * j + 2], catch_up, dt)  # fmt: skip
            st[3 * j] = a
            st[3 * j + 1] = w
            st[3 * j + 2] = target
            sat_pos |= s_p
            sat_rate |= s_v
            sat_angacc |= s_a
        if j == 0:
            a0 = st[0]
        elif j == 1:
            a1 = st[3]
        else:
            a2 = st[6]
    z = 0.0
    zmax = rig[9]
    if zmax > 0.0:
        target = p_sp[2]
        if not -zmax <= target <= zmax:
            target = min(zmax, max(-zmax, target))
            sat_pos = 1
        if first:
            st[9] = target
            st[10] = 0.0
            st[11] = target
            z = target
        else:
            z, v, s_p, s_v, s_a = track_axis(st[9], st[10], st[11], target, zmax, rig[10], rig[11], catch_up, dt)
            st[9] = z
            st[10] = v
            st[11] = target
            sat_pos |= s_p
            sat_vel |= s_v
            sat_acc |= s_a
    q = quat_from_euler(a0, a1, a2)
    return (0.0, 0.0, z), q, sat_pos, sat_vel, sat_acc, sat_rate, sat_angacc


__all__ = ["NRIG_STATE", "rig_track"]
