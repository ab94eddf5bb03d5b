"""The platform stage: kinematic models of motion platforms, from a washout's set points to the pose reached.

One interface (``model``: ``Platform``, ``PlatformContext``, the loader that reads a platform file and picks the
model by its ``kind:`` key) and the models: the Atlas of Carleton University (``limits``, ``kinematics``: a
three-axis stage carrying a sphere that turns without limit on omni-wheels; the default, ``atlas.yaml``), a 6-6
Gough-Stewart hexapod (``hexapod``, ``hexapod_kinematics``: TU Delft's SIMONA bundled as ``hexapod.yaml``), 2- and
3-DOF rigs (``rig``, ``rig_kinematics``: ``rig2dof.yaml``) and a user's platform as a plugin (``plugins``:
``--platform-plugin FILE.py:NAME`` or the ``washbench.platforms`` entry points). ``docs/platforms.md`` has the
equations; the bundled files are named by ``--platform atlas|hexapod|rig2dof`` from any folder.

Frames and units: translation in the inertial NED frame (m, m/s, m/s^2); attitude as a body->inertial unit
quaternion, scalar first; body angular velocity in rad/s; the Atlas's wheel speeds in rad/s, a hexapod's leg
lengths in m. This package's own names are the Atlas's limits (below); the other models are imported from their
modules.
"""

from washbench.platform.limits import (
    DEFAULT_LIMITS_PATH,
    PlatformLimits,
    load_platform_limits,
    wheel_geometry,
    wheel_jacobian,
)

__all__ = ["DEFAULT_LIMITS_PATH", "PlatformLimits", "load_platform_limits", "wheel_geometry", "wheel_jacobian"]
