"""The recorded pilot-head motion the washouts take in (:class:`Motion`), and the limits of its numbers.

Read from a file by :func:`washbench.io.motion_file.read_motion` (washbench's own columns,
:data:`washbench.io.columns.INPUT_COLUMNS`) or, mapped, resampled and split, by :mod:`washbench.io.readers` and
:mod:`washbench.io.resample`; built in memory by the flight pipeline.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: Time steps an input motion may have, s: beyond, the filters cannot be discretised (a subnormal step, or one of
#: 8e307 s, overflows them). Wide on purpose: a time column in ms or ns read as seconds still passes, and the
#: plausibility warnings (:mod:`washbench.io.plausibility`) say so.
DT_RANGE_S = (1e-6, 1e7)
#: Largest magnitudes accepted in the motion columns (10,000 g and 100,000 deg/s): no sensor records more, and
#: such numbers only make the platform model meaningless. Crashes and spikes well below are reported by the
#: plausibility checks.
F_MAX_MPS2 = 1e5
OMEGA_MAX_DEGPS = 1e5


@dataclass(frozen=True, eq=False)
class Motion:
    """A recorded pilot-head motion on a uniform time grid.

    ``t_s`` (N,) [s]; ``dt_s`` the time step [s]; ``f_mps2`` (N, 3) specific force [m/s^2] and
    ``omega_radps`` (N, 3) angular velocity [rad/s], body axes; ``extra`` other columns by name
    (passed through to results). ``omega_degps`` keeps the angular velocity exactly as read
    (deg/s) so it can be written back bit for bit; ``None`` when built in memory.
    """

    t_s: np.ndarray
    dt_s: float
    f_mps2: np.ndarray
    omega_radps: np.ndarray
    extra: dict[str, np.ndarray] = field(default_factory=dict)
    omega_degps: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = self.t_s.shape[0] if self.t_s.ndim == 1 else -1
        if n < 2:
            raise ValueError(f"t_s must be 1-D with at least 2 samples, got shape {self.t_s.shape}")
        for name in ("f_mps2", "omega_radps"):
            shape = getattr(self, name).shape
            if shape != (n, 3):
                raise ValueError(f"{name} must have shape ({n}, 3), got {shape}")
        if self.omega_degps is not None and self.omega_degps.shape != (n, 3):
            raise ValueError(f"omega_degps must have shape ({n}, 3), got {self.omega_degps.shape}")
        for name, col in self.extra.items():
            if len(col) != n:
                raise ValueError(f"extra column {name!r} has {len(col)} rows, expected {n}")
        if not (self.dt_s > 0.0 and math.isfinite(self.dt_s)):
            raise ValueError(f"dt_s must be positive and finite, got {self.dt_s}")

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.t_s.shape[0])

    @property
    def duration_s(self) -> float:
        """Time from the first to the last sample [s]."""
        return float(self.t_s[-1] - self.t_s[0])

    def omega_degps_out(self) -> np.ndarray:
        """Angular velocity in deg/s for output: the values as read if known, else converted."""
        return self.omega_degps if self.omega_degps is not None else np.degrees(self.omega_radps)
