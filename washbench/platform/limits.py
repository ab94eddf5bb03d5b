"""Atlas platform limits and geometry: the typed, frozen model of ``washbench/data/atlas.yaml``.

Units are in the key names (m, m/s, m/s^2, deg/s, deg/s^2, deg); :func:`wheel_jacobian` returns SI.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import numpy as np
from pydantic import Field

from washbench.io.paths import DATA_DIR
from washbench.io.yamlio import StrictModel, load_yaml_model

DEFAULT_LIMITS_PATH = DATA_DIR / "atlas.yaml"

# Accepted ranges: a motion platform, not a planet. Absurd but finite limits (a travel of 1e300 m, an
# acceleration of 1e-300 m/s^2) are refused instead of being computed with.
Positive = Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)]  # m, m/s
Acceleration = Annotated[float, Field(ge=1e-3, le=1e3, allow_inf_nan=False)]  # m/s^2
Finite = Annotated[float, Field(ge=-360.0, le=360.0, allow_inf_nan=False)]  # deg


class Accelerations(StrictModel):
    """One acceleration limit per inertial axis x, y, z (m/s^2, 1e-3..1000)."""

    x: Acceleration
    y: Acceleration
    z: Acceleration

    @property
    def xyz(self) -> tuple[float, float, float]:
        """The three values in axis order (x, y, z)."""
        return (self.x, self.y, self.z)


class Axes(StrictModel):
    """One positive value per inertial axis x (north), y (east), z (down)."""

    x: Positive
    y: Positive
    z: Positive

    @property
    def xyz(self) -> tuple[float, float, float]:
        """The three values in axis order (x, y, z)."""
        return (self.x, self.y, self.z)


class Translation(StrictModel):
    """Three-axis translational stage: symmetric limits about the centre, per axis."""

    position_limit_m: Axes
    velocity_limit_mps: Axes
    acceleration_limit_mps2: Accelerations


class Rotation(StrictModel):
    """Cockpit sphere: unlimited attitude, limited angular velocity and acceleration (norms)."""

    rate_limit_degps: Annotated[float, Field(gt=0.0, le=3600.0, allow_inf_nan=False)]
    acceleration_limit_degps2: Annotated[float, Field(ge=0.01, le=1e5, allow_inf_nan=False)]
    catch_up_fraction: Annotated[float, Field(gt=0.0, le=1.0)]


class Wheels(StrictModel):
    """The three omni-wheels that drive the sphere."""

    radius_m: Annotated[float, Field(gt=0.0, le=10.0, allow_inf_nan=False)]
    azimuth_deg: tuple[Finite, Finite, Finite]
    below_equator_deg: Annotated[float, Field(gt=0.0, lt=90.0)]


class PlatformLimits(StrictModel):
    """Kinematic Atlas model parameters."""

    name: str
    translation: Translation
    rotation: Rotation
    sphere_diameter_m: Positive
    wheels: Wheels


def load_platform_limits(path: Path | None = None) -> PlatformLimits:
    """Load platform limits YAML (``None``: the bundled Atlas file, ``washbench/data/atlas.yaml``).

    Raises :class:`washbench.errors.WashbenchError` with ``file:line: field: problem`` on bad input.
    """
    return load_yaml_model(DEFAULT_LIMITS_PATH if path is None else Path(path), PlatformLimits)


def wheel_geometry(limits: PlatformLimits) -> tuple[np.ndarray, np.ndarray]:
    """Contact points r_i (3, 3) in m and rolling directions d_i (3, 3), unit, gantry frame (NED-aligned).

    Wheel i touches the sphere at azimuth a_i (from north towards east) and elevation e below the
    equator: r_i = R [cos e cos a_i, cos e sin a_i, sin e] (z down, so below the centre). It rolls
    horizontally along the azimuthal direction d_i = [-sin a_i, cos a_i, 0].
    """
    radius = 0.5 * limits.sphere_diameter_m
    e = math.radians(limits.wheels.below_equator_deg)
    r = np.empty((3, 3))
    d = np.empty((3, 3))
    for i, az_deg in enumerate(limits.wheels.azimuth_deg):
        a = math.radians(az_deg)
        r[i] = radius * np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
        d[i] = [-math.sin(a), math.cos(a), 0.0]
    return r, d


def wheel_jacobian(limits: PlatformLimits) -> np.ndarray:
    """J (3, 3): wheel angular speeds (rad/s) = J @ omega_I, sphere angular velocity in the gantry frame (rad/s).

    Wheel surface speed = (omega x r_i) . d_i = omega . (r_i x d_i) (no slip), divided by the wheel radius.
    A positive wheel speed means the sphere's surface at the contact moves along +d_i.
    """
    r, d = wheel_geometry(limits)
    return np.cross(r, d) / limits.wheels.radius_m
