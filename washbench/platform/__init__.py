"""Kinematic model of the Atlas motion platform: limits (``atlas.yaml``), set-point tracking, omni-wheels.

Frames and units: translational stage in the inertial NED frame (m, m/s, m/s^2); sphere attitude as a
body->inertial unit quaternion, scalar first; body angular velocity in rad/s; wheel speeds in rad/s.
"""

from washbench.platform.limits import (
    DEFAULT_LIMITS_PATH,
    PlatformLimits,
    load_platform_limits,
    wheel_geometry,
    wheel_jacobian,
)

__all__ = ["DEFAULT_LIMITS_PATH", "PlatformLimits", "load_platform_limits", "wheel_geometry", "wheel_jacobian"]
