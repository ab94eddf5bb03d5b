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

Integration is the bench's own (explicit, one sample at a time); nothing is tuned. Each has the whole-trace form
(``trace``), the same numbers as its steps.
"""

from __future__ import annotations

import math

import numpy as np

from washbench.cueing.algorithm import SetPoint, WashoutContext

REFERENCE_KINDS = ("replay", "replay-rotation", "still")
"""The naive references' washout names (module docstring)."""


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


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw])  # fmt: skip


def _qexp(w_radps: np.ndarray, dt_s: float) -> np.ndarray:
    """exp(omega dt / 2) (4,): the rotation by body rate ``omega`` held over ``dt``."""
    angle = float(np.linalg.norm(w_radps)) * dt_s
    if angle < 1e-12:
        return np.array([1.0, 0.5 * dt_s * w_radps[0], 0.5 * dt_s * w_radps[1], 0.5 * dt_s * w_radps[2]])
    axis = np.asarray(w_radps) * (dt_s / angle)
    s = math.sin(0.5 * angle)
    return np.array([math.cos(0.5 * angle), s * axis[0], s * axis[1], s * axis[2]])


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """q v q* (3,): a body vector in inertial axes."""
    w, x, y, z = q
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])  # fmt: skip
    return r @ v


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
        self.q = np.array([1.0, 0.0, 0.0, 0.0])
        self.p = np.zeros(3)
        self.v = np.zeros(3)

    def start(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        self.q = tilt_of(f_mps2)
        self.p = np.zeros(3)
        self.v = np.zeros(3)
        return self.p.copy(), self.q.copy()

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        if self.rotate:
            q = _qmul(self.q, _qexp(np.asarray(omega_radps, dtype=np.float64), self.dt))
            self.q = q / np.linalg.norm(q)
        if self.translate:
            a = _rotate(self.q, np.asarray(f_mps2, dtype=np.float64)) + np.array([0.0, 0.0, self.g])
            self.v = self.v + a * self.dt
            self.p = self.p + self.v * self.dt
        return np.clip(self.p, -self.travel, self.travel), self.q.copy()

    def trace(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The whole-trace form: the steps' set points (N, 3) and (N, 4) for inputs (N, 3) each."""
        n = len(f_mps2)
        pos = np.empty((n, 3))
        q = np.empty((n, 4))
        for k in range(n):
            pos[k], q[k] = self.step(f_mps2[k], omega_radps[k])
        return pos, q


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
