"""Quaternion and ZYX Euler-angle kinematics used by the washouts (numba-compiled, tuple based).

Conventions (see DESIGN.md): body axes x forward, y right, z down; inertial frame NED; quaternions are
scalar first ``(w, x, y, z)``, Hamilton product, and a quaternion ``q`` maps body vectors to inertial
ones, ``v_I = q v_B q*``. Euler angles are the ZYX (yaw psi, pitch theta, roll phi) sequence in rad;
angular velocities are body rates in rad/s.

Every function takes and returns plain tuples of floats so that the compiled washout step allocates
nothing; each is also callable from Python (tests compare them with scipy's ``Rotation``).
"""

from __future__ import annotations

import math

from washbench.numerics.jit import njit

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]

IDENTITY: Quat = (1.0, 0.0, 0.0, 0.0)


@njit(cache=True)
def cross(a: Vec3, b: Vec3) -> Vec3:
    """Vector product a x b."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True)
def dot(a: Vec3, b: Vec3) -> float:
    """Scalar product."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True)
def norm3(a: Vec3) -> float:
    """Euclidean norm of a 3-vector."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@njit(cache=True, inline="always")
def limit_norm(v: Vec3, vmax: float) -> tuple[Vec3, int]:
    """``v`` scaled down to norm ``vmax`` if longer (direction kept); returns (v, 1 if limited else 0).

    ``norm3`` of the result is ``<= vmax`` exactly (the scale is nudged down by ulps where rounding lands above).
    """
    n = norm3(v)
    if n > vmax:
        s = vmax / n
        out = (v[0] * s, v[1] * s, v[2] * s)
        for _ in range(8):
            if norm3(out) <= vmax:
                break
            s *= 1.0 - 2.0**-52
            out = (v[0] * s, v[1] * s, v[2] * s)
        return out, 1
    return v, 0


@njit(cache=True)
def qmul(a: Quat, b: Quat) -> Quat:
    """Hamilton product a (x) b."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(cache=True)
def qconj(q: Quat) -> Quat:
    """Conjugate q* = [q0, -q_v] (paper Eq. 16)."""
    return (q[0], -q[1], -q[2], -q[3])


@njit(cache=True)
def qnormalize(q: Quat) -> Quat:
    """q / |q|; the identity for a zero quaternion."""
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if n == 0.0 or not math.isfinite(n):
        return (1.0, 0.0, 0.0, 0.0)
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


@njit(cache=True)
def qrot(q: Quat, v: Vec3) -> Vec3:
    """Rotate a body vector into the inertial frame: the vector part of q (x) [0, v] (x) q* (paper Eq. 15).

    Eq. 15 writes (-q) (x) f (x) (-q*), which is the same product (the two signs cancel). Computed in the
    expanded form v + 2 q0 (q_v x v) + 2 q_v x (q_v x v), algebraically identical for a unit q.
    """
    u = (q[1], q[2], q[3])
    t = cross(u, v)
    t = (2.0 * t[0], 2.0 * t[1], 2.0 * t[2])
    c = cross(u, t)
    return (v[0] + q[0] * t[0] + c[0], v[1] + q[0] * t[1] + c[1], v[2] + q[0] * t[2] + c[2])


@njit(cache=True)
def qrot_inv(q: Quat, v: Vec3) -> Vec3:
    """Rotate an inertial vector into the body frame: q* (x) [0, v] (x) q (the transpose, L_SI)."""
    return qrot((q[0], -q[1], -q[2], -q[3]), v)


@njit(cache=True)
def qexp_body(w: Vec3, dt: float) -> Quat:
    """Rotation quaternion [cos(|w| dt/2), w/|w| sin(|w| dt/2)] for a constant body rate w (rad/s) over dt (s)."""
    n = norm3(w)
    half = 0.5 * n * dt
    # k = sin(half) / n; near rest its series, exact to double precision, avoids 0/0
    k = 0.5 * dt * (1.0 - half * half / 6.0) if half < 1e-8 else math.sin(half) / n
    return (math.cos(half), w[0] * k, w[1] * k, w[2] * k)


@njit(cache=True)
def qintegrate(q: Quat, w: Vec3, dt: float) -> Quat:
    """Quaternion integrator of paper Eq. 17: q_n = q_{n-1} (x) exp(w dt / 2), renormalised.

    ``w`` is the body angular velocity (rad/s) held over the step ``dt`` (s). The renormalisation only
    removes rounding drift (the product of unit quaternions is unit).
    """
    return qnormalize(qmul(q, qexp_body(w, dt)))


@njit(cache=True)
def qrate_body(q_new: Quat, q_old: Quat, dt: float) -> Vec3:
    """Body angular velocity from two successive attitudes (paper Eqs. 18-19), rad/s.

    omega = vector part of 2 q_n* (x) (q_n - q_{n-1}) / dt. For a constant rate w this returns
    2 sin(|w| dt / 2) / dt * w/|w|, i.e. w to second order in dt. The sign of q_old is matched to q_new
    first (q and -q are the same attitude).
    """
    s = 1.0
    if q_new[0] * q_old[0] + q_new[1] * q_old[1] + q_new[2] * q_old[2] + q_new[3] * q_old[3] < 0.0:
        s = -1.0
    d = (
        (q_new[0] - s * q_old[0]) / dt,
        (q_new[1] - s * q_old[1]) / dt,
        (q_new[2] - s * q_old[2]) / dt,
        (q_new[3] - s * q_old[3]) / dt,
    )
    r = qmul(qconj(q_new), d)
    return (2.0 * r[1], 2.0 * r[2], 2.0 * r[3])


@njit(cache=True)
def qrotvec(q: Quat) -> Vec3:
    """Rotation vector (axis * angle, rad) of the shortest rotation represented by q (angle in [0, pi])."""
    w, x, y, z = q
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    n = math.sqrt(x * x + y * y + z * z)
    k = (2.0 / w if w > 0.0 else 0.0) if n < 1e-12 else 2.0 * math.atan2(n, w) / n
    return (x * k, y * k, z * k)


@njit(cache=True)
def quat_from_euler(phi: float, theta: float, psi: float) -> Quat:
    """Body->inertial quaternion of ZYX Euler angles (rad): q = q_z(psi) (x) q_y(theta) (x) q_x(phi)."""
    cf, sf = math.cos(0.5 * phi), math.sin(0.5 * phi)
    ct, st = math.cos(0.5 * theta), math.sin(0.5 * theta)
    cp, sp = math.cos(0.5 * psi), math.sin(0.5 * psi)
    return (
        cp * ct * cf + sp * st * sf,
        cp * ct * sf - sp * st * cf,
        cp * st * cf + sp * ct * sf,
        sp * ct * cf - cp * st * sf,
    )


@njit(cache=True)
def euler_from_quat(q: Quat) -> Vec3:
    """ZYX Euler angles (phi, theta, psi) in rad of a body->inertial quaternion; theta in [-pi/2, pi/2].

    At theta = +-90 deg roll and yaw are not separable (gimbal lock): the split returned there is
    arbitrary but finite.
    """
    w, x, y, z = q
    phi = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    s = 2.0 * (w * y - z * x)
    s = min(1.0, max(-1.0, s))
    theta = math.asin(s)
    psi = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return (phi, theta, psi)


@njit(cache=True)
def rot_euler(phi: float, theta: float, psi: float, v: Vec3) -> Vec3:
    """L_IS v: body vector to inertial with the ZYX Euler angles of the body (paper Eq. 1)."""
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    return (
        ct * cp * v[0] + (sf * st * cp - cf * sp) * v[1] + (cf * st * cp + sf * sp) * v[2],
        ct * sp * v[0] + (sf * st * sp + cf * cp) * v[1] + (cf * st * sp - sf * cp) * v[2],
        -st * v[0] + sf * ct * v[1] + cf * ct * v[2],
    )


@njit(cache=True)
def rot_euler_inv(phi: float, theta: float, psi: float, v: Vec3) -> Vec3:
    """L_SI v = L_IS^T v: inertial vector to body (paper Eq. 7)."""
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    return (
        ct * cp * v[0] + ct * sp * v[1] - st * v[2],
        (sf * st * cp - cf * sp) * v[0] + (sf * st * sp + cf * cp) * v[1] + sf * ct * v[2],
        (cf * st * cp + sf * sp) * v[0] + (cf * st * sp - sf * cp) * v[1] + cf * ct * v[2],
    )


@njit(cache=True)
def euler_rates(phi: float, theta: float, w: Vec3, cos_theta_min: float) -> Vec3:
    """T_s w: body rates (rad/s) to ZYX Euler-angle rates (rad/s) (paper Eq. 4).

    T_s is singular at theta = +-90 deg (tan and sec). To keep the small-angle washout finite there,
    |cos theta| is not allowed below ``cos_theta_min`` (sign kept); the rates are then wrong by
    construction, which is the Euler-angle washout's known limitation.
    """
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(theta), math.sin(theta)
    if abs(ct) < cos_theta_min:
        ct = cos_theta_min if ct >= 0.0 else -cos_theta_min
    t = st / ct
    return (
        w[0] + sf * t * w[1] + cf * t * w[2],
        cf * w[1] - sf * w[2],
        (sf * w[1] + cf * w[2]) / ct,
    )


@njit(cache=True)
def body_rates(phi: float, theta: float, bdot: Vec3) -> Vec3:
    """R_S beta_dot: ZYX Euler-angle rates (rad/s) to body rates (rad/s) (paper Eq. 9, the inverse of T_s)."""
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(theta), math.sin(theta)
    return (
        bdot[0] - st * bdot[2],
        cf * bdot[1] + sf * ct * bdot[2],
        -sf * bdot[1] + cf * ct * bdot[2],
    )


@njit(cache=True)
def wrap_near(angle: float, ref: float) -> float:
    """``angle`` plus the multiple of 2 pi that brings it within pi of ``ref`` (to unwrap Euler angles)."""
    d = angle - ref
    if d > math.pi or d < -math.pi:
        d -= 2.0 * math.pi * math.floor((d + math.pi) / (2.0 * math.pi))
    return ref + d
