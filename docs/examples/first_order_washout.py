"""A worked example of a washout plugin for washbench: a first-order washout with tilt coordination.

Load it with ``washbench run c172/takeoff --washout-plugin docs/examples/first_order_washout.py:FirstOrder
--washout first-order`` (or through the ``washbench.washouts`` entry-point group of an installed package); its
parameters are the ``first-order:`` section of the parameter file. See docs/washouts.md.

Per axis: the platform's acceleration set point is the aircraft's specific force change (body axes, taken as
inertial: a small-angle simplification), scaled and high-passed to first order, k s/(s + w), then integrated twice
with leaks at w so the stage drifts back to centre; the sustained part of f_x and f_y becomes a tilt of the
cockpit, theta = asin(f_x / g) (and phi = -asin(f_y / g)), low-passed to first order and rate-limited;
body rates are scaled and high-passed to first order and integrated into the attitude set point.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field


class Params(BaseModel):
    """The ``first-order:`` section of the parameter file."""

    model_config = ConfigDict(extra="forbid")

    scale: float = Field(0.5, gt=0.0, le=1.0)
    """Gain on the aircraft's specific force and angular velocity (dimensionless)."""
    highpass_wn_radps: float = Field(1.0, gt=0.0, le=100.0)
    """Break frequency w of the first-order high-passes s/(s + w), rad/s."""
    tilt_wn_radps: float = Field(0.5, gt=0.0, le=100.0)
    """Break frequency of the tilt's first-order low-pass, rad/s."""
    tilt_rate_limit_degps: float = Field(3.0, gt=0.0, le=90.0)
    """The tilt's rate limit, deg/s."""


def _quat_from_euler(phi: float, theta: float, psi: float) -> np.ndarray:
    """Body->inertial quaternion, scalar first, from ZYX Euler angles (rad)."""
    cr, sr = math.cos(phi / 2), math.sin(phi / 2)
    cp, sp = math.cos(theta / 2), math.sin(theta / 2)
    cy, sy = math.cos(psi / 2), math.sin(psi / 2)
    w = cr * cp * cy + sr * sp * sy
    x = sr * cp * cy - cr * sp * sy
    y = cr * sp * cy + sr * cp * sy
    z = cr * cp * sy - sr * sp * cy
    return np.array([w, x, y, z])


class FirstOrder:
    """The algorithm: made once per run with its parameters and the run's context (dt, g, platform limits)."""

    washout_name = "first-order"
    Params = Params

    def __init__(self, params: Params, context) -> None:
        self.p = params
        self.dt = context.dt_s
        self.g = context.gravity_mps2
        self.a = math.exp(-params.highpass_wn_radps * self.dt)  # discrete pole of s/(s + w)
        self.b = math.exp(-params.tilt_wn_radps * self.dt)

    def _tilt_target(self, f: np.ndarray) -> tuple[float, float]:
        fx = max(-1.0, min(1.0, self.p.scale * f[0] / self.g))
        fy = max(-1.0, min(1.0, self.p.scale * f[1] / self.g))
        return -math.asin(fy), math.asin(fx)  # roll, pitch that make gravity give f_x, f_y

    def start(self, f, omega):
        self.f_prev = np.array(f, dtype=float)
        self.w_prev = np.array(omega, dtype=float)
        self.acc_hp = np.zeros(3)
        self.rate_hp = np.zeros(3)
        self.vel = np.zeros(3)
        self.pos = np.zeros(3)
        self.tilt = np.array(self._tilt_target(f))
        self.euler = np.zeros(3)  # the rotational channel's angles (roll, pitch, yaw)
        return self.pos.copy(), _quat_from_euler(self.tilt[0], self.tilt[1], 0.0)

    def step(self, f, omega):
        s, dt = self.p.scale, self.dt
        # first-order high-pass y_k = a (y_{k-1} + u_k - u_{k-1}) on the specific force change and the body rates
        self.acc_hp = self.a * (self.acc_hp + s * (f - self.f_prev))
        self.rate_hp = self.a * (self.rate_hp + s * (omega - self.w_prev))
        self.f_prev = np.array(f, dtype=float)
        self.w_prev = np.array(omega, dtype=float)
        # leaky double integration: velocity and position decay at the high-pass frequency (back to centre)
        w = self.p.highpass_wn_radps
        self.vel = self.vel * (1.0 - w * dt) + self.acc_hp * dt
        self.pos = self.pos * (1.0 - w * dt) + self.vel * dt
        # tilt: first-order low-pass toward the target, rate-limited
        target = np.array(self._tilt_target(f))
        step = (1.0 - self.b) * (target - self.tilt)
        limit = math.radians(self.p.tilt_rate_limit_degps) * dt
        self.tilt += np.clip(step, -limit, limit)
        self.euler += self.rate_hp * dt  # small-angle integration of the high-passed rates
        q = _quat_from_euler(self.tilt[0] + self.euler[0], self.tilt[1] + self.euler[1], self.euler[2])
        return self.pos.copy(), q
