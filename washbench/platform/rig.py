"""2- and 3-DOF motion rigs (roll and pitch, optionally heave or yaw): the typed, frozen model of a ``kind: rig``
platform file.

The file (units in the key names; frames in docs/platforms.md)::

    kind: rig
    name: ...
    roll:  {angle_limit_deg: ..., rate_limit_degps: ..., acceleration_limit_degps2: ...}
    pitch: {angle_limit_deg: ..., rate_limit_degps: ..., acceleration_limit_degps2: ...}
    yaw:   {angle_limit_deg: ..., rate_limit_degps: ..., acceleration_limit_degps2: ...}   # optional
    heave: {position_limit_m: ..., velocity_limit_mps: ..., acceleration_limit_mps2: ...}  # optional
    catch_up_fraction: 0.5                                                                  # optional

Each rotational axis is a gimbal of the ZYX Euler sequence (yaw, then pitch, then roll) turning the cockpit about its
motion reference point; heave moves it along the inertial down axis. An axis the file leaves out stays at zero.
The compiled step is :mod:`washbench.platform.rig_kinematics`.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from washbench.io.yamlio import StrictModel
from washbench.platform.hexapod import MotionEnvelope
from washbench.platform.limits import Accelerations, Axes, Rotation, Translation

NRIG = 12
"""The compiled step's ``rig`` array: (angle rad, rate rad/s, acceleration rad/s^2) for roll, pitch, yaw, then
(position m, velocity m/s, acceleration m/s^2) for heave; an absent axis has zeros."""


class RotationalAxis(StrictModel):
    """One rotational axis: symmetric angle limit about level, rate and acceleration limits."""

    angle_limit_deg: Annotated[float, Field(gt=0.0, le=180.0, allow_inf_nan=False)]
    rate_limit_degps: Annotated[float, Field(gt=0.0, le=3600.0, allow_inf_nan=False)]
    acceleration_limit_degps2: Annotated[float, Field(ge=0.01, le=1e5, allow_inf_nan=False)]


class HeaveAxis(StrictModel):
    """Heave: symmetric travel about neutral, velocity and acceleration limits (inertial down axis)."""

    position_limit_m: Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)]
    velocity_limit_mps: Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)]
    acceleration_limit_mps2: Annotated[float, Field(ge=1e-3, le=1e3, allow_inf_nan=False)]


class RigModel(StrictModel):
    """A 2- or 3-DOF rig (the module docstring gives the keys, units and frames)."""

    kind: Literal["rig"]
    name: str
    roll: RotationalAxis
    pitch: RotationalAxis
    yaw: RotationalAxis | None = None
    heave: HeaveAxis | None = None
    catch_up_fraction: Annotated[float, Field(gt=0.0, le=1.0)] = 0.5

    def limits_array(self) -> np.ndarray:
        """The compiled step's ``rig`` array (:data:`NRIG`,), SI."""
        out = np.zeros(NRIG)
        for j, ax in enumerate((self.roll, self.pitch, self.yaw)):
            if ax is not None:
                out[3 * j : 3 * j + 3] = [math.radians(ax.angle_limit_deg), math.radians(ax.rate_limit_degps),
                                          math.radians(ax.acceleration_limit_degps2)]  # fmt: skip
        if self.heave is not None:
            h = self.heave
            out[9:12] = [h.position_limit_m, h.velocity_limit_mps, h.acceleration_limit_mps2]
        return out

    def envelope(self) -> MotionEnvelope:
        """Atlas-shaped limits for washouts that plan against a box (the MPC): no horizontal travel (1 mm), the
        heave's limits (or 1 mm), the slowest present rotational axis's rate and acceleration."""
        h = self.heave
        tiny = 1e-3
        axes = [a for a in (self.roll, self.pitch, self.yaw) if a is not None]
        return MotionEnvelope(
            name=f"{self.name} (box)",
            translation=Translation(
                position_limit_m=Axes(x=tiny, y=tiny, z=h.position_limit_m if h else tiny),
                velocity_limit_mps=Axes(x=tiny, y=tiny, z=h.velocity_limit_mps if h else tiny),
                acceleration_limit_mps2=Accelerations(x=tiny, y=tiny, z=h.acceleration_limit_mps2 if h else tiny),
            ),
            rotation=Rotation(
                rate_limit_degps=min(a.rate_limit_degps for a in axes),
                acceleration_limit_degps2=min(a.acceleration_limit_degps2 for a in axes),
                catch_up_fraction=self.catch_up_fraction,
            ),
        )


__all__ = ["NRIG", "HeaveAxis", "RigModel", "RotationalAxis"]
