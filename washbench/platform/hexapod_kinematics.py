"""Kinematic 6-6 Gough-Stewart hexapod: inverse and forward kinematics, leg limits (numba-compiled, allocation-free).

Frames and units (docs/platforms.md): the base frame is inertial north-east-down (m), origin at the base centre;
base joint i at ``b_i``; platform joint i at ``a_i`` in the cockpit's body axes (x forward, y right, z down), origin
at the motion reference point (MRP); the MRP at neutral is at ``n`` (base frame). A pose is the MRP's displacement
from neutral ``p`` (NED, m) and the cockpit attitude ``q`` (body -> inertial, scalar first), and leg i is the
joint-to-joint length

    l_i(p, q) = | n + p + R(q) a_i - b_i |                                                     (inverse kinematics)

Each step (:func:`hexapod_track`) a set point outside the workspace is first scaled towards neutral: the largest
s in [0, 1] (bisection) for which every leg of the pose (s p, exp(s log q)) lies within its stroke; then every
leg tracks its own set point under the stroke, leg velocity and leg acceleration limits with the Atlas stage's
per-axis tracker (:func:`washbench.platform.kinematics.track_axis`: braking-aware, so no leg ever leaves its
stroke); last the pose that has those six leg lengths is found by Newton's method from the previous pose (forward
kinematics, :func:`forward_kinematics`). When no limit acts the legs are the set point's, and the pose is the
set point itself, exactly.

Arrays: ``geo`` (42,) = base joints (18, row-major), platform joints (18), neutral (3), then leg min, leg max
(m) and the stroke margin (m); ``work`` (48,) scratch for the 6 x 7 Newton system and its solution.
"""

from __future__ import annotations

import math
from pathlib import Path

from washbench.numerics.jit import njit
from washbench.numerics.jitcache import drop_stale_cache
from washbench.numerics.rotations import cross, norm3, qmul, qnormalize, qrot, qrotvec
from washbench.platform.kinematics import track_axis

drop_stale_cache(
    __file__,
    [
        Path(__file__).resolve().parent.parent / "numerics" / "rotations.py",
        Path(__file__).resolve().parent / "kinematics.py",
    ],
)

G_BASE, G_PLAT, G_NEUTRAL, G_LMIN, G_LMAX, G_MARGIN = 0, 18, 36, 39, 40, 41
NGEO = 42
NWORK = 48

SCALE_ITERATIONS = 48
"""Bisection steps of the scaling towards neutral (the scale is then within 2^-48 of the boundary's)."""
NEWTON_ITERATIONS = 12
NEWTON_TOL_M = 1e-13


@njit(cache=True)
def leg(geo, i, p, q):
    """Length (m) of leg i at pose (p, q): |n + p + R(q) a_i - b_i|."""
    a = (geo[G_PLAT + 3 * i], geo[G_PLAT + 3 * i + 1], geo[G_PLAT + 3 * i + 2])
    ra = qrot(q, a)
    dx = geo[G_NEUTRAL] + p[0] + ra[0] - geo[G_BASE + 3 * i]
    dy = geo[G_NEUTRAL + 1] + p[1] + ra[1] - geo[G_BASE + 3 * i + 1]
    dz = geo[G_NEUTRAL + 2] + p[2] + ra[2] - geo[G_BASE + 3 * i + 2]
    return math.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True)
def within(geo, p, q):
    """Whether every leg of pose (p, q) is within its stroke less the margin."""
    lo = geo[G_LMIN] + geo[G_MARGIN]
    hi = geo[G_LMAX] - geo[G_MARGIN]
    for i in range(6):
        li = leg(geo, i, p, q)
        if not (lo <= li <= hi):
            return False
    return True


@njit(cache=True)
def scaled_pose(p, r, s):
    """The pose s of the way from neutral to (p, exp(r)): (s p, exp(s r)) with r the rotation vector (rad)."""
    x = s * r[0]
    y = s * r[1]
    z = s * r[2]
    ang = math.sqrt(x * x + y * y + z * z)
    if ang < 1e-12:
        q = (1.0, 0.5 * x, 0.5 * y, 0.5 * z)
    else:
        k = math.sin(0.5 * ang) / ang
        q = (math.cos(0.5 * ang), x * k, y * k, z * k)
    return (s * p[0], s * p[1], s * p[2]), qnormalize(q)


@njit(cache=True)
def reachable(geo, p, q):
    """The set point (p, q) if every leg is within its stroke, else scaled towards neutral (bisection on s, the
    largest s found with every leg within): returns (p, q, 1 if scaled)."""
    if within(geo, p, q):
        return p, q, 0
    r = qrotvec(q)
    lo = 0.0
    hi = 1.0
    for _ in range(SCALE_ITERATIONS):
        mid = 0.5 * (lo + hi)
        ps, qs = scaled_pose(p, r, mid)
        if within(geo, ps, qs):
            lo = mid
        else:
            hi = mid
    ps, qs = scaled_pose(p, r, lo)
    return ps, qs, 1


@njit(cache=True)
def _solve6(work):
    """Solve the 6 x 6 system held row-major with its right-hand side as column 6 of ``work[:42]`` (Gaussian
    elimination, partial pivoting); the solution into ``work[42:48]``. Returns False if singular."""
    for col in range(6):
        piv = col
        best = abs(work[7 * col + col])
        for r in range(col + 1, 6):
            v = abs(work[7 * r + col])
            if v > best:
                best = v
                piv = r
        if best < 1e-12:
            return False
        if piv != col:
            for j in range(7):
                t = work[7 * col + j]
                work[7 * col + j] = work[7 * piv + j]
                work[7 * piv + j] = t
        d = work[7 * col + col]
        for r in range(col + 1, 6):
            f = work[7 * r + col] / d
            if f != 0.0:
                for j in range(col, 7):
                    work[7 * r + j] -= f * work[7 * col + j]
    for r in range(5, -1, -1):
        s = work[7 * r + 6]
        for j in range(r + 1, 6):
            s -= work[7 * r + j] * work[42 + j]
        work[42 + r] = s / work[7 * r + r]
    return True


@njit(cache=True)
def forward_kinematics(geo, legs, p0, q0, work):
    """The pose whose six legs have lengths ``legs`` (6 consecutive floats, indexable), by Newton's method from
    (p0, q0). Jacobian row i: [u_i, (R a_i) x u_i] with u_i the unit leg vector, for a displacement dp and a
    small rotation dtheta about inertial axes (q <- exp(dtheta) q). Returns (p, q, converged)."""
    p = p0
    q = q0
    for _ in range(NEWTON_ITERATIONS):
        worst = 0.0
        for i in range(6):
            a = (geo[G_PLAT + 3 * i], geo[G_PLAT + 3 * i + 1], geo[G_PLAT + 3 * i + 2])
            ra = qrot(q, a)
            d = (
                geo[G_NEUTRAL] + p[0] + ra[0] - geo[G_BASE + 3 * i],
                geo[G_NEUTRAL + 1] + p[1] + ra[1] - geo[G_BASE + 3 * i + 1],
                geo[G_NEUTRAL + 2] + p[2] + ra[2] - geo[G_BASE + 3 * i + 2],
            )
            li = norm3(d)
            u = (d[0] / li, d[1] / li, d[2] / li)
            m = cross(ra, u)
            work[7 * i] = u[0]
            work[7 * i + 1] = u[1]
            work[7 * i + 2] = u[2]
            work[7 * i + 3] = m[0]
            work[7 * i + 4] = m[1]
            work[7 * i + 5] = m[2]
            e = legs[i] - li
            work[7 * i + 6] = e
            worst = max(worst, abs(e))
        if worst <= NEWTON_TOL_M:
            return p, q, True
        if not _solve6(work):
            return p, q, False
        p = (p[0] + work[42], p[1] + work[43], p[2] + work[44])
        th = (work[45], work[46], work[47])
        ang = norm3(th)
        if ang < 1e-12:
            dq = (1.0, 0.5 * th[0], 0.5 * th[1], 0.5 * th[2])
        else:
            k = math.sin(0.5 * ang) / ang
            dq = (math.cos(0.5 * ang), th[0] * k, th[1] * k, th[2] * k)
        q = qnormalize(qmul(dq, q))
    worst = 0.0
    for i in range(6):
        worst = max(worst, abs(legs[i] - leg(geo, i, p, q)))
    return p, q, worst <= 1e3 * NEWTON_TOL_M


@njit(cache=True)
def hexapod_track(geo, v_max, a_max, catch_up, dt, p_prev, q_prev, p_sp, q_sp, legs, vels, leg_sp, work, first):
    """One step of the hexapod towards set point (p_sp, q_sp).

    ``legs``, ``vels``, ``leg_sp`` (6 each, updated in place): leg lengths (m), leg velocities (m/s) and the leg
    set points of the previous step; (p_prev, q_prev) the previous pose. On the ``first`` step the platform starts
    at rest at the (reachable) set point. Returns (p, q, sat_stroke, sat_vel, sat_acc): the pose, and 0/1 flags:
    the set point was scaled towards neutral or a leg was held by its stroke; a leg's velocity or acceleration
    limit acted.
    """
    ps, qs, scaled = reachable(geo, p_sp, q_sp)
    centre = 0.5 * (geo[G_LMIN] + geo[G_LMAX])
    half = 0.5 * (geo[G_LMAX] - geo[G_LMIN]) - geo[G_MARGIN]
    if first:
        for i in range(6):
            li = leg(geo, i, ps, qs)
            legs[i] = li
            vels[i] = 0.0
            leg_sp[i] = li
        return ps, qs, scaled, 0, 0
    sat_pos = scaled
    sat_vel = 0
    sat_acc = 0
    exact = True
    for i in range(6):
        target = leg(geo, i, ps, qs)
        li, vi, s_p, s_v, s_a = track_axis(
            legs[i] - centre, vels[i], leg_sp[i] - centre, target - centre, half, v_max, a_max, catch_up, dt
        )
        new = li + centre
        if abs(new - target) <= 1e-12:  # reached (the shift by the centre rounds)
            new = target
        else:
            exact = False
        legs[i] = new
        vels[i] = vi
        leg_sp[i] = target
        sat_pos |= s_p
        sat_vel |= s_v
        sat_acc |= s_a
    if exact:
        return ps, qs, sat_pos, sat_vel, sat_acc
    p, q, ok = forward_kinematics(geo, legs, p_prev, q_prev, work)
    if not ok:  # (not met with the bundled geometry) stay where the legs were: the previous pose, at rest
        p = p_prev
        q = q_prev
        for i in range(6):
            legs[i] = leg(geo, i, p, q)
            vels[i] = 0.0
    return p, q, sat_pos, sat_vel, sat_acc


__all__ = ["NGEO", "NWORK", "forward_kinematics", "hexapod_track", "leg", "reachable", "within"]
