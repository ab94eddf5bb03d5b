"""Perception thresholds, applied as a dead band to the vestibular model outputs (off by default).

Values: Zacharias, G. L., "Motion cue models for pilot-vehicle analysis", Bolt Beranek and
Newman report, 1978, as used with the Meiry-Young otolith and Young-Oman canal models by
Reid and Nahon (1985, Part 1) and tabulated by Telban and Cardullo (NASA CR-2005-213747):

====================  ================
specific force x, y   0.17 m/s^2
specific force z      0.28 m/s^2
roll rate             3.0 deg/s
pitch rate            3.6 deg/s
yaw rate              2.6 deg/s
====================  ================

(Quoted from those secondary sources; the 1978 report itself was not available to check.)

The dead band is continuous: a perceived deviation ``d`` below the threshold ``T`` becomes 0 and
a larger one becomes ``sign(d) (|d| - T)``. For angular velocity the deviation is from zero. For
specific force it is from the resting value ``[0, 0, -g]``, so a pilot sitting still in 1 g
perceives exactly ``[0, 0, -g]`` and small changes of heave around it are below threshold.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

from washbench.io.yamlio import StrictModel

STANDARD_GRAVITY_MPS2 = 9.80665
"""Resting specific force magnitude used as the dead band's reference for heave [m/s^2]."""


class Thresholds(StrictModel):
    """Perception thresholds per body axis (defaults: Zacharias 1978, see module docstring)."""

    f_x_mps2: float = Field(default=0.17, ge=0.0)
    f_y_mps2: float = Field(default=0.17, ge=0.0)
    f_z_mps2: float = Field(default=0.28, ge=0.0)
    omega_x_degps: float = Field(default=3.0, ge=0.0)
    omega_y_degps: float = Field(default=3.6, ge=0.0)
    omega_z_degps: float = Field(default=2.6, ge=0.0)

    def f_mps2(self) -> np.ndarray:
        """Specific force thresholds (3,) [m/s^2]."""
        return np.array([self.f_x_mps2, self.f_y_mps2, self.f_z_mps2])

    def omega_radps(self) -> np.ndarray:
        """Angular velocity thresholds (3,) [rad/s]."""
        return np.array([self.omega_x_degps, self.omega_y_degps, self.omega_z_degps]) * (math.pi / 180.0)


ZACHARIAS = Thresholds()
"""The default (Zacharias 1978) thresholds."""


def deadband(x: np.ndarray, threshold: np.ndarray, reference: np.ndarray | float = 0.0) -> np.ndarray:
    """Continuous dead band of ``x`` around ``reference``: ``ref + sign(d) * max(|d| - T, 0)``, ``d = x - ref``.

    ``threshold`` and ``reference`` broadcast against ``x`` (e.g. (3,) against (N, 3)).
    """
    d = np.asarray(x, dtype=np.float64) - reference
    return reference + np.sign(d) * np.maximum(np.abs(d) - threshold, 0.0)


def apply_deadband(f_mps2: np.ndarray, omega_radps: np.ndarray, th: Thresholds) -> tuple[np.ndarray, np.ndarray]:
    """Dead band on perceived specific force (around ``[0, 0, -g]``) and angular velocity (around 0), (N, 3) each."""
    rest = np.array([0.0, 0.0, -STANDARD_GRAVITY_MPS2])
    return deadband(f_mps2, th.f_mps2(), rest), deadband(omega_radps, th.omega_radps(), 0.0)
