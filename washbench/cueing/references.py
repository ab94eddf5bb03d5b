"""The naive references: what a platform does when it simply replays the aircraft's motion, or stands still.

A washout is worth its complexity only where it beats these; every verdict says whether it does
(docs/metrics.md, "The naive references"). Three built-in washouts (:data:`washbench.cueing.registry.BUILTIN_PYTHON`),
selectable like any other:

- ``replay``: the aircraft's motion replayed through the platform's limits. The cockpit's attitude follows the
  aircraft's, integrated from its body rates, ``q_k = q_{k-1} exp(omega_k dt / 2)`` (scalar first, body to
  inertial), from the tilt at which gravity alone gives the first sample's specific force (``R_0' [0, 0, -g]``
  along ``f_0``; level with ``filter_start="rest"``); the stage is driven by what that rotation leaves of the
  specific force, the inertial acceleration ``a = R f + g_I`` (``g_I = [0, 0, g]``, so that ``f = R' (a - g_I)``)
  integrated twice from rest at the centre, its position set point clipped to the platform's travel
  (:attr:`washbench.cueing.algorithm.WashoutContext.limits`). The platform model then follows what it can: on the
  Atlas any attitude at its rate limits, on a hexapod or a rig its own workspace; the stage runs into its stops and
  stays there as long as the integral says, as a naive replay does.
- ``replay-rotation``: the same attitude, the stage held at its centre (the rotational half alone: the gravity tilt
  of sustained attitudes and the exact rotation, no stage).
- ``still``: the platform held at its first pose (the tilt of the first sample, or level), never moving: the
  ranking's "1" (docs/metrics.md).

Integration is explicit, one sample at a time, compiled (:func:`reference_block`); nothing is tuned. Each has the
block form (``steps``, a flight's lockstep block at a time) and the whole-trace form (``trace``), the same numbers as
its steps.
"""

from __future__ import annotations

import math

import numpy as np

from washbench.cueing.algorithm import SetPoint, WashoutContext
from washbench.cueing.registry import REFERENCE_KINDS
from washbench.numerics.jit import njit
from washbench.numerics.jitcache import announce_compile


def tilt_of(f_mps2: np.ndarray) -> np.ndarray:
    """The quaternion (4,) (scalar first, body to inertial) of the least rotation from level at which gravity alone
    gives a specific force along ``f_mps2`` (3,), body axes: ``R' [0, 0, -1]`` along ``f / |f|``; level for a force
    of less than 1e-6 m/s^2 or pointing straight up the body's z axis's other way (no unique least rotation)."""
    f = np.asarray(f_mps2, dtype=np.float64)
    n = float(np.linalg.norm(f))
    if n < 1e-6:
        return np.array([1.0, 0.0, 0.0, 0.0])
    u = -f / n  # gravity's direction in body axes, to become [0, 0, 1] in inertial axes: R u = e_z
    # the rotation taking u to e_z: axis u x e_z, angle acos(u_z); q = [cos(a/2), sin(a/2) axis]
    w = 1.0 + u[2]
    if w < 1e-12:
        return np.array([1.0, 0.0, 0.0, 0.0])
    q = np.array([w, u[1], -u[0], 0.0])  # [1 + u.e_z, u x e_z], normalised below (the half-angle form)
    return q / np.linalg.norm(q)


@njit(cache=True)
def reference_block(f, w, dt, g, travel, rotate, translate, state, pos_out, q_out):
    """The references' steps over a block (compiled): ``f``, ``w`` (M, 3) the aircraft's specific force (m/s^2)
    and body rates (rad/s); ``state`` (10,) the attitude q (4, scalar first, body to inertial), the stage's position
    and velocity (3 + 3, inertial, m and m/s), updated in place; set points into ``pos_out`` (M, 3), clipped to
    ``travel`` (3,), and ``q_out`` (M, 4). ``rotate``: q turns at the body rates, ``q exp(w dt / 2)``;
    ``translate``: the stage integrates ``a = R f + [0, 0, g]`` (explicit: v, then p)."""
    for k in range(f.shape[0]):
        qw, qx, qy, qz = state[0], state[1], state[2], state[3]
        if rotate:
            wx, wy, wz = w[k, 0], w[k, 1], w[k, 2]
            angle = math.sqrt(wx * wx + wy * wy + wz * wz) * dt
            if angle < 1e-12:
                dw, dx, dy, dz = 1.0, 0.5 * dt * wx, 0.5 * dt * wy, 0.5 * dt * wz
            else:
                s = math.sin(0.5 * angle) * dt / angle
                dw, dx, dy, dz = math.cos(0.5 * angle), s * wx, s * wy, s * wz
            nw = qw * dw - qx * dx - qy * dy - qz * dz
            nx = qw * dx + qx * dw + qy * dz - qz * dy
            ny = qw * dy - qx * dz + qy * dw + qz * dx
            nz = qw * dz + qx * dy - qy * dx + qz * dw
            n = math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
            qw, qx, qy, qz = nw / n, nx / n, ny / n, nz / n
            state[0], state[1], state[2], state[3] = qw, qx, qy, qz
        if translate:
            fx, fy, fz = f[k, 0], f[k, 1], f[k, 2]
            ax = (1 - 2 * (qy * qy + qz * qz)) * fx + 2 * (qx * qy - qw * qz) * fy + 2 * (qx * qz + qw * qy) * fz
            ay = 2 * (qx * qy + qw * qz) * fx + (1 - 2 * (qx * qx + qz * qz)) * fy + 2 * (qy * qz - qw * qx) * fz
            az = 2 * (qx * qz - qw * qy) * fx + 2 * (qy * qz + qw * qx) * fy + (1 - 2 * (qx * qx + qy * qy)) * fz + g
            state[7] += ax * dt
            state[8] += ay * dt
            state[9] += az * dt
            state[4] += state[7] * dt
            state[5] += state[8] * dt
            state[6] += state[9] * dt
        for j in range(3):
            pos_out[k, j] = min(max(state[4 + j], -travel[j]), travel[j])
        q_out[k, 0], q_out[k, 1], q_out[k, 2], q_out[k, 3] = qw, qx, qy, qz


class _Reference:
    """A naive reference (module docstring): ``rotate`` (follow the aircraft's attitude), ``translate`` (drive the
    stage by the residual specific force)."""

    rotate = True
    translate = True

    def __init__(self, params: object, context: WashoutContext) -> None:
        self.dt = float(context.dt_s)
        self.g = float(context.gravity_mps2)
        travel = context.limits.translation.position_limit_m
        self.travel = np.array(travel.xyz, dtype=np.float64)
        self.state = np.zeros(10)
        self.state[0] = 1.0

    def start(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        self.state[:] = 0.0
        self.state[:4] = tilt_of(f_mps2)
        return np.zeros(3), self.state[:4].copy()

    def steps(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The next M samples' set points (M, 3) and (M, 4) (the block form)."""
        f = np.ascontiguousarray(f_mps2, dtype=np.float64).reshape(-1, 3)
        w = np.ascontiguousarray(omega_radps, dtype=np.float64).reshape(-1, 3)
        pos = np.empty((len(f), 3))
        q = np.empty((len(f), 4))
        announce_compile(reference_block)
        reference_block(f, w, self.dt, self.g, self.travel, self.rotate, self.translate, self.state, pos, q)
        return pos, q

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        pos, q = self.steps(f_mps2, omega_radps)
        return pos[0], q[0]

    def trace(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The whole-trace form: the steps' set points (N, 3) and (N, 4) for inputs (N, 3) each (after start)."""
        return self.steps(f_mps2, omega_radps)


class ReplayWashout(_Reference):
    """``replay``: the aircraft's attitude and, through the stage, the rest of its specific force, clipped."""


class ReplayRotationWashout(_Reference):
    """``replay-rotation``: the aircraft's attitude, the stage at its centre."""

    translate = False


class StillWashout(_Reference):
    """``still``: the platform at its first pose, never moving."""

    rotate = False
    translate = False


__all__ = ["REFERENCE_KINDS", "ReplayRotationWashout", "ReplayWashout", "StillWashout", "tilt_of"]
