"""6-6 Gough-Stewart hexapod: the typed, frozen model of a ``kind: hexapod`` platform file, and its legs in numpy.

The file's keys (SI; frames in docs/platforms.md)::

    kind: hexapod
    name: ...
    base_joints_m: [[x, y, z], ...]       # six points; base frame = inertial NED, origin at the base centre
    platform_joints_m: [[x, y, z], ...]   # six points; cockpit body axes, origin at the motion reference point
    neutral_m: [x, y, z]                  # the motion reference point at neutral, base frame
    leg_length_m: {min: ..., max: ...}    # joint-to-joint length of every leg
    leg_velocity_limit_mps: ...
    leg_acceleration_limit_mps2: ...

Leg i joins base joint i to platform joint i. The compiled step is :mod:`washbench.platform.hexapod_kinematics`.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from washbench.io.yamlio import StrictModel
from washbench.platform.limits import Accelerations, Axes, Rotation, Translation

Coordinate = Annotated[float, Field(ge=-50.0, le=50.0, allow_inf_nan=False)]  # m
Point = tuple[Coordinate, Coordinate, Coordinate]
Six = Annotated[list[Point], Field(min_length=6, max_length=6)]
Length = Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)]  # m

STROKE_MARGIN_M = 1e-9
"""The legs are kept this far inside their stroke (so a leg recomputed from the pose rounds inside it)."""
RATE_MARGIN = 1e-9
"""... and their velocity and acceleration this fraction inside their limits."""
CATCH_UP_FRACTION = 0.5
"""After a saturation each leg closes its lag with at most this fraction of its acceleration limit (as the
Atlas file's ``catch_up_fraction``; assumed, not a file key)."""


class LegLength(StrictModel):
    """Joint-to-joint length of every leg, m: fully retracted (min) and fully extended (max)."""

    min: Length
    max: Length


class HexapodModel(StrictModel):
    """A 6-6 Gough-Stewart hexapod (the module docstring gives the keys, units and frames)."""

    kind: Literal["hexapod"]
    name: str
    base_joints_m: Six
    platform_joints_m: Six
    neutral_m: Point
    leg_length_m: LegLength
    leg_velocity_limit_mps: Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)]
    leg_acceleration_limit_mps2: Annotated[float, Field(ge=1e-3, le=1e3, allow_inf_nan=False)]

    @model_validator(mode="after")
    def _check(self) -> HexapodModel:
        lo, hi = self.leg_length_m.min, self.leg_length_m.max
        if not hi > lo + 4 * STROKE_MARGIN_M:
            raise ValueError(f"leg_length_m: max ({hi}) must exceed min ({lo})")
        legs = leg_lengths(self, np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0, 0.0]]))[0]
        for i, li in enumerate(legs):
            if not lo + STROKE_MARGIN_M < li < hi - STROKE_MARGIN_M:
                raise ValueError(
                    f"neutral_m: at neutral leg {i + 1} is {li:.4f} m long, outside leg_length_m {lo:g}..{hi:g} m"
                )
        jac = leg_jacobian(self, np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
        if np.linalg.matrix_rank(jac, tol=1e-6) < 6:
            raise ValueError("the joints make a singular hexapod at neutral (its legs cannot hold every pose)")
        return self

    def geometry(self) -> np.ndarray:
        """The compiled step's ``geo`` array (:mod:`washbench.platform.hexapod_kinematics`), (42,) float64."""
        return np.concatenate([
            np.asarray(self.base_joints_m, dtype=np.float64).ravel(),
            np.asarray(self.platform_joints_m, dtype=np.float64).ravel(),
            np.asarray(self.neutral_m, dtype=np.float64),
            [self.leg_length_m.min, self.leg_length_m.max, STROKE_MARGIN_M],
        ])  # fmt: skip

    def envelope(self) -> MotionEnvelope:
        """An Atlas-shaped box of limits about neutral for washouts that plan against one (the MPC): per axis the
        pure translation that brings a leg to its stroke, and the speed and acceleration along that axis, and the
        angular rate (norm, any axis) that make the most affected leg reach its limit at neutral. Inside the box
        the hexapod is not guaranteed to follow (the legs couple the axes); the hexapod's own limits always hold."""
        jac = leg_jacobian(self, np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
        # the six searches (each axis, each way) side by side: one leg_lengths call of six poses per halving
        axis = np.repeat(np.arange(3), 2)
        sign = np.tile([1.0, -1.0], 3)
        lo, hi = np.zeros(6), np.full(6, 50.0)
        upright = np.tile([1.0, 0.0, 0.0, 0.0], (6, 1))
        p = np.zeros((6, 3))
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            p[np.arange(6), axis] = sign * mid
            legs = leg_lengths(self, p, upright)
            ok = np.all((legs >= self.leg_length_m.min) & (legs <= self.leg_length_m.max), axis=1)
            lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
        reach = [max(min(lo[2 * i], lo[2 * i + 1]), 1e-3) for i in range(3)]
        trans = np.abs(jac[:, :3]).max(axis=0)
        rot = np.linalg.norm(jac[:, 3:], axis=1).max()
        v, a = self.leg_velocity_limit_mps, self.leg_acceleration_limit_mps2
        return MotionEnvelope(
            name=f"{self.name} (box about neutral)",
            translation=Translation(
                position_limit_m=Axes(x=reach[0], y=reach[1], z=reach[2]),
                velocity_limit_mps=Axes(
                    x=min(100.0, v / trans[0]), y=min(100.0, v / trans[1]), z=min(100.0, v / trans[2])
                ),
                acceleration_limit_mps2=Accelerations(
                    x=min(1e3, a / trans[0]), y=min(1e3, a / trans[1]), z=min(1e3, a / trans[2])
                ),
            ),
            rotation=Rotation(
                rate_limit_degps=min(3600.0, math.degrees(v / rot)),
                acceleration_limit_degps2=min(1e5, math.degrees(a / rot)),
                catch_up_fraction=CATCH_UP_FRACTION,
            ),
        )


class MotionEnvelope(StrictModel):
    """Atlas-shaped limits (a box for the translation, norms for the rotation) that stand for a platform of another
    kind in a washout that plans against them (:attr:`washbench.cueing.algorithm.WashoutContext.limits`)."""

    name: str
    translation: Translation
    rotation: Rotation


def leg_lengths(model: HexapodModel, pos_m: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Leg lengths (N, 6), m, of poses ``pos_m`` (N, 3) (the MRP from neutral, NED) and ``q`` (N, 4) (body ->
    inertial, scalar first): |n + p + R(q) a_i - b_i| (numpy; the compiled step has its own)."""
    b = np.asarray(model.base_joints_m, dtype=np.float64)
    a = np.asarray(model.platform_joints_m, dtype=np.float64)
    n = np.asarray(model.neutral_m, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    w, v = q[:, :1], q[:, 1:]
    base = n + np.asarray(pos_m, dtype=np.float64)
    out = np.empty((len(q), 6))
    for i in range(6):
        t = 2.0 * _cross(v, a[i])
        ra = a[i] + w * t + _cross(v, t)
        d = base + ra - b[i]
        out[:, i] = np.sqrt(np.add.reduce(d * d, axis=1))
    return out


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """u x v of rows (N, 3) and (N, 3) or (3,): ``np.cross``'s products and differences, without its
    broadcasting set-up (which cost more than the arithmetic on the envelope's few poses)."""
    u0, u1, u2 = u[..., 0], u[..., 1], u[..., 2]
    v0, v1, v2 = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0], axis=-1)


def leg_jacobian(model: HexapodModel, pos_m: np.ndarray, q: np.ndarray) -> np.ndarray:
    """d(legs)/d(p, theta) (6, 6) at one pose: row i = [u_i, (R a_i) x u_i] (theta: a small rotation about inertial
    axes), m per m and m per rad."""
    b = np.asarray(model.base_joints_m, dtype=np.float64)
    a = np.asarray(model.platform_joints_m, dtype=np.float64)
    n = np.asarray(model.neutral_m, dtype=np.float64)
    w, v = float(q[0]), np.asarray(q[1:], dtype=np.float64)
    jac = np.empty((6, 6))
    for i in range(6):
        t = 2.0 * np.cross(v, a[i])
        ra = a[i] + w * t + np.cross(v, t)
        d = n + pos_m + ra - b[i]
        u = d / np.linalg.norm(d)
        jac[i, :3] = u
        jac[i, 3:] = np.cross(ra, u)
    return jac


__all__ = ["HexapodModel", "MotionEnvelope", "leg_jacobian", "leg_lengths"]
