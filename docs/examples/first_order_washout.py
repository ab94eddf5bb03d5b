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


def _quat_from_euler(phi: float, theta: float, psi: float) -> tuple[float, float, float, float]:
    """Body->inertial quaternion, scalar first, from ZYX Euler angles (rad)."""
    cr, sr = math.cos(phi / 2), math.sin(phi / 2)
    cp, sp = math.cos(theta / 2), math.sin(theta / 2)
    cy, sy = math.cos(psi / 2), math.sin(psi / 2)
    w = cr * cp * cy + sr * sp * sy
    x = sr * cp * cy - cr * sp * sy
    y = cr * sp * cy + sr * cp * sy
    z = cr * cp * sy - sr * sp * cy
    return (w, x, y, z)


class FirstOrder:
    """The algorithm: made once per run with its parameters and the run's context (dt, g, platform limits).

    Plain floats rather than numpy arrays inside: a step on three numbers is several times faster that way.
    """

    washout_name = "first-order"
    Params = Params

    def __init__(self, params: Params, context) -> None:
        self.p = params
        self.dt = context.dt_s
        self.g = context.gravity_mps2
        self.a = math.exp(-params.highpass_wn_radps * self.dt)  # discrete pole of s/(s + w)
        self.b = math.exp(-params.tilt_wn_radps * self.dt)
        self.leak = 1.0 - params.highpass_wn_radps * self.dt
        self.max_tilt_step = math.radians(params.tilt_rate_limit_degps) * self.dt

    def _tilt_target(self, f) -> tuple[float, float]:
        fx = max(-1.0, min(1.0, self.p.scale * float(f[0]) / self.g))
        fy = max(-1.0, min(1.0, self.p.scale * float(f[1]) / self.g))
        return -math.asin(fy), math.asin(fx)  # roll, pitch that make gravity give f_x, f_y

    def start(self, f, omega):
        self.f_prev = [float(v) for v in f]
        self.w_prev = [float(v) for v in omega]
        self.acc_hp = [0.0, 0.0, 0.0]
        self.rate_hp = [0.0, 0.0, 0.0]
        self.vel = [0.0, 0.0, 0.0]
        self.pos = [0.0, 0.0, 0.0]
        self.tilt = list(self._tilt_target(f))
        self.euler = [0.0, 0.0, 0.0]  # the rotational channel's angles (roll, pitch, yaw)
        return tuple(self.pos), _quat_from_euler(self.tilt[0], self.tilt[1], 0.0)

    def step(self, f, omega):
        s, dt, a, leak = self.p.scale, self.dt, self.a, self.leak
        for j in range(3):
            fj, wj = float(f[j]), float(omega[j])
            # first-order high-pass y_k = a (y_{k-1} + u_k - u_{k-1}) on the specific force change and the body rates
            self.acc_hp[j] = a * (self.acc_hp[j] + s * (fj - self.f_prev[j]))
            self.rate_hp[j] = a * (self.rate_hp[j] + s * (wj - self.w_prev[j]))
            self.f_prev[j] = fj
            self.w_prev[j] = wj
            # leaky double integration: velocity and position decay at the high-pass frequency (back to centre)
            self.vel[j] = self.vel[j] * leak + self.acc_hp[j] * dt
            self.pos[j] = self.pos[j] * leak + self.vel[j] * dt
            self.euler[j] += self.rate_hp[j] * dt  # small-angle integration of the high-passed rates
        # tilt: first-order low-pass toward the target, rate-limited
        target = self._tilt_target(f)
        for j in range(2):
            step = (1.0 - self.b) * (target[j] - self.tilt[j])
            self.tilt[j] += max(-self.max_tilt_step, min(self.max_tilt_step, step))
        q = _quat_from_euler(self.tilt[0] + self.euler[0], self.tilt[1] + self.euler[1], self.euler[2])
        return tuple(self.pos), q
